//! The panel's figures, folded by default so the controls fit: the readouts (with units and
//! the energy plot) and the gas (temperature, pressure and the speed histogram against the
//! Maxwell–Boltzmann curve). Drawn in `EguiPrimaryContextPass` by the panel's system.

use bevy::diagnostic::DiagnosticsStore;
use bevy_egui::egui::{self, Color32};
use egui_plot::{Bar, BarChart, Line, Plot, PlotPoints};

use super::readouts::Readouts;
use crate::diagnostics::frame_figures;

/// FPS, frame and simulation times, balls, sleeping balls, collisions, energy and momentum,
/// with units; and the energy plot.
pub fn readouts(
    ui: &mut egui::Ui,
    readouts: &Readouts,
    diagnostics: &DiagnosticsStore,
    asleep: usize,
) {
    egui::CollapsingHeader::new("Readouts")
        .default_open(false)
        .show(ui, |ui| {
            let (frame_ms, fps, simulation_ms) = frame_figures(diagnostics);
            let r = readouts;
            egui::Grid::new("readouts").num_columns(2).show(ui, |ui| {
                for (name, value) in [
                    ("FPS", format!("{:.0} /s", fps.unwrap_or(0.0))),
                    ("frame", format!("{:.1} ms", frame_ms.unwrap_or(0.0))),
                    (
                        "simulation",
                        format!("{:.1} ms/frame", simulation_ms.unwrap_or(0.0)),
                    ),
                    ("balls", format!("{}", r.summary.ball_count)),
                    ("sleeping", format!("{asleep}")),
                    ("collisions", format!("{:.0} /s", r.collisions_per_second)),
                    (
                        "kinetic energy",
                        format!("{:.4e} m·px²/s²", r.summary.kinetic_energy),
                    ),
                    (
                        "momentum",
                        format!(
                            "({:.3e}, {:.3e}) m·px/s",
                            r.summary.momentum.x, r.summary.momentum.y
                        ),
                    ),
                ] {
                    ui.label(name);
                    ui.monospace(value);
                    ui.end_row();
                }
            });
            // A fresh scene has one point or none: at least a second of axis, from its start.
            let start = r.energy_history.front().map_or(0.0, |point| point[0]);
            let points: PlotPoints = r.energy_history.iter().copied().collect();
            Plot::new("energy-plot")
                .height(90.0)
                .include_x(start)
                .include_x(start + 1.0)
                .include_y(0.0)
                .allow_drag(false)
                .allow_zoom(false)
                .allow_scroll(false)
                .allow_boxed_zoom(false)
                .x_axis_label("simulated s")
                .y_axis_label("m·px²/s²")
                .show(ui, |plot| plot.line(Line::new("kinetic energy", points)));
        });
}

/// Temperature, pressure and the speed histogram against the Maxwell–Boltzmann curve.
pub fn gas(ui: &mut egui::Ui, readouts: &Readouts) {
    egui::CollapsingHeader::new("Gas")
        .default_open(false)
        .show(ui, |ui| {
            egui::Grid::new("gas").num_columns(2).show(ui, |ui| {
                for (name, value) in [
                    (
                        "temperature",
                        format!("{:.4e} m·px²/s²", readouts.summary.temperature()),
                    ),
                    ("pressure", format!("{:.4e} m/s²", readouts.pressure)),
                ] {
                    ui.label(name);
                    ui.monospace(value);
                    ui.end_row();
                }
            });
            let histogram = &readouts.summary.speed_histogram;
            let width = histogram.bin_width;
            let bars = histogram
                .counts
                .iter()
                .enumerate()
                .map(|(bin, &count)| {
                    Bar::new((bin as f64 + 0.5) * width, count as f64).width(width)
                })
                .collect();
            let curve: PlotPoints = histogram
                .expected
                .iter()
                .enumerate()
                .map(|(bin, &expected)| [(bin as f64 + 0.5) * width, expected])
                .collect();
            Plot::new("speed-histogram")
                .height(120.0)
                .include_y(0.0)
                .allow_drag(false)
                .allow_zoom(false)
                .allow_scroll(false)
                .allow_boxed_zoom(false)
                .x_axis_label("speed px/s")
                .show(ui, |plot| {
                    plot.bar_chart(
                        BarChart::new("balls", bars).color(Color32::from_rgb(90, 140, 220)),
                    );
                    plot.line(
                        Line::new("Maxwell–Boltzmann", curve)
                            .color(Color32::from_rgb(240, 170, 60))
                            .width(2.0),
                    );
                });
        });
}
