//! The windowed toy put together: default plugins, the simulation, the toy's shared state
//! ([`app`]), its rendering, its UI and frame diagnostics; optionally a
//! screenshot after a number of frames, or a recording of them ([`record`](crate::record)),
//! for the README and for checks under Xvfb.

use std::path::PathBuf;
use std::sync::atomic::Ordering;

use bevy::diagnostic::DiagnosticsStore;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::window::WindowResolution;

use crate::app::scenes::CurrentScene;
use crate::app::view::{PANEL_WIDTH, fit_window};
use crate::record::{RecordPlan, start_recording};
use crate::sim::params::DEFAULT_STEP_RATE;
use crate::sim::{Ball, RunControl, SimPlugin};
use crate::{app, diagnostics, render, ui};

/// What to play and whether to take a screenshot and quit.
pub struct PlayOptions {
    pub scene: CurrentScene,
    /// The scene's arena, pixels (from validating it): sizes the window.
    pub arena: Vec2,
    /// Save a PNG of the window after `frames` frames, then exit.
    pub screenshot: Option<(PathBuf, u32)>,
    /// Record `frames` frames of the window as a GIF, then exit.
    pub record: Option<(PathBuf, u32)>,
    /// Start paused (Space or the Pause button runs it).
    pub paused: bool,
}

/// Opens the window and runs until it is closed (or the screenshot is saved).
pub fn play(options: PlayOptions) -> AppExit {
    let window = fit_window(options.arena, PANEL_WIDTH);
    let mut app = App::new();
    app.add_plugins(DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window {
            title: "ballpit".into(),
            resolution: WindowResolution::new(window.x as u32, window.y as u32),
            // A recording's frames must all be one size.
            resizable: options.record.is_none(),
            ..default()
        }),
        ..default()
    }))
    .add_plugins(GamePlugin)
    .insert_resource(options.scene);
    // Loading a scene keeps the pause state, so this survives the start-up load.
    app.world_mut().resource_mut::<RunControl>().paused = options.paused;
    if let Some((path, frames)) = options.screenshot {
        app.insert_resource(ScreenshotPlan {
            path,
            frames,
            requested_at: None,
        })
        .add_systems(Update, take_screenshot_and_exit);
    }
    let recorded = options
        .record
        .map(|(path, frames)| start_recording(&mut app, RecordPlan::new(path, frames)));
    match app.run() {
        AppExit::Success if recorded.is_some_and(|written| !written.load(Ordering::Acquire)) => {
            error!("the window closed before the recording was written");
            AppExit::error()
        }
        exit => exit,
    }
}

/// The whole toy but the window and rendering backends: the simulation at 60 steps per
/// second, its rendering, the panel and input, and scene requests. The scene to play comes
/// in a [`CurrentScene`] resource; it is loaded at start-up.
pub struct GamePlugin;

impl Plugin for GamePlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins((
            SimPlugin,
            app::plugin,
            render::plugin,
            ui::plugin,
            diagnostics::plugin,
        ))
        .insert_resource(Time::<Fixed>::from_hz(DEFAULT_STEP_RATE));
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
    store: Res<DiagnosticsStore>,
    balls: Query<(), With<Ball>>,
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
            let (frame_ms, fps, simulation_ms) = diagnostics::frame_figures(&store);
            let show = |value: Option<f64>| value.map_or("-".to_string(), |v| format!("{v:.2}"));
            println!(
                "frame {}: {} balls, frame time {} ms ({} FPS), simulation {} ms per frame",
                *frame,
                balls.iter().len(),
                show(frame_ms),
                show(fps),
                show(simulation_ms)
            );
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
