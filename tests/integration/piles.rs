//! Gravity with restitution below 1, in both modes: bounces that die out by the resting rule,
//! resting contacts that carry weight without being hits, piles that rest with little
//! overlap, sleep and every way of waking, determinism with sleeping balls.

use ballpit::prelude::*;
use ballpit::sim::Rest;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::common::*;

const GRAVITY: DVec2 = DVec2::new(0.0, -500.0);

/// A 400 x 400 arena (floor at y = -200) under [`GRAVITY`] with `restitution`.
fn falling(restitution: f64) -> SimParams {
    SimParams {
        arena_size: DVec2::new(400.0, 400.0),
        gravity: GRAVITY,
        restitution,
        ..default()
    }
}

fn sleeping_count(app: &mut App) -> usize {
    StateSummary::measure(app.world_mut()).sleeping
}

fn weight(app: &mut App) -> f64 {
    let params = app.world().resource::<SimParams>().clone();
    states(app)
        .iter()
        .map(|b| params.mass_model.mass(b.radius) * params.gravity.length())
        .sum()
}

#[test]
fn a_dropped_ball_bounces_lower_by_e_squared_each_time_then_rests() {
    for mode in CollisionMode::ALL {
        // Dropped from 290 px above the floor with e = 0.5: apexes 72.5, 18.1, 4.5 px...
        let mut app = app_in(mode, falling(0.5), &[ball(0.0, 100.0, 0.0, 0.0, 10.0)]);
        record_collisions(&mut app);
        let floor = -190.0;
        let mut apexes = Vec::new();
        let (mut last_y, mut rising) = (100.0, false);
        for _ in 0..600 {
            step(&mut app, 1);
            let y = states(&mut app)[0].position.y;
            if rising && y < last_y {
                apexes.push(last_y - floor);
            }
            // A flat top (the step that ends at the apex) still counts as rising.
            rising = y >= last_y;
            last_y = y;
        }
        match mode {
            // Exact flight: each apex is e² of the one before, to the sampling of the steps
            // (0.02 px) and, for the low bounces the resting solver carries off the floor, 1%.
            CollisionMode::Continuous => {
                for (n, apex) in apexes.iter().take(4).enumerate() {
                    let expected = 290.0 * 0.25_f64.powi(n as i32 + 1);
                    assert!(
                        (apex - expected).abs() < 0.02 + 0.01 * expected,
                        "apex {n}: {apex} px, not {expected}"
                    );
                }
            }
            // Semi-implicit Euler tops out about v·dt/2 low each flight (69.4 px, not 72.5):
            // each apex is e² of the one before, less that.
            CollisionMode::Discrete => {
                for pair in apexes.windows(2).take(3) {
                    let ratio = pair[1] / pair[0];
                    assert!((0.75 * 0.25..=1.02 * 0.25).contains(&ratio), "{apexes:?}");
                }
            }
        }
        // Finitely many bounces, then it rests on the floor, asleep, exactly still.
        let hits = app.world().resource::<Recorded>().wall_hits.len();
        assert!((4..=8).contains(&hits), "{mode:?}: {hits} wall hits");
        let ball = states(&mut app)[0];
        assert!((ball.position.y - floor).abs() < 0.05, "{mode:?}: {ball:?}");
        assert_eq!(ball.velocity, DVec2::ZERO, "{mode:?}");
        assert_eq!(sleeping_count(&mut app), 1, "{mode:?}");
    }
}

#[test]
fn an_elastic_ball_never_comes_to_rest() {
    for mode in CollisionMode::ALL {
        let mut app = app_in(mode, falling(1.0), &[ball(0.0, 100.0, 0.0, 0.0, 10.0)]);
        record_collisions(&mut app);
        step(&mut app, 600);
        // A bounce every 2.15 s: e = 1 always bounces.
        assert!(app.world().resource::<Recorded>().wall_hits.len() >= 4);
        assert_eq!(sleeping_count(&mut app), 0, "{mode:?}");
    }
}

/// A column of three balls standing on the floor, and one beside it.
fn column() -> Vec<BallState> {
    vec![
        ball(0.0, -190.0, 0.0, 0.0, 10.0),
        ball(0.0, -170.0, 0.0, 0.0, 10.0),
        ball(0.0, -150.0, 0.0, 0.0, 10.0),
        ball(100.0, -185.0, 0.0, 0.0, 15.0),
    ]
}

#[test]
fn the_floor_carries_a_resting_pile_s_weight_and_no_hit_is_counted() {
    for mode in CollisionMode::ALL {
        // The column and the lone ball, and a ball sliding along the floor at 30 px/s, which
        // never sleeps: from 3 s on some balls sleep and one does not.
        let mut balls = column();
        balls.push(ball(-150.0, -190.0, 30.0, 0.0, 10.0));
        let mut app = app_in(mode, falling(0.5), &balls);
        record_collisions(&mut app);
        let weight = weight(&mut app);
        step(&mut app, 31);
        // Awake and resting (0.5 s to 1.5 s), then mostly asleep (3 s to 4 s): each second the
        // floor gives the weight times a second.
        for (from, to) in [(31, 91), (181, 241)] {
            let before = app.world().resource::<SimStats>().wall_impulse;
            step(&mut app, to - from);
            let impulse = app.world().resource::<SimStats>().wall_impulse - before;
            assert!(
                (impulse - weight).abs() < 1e-3 * weight,
                "{mode:?}, steps {from}..{to}: floor impulse {impulse}, weight x 1 s {weight}"
            );
        }
        let recorded = app.world().resource::<Recorded>();
        assert!(recorded.ball_hits.is_empty() && recorded.wall_hits.is_empty());
        assert_eq!(app.world().resource::<SimStats>().wall_collisions, 0);
        assert_eq!(sleeping_count(&mut app), 4, "{mode:?}");
    }
}

