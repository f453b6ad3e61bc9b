//! The windowed toy's plugins, built and run without a window or GPU: a broken plugin setup
//! (a missing resource, a bad schedule) fails here rather than on a player's screen.

use ballpit::app::scenes::{CurrentScene, SceneRequest, SceneStatus};
use ballpit::app::view::{FIT_MARGIN, PANEL_WIDTH, PanelVisible, PlayArea};
use ballpit::play::GamePlugin;
use ballpit::prelude::*;
use ballpit::sim::BallCountOutcome;
use bevy::input::ButtonState;
use bevy::input::keyboard::{Key, KeyboardInput, NativeKey};
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::settings::{RenderCreation, WgpuSettings};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;

use crate::common::*;

fn windowless_game(scene: &str) -> App {
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                ..default()
            })
            .set(RenderPlugin {
                render_creation: RenderCreation::Automatic(Box::new(WgpuSettings {
                    backends: None,
                    ..default()
                })),
                ..default()
            })
            .disable::<WinitPlugin>()
            .disable::<bevy::log::LogPlugin>(),
    )
    .add_plugins(GamePlugin)
    .insert_resource(CurrentScene {
        file: shipped_scene(scene),
        origin: scene.into(),
    })
    .insert_resource(bevy::time::TimeUpdateStrategy::FixedTimesteps(1));
    app
}

/// Adds a primary window (logical size only: nothing opens it).
fn add_window(app: &mut App) -> Entity {
    app.world_mut()
        .spawn((Window::default(), bevy::window::PrimaryWindow))
        .id()
}

/// Resizes the window as a player would, then runs `frames` frames.
fn resize_window(app: &mut App, window: Entity, size: (f32, f32), frames: usize) {
    let mut entity = app.world_mut().entity_mut(window);
    entity
        .get_mut::<Window>()
        .unwrap()
        .resolution
        .set(size.0, size.1);
    for _ in 0..frames {
        app.update();
    }
}

/// Asserts every ball lies inside the arena.
fn assert_all_inside(app: &mut App) {
    let half = app.world().resource::<SimParams>().half_extents();
    for ball in states(app) {
        let reach = ball.position.abs() + bevy::math::DVec2::splat(ball.radius);
        assert!(
            reach.x <= half.x + 1e-9 && reach.y <= half.y + 1e-9,
            "{ball:?}"
        );
    }
}

#[test]
fn the_game_builds_loads_its_scene_and_steps_without_a_window() {
    let mut app = windowless_game("demo.ron");
    for _ in 0..4 {
        app.update();
    }
    let world = app.world_mut();
    let balls = world
        .query_filtered::<&Sprite, With<Ball>>()
        .iter(world)
        .count();
    assert_eq!(balls, 40, "every ball of the demo has a sprite");
    // The drawing's own state: each ball's centre at the start of the step, for drawing
    // between steps, kept by the movement stage.
    let previous: Vec<(bevy::math::DVec2, bevy::math::DVec2)> = world
        .query_filtered::<(&ballpit::sim::PreviousPosition, &Position), With<Ball>>()
        .iter(world)
        .map(|(previous, position)| (previous.0, position.0))
        .collect();
    assert_eq!(previous.len(), 40, "every ball has a previous position");
    assert!(
        previous
            .iter()
            .any(|(previous, position)| previous != position),
        "and it is where the ball was a step ago"
    );
    let step = world.resource::<Time<Fixed>>().timestep().as_secs_f64();
    assert!((step - 1.0 / 60.0).abs() < 1e-9, "{step}");
    assert!(world.resource::<SimClock>().steps >= 2);
    // A slow frame advances the game by at most the catch-up bound: at 60 steps a second,
    // four steps, so it never makes the next frame slower.
    let bound = world.resource::<Time<Virtual>>().max_delta();
    assert_eq!(bound, ballpit::diagnostics::MAX_CATCH_UP);
    assert!((bound.as_secs_f64() / step - 4.0).abs() < 1e-3);
}

#[test]
fn a_bad_scene_request_keeps_the_current_scene_and_reports() {
    let mut app = windowless_game("head_on.ron");
    app.update();
    app.world_mut()
        .write_message(SceneRequest::Load("assets/scenes/no_such_scene.ron".into()));
    app.update();
    app.update();
    let world = app.world_mut();
    let status = world.resource::<SceneStatus>().0.clone();
    assert!(status.unwrap().contains("no_such_scene.ron"));
    assert_eq!(
        world.query_filtered::<(), With<Ball>>().iter(world).count(),
        2
    );
    assert_eq!(world.resource::<CurrentScene>().origin, "head_on.ron");
}

