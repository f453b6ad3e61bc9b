//! Headless runs: a scene stepped a fixed number of times under `MinimalPlugins`, with no
//! window or GPU, measured into a [`RunReport`]. Used by `ballpit run`, the tests and the
//! benchmarks.

use std::time::{Duration, Instant};

use bevy::app::{TaskPoolOptions, TaskPoolPlugin};
use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use serde::Serialize;

use crate::sim::gas::SpeedHistogram;
use crate::sim::{
    Ball, BallId, Position, Radius, SceneSetup, SimParams, SimPlugin, SimStats, StateSummary,
    Velocity,
};

/// Default fixed step, seconds.
pub const DEFAULT_DT: f64 = 1.0 / 60.0;

/// An app with only the simulation, in which every `update()` runs exactly one fixed step of
/// `dt` seconds. The first update (which runs `Startup` and no step) has already happened.
pub fn headless_app(dt: f64) -> App {
    headless_app_with_threads(dt, None)
}

/// [`headless_app`] with the compute pool (which runs the parallel parts of the stages) set to
/// `compute_threads` threads. Bevy's task pools belong to the process: only the first app in
/// a process sets them.
pub fn headless_app_with_threads(dt: f64, compute_threads: Option<usize>) -> App {
    let mut task_pool_options = TaskPoolOptions::default();
    if let Some(threads) = compute_threads {
        task_pool_options.compute.min_threads = threads;
        task_pool_options.compute.max_threads = threads;
    }
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins.set(TaskPoolPlugin { task_pool_options }),
        SimPlugin,
    ))
    .insert_resource(Time::<Fixed>::from_seconds(dt))
    .insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    // Virtual time clamps each frame to `max_delta`; one frame must be able to hold a step.
    app.world_mut()
        .resource_mut::<Time<Virtual>>()
        .set_max_delta(Duration::from_secs_f64(dt.max(0.25) * 2.0));
    app.update();
    // The stages are chained and each uses the compute pool inside itself where that pays, so
    // handing systems to other threads only adds wake-ups: run every schedule on this thread.
    for (_, schedule) in app.world_mut().resource_mut::<Schedules>().iter_mut() {
        schedule.set_executor(SingleThreadedExecutor::default());
    }
    app
}

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
    /// The report as aligned `name  value` lines.
    pub fn to_text(&self) -> String {
        let value = serde_json::to_value(self).expect("a report is plain numbers");
        let fields = value.as_object().expect("a report serialises to an object");
        let width = fields.keys().map(String::len).max().unwrap_or(0);
        fields
            .iter()
            .map(|(name, value)| format!("{name:<width$}  {value}\n"))
            .collect()
    }
}

/// Loads `setup` into a fresh headless app and runs `steps` fixed steps of `dt` seconds,
/// timing each. Returns the app (for dumps and further checks) and the report.
pub fn run_scene(setup: &SceneSetup, steps: u64, dt: f64) -> (App, RunReport) {
    run_scene_with_threads(setup, steps, dt, None)
}

/// [`run_scene`] with the compute pool set to `compute_threads` threads (see
/// [`headless_app_with_threads`]).
pub fn run_scene_with_threads(
    setup: &SceneSetup,
    steps: u64,
    dt: f64,
    compute_threads: Option<usize>,
) -> (App, RunReport) {
    let mut app = headless_app_with_threads(dt, compute_threads);
    setup.apply(app.world_mut());
    let start = StateSummary::measure(app.world_mut());
    let mut step_times = Vec::with_capacity(steps as usize);
    for _ in 0..steps {
        let started = Instant::now();
        app.update();
        step_times.push(started.elapsed().as_secs_f64() * 1e3);
    }
    let end = StateSummary::measure(app.world_mut());
    let stats = app.world().resource::<SimStats>().clone();
    let arena_size = app.world().resource::<SimParams>().arena_size;
    let report = RunReport {
        balls: end.ball_count,
        arena: arena_size.to_array(),
        steps: stats.steps,
        dt_s: dt,
        sim_time_s: stats.sim_time,
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
        escaped: end.escaped,
        pressure: stats.pressure(arena_size),
        temperature: end.temperature(),
        speed_histogram: end.speed_histogram,
        cut_short_steps: stats.cut_short_steps,
    };
    (app, report)
}

/// The middle value (the mean of the two middle ones for an even count); zero for none.
pub(crate) fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let middle = values.len() / 2;
    if values.len() % 2 == 1 {
        values[middle]
    } else {
        0.5 * (values[middle - 1] + values[middle])
    }
}

fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}

/// `(end - start) / |start|`, so a drop reads negative whatever the sign of `start`.
fn relative_change(start: f64, end: f64) -> f64 {
    if start == 0.0 {
        0.0
    } else {
        (end - start) / start.abs()
    }
}

/// One ball in a `--dump` file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DumpedBall {
    pub id: u32,
    pub x: f64,
    pub y: f64,
    pub vx: f64,
    pub vy: f64,
    pub r: f64,
    pub m: f64,
}

/// The `--dump` file: every ball's final state, in id order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StateDump {
    pub balls: Vec<DumpedBall>,
}

impl StateDump {
    pub fn capture(world: &mut World) -> StateDump {
        let mass_model = world.resource::<SimParams>().mass_model;
        let mut balls: Vec<DumpedBall> = world
            .query_filtered::<(&BallId, &Position, &Velocity, &Radius), With<Ball>>()
            .iter(world)
            .map(|(id, position, velocity, radius)| DumpedBall {
                id: id.0,
                x: position.x,
                y: position.y,
                vx: velocity.x,
                vy: velocity.y,
                r: radius.0,
                m: mass_model.mass(radius.0),
            })
            .collect();
        balls.sort_by_key(|ball| ball.id);
        StateDump { balls }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_mean() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median(&mut []), 0.0);
        assert_eq!(mean(&[1.0, 2.0, 6.0]), 3.0);
        assert_eq!(relative_change(0.0, 5.0), 0.0);
        assert_eq!(relative_change(2.0, 3.0), 0.5);
    }
}
