//! Scene files: the shipped ones load, a scene survives a round trip, and every kind of bad
//! scene fails with a message naming the file and the line/column or the ball.

use std::path::Path;

use ballpit::prelude::*;
use ballpit::sim::SceneError;
use ballpit::sim::scene::{BallSpec, audit_scene_text};
use bevy::math::DVec2;

use crate::common::*;

fn build(text: &str) -> Result<SceneSetup, SceneError> {
    SceneFile::parse(text, "bad.ron")?.build("bad.ron")
}

fn error_of(text: &str) -> String {
    match build(text) {
        Ok(_) => panic!("scene was accepted: {text}"),
        Err(error) => error.to_string(),
    }
}

#[test]
fn every_shipped_scene_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".ron"))
        .collect();
    names.sort();
    for name in [
        "billiards.ron",
        "gas.ron",
        "head_on.ron",
        "maxwell.ron",
        "newtons_cradle.ron",
        "tutorial.ron",
    ] {
        assert!(
            names.iter().any(|n| n == name),
            "{name} missing from {names:?}"
        );
    }
    for name in &names {
        let setup = shipped_scene(name)
            .build(name)
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(!setup.balls.is_empty(), "{name} has no balls");
    }
}

#[test]
fn the_standard_gas_matches_its_definition() {
    let setup = shipped_scene("gas.ron").build("gas.ron").unwrap();
    assert_eq!(setup.balls.len(), 1000);
    let ball_area: f64 = setup
        .balls
        .iter()
        .map(|b| std::f64::consts::PI * b.radius * b.radius)
        .sum();
    let arena = setup.params.arena_size;
    assert!((ball_area / (arena.x * arena.y) - 0.30).abs() < 1e-9);
    for b in &setup.balls {
        assert!((5.0..=15.0).contains(&b.radius));
        assert!(b.velocity.length() <= 500.0 + 1e-9);
    }
    let mean_speed = setup.balls.iter().map(|b| b.velocity.length()).sum::<f64>() / 1000.0;
    assert!((mean_speed - 250.0).abs() < 20.0, "mean speed {mean_speed}");
}

#[test]
fn balls_are_stored_in_space_order_and_keep_their_places_in_the_scene_as_ids() {
    let setup = shipped_scene("mixed.ron").build("mixed.ron").unwrap();
    let mut app = headless_app(DT);
    setup.apply(app.world_mut());
    let world = app.world_mut();
    let stored: Vec<(u32, BallState)> = world
        .query::<(&BallId, &Position, &Velocity, &Radius)>()
        .iter(world)
        .map(|(id, p, v, r)| (id.0, ball(p.x, p.y, v.x, v.y, r.0)))
        .collect();
    // Each id names the scene's ball of that place: the three hand-placed big ones first.
    assert_eq!(stored.len(), setup.balls.len());
    for (id, state) in &stored {
        assert_eq!(*state, setup.balls[*id as usize]);
    }
    // Stored row by row of cells (here 80 px, the big balls' diameter), so each ball lies
    // about a cell from the one stored before it, where in the scene's order (as drawn) it
    // lies half an arena away.
    let mean = |pairs: &mut dyn Iterator<Item = f64>| {
        let (sum, count) = pairs.fold((0.0, 0), |(s, n), d| (s + d, n + 1));
        sum / count as f64
    };
    let apart = |balls: &[BallState]| {
        mean(
            &mut balls
                .windows(2)
                .map(|w| w[0].position.distance(w[1].position)),
        )
    };
    let in_storage: Vec<BallState> = stored.iter().map(|(_, state)| *state).collect();
    let (stored_apart, drawn_apart) = (apart(&in_storage), apart(&setup.balls));
    assert!(
        stored_apart < drawn_apart / 5.0,
        "{stored_apart} vs {drawn_apart}"
    );
}

