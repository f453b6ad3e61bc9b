//! The continuous mode's own promises: nothing tunnels at 20 diameters a step (where the
//! discrete mode, tested beside it, lets balls pass through), energy is kept to rounding, and
//! the result does not depend on the order in which pairs are found. Physics both modes share
//! is tested in both in `physics.rs`.

use ballpit::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::common::{DT, Recorded, app_in, ball, record_collisions, shipped_scene, states, step};

fn arena(width: f64, height: f64) -> SimParams {
    SimParams {
        arena_size: DVec2::new(width, height),
        ..default()
    }
}

/// Asserts that an energy went from `start` to `end` within `tolerance` of `start`, and that
/// no two balls overlap in `end_state` (beyond 1e-9 of the smaller radius).
fn assert_kept_with_no_overlap((start, end): (f64, f64), tolerance: f64, end_state: &StateSummary) {
    let change = (end - start) / start;
    assert!(change.abs() < tolerance, "relative change {change}");
    assert!(
        end_state.max_overlap_rel < 1e-9,
        "overlap {}",
        end_state.max_overlap_rel
    );
}

/// Pixels per second for `diameters` diameters of a `radius` ball per step.
fn speed(diameters: f64, radius: f64) -> f64 {
    diameters * 2.0 * radius / DT
}

#[test]
fn head_on_at_20_diameters_per_step_bounces_where_discrete_tunnels() {
    let v = speed(20.0, 5.0); // 200 px a step
    let balls = [
        ball(-100.0, 0.0, v, 0.0, 5.0),
        ball(100.0, 0.0, -v, 0.0, 5.0),
    ];
    let mut app = app_in(CollisionMode::Continuous, arena(2000.0, 200.0), &balls);
    record_collisions(&mut app);
    step(&mut app, 1);
    let [a, b] = states(&mut app)[..] else {
        panic!("two balls")
    };
    // The message carries the true moment and point of contact.
    let hits = &app.world().resource::<Recorded>().ball_hits;
    assert_eq!(hits.len(), 1);
    assert!((hits[0].time - 0.475 * DT).abs() < 1e-9, "{}", hits[0].time);
    assert!(
        hits[0].point.distance(DVec2::ZERO) < 1e-5,
        "{}",
        hits[0].point
    );
    // They close 400 px a step over a 190 px gap: contact at 0.475 of the step at x = -5 and
    // 5; equal masses swap velocities and travel back for the remaining 0.525 step (105 px).
    // (The fixed step is 1/60 s rounded to whole nanoseconds: 4e-6 px over the step.)
    assert!((a.position.x + 110.0).abs() < 1e-5, "{}", a.position);
    assert!((b.position.x - 110.0).abs() < 1e-5, "{}", b.position);
    assert!((a.velocity.x + v).abs() < 1e-9 && (b.velocity.x - v).abs() < 1e-9);

    // The tutorial's method only looks at the end of the step and misses the hit.
    let mut app = app_in(CollisionMode::Discrete, arena(2000.0, 200.0), &balls);
    step(&mut app, 1);
    let [a, b] = states(&mut app)[..] else {
        panic!("two balls")
    };
    assert!(
        a.position.x > b.position.x,
        "discrete mode should tunnel here"
    );
}

#[test]
fn a_ball_at_20_diameters_per_step_stays_in_the_arena_and_keeps_its_speed() {
    let v = speed(20.0, 5.0);
    let mut app = app_in(
        CollisionMode::Continuous,
        arena(400.0, 300.0),
        &[ball(0.0, 0.0, v, v * 0.37, 5.0)],
    );
    record_collisions(&mut app);
    for step_index in 0..120 {
        step(&mut app, 1);
        let b = states(&mut app)[0];
        let reach = b.position.abs() + DVec2::splat(b.radius);
        assert!(
            reach.x <= 200.0 + 1e-9 && reach.y <= 150.0 + 1e-9,
            "step {step_index}: {} outside",
            b.position
        );
        let expected = DVec2::new(v, v * 0.37).length();
        assert!((b.velocity.length() - expected).abs() < 1e-9 * expected);
    }
    // 120 steps of 200 px along x over a 390 px track: about 61 hits on the side walls.
    let recorded = app.world().resource::<Recorded>();
    let side_hits = recorded
        .wall_hits
        .iter()
        .filter(|hit| matches!(hit.wall, Wall::Left | Wall::Right))
        .count();
    assert!((60..=62).contains(&side_hits), "{side_hits} side-wall hits");
}

