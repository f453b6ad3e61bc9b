//! Frame diagnostics of the windowed toy: how long the simulation's fixed steps take per
//! frame (from `FixedFirst` to `FixedLast`), beside Bevy's frame time and FPS, and the game's
//! speed against real time. The panel shows them and a screenshot run prints them. Wall-clock
//! reads live here, never in the simulation.
//!
//! **Catch-up is bounded**: a frame advances game time by at most [`MAX_CATCH_UP`], so a slow
//! frame runs at most that many fixed steps after it and never makes the next frame slower;
//! the game then runs slower than real time, and [`GAME_SPEED`] says by how much.

use std::time::{Duration, Instant};

use bevy::diagnostic::{
    Diagnostic, DiagnosticPath, Diagnostics, DiagnosticsStore, FrameTimeDiagnosticsPlugin,
    RegisterDiagnostic,
};
use bevy::prelude::*;

/// Milliseconds of fixed steps (the simulation) per frame.
pub const SIMULATION_TIME: DiagnosticPath = DiagnosticPath::const_new("ballpit/simulation_ms");
/// Game seconds per real second, over a frame: 1 when the simulation keeps up.
pub const GAME_SPEED: DiagnosticPath = DiagnosticPath::const_new("ballpit/game_speed");
/// The most game time one frame advances: four steps at the default 60 a second.
pub const MAX_CATCH_UP: Duration = Duration::from_micros(66_667);

pub fn plugin(app: &mut App) {
    if !app.is_plugin_added::<FrameTimeDiagnosticsPlugin>() {
        app.add_plugins(FrameTimeDiagnosticsPlugin::default());
    }
    if let Some(mut time) = app.world_mut().get_resource_mut::<Time<Virtual>>() {
        time.set_max_delta(MAX_CATCH_UP);
    }
    app.register_diagnostic(Diagnostic::new(SIMULATION_TIME).with_suffix(" ms"))
        .register_diagnostic(Diagnostic::new(GAME_SPEED))
        .init_resource::<SimulationClock>()
        .add_systems(FixedFirst, start_clock)
        .add_systems(FixedLast, stop_clock)
        .add_systems(Last, (record_simulation_time, record_game_speed));
}

#[derive(Resource, Default)]
struct SimulationClock {
    started: Option<Instant>,
    this_frame: Duration,
}

fn start_clock(mut clock: ResMut<SimulationClock>) {
    clock.started = Some(Instant::now());
}

fn stop_clock(mut clock: ResMut<SimulationClock>) {
    if let Some(started) = clock.started.take() {
        clock.this_frame += started.elapsed();
    }
}

fn record_simulation_time(mut diagnostics: Diagnostics, mut clock: ResMut<SimulationClock>) {
    let milliseconds = clock.this_frame.as_secs_f64() * 1e3;
    diagnostics.add_measurement(&SIMULATION_TIME, || milliseconds);
    clock.this_frame = Duration::ZERO;
}

fn record_game_speed(
    mut diagnostics: Diagnostics,
    real: Res<Time<Real>>,
    game: Res<Time<Virtual>>,
) {
    let real = real.delta_secs_f64();
    if real > 0.0 && !game.is_paused() {
        let speed = game.delta_secs_f64() / real;
        diagnostics.add_measurement(&GAME_SPEED, || speed);
    }
}

/// The smoothed game speed against real time (see [`GAME_SPEED`]), once measured.
pub fn game_speed(store: &DiagnosticsStore) -> Option<f64> {
    store.get(&GAME_SPEED).and_then(Diagnostic::smoothed)
}

/// Smoothed (frame time ms, FPS, simulation ms per frame), where measured yet.
pub fn frame_figures(store: &DiagnosticsStore) -> (Option<f64>, Option<f64>, Option<f64>) {
    let smoothed = |path: &DiagnosticPath| store.get(path).and_then(Diagnostic::smoothed);
    (
        smoothed(&FrameTimeDiagnosticsPlugin::FRAME_TIME),
        smoothed(&FrameTimeDiagnosticsPlugin::FPS),
        smoothed(&SIMULATION_TIME),
    )
}
