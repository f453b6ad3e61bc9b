//! What the toy's controls do to the simulation, headless: single steps while paused, the
//! ball-count slider, and the aiming guide's prediction against the simulation's outcome.

use ballpit::prelude::*;
use ballpit::sim::aim::{AimTarget, predict_first_hit};
use ballpit::sim::collision::narrow_phase::Circle;
use ballpit::sim::spawn::set_ball_count;
use ballpit::sim::{PendingSteps, SpawnSettings};
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
    let mut app = app_with(
        SimParams {
            paused: true,
            ..arena(1000.0)
        },
        &[ball(0.0, 0.0, 60.0, 0.0, 5.0)],
    );
    app.world_mut().resource_mut::<PendingSteps>().0 = 1;
    step(&mut app, 5);
    assert_eq!(app.world().resource::<SimStats>().steps, 1);
    assert!((states(&mut app)[0].position.x - 1.0).abs() < 1e-6);
    assert_eq!(app.world().resource::<PendingSteps>().0, 0);
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
    // Slow enough that discrete detection sees the hit within 0.5 px of first touch.
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
    let mut app = app_with(params, &[cue, target]);
    record_collisions(&mut app);
    let steps = (prediction.time / DT).ceil() as usize + 1;
    step(&mut app, steps);
    let hits = app.world().resource::<Recorded>().ball_hits.clone();
    assert_eq!(hits.len(), 1);
    assert!(
        hits[0].point.distance(prediction.point) < 0.5,
        "{} vs {}",
        hits[0].point,
        prediction.point
    );
    let balls = states(&mut app);
    let angle = |a: DVec2, b: DVec2| a.angle_to(b).abs();
    assert!(angle(balls[0].velocity, prediction.cue_velocity_after) < 0.02);
    assert!(angle(balls[1].velocity, prediction.target_velocity_after) < 0.02);
    let speed_error =
        (balls[1].velocity.length() / prediction.target_velocity_after.length() - 1.0).abs();
    assert!(speed_error < 0.02, "{speed_error}");
}
