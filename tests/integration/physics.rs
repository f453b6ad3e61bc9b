//! The physics through the whole pipeline: movement → collision → response → report, one
//! fixed step per `update()`. Where both collision modes should give the same physics, each
//! test runs in both (`for mode in CollisionMode::ALL`), with the tolerance that fits each:
//! rounding for the continuous mode, which handles every impact at its exact moment; the
//! discrete mode sees a hit only as an overlap at the end of a step, so where the moment
//! matters its tolerance is a step's worth of motion.

use ballpit::prelude::*;
use ballpit::sim::geometry::Circle;
use ballpit::sim::geometry::grid::UniformGrid;
use ballpit::sim::geometry::pairs::{FoundInBands, IndexedContact, contacts_among, find_contacts};
use bevy::math::DVec2;
use bevy::prelude::*;
use rand::{RngExt, SeedableRng};

use crate::common::*;

fn params() -> SimParams {
    SimParams {
        arena_size: DVec2::new(2000.0, 2000.0),
        ..default()
    }
}

#[test]
fn one_update_is_exactly_one_fixed_step() {
    for mode in CollisionMode::ALL {
        let mut app = app_in(mode, params(), &[ball(0.0, 0.0, 60.0, 0.0, 5.0)]);
        step(&mut app, 3);
        let clock = *app.world().resource::<SimClock>();
        assert_eq!(clock.steps, 3, "{mode:?}");
        assert!((clock.elapsed - 3.0 * DT).abs() < 1e-6, "{mode:?}");
        assert!(
            (states(&mut app)[0].position.x - 3.0).abs() < 1e-4,
            "{mode:?}"
        );
    }
}

#[test]
fn tutorial_worked_example_masses_10_and_10_at_5_and_minus_1() {
    // Radius 10 with mass = radius: both masses 10. Touching now (continuous: an impact at
    // the step's start), overlapping after one move (discrete).
    for mode in CollisionMode::ALL {
        let mut app = app_in(
            mode,
            params(),
            &[
                ball(-10.0, 0.0, 5.0, 0.0, 10.0),
                ball(10.0, 0.0, -1.0, 0.0, 10.0),
            ],
        );
        step(&mut app, 1);
        let balls = states(&mut app);
        assert!(
            (balls[0].velocity - DVec2::new(-1.0, 0.0)).length() < 1e-12,
            "{mode:?}: {:?}",
            balls[0]
        );
        assert!(
            (balls[1].velocity - DVec2::new(5.0, 0.0)).length() < 1e-12,
            "{mode:?}: {:?}",
            balls[1]
        );
        assert_eq!(
            app.world().resource::<SimStats>().ball_collisions,
            1,
            "{mode:?}"
        );
    }
}

#[test]
fn unequal_masses_head_on_follow_the_1d_elastic_formulas() {
    for (mode, mass_model, e) in CollisionMode::ALL.into_iter().flat_map(|mode| {
        [
            (mode, MassModel::Radius, 1.0),
            (mode, MassModel::Area, 1.0),
            (mode, MassModel::Radius, 0.4),
        ]
    }) {
        let (r1, r2, u1, u2) = (5.0, 20.0, 30.0, -12.0);
        let mut app = app_in(
            mode,
            SimParams {
                mass_model,
                restitution: e,
                ..params()
            },
            &[ball(-5.0, 0.0, u1, 0.0, r1), ball(20.0, 0.0, u2, 0.0, r2)],
        );
        step(&mut app, 1);
        let (m1, m2) = (mass_model.mass(r1), mass_model.mass(r2));
        let v1 = (m1 * u1 + m2 * u2 - m2 * e * (u1 - u2)) / (m1 + m2);
        let v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2);
        let balls = states(&mut app);
        assert!(
            (balls[0].velocity.x - v1).abs() < 1e-9,
            "{mode:?} {mass_model:?} e={e}: {} vs {v1}",
            balls[0].velocity.x
        );
        assert!(
            (balls[1].velocity.x - v2).abs() < 1e-9,
            "{mode:?} {mass_model:?} e={e}: {} vs {v2}",
            balls[1].velocity.x
        );
        assert_eq!(balls[0].velocity.y, 0.0);
    }
}