#[test]
fn balls_on_a_line_at_up_to_10_diameters_per_step_never_pass_each_other() {
    // Ten balls on one horizontal line: any tunnelling would change their order.
    let balls: Vec<BallState> = (0..10)
        .map(|i| {
            let v = speed(10.0, 4.0) * (((i * 7) % 10) as f64 / 9.0 * 2.0 - 1.0);
            ball(-450.0 + i as f64 * 100.0, 0.0, v, 0.0, 4.0 + (i % 3) as f64)
        })
        .collect();
    let mut app = app_in(CollisionMode::Continuous, arena(1000.0, 100.0), &balls);
    for step_index in 0..300 {
        step(&mut app, 1);
        let now = states(&mut app);
        for pair in now.windows(2) {
            let gap = pair[1].position.x - pair[0].position.x - pair[0].radius - pair[1].radius;
            assert!(
                gap >= -1e-9,
                "step {step_index}: overlap or pass, gap {gap}"
            );
        }
    }
}

#[test]
fn newtons_cradle_passes_the_speed_to_the_last_ball() {
    let setup = shipped_scene("newtons_cradle.ron")
        .build("newtons_cradle.ron")
        .unwrap();
    let mut app = app_in(
        CollisionMode::Continuous,
        setup.params.clone(),
        &setup.balls,
    );
    // The first ball reaches the row after 260 px at 300 px/s: 52 steps; run a little more.
    step(&mut app, 60);
    let balls = states(&mut app);
    let last = balls.last().unwrap();
    assert!((last.velocity.x - 300.0).abs() < 1e-9, "{}", last.velocity);
    for other in &balls[..balls.len() - 1] {
        assert!(other.velocity.length() < 1e-9, "{}", other.velocity);
    }
    assert!(balls.iter().all(|b| b.velocity.y == 0.0));
}

/// The standard gas (1,000 balls) under `gravity`, run 600 continuous steps: the app and
/// the state's summary before and after.
fn standard_gas_after_600_steps(gravity: DVec2) -> (App, StateSummary, StateSummary) {
    let mut setup = shipped_scene("gas.ron").build("gas.ron").unwrap();
    setup.params.gravity = gravity;
    let mut app = app_in(CollisionMode::Continuous, setup.params, &setup.balls);
    let start = StateSummary::measure(app.world_mut());
    step(&mut app, 600);
    let end = StateSummary::measure(app.world_mut());
    (app, start, end)
}

#[test]
fn standard_gas_keeps_its_energy_to_one_part_in_a_million() {
    let (app, start, end) = standard_gas_after_600_steps(DVec2::ZERO);
    assert_eq!(end.ball_count, 1000);
    // And nothing overlaps: the continuous mode never lets a pair interpenetrate.
    assert_kept_with_no_overlap((start.kinetic_energy, end.kinetic_energy), 1e-6, &end);
    assert!(app.world().resource::<SimStats>().ball_collisions > 50_000);
}

