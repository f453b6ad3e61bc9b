//! `ballpit run`: a scene stepped a fixed number of times in a [`headless_app`](crate::headless::headless_app), measured
//! into a [`RunReport`], with [`Observers`] recording along the way (the series and the
//! trajectory). Used by the command line and the tests.

use bevy::prelude::*;
use serde::Serialize;

use super::observe::Observers;
use super::progress::Progress;
use crate::headless::{counters_only, headless_app_with_threads, mean, median, time_steps};
use crate::sim::measure::gas::SpeedHistogram;
use crate::sim::{SceneSetup, SimClock, SimParams, SimStats, StateSummary};

/// What `ballpit run` prints. Units: pixels, seconds, mass from the mass model.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    pub balls: usize,
    /// Arena width and height, pixels.
    pub arena: [f64; 2],
    pub steps: u64,
    pub dt_s: f64,
    pub sim_time_s: f64,
    pub ms_per_step_median: f64,
    pub ms_per_step_mean: f64,
    pub ball_collisions: u64,
    pub wall_collisions: u64,
    pub kinetic_energy_start: f64,
    pub kinetic_energy_end: f64,
    /// (end - start) / start; zero when the start energy is zero.
    pub kinetic_energy_change_rel: f64,
    pub mechanical_energy_start: f64,
    pub mechanical_energy_end: f64,
    /// (end - start) / |start| of kinetic plus potential energy: the drift with gravity.
    pub mechanical_energy_change_rel: f64,
    pub momentum_start: [f64; 2],
    pub momentum_end: [f64; 2],
    /// Largest remaining overlap at the end, divided by the smaller radius of the pair.
    pub max_overlap_rel: f64,
    /// Mean of the same over the overlapping pairs.
    pub mean_overlap_rel: f64,
    /// Balls faster than 1 px/s at the end.
    pub moving: usize,
    /// Root mean square speed at the end, pixels per second.
    pub rms_speed: f64,
    /// Balls asleep at the end.
    pub sleeping: usize,
    /// Balls whose centre is outside the arena at the end.
    pub escaped: usize,
    /// Total normal impulse on the walls / (perimeter x simulated time).
    pub pressure: f64,
    /// Mean kinetic energy per ball at the end.
    pub temperature: f64,
    /// Ball speeds at the end, binned, against the 2-D Maxwell–Boltzmann expectation.
    pub speed_histogram: SpeedHistogram,
    /// Continuous steps that hit the per-ball hit limit (see `SimStats::cut_short_steps`).
    pub cut_short_steps: u64,
}

impl RunReport {
    /// The report as aligned `name  value` lines, pairs as `x, y`, and the speed histogram
    /// as a table with a bar per bin: nothing a person has to read as JSON (`--json` has it
    /// all as JSON).
    pub fn to_text(&self) -> String {
        let value = serde_json::to_value(self).expect("a report is plain numbers");
        let fields = value.as_object().expect("a report serialises to an object");
        let width = fields.keys().map(String::len).max().unwrap_or(0);
        let mut text = String::new();
        for (name, value) in fields {
            let shown = match value {
                serde_json::Value::Array(items) => items
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join(", "),
                serde_json::Value::Object(_) => histogram_heading(&self.speed_histogram),
                other => other.to_string(),
            };
            text.push_str(&format!("{name:<width$}  {shown}\n"));
            if name == "speed_histogram" {
                text.push_str(&histogram_rows(&self.speed_histogram));
            }
        }
        text
    }
}

/// Widest bar of the text histogram, characters.
const HISTOGRAM_BAR: usize = 40;

fn histogram_heading(histogram: &SpeedHistogram) -> String {
    format!(
        "{} bins of {:.1} px/s; balls per bin, and as many as the 2-D Maxwell–Boltzmann \
         distribution at this temperature expects:",
        histogram.counts.len(),
        histogram.bin_width
    )
}

/// One line per bin up to the last that holds a ball or expects half of one: the speeds,
/// the count, the expected count and a bar of the count.
fn histogram_rows(histogram: &SpeedHistogram) -> String {
    let shown = (0..histogram.counts.len())
        .rev()
        .find(|&bin| histogram.counts[bin] > 0 || histogram.expected[bin] >= 0.5)
        .map_or(0, |last| last + 1);
    let largest = histogram.counts.iter().copied().max().unwrap_or(0).max(1);
    (0..shown)
        .map(|bin| {
            let (low, high) = (
                bin as f64 * histogram.bin_width,
                (bin + 1) as f64 * histogram.bin_width,
            );
            let count = histogram.counts[bin];
            let bar = "#".repeat((count as usize * HISTOGRAM_BAR).div_ceil(largest as usize));
            format!(
                "    {low:>8.1} – {high:<8.1} {count:>7} {:>9.1}  {bar}\n",
                histogram.expected[bin]
            )
        })
        .collect()
}

