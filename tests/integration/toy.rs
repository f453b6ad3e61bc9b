//! What the toy's controls do to the simulation, headless: single steps while paused, the
//! intents the UI sends (fling, spawn, ball count), the ball-count slider, and the aiming
//! guide's prediction against the simulation's outcome; pausing and a window with no room.
//! Each runs in both collision modes where the mode could matter.

use ballpit::prelude::*;
use ballpit::sim::aim::{AimTarget, predict_first_hit};
use ballpit::sim::geometry::Circle;
use ballpit::sim::spawn::set_ball_count;
use ballpit::sim::{BallCountOutcome, SpawnSettings};
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::common::*;

fn arena(side: f64) -> SimParams {
    SimParams {
        arena_size: DVec2::splat(side),
        ..default()
    }
}

#[test]
fn single_step_runs_exactly_one_step_while_paused() {
    let mut app = app_with(arena(1000.0), &[ball(0.0, 0.0, 60.0, 0.0, 5.0)]);
    set_paused(&mut app, true);
    app.world_mut().resource_mut::<RunControl>().pending_steps = 1;
    step(&mut app, 5);
    assert_eq!(steps_run(&app), 1);
    assert!((states(&mut app)[0].position.x - 1.0).abs() < 1e-6);
    assert_eq!(app.world().resource::<RunControl>().pending_steps, 0);
}

#[test]
fn intents_apply_at_the_next_fixed_step_even_while_paused() {
    for mode in CollisionMode::ALL {
        let mut app = app_in(mode, arena(1000.0), &[ball(0.0, 0.0, 0.0, 0.0, 10.0)]);
        set_paused(&mut app, true);
        let first = entity_of(&mut app, 0);
        app.world_mut().write_message(Intent::Fling {
            ball: first,
            velocity: DVec2::new(120.0, -30.0),
        });
        app.world_mut()
            .write_message(Intent::Spawn(ball(200.0, 0.0, 0.0, 0.0, 15.0)));
        // A spawn the simulation would refuse (radius out of range) is dropped.
        app.world_mut()
            .write_message(Intent::Spawn(ball(-200.0, 0.0, 0.0, 0.0, f64::NAN)));
        step(&mut app, 1);
        let balls = states(&mut app);
        assert_eq!(balls.len(), 2, "{mode:?}");
        assert_eq!(balls[0].velocity, DVec2::new(120.0, -30.0), "{mode:?}");
        assert_eq!(
            balls[0].position,
            DVec2::ZERO,
            "{mode:?}: paused, not moved"
        );
        assert_eq!(balls[1], ball(200.0, 0.0, 0.0, 0.0, 15.0), "{mode:?}");
        assert_eq!(steps_run(&app), 0);
        // The count intent adds balls and says how many it reached.
        app.world_mut().write_message(Intent::SetBallCount(30));
        step(&mut app, 1);
        assert_eq!(states(&mut app).len(), 30, "{mode:?}");
        assert_eq!(
            *app.world().resource::<BallCountOutcome>(),
            BallCountOutcome {
                wanted: 30,
                reached: 30,
                smaller_radius: None,
            }
        );
    }
}

#[test]
fn ball_count_grows_without_overlap_and_shrinks_newest_first() {
    let mut app = app_with(arena(800.0), &[ball(0.0, 0.0, 0.0, 0.0, 10.0)]);
    assert_eq!(set_ball_count(app.world_mut(), 60), 60);
    let balls = states(&mut app);
    assert_eq!(balls.len(), 60);
    assert_eq!(
        balls[0],
        ball(0.0, 0.0, 0.0, 0.0, 10.0),
        "existing balls are kept"
    );
    let summary = StateSummary::measure(app.world_mut());
    assert!(
        summary.max_overlap_rel < 1e-9,
        "{}",
        summary.max_overlap_rel
    );
    assert_eq!(summary.escaped, 0);
    let settings = SpawnSettings::default();
    for b in &balls[1..] {
        assert!((settings.radius.0..=settings.radius.1).contains(&b.radius));
        let speed = b.velocity.length();
        assert!(speed >= settings.speed.0 - 1e-9 && speed <= settings.speed.1 + 1e-9);
    }
    assert_eq!(set_ball_count(app.world_mut(), 10), 10);
    assert_eq!(states(&mut app), balls[..10].to_vec());
}

