//! The windowed toy: default plugins, the simulation and its rendering, a scene loaded at
//! start-up, and optionally a screenshot after a number of frames (for checks under Xvfb).

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::window::WindowResolution;

use crate::render;
use crate::sim::{SceneSetup, SimPlugin};

/// Largest window the play command opens, logical pixels; a larger arena is fitted to it.
const MAX_WINDOW: Vec2 = Vec2::new(1600.0, 1000.0);

/// What to play and whether to take a screenshot and quit.
pub struct PlayOptions {
    pub setup: SceneSetup,
    /// Save a PNG of the window after `frames` frames, then exit.
    pub screenshot: Option<(PathBuf, u32)>,
}

/// Opens the window and runs until it is closed (or the screenshot is saved).
pub fn play(options: PlayOptions) -> AppExit {
    let arena = options.setup.params.arena_size.as_vec2().min(MAX_WINDOW);
    let mut app = App::new();
    app.add_plugins(DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window {
            title: "ballpit".into(),
            resolution: WindowResolution::new(arena.x as u32, arena.y as u32),
            ..default()
        }),
        ..default()
    }))
    .add_plugins((SimPlugin, render::plugin))
    .insert_resource(SceneToLoad(options.setup))
    .add_systems(Startup, load_scene);
    if let Some((path, frames)) = options.screenshot {
        app.insert_resource(ScreenshotPlan {
            path,
            frames,
            requested_at: None,
        })
        .add_systems(Update, take_screenshot_and_exit);
    }
    app.run()
}

#[derive(Resource)]
struct SceneToLoad(SceneSetup);

fn load_scene(world: &mut World) {
    if let Some(SceneToLoad(setup)) = world.remove_resource::<SceneToLoad>() {
        setup.apply(world);
    }
}

#[derive(Resource)]
struct ScreenshotPlan {
    path: PathBuf,
    frames: u32,
    requested_at: Option<u32>,
}

/// Frames to wait after the screenshot is written, so the file is complete before exit.
const FRAMES_TO_SAVE: u32 = 30;
/// Frames after the request at which a screenshot that never arrived counts as failed.
const FRAMES_TO_GIVE_UP: u32 = 600;

fn take_screenshot_and_exit(
    mut plan: ResMut<ScreenshotPlan>,
    mut frame: Local<u32>,
    mut commands: Commands,
    mut exit: MessageWriter<AppExit>,
) {
    *frame += 1;
    match plan.requested_at {
        None if *frame >= plan.frames => {
            commands
                .spawn(Screenshot::primary_window())
                .observe(save_to_disk(plan.path.clone()));
            plan.requested_at = Some(*frame);
        }
        Some(requested) if *frame >= requested + FRAMES_TO_SAVE && plan.path.exists() => {
            exit.write(AppExit::Success);
        }
        Some(requested) if *frame >= requested + FRAMES_TO_GIVE_UP => {
            error!("the screenshot {} was not written", plan.path.display());
            exit.write(AppExit::error());
        }
        _ => {}
    }
}
