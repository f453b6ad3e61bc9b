//! Frame diagnostics of the windowed toy: how long the simulation's fixed steps take per
//! frame (from `FixedFirst` to `FixedLast`), beside Bevy's frame time and FPS. The panel shows
//! them and a screenshot run prints them. Wall-clock reads live here, never in the simulation.

use std::time::{Duration, Instant};

use bevy::diagnostic::{
    Diagnostic, DiagnosticPath, Diagnostics, DiagnosticsStore, FrameTimeDiagnosticsPlugin,
    RegisterDiagnostic,
};
use bevy::prelude::*;

/// Milliseconds of fixed steps (the simulation) per frame.
pub const SIMULATION_TIME: DiagnosticPath = DiagnosticPath::const_new("ballpit/simulation_ms");

pub fn plugin(app: &mut App) {
    if !app.is_plugin_added::<FrameTimeDiagnosticsPlugin>() {
        app.add_plugins(FrameTimeDiagnosticsPlugin::default());
    }
    app.register_diagnostic(Diagnostic::new(SIMULATION_TIME).with_suffix(" ms"))
        .init_resource::<SimulationClock>()
        .add_systems(FixedFirst, start_clock)
        .add_systems(FixedLast, stop_clock)
        .add_systems(Last, record_simulation_time);
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

/// Smoothed (frame time ms, FPS, simulation ms per frame), where measured yet.
pub fn frame_figures(store: &DiagnosticsStore) -> (Option<f64>, Option<f64>, Option<f64>) {
    let smoothed = |path: &DiagnosticPath| store.get(path).and_then(Diagnostic::smoothed);
    (
        smoothed(&FrameTimeDiagnosticsPlugin::FRAME_TIME),
        smoothed(&FrameTimeDiagnosticsPlugin::FPS),
        smoothed(&SIMULATION_TIME),
    )
}