#[test]
fn ball_count_stops_when_the_arena_is_full() {
    let mut app = app_with(arena(100.0), &[]);
    let reached = set_ball_count(app.world_mut(), 10_000);
    assert!(reached > 0 && reached < 100, "{reached}");
    assert_eq!(states(&mut app).len(), reached);
}

#[test]
fn guide_prediction_matches_what_the_simulation_does() {
    // Slow enough (0.5 px a step) that discrete detection sees the hit within 0.5 px of first
    // touch.
    let cue = ball(-60.0, 0.0, 30.0, 0.0, 10.0);
    let target = ball(0.0, 9.0, 0.0, 0.0, 14.0);
    let params = arena(1000.0);
    let prediction = predict_first_hit(
        Circle::new(cue.position, cue.radius),
        cue.velocity,
        params.mass_model.inverse_mass(cue.radius),
        [AimTarget {
            id: (),
            circle: Circle::new(target.position, target.radius),
            velocity: target.velocity,
            inverse_mass: params.mass_model.inverse_mass(target.radius),
        }],
        params.restitution,
        10.0,
    )
    .expect("the cue ball's path crosses the target");
    // The continuous mode meets the prediction to rounding; the discrete one sees the hit
    // up to a step (0.5 px) late.
    for (mode, point_tolerance, tolerance) in [
        (CollisionMode::Continuous, 1e-9, 1e-9),
        (CollisionMode::Discrete, 0.5, 0.02),
    ] {
        let mut app = app_in(mode, params.clone(), &[cue, target]);
        record_collisions(&mut app);
        let steps = (prediction.time / DT).ceil() as usize + 1;
        step(&mut app, steps);
        let hits = app.world().resource::<Recorded>().ball_hits.clone();
        assert_eq!(hits.len(), 1, "{mode:?}");
        assert!(
            hits[0].point.distance(prediction.point) < point_tolerance,
            "{mode:?}: {} vs {}",
            hits[0].point,
            prediction.point
        );
        let balls = states(&mut app);
        let angle = |a: DVec2, b: DVec2| a.angle_to(b).abs();
        assert!(angle(balls[0].velocity, prediction.cue_velocity_after) < tolerance);
        assert!(angle(balls[1].velocity, prediction.target_velocity_after) < tolerance);
        let speed_error =
            (balls[1].velocity.length() / prediction.target_velocity_after.length() - 1.0).abs();
        assert!(speed_error < tolerance, "{mode:?}: {speed_error}");
    }
}

#[test]
fn paused_simulation_does_not_move() {
    for mode in CollisionMode::ALL {
        let mut app = app_in(mode, arena(2000.0), &[ball(0.0, 0.0, 50.0, 0.0, 5.0)]);
        set_paused(&mut app, true);
        step(&mut app, 10);
        assert_eq!(states(&mut app)[0].position, DVec2::ZERO, "{mode:?}");
        assert_eq!(steps_run(&app), 0, "{mode:?}");
    }
}

#[test]
fn a_zero_sized_arena_makes_the_simulation_wait_and_loses_no_ball() {
    let balls: Vec<BallState> = (0..40)
        .map(|i| ball(-300.0 + 15.0 * i as f64, 0.0, 100.0, 37.0 * i as f64, 5.0))
        .collect();
    for mode in CollisionMode::ALL {
        let mut app = app_in(mode, arena(2000.0), &balls);
        step(&mut app, 5);
        let before = states(&mut app);
        let arena = app.world().resource::<SimParams>().arena_size;
        // A minimised window: no room, so no step runs and nothing moves.
        app.world_mut().resource_mut::<SimParams>().arena_size = DVec2::ZERO;
        step(&mut app, 20);
        assert_eq!(states(&mut app), before, "{mode:?}");
        assert_eq!(steps_run(&app), 5);
        // Restored: it carries on, every ball still there and inside.
        app.world_mut().resource_mut::<SimParams>().arena_size = arena;
        step(&mut app, 20);
        assert_eq!(steps_run(&app), 25);
        let after = states(&mut app);
        assert_eq!(after.len(), 40);
        assert!(after.iter().all(|b| b.position.is_finite()
            && b.position.x.abs() + b.radius <= arena.x / 2.0 + 1e-9
            && b.position.y.abs() + b.radius <= arena.y / 2.0 + 1e-9));
    }
}