#[test]
fn the_window_is_a_view_of_the_arena_fitted_until_zoomed_and_still_when_the_panel_hides() {
    let mut app = windowless_game("gas.ron");
    let window = add_window(&mut app);
    app.update();
    let arena = app.world().resource::<SimParams>().arena_size;
    resize_window(&mut app, window, (1400.0, 900.0), 3);
    // The arena keeps the scene's size; the view fits it right of the panel.
    assert_eq!(app.world().resource::<SimParams>().arena_size, arena);
    let area = *app.world().resource::<PlayArea>();
    let room = 900.0 - 2.0 * FIT_MARGIN;
    assert!((area.zoom - arena.y as f32 / room).abs() < 1e-4, "{area:?}");
    assert_eq!(area.center, Vec2::new(-PANEL_WIDTH / 2.0 * area.zoom, 0.0));
    // Hiding the panel moves nothing on screen.
    press(&mut app, KeyCode::KeyH);
    assert!(!app.world().resource::<PanelVisible>().0);
    let hidden = *app.world().resource::<PlayArea>();
    assert_eq!((hidden.zoom, hidden.center), (area.zoom, area.center));
    // Zoomed by the player, a resize keeps the zoom; F fits again.
    app.world_mut()
        .resource_mut::<PlayArea>()
        .zoom_at(Vec2::ZERO, 0.5);
    resize_window(&mut app, window, (1000.0, 700.0), 2);
    assert!((app.world().resource::<PlayArea>().zoom - area.zoom * 0.5).abs() < 1e-6);
    press(&mut app, KeyCode::KeyF);
    let fitted = *app.world().resource::<PlayArea>();
    assert!((fitted.zoom - arena.y as f32 / (700.0 - 2.0 * FIT_MARGIN)).abs() < 1e-4);
    // Loading a scene keeps the window's size and fits the new arena.
    app.world_mut()
        .write_message(SceneRequest::Load("assets/scenes/billiards.ron".into()));
    app.update();
    app.update();
    let size = app.world().get::<Window>(window).unwrap().size();
    assert_eq!(size, Vec2::new(1000.0, 700.0));
    let arena = app.world().resource::<SimParams>().arena_size.as_vec2();
    let zoom = app.world().resource::<PlayArea>().zoom;
    let shown = (size - Vec2::new(0.0, 0.0) - Vec2::splat(2.0 * FIT_MARGIN)) * zoom;
    assert!(
        shown.x >= arena.x - 1e-3 && shown.y >= arena.y - 1e-3,
        "{shown} {arena}"
    );
    assert!((shown.x - arena.x).abs() < 1e-3 || (shown.y - arena.y).abs() < 1e-3);
    assert_all_inside(&mut app);
}

#[test]
fn a_minimised_window_keeps_the_arena_and_every_ball() {
    let mut app = windowless_game("demo.ron");
    let window = add_window(&mut app);
    for _ in 0..3 {
        app.update();
    }
    let arena = app.world().resource::<SimParams>().arena_size;
    let steps = steps_run(&app);
    resize_window(&mut app, window, (0.0, 0.0), 5);
    assert_eq!(app.world().resource::<SimParams>().arena_size, arena);
    assert!(steps_run(&app) >= steps + 4);
    assert_eq!(states(&mut app).len(), 40);
    assert_all_inside(&mut app);
}

#[test]
fn asking_for_more_balls_than_fit_gives_a_note_not_a_hang() {
    let mut app = windowless_game("demo.ron");
    app.update();
    app.world_mut()
        .resource_mut::<ballpit::sim::SpawnSettings>()
        .radius = (40.0, 40.0);
    // The count slider sends this; the fixed step applies it.
    app.world_mut().write_message(Intent::SetBallCount(100_000));
    app.update();
    let world = app.world_mut();
    let balls = world.query_filtered::<(), With<Ball>>().iter(world).count();
    let note = world.resource::<BallCountOutcome>().note();
    assert!(balls > 40 && balls < 1_000, "{balls}");
    let note = note.expect("a note when the arena is full");
    assert!(
        note.contains(&format!("{balls} of 100000 balls fit")),
        "{note}"
    );
    // A request that is met clears it.
    app.world_mut().write_message(Intent::SetBallCount(10));
    app.update();
    assert_eq!(app.world().resource::<BallCountOutcome>().note(), None);
}

/// Presses `key` for one frame and releases it, as the window's keyboard messages would:
/// Bevy's input plugin turns them into `ButtonInput<KeyCode>`, which the toy reads.
fn press(app: &mut App, key: KeyCode) {
    for state in [ButtonState::Pressed, ButtonState::Released] {
        app.world_mut().write_message(KeyboardInput {
            key_code: key,
            logical_key: Key::Unidentified(NativeKey::Unidentified),
            state,
            text: None,
            repeat: false,
            window: Entity::PLACEHOLDER,
        });
        app.update();
    }
}

#[test]
fn the_keys_pause_step_hide_and_reset() {
    let mut app = windowless_game("demo.ron");
    app.update();
    app.update();
    // Space pauses: no more steps run.
    press(&mut app, KeyCode::Space);
    assert!(app.world().resource::<RunControl>().paused);
    let paused_at = steps_run(&app);
    for _ in 0..3 {
        app.update();
    }
    assert_eq!(steps_run(&app), paused_at);
    // N runs exactly one step and stays paused.
    press(&mut app, KeyCode::KeyN);
    assert_eq!(steps_run(&app), paused_at + 1);
    assert!(app.world().resource::<RunControl>().paused);
    // H hides the panel, and again shows it.
    press(&mut app, KeyCode::KeyH);
    assert!(!app.world().resource::<PanelVisible>().0);
    press(&mut app, KeyCode::KeyH);
    assert!(app.world().resource::<PanelVisible>().0);
    // R reloads the scene: the clock starts again.
    press(&mut app, KeyCode::KeyR);
    assert_eq!(steps_run(&app), 0);
    // Space again resumes.
    press(&mut app, KeyCode::Space);
    app.update();
    assert!(!app.world().resource::<RunControl>().paused);
    assert!(steps_run(&app) > 0);
}
