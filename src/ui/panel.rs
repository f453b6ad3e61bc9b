//! The egui side panel: every tunable live (sliders, buttons, scene picker, overlays) and
//! readouts (FPS, balls, collisions per second, energy, momentum, an energy plot; the gas's
//! temperature, pressure and speed histogram against the Maxwell–Boltzmann curve). Edits go
//! to copies that are clamped to their limits and written back only when they changed; the
//! ball count is an [`Intent`]. Runs in `EguiPrimaryContextPass`; the [`Readouts`] it shows
//! are gathered in `Update`.

use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

use bevy::diagnostic::DiagnosticsStore;
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::egui::{self, Color32, RichText, Slider, SliderClamping, emath::Numeric};
use bevy_egui::{EguiContexts, EguiPrimaryContextPass};

use super::figures::{gas, readouts};
use super::help::help_window;
use super::readouts::Readouts;
use crate::app::scenes::{CurrentScene, SceneRequest, SceneStatus};
use crate::app::view::{
    ColourMode, HOT_SPEED, HelpVisible, PANEL_WIDTH, PanelVisible, PlayArea, SIZE_COLOUR_RANGE,
    ViewSettings, heat_colour,
};
use crate::diagnostics::{frame_figures, game_speed};
use crate::sim::params::{
    ARENA_SLIDER, BALL_COUNT_SLIDER, DAMPING_SLIDER, DEFAULT_STEP_RATE, GRAVITY_SLIDER,
    RADIUS_SLIDER, RESTITUTION_RANGE, SPEED_SLIDER, STEP_RATE_SLIDER, TIME_SCALE_SLIDER,
};
use crate::sim::resting::RestingState;
use crate::sim::{
    BallCountOutcome, CollisionMode, Intent, MassModel, RunControl, SimParams, Solver,
    SpawnSettings,
};

/// Below this game speed against real time the panel warns that the game runs slow.
const SLOW_GAME: f64 = 0.95;
/// The colour of warnings: a full arena, a slow game.
const WARNING: Color32 = Color32::from_rgb(255, 190, 90);

/// Where the scene picker looks for scene files, relative to the working directory.
pub const SCENE_FOLDER: &str = "assets/scenes";
pub(super) fn plugin(app: &mut App) {
    app.insert_resource(SceneList::read(Path::new(SCENE_FOLDER)))
        .add_systems(EguiPrimaryContextPass, draw_panel);
}

/// The scene files the picker offers.
#[derive(Resource, Debug, Clone, Default, PartialEq)]
pub struct SceneList(pub Vec<PathBuf>);

impl SceneList {
    /// The `.ron` files in `folder`, sorted; none if it cannot be read.
    pub fn read(folder: &Path) -> SceneList {
        let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
            .map(|entries| {
                entries
                    .filter_map(|entry| entry.ok().map(|e| e.path()))
                    .filter(|path| path.extension().is_some_and(|ext| ext == "ron"))
                    .collect()
            })
            .unwrap_or_default();
        files.sort();
        SceneList(files)
    }
}

/// Everything the panel edits.
#[derive(SystemParam)]
struct Tunables<'w> {
    params: ResMut<'w, SimParams>,
    solver: ResMut<'w, Solver>,
    run: ResMut<'w, RunControl>,
    spawn: ResMut<'w, SpawnSettings>,
    view: ResMut<'w, ViewSettings>,
    fixed: ResMut<'w, Time<Fixed>>,
}

/// Everything the panel only shows.
#[derive(SystemParam)]
struct Shown<'w> {
    readouts: Res<'w, Readouts>,
    diagnostics: Res<'w, DiagnosticsStore>,
    scenes: Res<'w, SceneList>,
    current: Res<'w, CurrentScene>,
    status: Res<'w, SceneStatus>,
    ball_count: Res<'w, BallCountOutcome>,
    resting: Res<'w, RestingState>,
}