#[test]
fn head_on_scene_is_the_worked_example() {
    let (mut app, _) = run_scene(
        &shipped_scene("head_on.ron").build("head_on").unwrap(),
        200,
        DT,
    );
    let balls = states(&mut app);
    assert!((balls[0].velocity.x + 1.0).abs() < 1e-12);
    assert!((balls[1].velocity.x - 5.0).abs() < 1e-12);
}

#[test]
fn scene_survives_a_round_trip() {
    for name in ["billiards.ron", "gas.ron", "tutorial.ron"] {
        let scene = shipped_scene(name);
        let text = scene.to_ron();
        assert_eq!(SceneFile::parse(&text, name).unwrap(), scene, "{text}");
    }
}

#[test]
fn optional_fields_take_their_defaults_and_some_is_optional() {
    let setup = build("(balls: [(position: (0.0, 0.0), radius: 3.0)])").unwrap();
    assert_eq!(setup.params.arena_size, DVec2::new(800.0, 600.0));
    assert_eq!(setup.params.restitution, 1.0);
    assert_eq!(setup.params.mass_model, MassModel::Radius);
    assert_eq!(setup.balls[0].velocity, DVec2::ZERO);
    let with_some =
        build("(generate: Some((count: 5, radius: (2, 3), speed: (0, 1), seed: 4)))").unwrap();
    let without = build("(generate: (count: 5, radius: (2, 3), speed: (0, 1), seed: 4))").unwrap();
    assert_eq!(with_some, without);
}

#[test]
fn syntax_errors_name_the_file_line_and_column() {
    let message = error_of("(\n  arena: (width: 800.0 height: 600.0),\n)");
    assert!(message.starts_with("bad.ron:2:"), "{message}");
}

#[test]
fn unknown_fields_are_refused_with_their_position() {
    let message = error_of("(\n  arena: (width: 8.0, height: 6.0),\n  gravty: (0.0, 1.0),\n)");
    assert!(message.starts_with("bad.ron:3:"), "{message}");
    assert!(message.contains("gravty"), "{message}");
}

#[test]
fn bad_radii_name_the_line_in_a_file_and_the_ball_in_code() {
    for radius in ["-1.0", "0.0", "NaN", "inf"] {
        let message = error_of(&format!(
            "(balls: [\n  (position: (0.0, 0.0), radius: 5.0),\n  (position: (100.0, 0.0), radius: {radius}),\n])"
        ));
        assert!(message.starts_with("bad.ron:3:"), "{radius}: {message}");
        assert!(message.contains("radius"), "{radius}: {message}");
    }
    // A scene built in code (or changed after parsing) is checked again when built.
    let mut scene =
        SceneFile::parse("(balls: [(position: (0.0, 0.0), radius: 5.0)])", "code").unwrap();
    scene.balls.push(BallSpec {
        position: (100.0, 0.0),
        velocity: (0.0, f64::NAN),
        radius: 5.0,
    });
    let message = scene.build("code").unwrap_err().to_string();
    assert!(message.starts_with("code: ball 1: velocity"), "{message}");
}

#[test]
fn balls_outside_the_arena_or_overlapping_are_refused() {
    let message = error_of(
        "(arena: (width: 100.0, height: 100.0), balls: [(position: (45.0, 0.0), radius: 10.0)])",
    );
    assert!(
        message.contains("ball 0") && message.contains("outside"),
        "{message}"
    );
    let message = error_of(
        "(balls: [(position: (0.0, 0.0), radius: 10.0), (position: (50.0, 0.0), radius: 5.0), \
          (position: (19.0, 0.0), radius: 10.0)])",
    );
    assert!(message.contains("balls 0 and 2 overlap"), "{message}");
}

#[test]
fn touching_balls_are_accepted() {
    // 1.65 - 0.55 rounds to a hair under 1.1: touching as written, accepted.
    let setup = build(
        "(balls: [(position: (0.55, 0.0), radius: 0.55), (position: (1.65, 0.0), radius: 0.55)])",
    );
    assert!(setup.is_ok(), "{:?}", setup.err());
}