#[test]
fn off_centre_hit_on_a_still_ball_parts_at_right_angles() {
    // Equal masses; the mover's line passes 8 px off the still ball's centre (radii sum 20).
    // Analytic impact normal for impact parameter 8 and reach 20: (sqrt(1 - 0.4^2), 0.4). The
    // continuous mode finds it to rounding; discrete detection sees the pair up to one step
    // (1 px) late, so its normal is only close.
    for (mode, normal_tolerance) in [
        (CollisionMode::Continuous, 1e-9),
        (CollisionMode::Discrete, 0.06),
    ] {
        let speed = 60.0;
        let mut app = app_in(
            mode,
            params(),
            &[
                ball(-40.0, 0.0, speed, 0.0, 10.0),
                ball(0.0, 8.0, 0.0, 0.0, 10.0),
            ],
        );
        record_collisions(&mut app);
        step(&mut app, 60);
        let hits = app.world().resource::<Recorded>().ball_hits.clone();
        assert_eq!(hits.len(), 1, "{mode:?}: exactly one collision");
        let normal = hits[0].normal;
        let exact_normal = DVec2::new((1.0f64 - 0.16).sqrt(), 0.4);
        assert!(
            normal.angle_to(exact_normal).abs() < normal_tolerance,
            "{mode:?}: normal {normal}"
        );
        parts_at_right_angles(&mut app, normal, speed);
    }
}

/// After a hit of a ball at `speed` on a still one of equal mass along `normal`: the struck
/// ball leaves along the normal, the mover keeps its perpendicular component, at 90°.
fn parts_at_right_angles(app: &mut App, normal: DVec2, speed: f64) {
    let balls = states(app);
    let (mover, struck) = (balls[0].velocity, balls[1].velocity);
    // The struck ball leaves along the line of centres with the mover's normal component...
    assert!(struck.normalize().dot(normal) > 1.0 - 1e-12);
    assert!((struck.length() - speed * normal.x).abs() < 1e-9);
    // ...the mover keeps only its perpendicular component: they part at 90 degrees.
    assert!((mover.length() - speed * normal.y.abs()).abs() < 1e-9);
    assert!(mover.dot(struck).abs() < 1e-9 * speed * speed);
    // Unlike the per-axis formula, the cue ball does not stop dead.
    assert!(mover.length() > 0.3 * speed);
}

/// A cluster of random non-overlapping balls in the middle of an arena too big to reach.
fn cluster(count: usize, seed: u64, speed: f64) -> Vec<BallState> {
    let scene = SceneFile::parse(
        &format!(
            "(arena: (width: 400.0, height: 400.0), generate: Some((count: {count}, \
             radius: (5.0, 15.0), speed: (0.0, {speed}), seed: {seed})))"
        ),
        "cluster",
    )
    .unwrap();
    scene.build("cluster").unwrap().balls
}

fn momentum_and_energy(app: &mut App) -> (DVec2, f64) {
    let summary = StateSummary::measure(app.world_mut());
    (summary.momentum, summary.kinetic_energy)
}

#[test]
fn momentum_and_energy_are_kept_with_restitution_one() {
    // Converging balls: all aimed at the centre, so they collide a lot.
    let mut balls = cluster(150, 3, 0.0);
    for (i, b) in balls.iter_mut().enumerate() {
        b.velocity = -b.position.normalize_or_zero() * (100.0 + i as f64);
    }
    for mode in CollisionMode::ALL {
        let mut app = app_in(
            mode,
            SimParams {
                arena_size: DVec2::splat(1.0e5),
                ..default()
            },
            &balls,
        );
        let (momentum_start, energy_start) = momentum_and_energy(&mut app);
        let momentum_scale: f64 = balls.iter().map(|b| b.radius * b.velocity.length()).sum();
        step(&mut app, 120);
        let (momentum_end, energy_end) = momentum_and_energy(&mut app);
        let stats = app.world().resource::<SimStats>().clone();
        assert!(
            stats.ball_collisions > 100,
            "{mode:?}: only {} collisions",
            stats.ball_collisions
        );
        assert_eq!(stats.wall_collisions, 0, "{mode:?}");
        assert!(
            (momentum_end - momentum_start).length() < 1e-12 * momentum_scale,
            "{mode:?}"
        );
        assert!(
            ((energy_end - energy_start) / energy_start).abs() < 1e-12,
            "{mode:?}"
        );
    }
}

