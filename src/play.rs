//! The windowed toy: default plugins, the simulation, its rendering and its UI; the scene being
//! played and requests to reset, reseed or switch it; optionally a screenshot after a number
//! of frames (for the README and for checks under Xvfb).
//!
//! Scene requests arrive as [`SceneRequest`] messages (from the panel and the keys) and are
//! applied as world commands in `Update`. A scene that fails to load leaves the current one
//! playing and its error in [`SceneStatus`].

use std::path::PathBuf;

use bevy::diagnostic::DiagnosticsStore;
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::window::{PrimaryWindow, WindowResolution};
use rand::RngExt;

use crate::render::{self, PlayArea};
use crate::sim::{Ball, SceneFile, SimParams, SimPlugin, SimRng};
use crate::{diagnostics, ui};

/// Largest window the toy opens or resizes to, logical pixels.
const MAX_WINDOW: Vec2 = Vec2::new(1600.0, 1000.0);
/// Smallest window the toy resizes to for a scene, logical pixels.
const MIN_WINDOW: Vec2 = Vec2::new(640.0, 400.0);
/// Fixed steps per second.
pub const DEFAULT_STEP_RATE: f64 = 60.0;

/// What to play and whether to take a screenshot and quit.
pub struct PlayOptions {
    pub scene: CurrentScene,
    /// The scene's arena, pixels (from validating it): sizes the window.
    pub arena: Vec2,
    /// Save a PNG of the window after `frames` frames, then exit.
    pub screenshot: Option<(PathBuf, u32)>,
    /// Start paused (Space or the Pause button runs it).
    pub paused: bool,
}

/// The scene being played, as a file (so reset and reseed rebuild it), and its name.
#[derive(Resource, Clone, Debug, PartialEq)]
pub struct CurrentScene {
    pub file: SceneFile,
    pub origin: String,
}

/// What the player asked to do with the scene.
#[derive(Message, Clone, Debug, PartialEq)]
pub enum SceneRequest {
    /// Rebuild the current scene with the same seed.
    Reset,
    /// Rebuild the current scene with a new random seed.
    NewSeed,
    /// Switch to the scene file at this path.
    Load(PathBuf),
}

/// A scene was (re)loaded: anything that keeps history of the old one starts afresh.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneLoaded;

/// The last scene error, shown in the panel until a scene loads.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct SceneStatus(pub Option<String>);

/// Opens the window and runs until it is closed (or the screenshot is saved).
pub fn play(options: PlayOptions) -> AppExit {
    let window = fit_window(options.arena, ui::PANEL_WIDTH).0;
    let mut app = App::new();
    app.add_plugins(DefaultPlugins.set(WindowPlugin {
        primary_window: Some(Window {
            title: "ballpit".into(),
            resolution: WindowResolution::new(window.x as u32, window.y as u32),
            ..default()
        }),
        ..default()
    }))
    .add_plugins(GamePlugin)
    .insert_resource(options.scene);
    // Loading a scene keeps the pause state, so this survives the start-up load.
    app.world_mut().resource_mut::<SimParams>().paused = options.paused;
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

/// The whole toy but the window and rendering backends: the simulation at 60 steps per
/// second, its rendering, the panel and input, and scene requests. The scene to play comes
/// in a [`CurrentScene`] resource; it is loaded at start-up.
pub struct GamePlugin;

impl Plugin for GamePlugin {
    fn build(&self, app: &mut App) {
        app.add_plugins((SimPlugin, render::plugin, ui::plugin, diagnostics::plugin))
            .insert_resource(Time::<Fixed>::from_hz(DEFAULT_STEP_RATE))
            .add_message::<SceneRequest>()
            .add_message::<SceneLoaded>()
            .init_resource::<SceneStatus>()
            .add_systems(Startup, |mut requests: MessageWriter<SceneRequest>| {
                requests.write(SceneRequest::Reset);
            })
            .add_systems(Update, handle_scene_requests);
    }
}

/// The window size and zoom that show `arena` beside a panel `panel` pixels wide: the arena at
/// one pixel per pixel if that fits the largest window, else zoomed out until it does.
pub fn fit_window(arena: Vec2, panel: f32) -> (Vec2, f32) {
    let room = MAX_WINDOW - Vec2::new(panel, 0.0);
    let zoom = (arena / room).max_element().max(1.0);
    let window = (arena / zoom + Vec2::new(panel, 0.0)).clamp(MIN_WINDOW, MAX_WINDOW);
    (window, zoom)
}

fn handle_scene_requests(mut requests: MessageReader<SceneRequest>, mut commands: Commands) {
    for request in requests.read().cloned() {
        commands.queue(move |world: &mut World| apply_scene_request(world, request));
    }
}

fn apply_scene_request(world: &mut World, request: SceneRequest) {
    let mut scene = world.resource::<CurrentScene>().clone();
    match request {
        SceneRequest::Reset => {}
        SceneRequest::NewSeed => {
            let seed = world.resource_mut::<SimRng>().0.random::<u64>();
            if let Some(generate) = scene.file.generate.as_mut() {
                generate.seed = seed;
            }
        }
        SceneRequest::Load(path) => match SceneFile::load(&path) {
            Ok(file) => {
                scene = CurrentScene {
                    file,
                    origin: path.display().to_string(),
                }
            }
            Err(error) => {
                world.resource_mut::<SceneStatus>().0 = Some(error.to_string());
                return;
            }
        },
    }
    match scene.file.build(&scene.origin) {
        Ok(setup) => {
            let arena = setup.params.arena_size;
            setup.apply(world);
            resize_window_for(world, arena);
            world.insert_resource(scene);
            world.resource_mut::<SceneStatus>().0 = None;
            world.write_message(SceneLoaded);
        }
        Err(error) => world.resource_mut::<SceneStatus>().0 = Some(error.to_string()),
    }
}

/// Zooms and asks for a window that show `arena` beside the panel. Until the window arrives
/// the arena keeps the scene's size; then it follows the window.
fn resize_window_for(world: &mut World, arena: DVec2) {
    let mut play_area = *world.resource::<PlayArea>();
    let (wanted, zoom) = fit_window(arena.as_vec2(), play_area.panel_width);
    play_area.zoom = zoom;
    world.insert_resource(play_area);
    let mut windows = world.query_filtered::<&mut Window, With<PrimaryWindow>>();
    if let Ok(mut window) = windows.single_mut(world)
        && window.size() != wanted
    {
        window.resolution.set(wanted.x, wanted.y);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_arenas_show_one_to_one_and_large_ones_zoom_out() {
        let (window, zoom) = fit_window(Vec2::new(800.0, 600.0), 300.0);
        assert_eq!((window, zoom), (Vec2::new(1100.0, 600.0), 1.0));
        let (window, zoom) = fit_window(Vec2::new(3000.0, 3000.0), 300.0);
        assert_eq!(zoom, 3.0);
        assert_eq!(window, Vec2::new(1300.0, 1000.0));
    }
}
