//! Headless apps: the simulation under `MinimalPlugins`, with no window or GPU, in which every
//! `update()` runs exactly one fixed step; and the timing loop every headless command uses.
//! What `ballpit run`, `bench` and `soak` and the tests build on.

use std::time::{Duration, Instant};

use bevy::app::{TaskPoolOptions, TaskPoolPlugin};
use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;

use crate::sim::{HitReports, SimPlugin};

/// Default fixed step, seconds.
pub const DEFAULT_DT: f64 = 1.0 / 60.0;

/// An app with only the simulation, in which every `update()` runs exactly one fixed step of
/// `dt` seconds. The first update (which runs `Startup` and no step) has already happened.
pub fn headless_app(dt: f64) -> App {
    headless_app_with_threads(dt, None)
}

/// [`headless_app`] with `threads` threads at work on each step: the calling thread, which
/// runs the schedule and takes its share of the stages' parallel parts, and `threads - 1`
/// workers in the compute pool. Bevy's task pools belong to the process: only the first app
/// in a process sets them.
pub fn headless_app_with_threads(dt: f64, threads: Option<usize>) -> App {
    let mut task_pool_options = TaskPoolOptions::default();
    if let Some(threads) = threads {
        let workers = threads.saturating_sub(1);
        task_pool_options.compute.min_threads = workers;
        task_pool_options.compute.max_threads = workers;
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
    run_on_this_thread(&mut app);
    app
}

/// For a headless command that reads only the counters: no message or contact point per
/// hit ([`HitReports`] off).
pub fn counters_only(app: &mut App) {
    app.insert_resource(HitReports { enabled: false });
}

/// This host's choice, not the simulation's: every schedule of the headless app runs its
/// systems on the calling thread. A headless frame has a handful of systems, and waking
/// worker threads for them costs more than they take: 0.26 against 0.14 ms a step for the
/// 1,000-ball discrete gas (measured in one run). The stages' own parallel parts (every pass
/// over the balls, from 20,000 balls up) still use the compute pool.
fn run_on_this_thread(app: &mut App) {
    for (_, schedule) in app.world_mut().resource_mut::<Schedules>().iter_mut() {
        schedule.set_executor(SingleThreadedExecutor::default());
    }
}

/// Runs `steps` fixed steps of `app`, calling `after_each(app)` after each, and returns each
/// step's wall-clock time, milliseconds (`after_each` untimed).
pub fn time_steps(app: &mut App, steps: u64, mut after_each: impl FnMut(&App)) -> Vec<f64> {
    let mut step_ms = Vec::with_capacity(steps as usize);
    for _ in 0..steps {
        let started = Instant::now();
        app.update();
        step_ms.push(started.elapsed().as_secs_f64() * 1e3);
        after_each(app);
    }
    step_ms
}

/// The middle value (the mean of the two middle ones for an even count); zero for none.
pub fn median(values: &mut [f64]) -> f64 {
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

/// The value a tenth of the way up `values` sorted (the lower of the nearest ranks): a run's
/// quickest tenth of steps took at most this. On a host that slows for spells, it tells the
/// speed between them. Zero for none.
pub fn quickest_tenth(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    values[(values.len() - 1) / 10]
}

pub fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        0.0
    } else {
        values.iter().sum::<f64>() / values.len() as f64
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
        let mut steps: Vec<f64> = (1..=200).rev().map(f64::from).collect();
        assert_eq!(quickest_tenth(&mut steps), 20.0);
        assert_eq!(quickest_tenth(&mut [7.0, 3.0]), 3.0);
        assert_eq!(quickest_tenth(&mut []), 0.0);
        assert_eq!(mean(&[1.0, 2.0, 6.0]), 3.0);
    }

    #[test]
    fn each_update_of_a_headless_app_is_one_step() {
        let mut app = headless_app(0.5);
        let times = time_steps(&mut app, 3, |_| {});
        assert_eq!(times.len(), 3);
        assert_eq!(app.world().resource::<crate::sim::SimClock>().steps, 3);
    }
}