/// The shipped pile with `balls` balls after `steps` steps in `mode`.
fn pile(mode: CollisionMode, balls: usize, steps: u64) -> (App, RunReport) {
    let mut scene = shipped_scene("pile.ron");
    if let Some(generate) = scene.generate.as_mut() {
        generate.count = balls;
    }
    let mut setup = scene.build("pile.ron").unwrap();
    setup.collisions = Some(mode);
    run_scene(&setup, steps, DT)
}

#[test]
fn a_small_pile_comes_to_rest_with_little_overlap_and_sleeps() {
    for mode in CollisionMode::ALL {
        let (_, report) = pile(mode, 300, 900);
        assert!(
            report.max_overlap_rel <= 0.10 && report.mean_overlap_rel <= 0.01,
            "{mode:?}: overlap max {} mean {}",
            report.max_overlap_rel,
            report.mean_overlap_rel
        );
        assert!(report.moving <= 3, "{mode:?}: {} moving", report.moving);
        assert!(
            report.sleeping >= 297,
            "{mode:?}: {} asleep",
            report.sleeping
        );
        assert_eq!(report.escaped, 0);
        // Mechanical energy only ever goes: restitution 0.5 and resting contacts.
        assert!(report.mechanical_energy_end < report.mechanical_energy_start);
    }
}

#[test]
fn a_pile_with_sleeping_balls_is_deterministic_and_asleep_is_bit_identical() {
    for mode in CollisionMode::ALL {
        let (mut first, _) = pile(mode, 300, 700);
        let (mut second, _) = pile(mode, 300, 700);
        let settled = states(&mut first);
        assert_eq!(settled, states(&mut second), "{mode:?}");
        assert!(sleeping_count(&mut first) >= 297);
        step(&mut first, 30);
        let asleep: Vec<bool> = rests(&mut first).iter().map(Rest::is_asleep).collect();
        for (index, (before, after)) in settled.iter().zip(states(&mut first)).enumerate() {
            if asleep[index] {
                assert_eq!(*before, after, "{mode:?}: sleeping ball {index} changed");
            }
        }
    }
}

/// Every ball's [`Rest`], in id order.
fn rests(app: &mut App) -> Vec<Rest> {
    let world = app.world_mut();
    let mut rests: Vec<(BallId, Rest)> = world
        .query::<(&BallId, &Rest)>()
        .iter(world)
        .map(|(id, rest)| (*id, *rest))
        .collect();
    rests.sort_by_key(|(id, _)| *id);
    rests.into_iter().map(|(_, rest)| rest).collect()
}

/// The column asleep in `mode`.
fn sleeping_column(mode: CollisionMode) -> App {
    let mut app = app_in(mode, falling(0.5), &column());
    step(&mut app, 60);
    assert_eq!(
        sleeping_count(&mut app),
        4,
        "{mode:?}: the column sleeps within 1 s"
    );
    app
}

#[test]
fn a_sleeping_pile_wakes_at_every_disturbance() {
    type Disturbance = fn(&mut App);
    let disturbances: [(&str, Disturbance, usize); 10] = [
        (
            "gravity",
            |app| app.world_mut().resource_mut::<SimParams>().gravity.x = 10.0,
            0,
        ),
        (
            "restitution",
            |app| app.world_mut().resource_mut::<SimParams>().restitution = 0.4,
            0,
        ),
        // Elastic: the resting rule is off, so every held ball flies again.
        (
            "elastic",
            |app| app.world_mut().resource_mut::<SimParams>().restitution = 1.0,
            0,
        ),
        (
            "mass model",
            |app| app.world_mut().resource_mut::<SimParams>().mass_model = MassModel::Area,
            0,
        ),
        (
            "arena",
            |app| app.world_mut().resource_mut::<SimParams>().arena_size.x = 380.0,
            0,
        ),
        (
            "mode",
            |app| {
                let mut solver = app.world_mut().resource_mut::<Solver>();
                solver.collisions = match solver.collisions {
                    CollisionMode::Continuous => CollisionMode::Discrete,
                    CollisionMode::Discrete => CollisionMode::Continuous,
                };
            },
            0,
        ),
        // Flinging the top ball of the column wakes the column; the lone ball sleeps on.
        (
            "fling",
            |app| {
                let top = entity_of(app, 2);
                let velocity = DVec2::new(50.0, 0.0);
                app.world_mut().write_message(Intent::Fling {
                    ball: top,
                    velocity,
                });
            },
            1,
        ),
        // A new ball set down on the lone one wakes it; the column sleeps on.
        (
            "spawn",
            |app| {
                let landing = ball(100.0, -155.0, 0.0, 0.0, 15.0);
                app.world_mut().write_message(Intent::Spawn(landing));
            },
            3,
        ),
        // A ball thrown at the column wakes it.
        (
            "hit",
            |app| {
                let thrown = ball(-100.0, -170.0, 400.0, 0.0, 10.0);
                app.world_mut().write_message(Intent::Spawn(thrown));
            },
            1,
        ),
        (
            "count",
            |app| {
                app.world_mut().write_message(Intent::SetBallCount(3));
            },
            0,
        ),
    ];
    for mode in CollisionMode::ALL {
        for (name, disturb, still_asleep) in disturbances {
            let mut app = sleeping_column(mode);
            disturb(&mut app);
            step(&mut app, if name == "hit" { 20 } else { 1 });
            assert_eq!(
                sleeping_count(&mut app),
                still_asleep,
                "{mode:?}, {name}: balls still asleep"
            );
        }
    }
}