fn draw_panel(
    mut contexts: EguiContexts,
    mut visible: ResMut<PanelVisible>,
    mut help: ResMut<HelpVisible>,
    mut play_area: ResMut<PlayArea>,
    mut tunables: Tunables,
    shown: Shown,
    mut requests: MessageWriter<SceneRequest>,
    mut intents: MessageWriter<Intent>,
) -> Result {
    let width = if visible.0 { PANEL_WIDTH } else { 0.0 };
    if play_area.panel_width != width {
        play_area.panel_width = width;
    }
    let ctx = contexts.ctx_mut()?;
    if !visible.0 {
        egui::Area::new("ballpit-reopen".into())
            .fixed_pos([6.0, 6.0])
            .show(ctx, |ui| {
                if ui.button("☰ Panel (H)").clicked() {
                    visible.0 = true;
                }
            });
        help_window(ctx, &mut help.0);
        return Ok(());
    }
    let mut root = egui::Ui::new(
        ctx.clone(),
        "ballpit-root".into(),
        egui::UiBuilder::new()
            .layer_id(egui::LayerId::background())
            .max_rect(ctx.viewport_rect()),
    );
    egui::Panel::left("ballpit-panel")
        .exact_size(PANEL_WIDTH)
        .resizable(false)
        .show(&mut root, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.horizontal(|ui| {
                    ui.heading("ballpit");
                    if ui.small_button("Help (?)").clicked() {
                        help.0 = !help.0;
                    }
                    if ui.small_button("Hide (H)").clicked() {
                        visible.0 = false;
                    }
                });
                status(ui, &shown);
                controls(ui, &mut tunables, &shown, &mut requests);
                balls(ui, &mut tunables, &shown, &mut intents);
                physics(ui, &mut tunables);
                view(ui, &mut tunables.view, &mut play_area);
                readouts(
                    ui,
                    &shown.readouts,
                    &shown.diagnostics,
                    shown.resting.asleep,
                );
                gas(ui, &shown.readouts);
            });
        });
    help_window(ctx, &mut help.0);
    Ok(())
}

/// The figures a player glances at, on one line: FPS, simulation time per frame, balls,
/// sleeping balls; and a warning when the game runs slower than real time.
fn status(ui: &mut egui::Ui, shown: &Shown) {
    let (_, fps, simulation_ms) = frame_figures(&shown.diagnostics);
    ui.label(format!(
        "{:.0} FPS · simulation {:.1} ms/frame · {} balls · {} asleep",
        fps.unwrap_or(0.0),
        simulation_ms.unwrap_or(0.0),
        shown.readouts.summary.ball_count,
        shown.resting.asleep
    ));
    if let Some(speed) = game_speed(&shown.diagnostics).filter(|&speed| speed < SLOW_GAME) {
        ui.colored_label(
            WARNING,
            format!("Slower than real time: {speed:.2}× (fewer balls or steps /s catch up)"),
        );
    }
}

fn controls(
    ui: &mut egui::Ui,
    tunables: &mut Tunables,
    shown: &Shown,
    requests: &mut MessageWriter<SceneRequest>,
) {
    ui.horizontal(|ui| {
        let label = if tunables.run.paused {
            "▶ Resume"
        } else {
            "⏸ Pause"
        };
        if ui.button(label).clicked() {
            tunables.run.paused = !tunables.run.paused;
        }
        if ui.button("Step").clicked() {
            tunables.run.step_once();
        }
        if ui.button("Reset").clicked() {
            requests.write(SceneRequest::Reset);
        }
        if ui.button("New seed").clicked() {
            requests.write(SceneRequest::NewSeed);
        }
    });
    let current_name = Path::new(&shown.current.origin)
        .file_name()
        .map_or(shown.current.origin.clone(), |name| {
            name.to_string_lossy().into_owned()
        });
    egui::ComboBox::from_label("Scene")
        .selected_text(current_name)
        .show_ui(ui, |ui| {
            for path in &shown.scenes.0 {
                let name = path.file_name().unwrap_or_default().to_string_lossy();
                if ui.selectable_label(false, name).clicked() {
                    requests.write(SceneRequest::Load(path.clone()));
                }
            }
            if shown.scenes.0.is_empty() {
                ui.label(format!("no scenes in ./{SCENE_FOLDER}"));
            }
        });
    if let Some(error) = &shown.status.0 {
        ui.colored_label(Color32::from_rgb(255, 120, 110), error);
    }
}

