//! The player's hands on the balls, headless, as the intents the UI sends: carrying (running
//! and paused), throwing, removing, and reaching thousands of balls from the demo with the
//! count slider and the one control the full-arena note names.

use ballpit::prelude::*;
use ballpit::sim::carry::MAX_CARRY_SPEED;
use ballpit::sim::{BallCountOutcome, Carried, Rest};
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::common::*;

fn arena(side: f64) -> SimParams {
    SimParams {
        arena_size: DVec2::splat(side),
        ..default()
    }
}

fn carry(app: &mut App, ball: Entity, target: DVec2) {
    app.world_mut()
        .write_message(Intent::Carry { ball, target });
}

#[test]
fn a_carried_ball_follows_the_pointer_pushing_balls_and_never_passing_through() {
    for mode in CollisionMode::ALL {
        let balls = [
            ball(-200.0, 0.0, 0.0, 0.0, 10.0),
            ball(0.0, 0.0, 0.0, 0.0, 10.0),
        ];
        let mut app = app_in(mode, arena(1000.0), &balls);
        let carried = entity_of(&mut app, 0);
        step(&mut app, 1);
        for _ in 0..120 {
            carry(&mut app, carried, DVec2::new(300.0, 0.0));
            step(&mut app, 1);
            let [a, b] = [0, 1].map(|i| states(&mut app)[i]);
            assert!(a.position.x < b.position.x, "{mode:?}: passed through");
            let gap = a.position.distance(b.position) - 20.0;
            assert!(gap > -0.5, "{mode:?}: overlap {gap}");
            assert!(a.velocity.length() <= MAX_CARRY_SPEED + 1e-9);
        }
        let [a, b] = [0, 1].map(|i| states(&mut app)[i]);
        assert!(a.position.x > 200.0, "{mode:?}: {a:?}");
        assert!(b.position.x > 220.0, "{mode:?}: pushed ahead, {b:?}");
        // Released, it flies at the pointer's velocity and is no longer held.
        app.world_mut().write_message(Intent::Release {
            ball: carried,
            velocity: DVec2::new(0.0, 250.0),
        });
        step(&mut app, 1);
        assert!(app.world().get::<Carried>(carried).is_none());
        let a = states(&mut app)[0];
        assert_eq!(a.velocity, DVec2::new(0.0, 250.0), "{mode:?}");
        step(&mut app, 10);
        assert!(states(&mut app)[0].position.y > 40.0, "{mode:?}");
    }
}

#[test]
fn a_carried_ball_rises_against_gravity_and_falls_when_released() {
    let params = SimParams {
        gravity: DVec2::new(0.0, -500.0),
        restitution: 0.5,
        ..arena(1000.0)
    };
    let mut app = app_with(params, &[ball(0.0, -490.0, 0.0, 0.0, 10.0)]);
    let carried = entity_of(&mut app, 0);
    step(&mut app, 120); // resting on the floor
    for _ in 0..60 {
        carry(&mut app, carried, DVec2::new(0.0, 100.0));
        step(&mut app, 1);
    }
    let held = states(&mut app)[0].position.y;
    assert!((held - 100.0).abs() < 2.0, "{held}");
    app.world_mut().write_message(Intent::Release {
        ball: carried,
        velocity: DVec2::ZERO,
    });
    step(&mut app, 30);
    assert!(states(&mut app)[0].position.y < held - 50.0);
}

#[test]
fn paused_a_carried_ball_moves_at_once_and_stops_at_the_first_ball_or_wall() {
    let balls = [
        ball(-200.0, 0.0, 50.0, 0.0, 10.0),
        ball(0.0, 0.0, 0.0, 0.0, 10.0),
    ];
    let mut app = app_with(arena(1000.0), &balls);
    set_paused(&mut app, true);
    let carried = entity_of(&mut app, 0);
    carry(&mut app, carried, DVec2::new(300.0, 0.0));
    step(&mut app, 1);
    let a = states(&mut app)[0];
    assert!(
        (a.position - DVec2::new(-20.0, 0.0)).length() < 1e-9,
        "{a:?}"
    );
    assert_eq!(a.velocity, DVec2::ZERO, "held still");
    carry(&mut app, carried, DVec2::new(-2_000.0, 0.0));
    step(&mut app, 1);
    let a = states(&mut app)[0];
    assert!(
        (a.position - DVec2::new(-490.0, 0.0)).length() < 1e-9,
        "{a:?}"
    );
    assert_eq!(steps_run(&app), 0);
    // A target that is not a number is ignored.
    carry(&mut app, carried, DVec2::NAN);
    step(&mut app, 1);
    assert_eq!(states(&mut app)[0].position, a.position);
}