/// Loads `setup` into a fresh headless app and runs `steps` fixed steps of `dt` seconds,
/// timing each. Returns the app (for dumps and further checks) and the report. The app keeps
/// the counters only: no collision messages or contact points ([`counters_only`]).
pub fn run_scene(setup: &SceneSetup, steps: u64, dt: f64) -> (App, RunReport) {
    run_scene_with_threads(setup, steps, dt, None)
}

/// [`run_scene`] with `threads` threads at work on each step (see
/// [`headless_app_with_threads`]).
pub fn run_scene_with_threads(
    setup: &SceneSetup,
    steps: u64,
    dt: f64,
    threads: Option<usize>,
) -> (App, RunReport) {
    run_scene_showing(
        setup,
        steps,
        dt,
        threads,
        &Progress::hidden(),
        &mut Observers::none(),
    )
}

/// [`run_scene_with_threads`], advancing `progress` a step at a time and letting
/// `observers` record at step 0, every `observers.every` steps and at the last.
pub fn run_scene_showing(
    setup: &SceneSetup,
    steps: u64,
    dt: f64,
    threads: Option<usize>,
    progress: &Progress,
    observers: &mut Observers,
) -> (App, RunReport) {
    let mut app = headless_app_with_threads(dt, threads);
    counters_only(&mut app);
    setup.apply(app.world_mut());
    let start = StateSummary::measure(app.world_mut());
    let chunk = if observers.is_empty() {
        steps.max(1)
    } else {
        observers.every
    };
    let mut step_times = Vec::with_capacity(steps as usize);
    loop {
        if !observers.is_empty() {
            observers.record(app.world_mut());
        }
        let left = steps - step_times.len() as u64;
        if left == 0 {
            break;
        }
        step_times.extend(time_steps(&mut app, chunk.min(left), |_| {
            progress.advance(1)
        }));
    }
    let end = StateSummary::measure(app.world_mut());
    let stats = app.world().resource::<SimStats>().clone();
    let clock = *app.world().resource::<SimClock>();
    let arena_size = app.world().resource::<SimParams>().arena_size;
    let report = RunReport {
        balls: end.ball_count,
        arena: arena_size.to_array(),
        steps: clock.steps,
        dt_s: dt,
        sim_time_s: clock.elapsed,
        ms_per_step_median: median(&mut step_times),
        ms_per_step_mean: mean(&step_times),
        ball_collisions: stats.ball_collisions,
        wall_collisions: stats.wall_collisions,
        kinetic_energy_start: start.kinetic_energy,
        kinetic_energy_end: end.kinetic_energy,
        kinetic_energy_change_rel: relative_change(start.kinetic_energy, end.kinetic_energy),
        mechanical_energy_start: start.mechanical_energy,
        mechanical_energy_end: end.mechanical_energy,
        mechanical_energy_change_rel: relative_change(
            start.mechanical_energy,
            end.mechanical_energy,
        ),
        momentum_start: start.momentum.to_array(),
        momentum_end: end.momentum.to_array(),
        max_overlap_rel: end.max_overlap_rel,
        mean_overlap_rel: end.mean_overlap_rel,
        moving: end.moving,
        rms_speed: end.rms_speed,
        sleeping: end.sleeping,
        escaped: end.escaped,
        pressure: stats.pressure(arena_size, clock.elapsed),
        temperature: end.temperature(),
        speed_histogram: end.speed_histogram,
        cut_short_steps: stats.cut_short_steps,
    };
    (app, report)
}

/// `(end - start) / |start|`, so a drop reads negative whatever the sign of `start`.
fn relative_change(start: f64, end: f64) -> f64 {
    if start == 0.0 {
        0.0
    } else {
        (end - start) / start.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_change_reads_a_drop_as_negative() {
        assert_eq!(relative_change(0.0, 5.0), 0.0);
        assert_eq!(relative_change(-2.0, -3.0), -0.5);
        assert_eq!(relative_change(2.0, 3.0), 0.5);
    }
}