/// A slider that clamps what the player drags or types (NaN and infinities included) to its
/// range, but leaves alone a value that came from elsewhere: a scene's gravity beyond the
/// slider's reach stays as the scene set it.
fn slider<Num: Numeric>(value: &mut Num, range: RangeInclusive<Num>) -> Slider<'_> {
    Slider::new(value, range).clamping(SliderClamping::Edits)
}

/// The fixed-step rate to set for a slider value: within the slider's range, the default for
/// anything that is not a number.
fn step_rate(slider_value: f64) -> f64 {
    if slider_value.is_finite() {
        slider_value.clamp(*STEP_RATE_SLIDER.start(), *STEP_RATE_SLIDER.end())
    } else {
        DEFAULT_STEP_RATE
    }
}

fn balls(
    ui: &mut egui::Ui,
    tunables: &mut Tunables,
    shown: &Shown,
    intents: &mut MessageWriter<Intent>,
) {
    egui::CollapsingHeader::new("Balls")
        .default_open(true)
        .show(ui, |ui| {
            let mut count = shown.readouts.summary.ball_count;
            let response = ui.add(
                slider(&mut count, BALL_COUNT_SLIDER)
                    .logarithmic(true)
                    .text("count"),
            );
            if response.changed() {
                intents.write(Intent::SetBallCount(count));
            }
            if let Some(note) = shown.ball_count.note() {
                ui.colored_label(WARNING, note);
                let wanted = shown.ball_count.wanted;
                if shown.ball_count.smaller_radius.is_some()
                    && ui.button("Add smaller balls").clicked()
                {
                    intents.write(Intent::AddSmallerBalls(wanted));
                }
            }
            let spawn = &mut tunables.spawn;
            let mut edited = **spawn;
            ui.add(
                slider(&mut edited.radius.0, RADIUS_SLIDER)
                    .logarithmic(true)
                    .text("radius min px"),
            );
            ui.add(
                slider(&mut edited.radius.1, RADIUS_SLIDER)
                    .logarithmic(true)
                    .text("radius max px"),
            );
            ui.add(slider(&mut edited.speed.0, SPEED_SLIDER).text("speed min px/s"));
            ui.add(slider(&mut edited.speed.1, SPEED_SLIDER).text("speed max px/s"));
            edited.clamp_to_limits();
            if edited != **spawn {
                **spawn = edited;
            }
            let mut arena = tunables.params.arena_size;
            ui.add(
                slider(&mut arena.x, ARENA_SLIDER)
                    .logarithmic(true)
                    .text("arena width px"),
            );
            ui.add(
                slider(&mut arena.y, ARENA_SLIDER)
                    .logarithmic(true)
                    .text("arena height px"),
            );
            if arena != tunables.params.arena_size {
                let mut params = tunables.params.clone();
                params.arena_size = arena;
                params.clamp_to_limits();
                *tunables.params = params;
            }
        });
}

fn physics(ui: &mut egui::Ui, tunables: &mut Tunables) {
    egui::CollapsingHeader::new("Physics")
        .default_open(true)
        .show(ui, |ui| {
            let mut edited = tunables.params.clone();
            let mut solver = *tunables.solver;
            let mut run = *tunables.run;
            ui.horizontal(|ui| {
                ui.label("collisions");
                for (mode, name) in CollisionMode::ALL
                    .into_iter()
                    .zip(["continuous", "discrete"])
                {
                    ui.radio_value(&mut solver.collisions, mode, name);
                }
            })
            .response
            .on_hover_text(
                "continuous: every impact at its exact moment, nothing tunnels\n\
                 discrete: the tutorial's move, find overlaps, respond, separate",
            );
            ui.add(slider(&mut edited.gravity.x, GRAVITY_SLIDER).text("gravity x"));
            ui.add(slider(&mut edited.gravity.y, GRAVITY_SLIDER).text("gravity y"));
            ui.add(slider(&mut edited.restitution, RESTITUTION_RANGE).text("restitution"));
            ui.horizontal(|ui| {
                ui.label("mass");
                for (model, name) in MassModel::ALL.into_iter().zip(["radius", "area", "unit"]) {
                    ui.radio_value(&mut edited.mass_model, model, name);
                }
            });
            ui.add(
                slider(&mut run.time_scale, TIME_SCALE_SLIDER)
                    .logarithmic(true)
                    .smallest_positive(0.01)
                    .text("time scale"),
            );
            ui.add(slider(&mut edited.linear_damping, DAMPING_SLIDER).text("damping /s"));
            edited.clamp_to_limits();
            run.clamp_to_limits();
            if edited != *tunables.params {
                *tunables.params = edited;
            }
            if solver != *tunables.solver {
                *tunables.solver = solver;
            }
            if run != *tunables.run {
                *tunables.run = run;
            }
            let mut rate = 1.0 / tunables.fixed.timestep().as_secs_f64();
            if ui
                .add(slider(&mut rate, STEP_RATE_SLIDER).text("steps /s"))
                .changed()
            {
                tunables.fixed.set_timestep_hz(step_rate(rate));
            }
        });
}