#[test]
fn removing_a_ball_takes_it_out_and_ignores_what_is_not_a_ball() {
    for mode in CollisionMode::ALL {
        let balls = [
            ball(-100.0, 0.0, 0.0, 0.0, 10.0),
            ball(100.0, 0.0, 0.0, 0.0, 10.0),
        ];
        let mut app = app_in(mode, arena(1000.0), &balls);
        let first = entity_of(&mut app, 0);
        app.world_mut().write_message(Intent::Remove(first));
        step(&mut app, 1);
        app.world_mut().write_message(Intent::Remove(first));
        app.world_mut()
            .write_message(Intent::Remove(Entity::PLACEHOLDER));
        step(&mut app, 1);
        let left = states(&mut app);
        assert_eq!(left.len(), 1, "{mode:?}");
        assert_eq!(left[0].position, DVec2::new(100.0, 0.0), "{mode:?}");
    }
}

#[test]
fn from_the_demo_the_count_slider_and_the_notes_one_control_reach_5000_balls() {
    let mut app = headless_app(DT);
    shipped_scene("demo.ron")
        .build("demo.ron")
        .unwrap()
        .apply(app.world_mut());
    app.world_mut().write_message(Intent::SetBallCount(5_000));
    step(&mut app, 1);
    let outcome = *app.world().resource::<BallCountOutcome>();
    assert!(outcome.reached < 5_000, "{outcome:?}");
    let note = outcome.note().expect("the arena is full");
    assert!(note.contains("Add smaller balls"), "{note}");
    let radius = outcome.smaller_radius.unwrap();
    assert!(radius >= 3.0, "{radius}");
    // The note's control, followed: every ball fits, none overlapping.
    app.world_mut()
        .write_message(Intent::AddSmallerBalls(outcome.wanted));
    step(&mut app, 1);
    let balls = states(&mut app);
    assert_eq!(balls.len(), 5_000);
    assert_eq!(app.world().resource::<BallCountOutcome>().note(), None);
    let added = &balls[outcome.reached..];
    assert!(added.iter().all(|b| (b.radius - radius).abs() < 1e-9));
    // In a small arena not even the smallest balls fit: the note says to enlarge it.
    app.world_mut().resource_mut::<SimParams>().arena_size = DVec2::splat(200.0);
    app.world_mut().write_message(Intent::SetBallCount(90_000));
    step(&mut app, 1);
    let note = app.world().resource::<BallCountOutcome>().note().unwrap();
    assert!(note.contains("enlarge the arena"), "{note}");
}

#[test]
fn a_carried_ball_wakes_a_sleeping_pile_and_pushes_its_way_up_through_it() {
    for mode in CollisionMode::ALL {
        let params = SimParams {
            gravity: DVec2::new(0.0, -500.0),
            restitution: 0.5,
            arena_size: DVec2::new(400.0, 400.0),
            ..default()
        };
        // A column of three standing on the floor, asleep after a second.
        let column = [-190.0, -170.0, -150.0].map(|y| ball(0.0, y, 0.0, 0.0, 10.0));
        let mut app = app_in(mode, params, &column);
        step(&mut app, 60);
        let asleep = |app: &mut App| {
            let world = app.world_mut();
            let mut rests = world.query::<&Rest>();
            rests.iter(world).filter(|rest| rest.is_asleep()).count()
        };
        assert_eq!(asleep(&mut app), 3, "{mode:?}");
        let bottom = entity_of(&mut app, 0);
        for _ in 0..90 {
            carry(&mut app, bottom, DVec2::new(0.0, 100.0));
            step(&mut app, 1);
        }
        let balls = states(&mut app);
        assert!(balls[0].position.y > 50.0, "{mode:?}: {:?}", balls[0]);
        for (i, a) in balls.iter().enumerate() {
            for b in &balls[i + 1..] {
                let gap = a.position.distance(b.position) - a.radius - b.radius;
                assert!(gap > -2.0, "{mode:?}: overlap {gap}");
            }
        }
        // The balls above were pushed up or aside, never passed through.
        assert!(balls[1].position.y > balls[0].position.y || balls[1].position.x.abs() > 5.0);
    }
}
