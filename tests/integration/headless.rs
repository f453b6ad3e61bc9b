//! What a headless run keeps: only what its reader asks for. Per-hit messages and contact
//! points are asked for ([`HitReports`]); the counters come either way, the same to the bit.
//! The drawing's state between steps is the render plugin's.

use ballpit::prelude::*;
use ballpit::sim::{ContactPoints, HitReports, PreviousPosition};
use bevy::prelude::*;

use crate::common::*;

/// A shipped scene (at most 400 balls) run `steps` steps in `mode`, with hit reports on or
/// off; and the contact points the overlay was handed, summed over the steps.
fn run_with_reports(scene: &str, mode: CollisionMode, reports: bool, steps: usize) -> (App, u64) {
    let mut file = shipped_scene(scene);
    if let Some(generate) = file.generate.as_mut() {
        generate.count = generate.count.min(400);
    }
    let mut setup = file.build(scene).unwrap();
    setup.collisions = Some(mode);
    let mut app = headless_app(DT);
    record_collisions(&mut app);
    app.insert_resource(HitReports { enabled: reports });
    setup.apply(app.world_mut());
    let mut points = 0;
    for _ in 0..steps {
        app.update();
        points += app.world().resource::<ContactPoints>().0.len() as u64;
    }
    (app, points)
}

#[test]
fn without_hit_reports_the_counters_and_the_balls_are_the_same_and_nothing_is_sent() {
    for scene in ["gas.ron", "pile.ron"] {
        for mode in [CollisionMode::Continuous, CollisionMode::Discrete] {
            let (mut on, points_on) = run_with_reports(scene, mode, true, 120);
            let (mut off, points_off) = run_with_reports(scene, mode, false, 120);
            let (stats_on, stats_off) = (
                on.world().resource::<SimStats>().clone(),
                off.world().resource::<SimStats>().clone(),
            );
            assert_eq!(stats_on, stats_off, "{scene} {mode:?}");
            assert!(
                stats_on.ball_collisions > 100,
                "{scene} {mode:?}: {stats_on:?}"
            );
            assert!(
                stats_on.contact_points > 0,
                "{scene} {mode:?}: {stats_on:?}"
            );
            // The overlay got every point counted, and without reports none.
            assert_eq!(points_on, stats_on.contact_points, "{scene} {mode:?}");
            assert_eq!(points_off, 0);
            assert_eq!(states(&mut on), states(&mut off), "{scene} {mode:?}");
            // With reports, a message for every hit counted; without, none, and no points.
            let (recorded_on, recorded_off) = (
                on.world().resource::<Recorded>(),
                off.world().resource::<Recorded>(),
            );
            assert_eq!(recorded_on.ball_hits.len() as u64, stats_on.ball_collisions);
            assert_eq!(recorded_on.wall_hits.len() as u64, stats_on.wall_collisions);
            assert!(recorded_off.ball_hits.is_empty() && recorded_off.wall_hits.is_empty());
        }
    }
}

#[test]
fn a_headless_ball_has_no_drawing_state_and_one_given_it_follows_the_steps() {
    let mut app = app_with(
        SimParams::default(),
        &[
            ball(0.0, 0.0, 120.0, 0.0, 10.0),
            ball(200.0, 0.0, 0.0, 0.0, 10.0),
        ],
    );
    let world = app.world_mut();
    let drawn = world.query::<&PreviousPosition>().iter(world).count();
    assert_eq!(drawn, 0, "headless balls carry no previous position");
    let first = entity_of(&mut app, 0);
    app.world_mut()
        .entity_mut(first)
        .insert(PreviousPosition(bevy::math::DVec2::ZERO));
    step(&mut app, 3);
    let position = app.world().get::<Position>(first).unwrap().0;
    let previous = app.world().get::<PreviousPosition>(first).unwrap().0;
    // One step of 120 px/s behind (the fixed step is 1/60 s to a few parts in 10^8).
    assert!(
        (position.x - previous.x - 2.0).abs() < 1e-6,
        "{previous} -> {position}"
    );
    assert!(previous.x > 3.0, "it moved with the steps: {previous}");
}

/// Marks balls so that they are stored in a table of their own.
#[derive(Component)]
struct Tagged;

#[test]
fn balls_stored_in_two_tables_are_each_read_and_written_back_as_themselves() {
    // The stages read and write the balls table by table: here two, interleaved by id.
    // A head-on pair (one ball in each table, equal masses) and two lone balls.
    let balls = [
        ball(-100.0, 0.0, 60.0, 0.0, 10.0),
        ball(100.0, 0.0, -60.0, 0.0, 10.0),
        ball(-200.0, 150.0, 30.0, -12.0, 8.0),
        ball(200.0, -150.0, -24.0, 18.0, 8.0),
    ];
    for (mode, place_tolerance) in [
        (CollisionMode::Continuous, 1e-9),
        // Seen at the end of a step, as an overlap, and pushed apart.
        (CollisionMode::Discrete, 2.0),
    ] {
        let mut app = app_in(mode, SimParams::default(), &balls);
        for id in [1, 3] {
            let entity = entity_of(&mut app, id);
            app.world_mut().entity_mut(entity).insert(Tagged);
        }
        let world = app.world_mut();
        assert_eq!(world.query::<&Tagged>().iter(world).count(), 2);
        // 2 s: the pair meets after 1.5 s (180 px apart, closing at 120 px/s).
        step(&mut app, 120);
        // The fixed step is 1/60 s to a few parts in 10^8.
        let elapsed = app.world().resource::<SimClock>().elapsed;
        assert!((elapsed - 2.0).abs() < 1e-6, "{elapsed}");
        let after = states(&mut app);
        for lone in [2, 3] {
            let expected = balls[lone].position + balls[lone].velocity * elapsed;
            assert!(
                after[lone].position.distance(expected) < 1e-9,
                "{mode:?}: ball {lone} at {} instead of {expected}",
                after[lone].position
            );
            assert_eq!(after[lone].velocity, balls[lone].velocity, "{mode:?}");
        }
        // Equal masses head on, touching at ±10 px: the velocities are exchanged, each ball
        // 30 px back by 2 s.
        let back = 60.0 * (elapsed - 1.5);
        for (id, x, vx) in [(0, -10.0 - back, -60.0), (1, 10.0 + back, 60.0)] {
            assert!(
                (after[id].velocity.x - vx).abs() < 1e-9 && after[id].velocity.y.abs() < 1e-9,
                "{mode:?}: ball {id} at {}",
                after[id].velocity
            );
            assert!(
                (after[id].position.x - x).abs() < place_tolerance,
                "{mode:?}: ball {id} at {}",
                after[id].position
            );
        }
    }
}