#[test]
fn every_hit_loses_exactly_the_restitution_share_of_energy() {
    // Energy lost = sum over hits of (1 - e^2)/2 * mu * v_n^2 (mu = reduced mass; the wall's
    // mass is infinite, so mu = m there).
    let e = 0.7;
    for mode in CollisionMode::ALL {
        let mut app = app_in(
            mode,
            SimParams {
                arena_size: DVec2::splat(420.0),
                restitution: e,
                ..default()
            },
            &cluster(120, 4, 400.0),
        );
        loses_the_restitution_share(&mut app, e);
    }
}

/// Runs `app` and checks that the energy lost is what the recorded hits should lose.
fn loses_the_restitution_share(app: &mut App, e: f64) {
    record_collisions(app);
    let (_, energy_start) = momentum_and_energy(app);
    let masses = radii_by_entity(app); // mass = radius
    step(app, 90);
    let (_, energy_end) = momentum_and_energy(app);
    let recorded = app.world().resource::<Recorded>();
    assert!(recorded.ball_hits.len() > 50 && recorded.wall_hits.len() > 10);
    let loss_factor = 0.5 * (1.0 - e * e);
    let ball_loss: f64 = recorded
        .ball_hits
        .iter()
        .map(|hit| {
            let (ma, mb) = (masses[&hit.a], masses[&hit.b]);
            loss_factor * ma * mb / (ma + mb) * hit.normal_speed * hit.normal_speed
        })
        .sum();
    let wall_loss: f64 = recorded
        .wall_hits
        .iter()
        .map(|hit| loss_factor * masses[&hit.ball] * hit.normal_speed * hit.normal_speed)
        .sum();
    let expected = ball_loss + wall_loss;
    let actual = energy_start - energy_end;
    assert!(actual > 0.0);
    assert!(
        (actual - expected).abs() < 1e-9 * energy_start,
        "lost {actual}, expected {expected}"
    );
}