#[test]
fn three_balls_meeting_in_one_step_end_the_same_whatever_the_order_found() {
    // A hits B early in the step and B then hits C; and a symmetric pinch where D and F
    // reach E at the same instant from both sides. Discrete mode would see both overlaps at
    // once and resolve them in the order the pairs were found.
    let chain = [
        ball(-60.0, 0.0, 3_000.0, 0.0, 10.0),
        ball(-15.0, 2.0, 0.0, 0.0, 12.0),
        ball(25.0, -3.0, -600.0, 0.0, 8.0),
    ];
    let pinch = [
        ball(-60.0, 100.0, 3_000.0, 0.0, 10.0),
        ball(0.0, 100.0, 0.0, 0.0, 10.0),
        ball(60.0, 100.0, -3_000.0, 0.0, 10.0),
    ];
    let orders = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut results: Vec<Vec<BallState>> = Vec::new();
    for order in orders {
        let balls: Vec<BallState> = order
            .iter()
            .map(|&i| chain[i])
            .chain(order.iter().map(|&i| pinch[i]))
            .collect();
        let mut app = app_in(CollisionMode::Continuous, arena(400.0, 400.0), &balls);
        step(&mut app, 1);
        let after = states(&mut app);
        // Back to the canonical order.
        let mut canonical = vec![after[0]; 6];
        for (slot, &i) in order.iter().enumerate() {
            canonical[i] = after[slot];
            canonical[3 + i] = after[3 + slot];
        }
        results.push(canonical);
    }
    for result in &results[1..] {
        for (got, want) in result.iter().zip(&results[0]) {
            assert!(got.position.distance(want.position) < 1e-9);
            assert!(got.velocity.distance(want.velocity) < 1e-9);
        }
    }
    let first = &results[0];
    // The chain really collided twice within the step: C now moves right.
    assert!(first[2].velocity.x > 0.0, "{}", first[2].velocity);
    // The pinch: equal masses, e = 1: D and F bounce back at full speed and E stays.
    assert!(
        (first[3].velocity.x + 3_000.0).abs() < 1e-9,
        "{}",
        first[3].velocity
    );
    assert!(first[4].velocity.length() < 1e-9, "{}", first[4].velocity);
    assert!(
        (first[5].velocity.x - 3_000.0).abs() < 1e-9,
        "{}",
        first[5].velocity
    );
}

#[test]
fn equal_speeds_relax_onto_the_maxwell_boltzmann_curve() {
    let setup = shipped_scene("maxwell.ron").build("maxwell.ron").unwrap();
    assert_eq!(setup.collisions, Some(CollisionMode::Continuous));
    let mut app = headless_app(DT);
    setup.apply(app.world_mut());
    let start = StateSummary::measure(app.world_mut());
    // Every ball at 300 px/s: one bar, far from the curve.
    assert!(start.speed_histogram.distance_from_expected() > 0.9);
    step(&mut app, 300);
    let end = StateSummary::measure(app.world_mut());
    let distance = end.speed_histogram.distance_from_expected();
    // 2,100 balls in 40 bins leave a sampling noise of about 0.04.
    assert!(distance < 0.08, "distance from the curve {distance}");
    let temperature_change = end.temperature() / start.temperature() - 1.0;
    assert!(temperature_change.abs() < 1e-9, "{temperature_change}");
}

#[test]
fn a_collapsing_pile_is_cut_short_yet_stays_finite_and_inside() {
    // Strong gravity and restitution 0.5 press the gas into a pile where impacts repeat ever
    // faster: steps reach the per-ball hit limit and finish with the discrete fallback.
    let setup = shipped_scene("gas.ron").build("gas.ron").unwrap();
    let mut params = setup.params.clone();
    params.gravity = DVec2::new(300.0, -2000.0);
    params.restitution = 0.5;
    let half = params.half_extents();
    let mut app = app_in(CollisionMode::Continuous, params, &setup.balls);
    step(&mut app, 90);
    assert!(app.world().resource::<SimStats>().cut_short_steps > 0);
    for b in states(&mut app) {
        assert!(b.position.is_finite() && b.velocity.is_finite());
        let reach = b.position.abs() + DVec2::splat(b.radius);
        assert!(reach.x <= half.x + 1e-9 && reach.y <= half.y + 1e-9);
    }
}

#[test]
fn an_elastic_ball_bounces_to_the_same_height_for_100_seconds() {
    // Dropped from 290 px above the floor under 500 px/s²: exact flight and exact wall times
    // keep its mechanical energy to rounding over 46 bounces. (The discrete mode's
    // semi-implicit Euler drifts by 1.4% over the same run.)
    let gravity = DVec2::new(0.0, -500.0);
    let mut app = app_in(
        CollisionMode::Continuous,
        SimParams {
            gravity,
            ..arena(400.0, 400.0)
        },
        &[ball(0.0, 100.0, 0.0, 0.0, 10.0)],
    );
    record_collisions(&mut app);
    let start = StateSummary::measure(app.world_mut()).mechanical_energy;
    let mut highest_late = f64::MIN;
    for step_index in 0..6_000 {
        step(&mut app, 1);
        if step_index >= 5_000 {
            highest_late = highest_late.max(states(&mut app)[0].position.y);
        }
    }
    let end = StateSummary::measure(app.world_mut()).mechanical_energy;
    assert!(
        ((end - start) / start).abs() < 1e-12,
        "energy {start} -> {end}"
    );
    // Still bouncing up to where it started (to within a step's travel near the top).
    assert!(
        highest_late > 100.0 - 0.1 && highest_late <= 100.0 + 1e-6,
        "{highest_late}"
    );
    assert!(app.world().resource::<Recorded>().wall_hits.len() >= 45);
}