#[test]
fn more_balls_than_fit_give_a_message_not_a_hang() {
    let message = error_of(
        "(arena: (width: 100.0, height: 100.0), generate: (count: 500, radius: (5, 5), speed: (0, 0)))",
    );
    assert!(message.contains("no packing"), "{message}");
    // Possible in principle, beyond what random placement reaches.
    let message =
        error_of("(generate: (count: 2000, radius: (5, 5), speed: (0, 0), area_fraction: 0.8))");
    assert!(message.contains("could not place"), "{message}");
    let message =
        error_of("(generate: (count: 2000000, radius: (5, 5), speed: (0, 0), area_fraction: 0.3))");
    assert!(message.contains("over the limit of 1000000"), "{message}");
}

#[test]
fn out_of_range_physics_is_refused() {
    assert!(error_of("(restitution: 1.5)").contains("bad.ron:1:15: restitution 1.5 is outside"));
    assert!(error_of("(restitution: -0.1)").contains("restitution"));
    assert!(error_of("(gravity: (0.0, NaN))").contains("gravity"));
    assert!(error_of("(linear_damping: -1.0)").contains("linear_damping"));
    assert!(error_of("(arena: (width: 0.0, height: 10.0))").contains("arena width"));
    assert!(
        error_of("(generate: (count: 5, radius: (6, 5), speed: (0, 1)))").contains("radius max")
    );
    assert!(
        error_of("(generate: (count: 5, radius: (5, 6), speed: (-1, 1)))").contains("speed min")
    );
    let both = "(arena: (width: 10.0, height: 10.0), generate: (count: 1, radius: (1, 1), speed: (0, 0), area_fraction: 0.1))";
    assert!(error_of(both).contains("not both"));
}

#[test]
fn missing_file_names_the_file() {
    let error = SceneFile::load(Path::new("no/such/scene.ron"))
        .unwrap_err()
        .to_string();
    assert!(
        error.starts_with("no/such/scene.ron: cannot read"),
        "{error}"
    );
}

#[test]
fn a_scene_may_choose_its_collision_mode() {
    let scene = SceneFile::parse(
        "(collisions: Discrete, balls: [(position: (0.0, 0.0), radius: 5.0)])",
        "mode.ron",
    )
    .unwrap();
    let setup = scene.build("mode.ron").unwrap();
    assert_eq!(setup.collisions, Some(CollisionMode::Discrete));
    let mut app = headless_app(1.0 / 60.0);
    setup.apply(app.world_mut());
    assert_eq!(
        app.world().resource::<Solver>().collisions,
        CollisionMode::Discrete
    );
    // Without the field the mode in use is kept.
    let plain = SceneFile::parse(
        "(balls: [(position: (0.0, 0.0), radius: 5.0)])",
        "plain.ron",
    )
    .unwrap();
    plain.build("plain.ron").unwrap().apply(app.world_mut());
    assert_eq!(
        app.world().resource::<Solver>().collisions,
        CollisionMode::Discrete
    );
    let error = SceneFile::parse("(\n  collisions: Sideways,\n)", "bad.ron").unwrap_err();
    assert!(error.to_string().starts_with("bad.ron:2:"), "{error}");
}

#[test]
fn fuzz_regressions_and_shipped_scenes_pass_the_fuzzer_audit() {
    // Every input the fuzzer ever failed on is kept in fuzz/regressions/ and replayed here.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut audited = 0;
    for folder in ["fuzz/regressions", "assets/scenes"] {
        for entry in std::fs::read_dir(root.join(folder)).unwrap() {
            let path = entry.unwrap().path();
            if path.file_name().is_some_and(|name| name == ".gitkeep") {
                continue;
            }
            let bytes = std::fs::read(&path).unwrap();
            let text = String::from_utf8_lossy(&bytes);
            if let Err(failure) = audit_scene_text(&text) {
                panic!("{}: {failure}", path.display());
            }
            audited += 1;
        }
    }
    assert!(audited >= 8);
}