#[test]
fn collision_messages_report_the_impulse_that_was_applied() {
    // impulse = (1 + e) * mu * v_n along a unit normal, for every message.
    let e = 0.8;
    for mode in CollisionMode::ALL {
        let mut app = app_in(
            mode,
            SimParams {
                arena_size: DVec2::splat(1.0e5),
                restitution: e,
                ..default()
            },
            &cluster(80, 5, 300.0),
        );
        record_collisions(&mut app);
        let radii = radii_by_entity(&mut app);
        step(&mut app, 60);
        let hits = &app.world().resource::<Recorded>().ball_hits;
        assert!(hits.len() > 20, "{mode:?}: only {} hits", hits.len());
        for hit in hits {
            let (ma, mb) = (radii[&hit.a], radii[&hit.b]);
            let expected = (1.0 + e) * ma * mb / (ma + mb) * hit.normal_speed;
            assert!(hit.normal_speed > 0.0);
            assert!(
                (hit.impulse - expected).abs() < 1e-9 * expected,
                "{mode:?}: {hit:?}"
            );
            assert!((hit.normal.length() - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn overlapping_balls_separate_and_do_not_stick() {
    for mode in CollisionMode::ALL {
        overlapping_balls_separate_in(mode);
    }
}

fn overlapping_balls_separate_in(mode: CollisionMode) {
    // Deep overlap, at rest: pushed apart to touching in one step, lighter ball moving more.
    let mut app = app_in(
        mode,
        params(),
        &[
            ball(0.0, 0.0, 0.0, 0.0, 10.0),
            ball(6.0, 0.0, 0.0, 0.0, 30.0),
        ],
    );
    step(&mut app, 1);
    let balls = states(&mut app);
    let gap = balls[1].position.x - balls[0].position.x;
    assert!((gap - 40.0).abs() < 1e-9, "gap {gap}");
    assert!(
        (balls[0].position.x + 25.5).abs() < 1e-9,
        "light ball takes 3/4 of the push"
    );
    // Overlapping but already separating: velocities untouched, and the pair comes apart.
    let mut app = app_in(
        mode,
        params(),
        &[
            ball(0.0, 0.0, -1.0, 0.0, 10.0),
            ball(15.0, 0.0, 1.0, 0.0, 10.0),
        ],
    );
    record_collisions(&mut app);
    step(&mut app, 5);
    let balls = states(&mut app);
    assert_eq!(balls[0].velocity, DVec2::new(-1.0, 0.0));
    assert_eq!(balls[1].velocity, DVec2::new(1.0, 0.0));
    assert!(balls[1].position.x - balls[0].position.x >= 20.0);
    assert!(app.world().resource::<Recorded>().ball_hits.is_empty());
}

#[test]
fn a_slow_pair_bounces_once_instead_of_sticking() {
    // The tutorial's sticking bug: an overlapping pair flips velocities every step. Here it
    // bounces once and leaves.
    for mode in CollisionMode::ALL {
        let mut app = app_in(
            mode,
            params(),
            &[
                ball(0.0, 0.0, 2.0, 0.0, 10.0),
                ball(19.0, 0.0, -2.0, 0.0, 10.0),
            ],
        );
        step(&mut app, 120);
        let balls = states(&mut app);
        assert_eq!(
            app.world().resource::<SimStats>().ball_collisions,
            1,
            "{mode:?}"
        );
        assert_eq!(balls[0].velocity, DVec2::new(-2.0, 0.0), "{mode:?}");
        assert!(
            balls[1].position.x - balls[0].position.x > 20.0 + 4.0 * 1.9,
            "{mode:?}"
        );
    }
}

#[test]
fn no_ball_ever_leaves_the_arena() {
    for mode in CollisionMode::ALL {
        let scene = shipped_scene("gas.ron");
        let mut setup = scene.build("gas.ron").unwrap();
        setup.params.gravity = DVec2::new(300.0, -2000.0);
        setup.params.restitution = 0.5;
        setup.collisions = Some(mode);
        let mut app = headless_app(DT);
        setup.apply(app.world_mut());
        let half = app.world().resource::<SimParams>().half_extents();
        for step_index in 0..240 {
            app.update();
            for ball in states(&mut app) {
                let reach = ball.position.abs() + DVec2::splat(ball.radius);
                assert!(
                    reach.x <= half.x + 1e-9 && reach.y <= half.y + 1e-9,
                    "{mode:?} step {step_index}: ball at {} radius {} outside",
                    ball.position,
                    ball.radius
                );
            }
        }
    }
}

#[test]
fn coincident_centres_give_no_nan() {
    for mode in CollisionMode::ALL {
        let mut app = app_in(
            mode,
            params(),
            &[
                ball(5.0, 5.0, 0.0, 0.0, 10.0),
                ball(5.0, 5.0, 0.0, 0.0, 6.0),
            ],
        );
        step(&mut app, 2);
        let balls = states(&mut app);
        for b in &balls {
            assert!(b.position.is_finite() && b.velocity.is_finite(), "{mode:?}");
        }
        assert!(
            (balls[0].position.distance(balls[1].position) - 16.0).abs() < 1e-9,
            "{mode:?}"
        );
    }
}

#[test]
fn same_seed_gives_bit_identical_state_and_another_seed_does_not() {
    for mode in CollisionMode::ALL {
        let run = |seed: u64| {
            let mut scene = shipped_scene("gas.ron");
            scene.generate.as_mut().unwrap().count = 400;
            scene.generate.as_mut().unwrap().seed = seed;
            scene.collisions = Some(mode);
            let (mut app, _) = run_scene(&scene.build("gas").unwrap(), 200, DT);
            states(&mut app)
        };
        let first = run(11);
        assert_eq!(first, run(11), "{mode:?}");
        assert_ne!(first, run(12), "{mode:?}");
    }
}

#[test]
fn grid_and_all_pairs_find_exactly_the_same_contacts() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
    for trial in 0..20 {
        let count = rng.random_range(2..600);
        let side = rng.random_range(50.0..600.0);
        let circles: Vec<Circle> = (0..count)
            .map(|_| {
                let center =
                    DVec2::new(rng.random_range(-side..side), rng.random_range(-side..side));
                Circle::new(center, rng.random_range(0.5..25.0))
            })
            .collect();
        let (by_grid, mut by_all_pairs) = (contacts_among(&circles), FoundInBands::default());
        find_contacts(
            &circles,
            BroadPhase::AllPairs,
            &mut UniformGrid::default(),
            &mut by_all_pairs,
        );
        let sorted = |found: &FoundInBands<IndexedContact>| {
            let mut contacts: Vec<IndexedContact> = found.iter().copied().collect();
            contacts.sort_by_key(|c| (c.a, c.b));
            contacts
        };
        assert_eq!(
            sorted(&by_grid),
            sorted(&by_all_pairs),
            "trial {trial}: {count} circles"
        );
    }
}