#[test]
fn the_elastic_gas_under_gravity_keeps_its_mechanical_energy() {
    let (app, start, end) = standard_gas_after_600_steps(DVec2::new(0.0, -500.0));
    let energy = (start.mechanical_energy, end.mechanical_energy);
    assert_kept_with_no_overlap(energy, 1e-9, &end);
    assert_eq!(app.world().resource::<SimStats>().cut_short_steps, 0);
}

#[test]
fn a_light_ball_between_a_heavy_one_and_a_wall_is_struck_as_often_as_pi_s_digits_say() {
    // Galperin's billiards: a heavy ball pushing a light one at rest against a wall, all on
    // one line, makes 31 impacts (ball and wall) for a mass ratio of 100 and 314 for 10,000,
    // the first digits of π. Here they come within a few steps, up to a hundred a step for the
    // light ball: the hit limit grows with the step's mass ratio, so none is cut short.
    for (mass_model, impacts) in [(MassModel::Radius, 31), (MassModel::Area, 314)] {
        let params = SimParams {
            mass_model,
            ..arena(2000.0, 400.0)
        };
        // The wall at x = -1000; the light ball 9 px from it, the heavy one 5 px further on.
        let balls = [
            ball(-990.0, 0.0, 0.0, 0.0, 1.0),
            ball(-884.0, 0.0, -300.0, 0.0, 100.0),
        ];
        let mut app = app_in(CollisionMode::Continuous, params, &balls);
        record_collisions(&mut app);
        let start = StateSummary::measure(app.world_mut()).kinetic_energy;
        step(&mut app, 60);
        let recorded = app.world().resource::<Recorded>();
        let (ball_hits, wall_hits) = (recorded.ball_hits.len(), recorded.wall_hits.len());
        assert_eq!(ball_hits + wall_hits, impacts, "{mass_model:?}");
        assert_eq!(app.world().resource::<SimStats>().cut_short_steps, 0);
        let end = StateSummary::measure(app.world_mut());
        assert_kept_with_no_overlap((start, end.kinetic_energy), 1e-12, &end);
        // Both fly away from the wall, the light one no faster than the heavy one.
        let [light, heavy] = states(&mut app)[..] else {
            panic!("two balls")
        };
        assert!(0.0 <= light.velocity.x && light.velocity.x <= heavy.velocity.x);
    }
}

#[test]
fn a_few_big_balls_among_many_small_ones_never_overlap_and_keep_the_energy() {
    // The mixed scene with 2,000 small balls: its three big ones stay out of the grid's
    // cells, in a grid of their own, so this checks that every impact with them is found,
    // first paths and redirected ones alike.
    let mut scene = shipped_scene("mixed.ron");
    scene.generate.as_mut().unwrap().count = 2000;
    let setup = scene.build("mixed.ron").unwrap();
    let mut app = app_in(CollisionMode::Continuous, setup.params, &setup.balls);
    let big_velocities = |app: &mut App| -> Vec<DVec2> {
        let balls = states(app);
        balls
            .iter()
            .filter(|b| b.radius >= 40.0)
            .map(|b| b.velocity)
            .collect()
    };
    let start = StateSummary::measure(app.world_mut());
    let big_before = big_velocities(&mut app);
    step(&mut app, 120);
    let end = StateSummary::measure(app.world_mut());
    assert_kept_with_no_overlap((start.kinetic_energy, end.kinetic_energy), 1e-9, &end);
    // A small ball caught by a big one is struck many times a step: never past its limit.
    assert_eq!(app.world().resource::<SimStats>().cut_short_steps, 0);
    let big_after = big_velocities(&mut app);
    assert_eq!(big_after.len(), 3);
    for (before, after) in big_before.iter().zip(&big_after) {
        assert!(
            before.distance(*after) > 1.0,
            "a big ball never hit: {before} {after}"
        );
    }
}
