//! The windowed toy's plugins, built and run without a window or GPU: a broken plugin setup
//! (a missing resource, a bad schedule) fails here rather than on a player's screen.

use ballpit::play::{CurrentScene, GamePlugin, SceneRequest};
use ballpit::prelude::*;
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
            .disable::<WinitPlugin>(),
    )
    .add_plugins(GamePlugin)
    .insert_resource(CurrentScene {
        file: shipped_scene(scene),
        origin: scene.into(),
    })
    .insert_resource(bevy::time::TimeUpdateStrategy::FixedTimesteps(1));
    app
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
    let step = world.resource::<Time<Fixed>>().timestep().as_secs_f64();
    assert!((step - 1.0 / 60.0).abs() < 1e-9, "{step}");
    assert!(world.resource::<SimStats>().steps >= 2);
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
    let status = world.resource::<ballpit::play::SceneStatus>().0.clone();
    assert!(status.unwrap().contains("no_such_scene.ron"));
    assert_eq!(
        world.query_filtered::<(), With<Ball>>().iter(world).count(),
        2
    );
    assert_eq!(world.resource::<CurrentScene>().origin, "head_on.ron");
}