fn view(ui: &mut egui::Ui, view: &mut ViewSettings, play_area: &mut PlayArea) {
    egui::CollapsingHeader::new("View")
        .default_open(true)
        .show(ui, |ui| {
            let mut edited = view.clone();
            ui.horizontal(|ui| {
                ui.label("colour");
                ui.radio_value(&mut edited.colour_mode, ColourMode::ByBall, "ball");
                ui.radio_value(&mut edited.colour_mode, ColourMode::BySize, "size");
                ui.radio_value(&mut edited.colour_mode, ColourMode::BySpeed, "speed");
            });
            colour_legend(ui, edited.colour_mode);
            ui.horizontal_wrapped(|ui| {
                ui.checkbox(&mut edited.show_aabbs, "AABBs");
                ui.checkbox(&mut edited.show_contacts, "contacts");
                ui.checkbox(&mut edited.show_velocities, "velocities");
                ui.checkbox(&mut edited.show_bursts, "bursts");
                ui.checkbox(&mut edited.dim_sleeping, "dim sleeping");
            });
            if edited != *view {
                *view = edited;
            }
            ui.horizontal(|ui| {
                ui.label(format!("zoom {:.0} %", 100.0 / play_area.zoom));
                if ui.button("Fit (F)").clicked() {
                    play_area.request_fit();
                }
            });
        });
}

/// What the colours mean: a scale from cool to hot with its ends, or a word for one colour
/// per ball.
fn colour_legend(ui: &mut egui::Ui, mode: ColourMode) {
    let (low, high) = match mode {
        ColourMode::ByBall => {
            ui.label(RichText::new("each ball its own colour").small());
            return;
        }
        ColourMode::BySize => (
            format!("r ≤ {:.0} px", SIZE_COLOUR_RANGE.0),
            format!("≥ {:.0} px", SIZE_COLOUR_RANGE.1),
        ),
        ColourMode::BySpeed => ("still".to_string(), format!("≥ {HOT_SPEED:.0} px/s")),
    };
    ui.horizontal(|ui| {
        ui.label(RichText::new(low).small());
        let (rect, _) = ui.allocate_exact_size(egui::vec2(120.0, 12.0), egui::Sense::hover());
        const STEPS: usize = 24;
        for step in 0..STEPS {
            let [r, g, b, _] = heat_colour(step as f64 / (STEPS - 1) as f64)
                .to_srgba()
                .to_u8_array();
            let width = rect.width() / STEPS as f32;
            let left = rect.left() + width * step as f32;
            let cell = egui::Rect::from_min_size(
                egui::pos2(left, rect.top()),
                egui::vec2(width + 0.5, rect.height()),
            );
            ui.painter()
                .rect_filled(cell, 0.0, Color32::from_rgb(r, g, b));
        }
        ui.label(RichText::new(high).small());
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_typed_step_rate_is_bounded_and_not_a_number_gives_the_default() {
        assert_eq!(step_rate(120.0), 120.0);
        assert_eq!(step_rate(1e9), *STEP_RATE_SLIDER.end());
        assert_eq!(step_rate(0.0), *STEP_RATE_SLIDER.start());
        assert_eq!(step_rate(-5.0), *STEP_RATE_SLIDER.start());
        assert_eq!(step_rate(f64::NAN), DEFAULT_STEP_RATE);
        assert_eq!(step_rate(f64::INFINITY), DEFAULT_STEP_RATE);
    }
}
