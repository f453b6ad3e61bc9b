//! One bench case: what it runs ([`BenchCase`]), what it measured ([`CaseResult`], and the
//! median of several rounds of it), and running it, in this process, in a child, or in one
//! child on each core started together.

use std::error::Error;
use std::process::{Child, Command, Output, Stdio};

use serde::{Deserialize, Serialize};

use crate::headless::{
    DEFAULT_DT, counters_only, headless_app_with_threads, median, quickest_tenth, time_steps,
};
use crate::sim::{BroadPhase, CollisionMode, SceneFile, SimStats, Solver};

/// The standard gas, built in so the bench runs from any directory.
pub const STANDARD_GAS: &str = include_str!("../../../assets/scenes/gas.ron");
/// Steps run before timing starts (first-touch allocations, caches).
const WARM_UP_STEPS: u64 = 5;

/// The text that the command line parses back to `value` (for the bench's children).
pub fn flag_value(value: impl clap::ValueEnum) -> String {
    value
        .to_possible_value()
        .expect("no flag value is hidden")
        .get_name()
        .to_string()
}

/// One case: how many balls, how many timed steps, which broad phase and collision mode.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BenchCase {
    pub balls: usize,
    pub steps: u64,
    /// Used by the discrete mode; the continuous mode always uses the grid.
    pub broad_phase: BroadPhase,
    pub collisions: CollisionMode,
}

/// What one case measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseResult {
    pub case: BenchCase,
    /// Cores the process could use.
    pub cores: usize,
    /// Threads at work on each step (the main thread and the compute pool's workers).
    pub threads: usize,
    pub ms_per_step_median: f64,
    /// The quickest tenth of the steps took at most this ([`quickest_tenth`]).
    #[serde(default)]
    pub ms_per_step_p10: f64,
    pub ns_per_ball_step: f64,
    pub contacts_per_step: f64,
    /// Ball–ball collisions (momentum exchanges) per step.
    pub collisions_per_step: f64,
    /// Ball–ball collisions per simulated second.
    pub collisions_per_sim_second: f64,
    /// Ball–ball collisions handled per second of computing.
    pub collisions_per_cpu_second: f64,
    /// Peak resident memory of the process, MiB (Linux only).
    pub peak_rss_mib: Option<f64>,
    /// In `bench`, each round's `ms_per_step_median`, in the order run.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rounds_ms_per_step: Vec<f64>,
}

impl CaseResult {
    /// The round whose step's median is the median of `rounds`' (the faster of the middle two
    /// for an even count), with every round's ms a step (in the order run) and the highest
    /// peak RSS of them all. `None` without rounds.
    pub fn median_round(rounds: Vec<CaseResult>) -> Option<CaseResult> {
        let in_order: Vec<f64> = rounds.iter().map(|r| r.ms_per_step_median).collect();
        let peak_rss_mib = rounds
            .iter()
            .filter_map(|r| r.peak_rss_mib)
            .reduce(f64::max);
        let mut sorted = rounds;
        sorted.sort_by(|a, b| a.ms_per_step_median.total_cmp(&b.ms_per_step_median));
        let middle = sorted.len().checked_sub(1)? / 2;
        let median = sorted.swap_remove(middle);
        Some(CaseResult {
            peak_rss_mib,
            rounds_ms_per_step: in_order,
            ..median
        })
    }
}

/// Runs `case` in this process with `threads` threads at work on each step.
pub fn run_case(case: BenchCase, threads: usize) -> Result<CaseResult, Box<dyn Error>> {
    let mut scene = SceneFile::parse(STANDARD_GAS, "gas.ron")?;
    if let Some(generate) = scene.generate.as_mut() {
        generate.count = case.balls;
    }
    let mut app = headless_app_with_threads(DEFAULT_DT, Some(threads));
    // The scene's own copy of the balls is dropped once they are spawned: at a million balls
    // it is 40 MB of the peak.
    scene.build("gas.ron")?.apply(app.world_mut());
    counters_only(&mut app);
    app.insert_resource(Solver {
        collisions: case.collisions,
        broad_phase: case.broad_phase,
    });
    time_steps(&mut app, WARM_UP_STEPS, |_| {});
    let before = app.world().resource::<SimStats>().clone();
    let mut step_ms = time_steps(&mut app, case.steps, |_| {});
    let total_ms: f64 = step_ms.iter().sum();
    let after = app.world().resource::<SimStats>();
    let collisions = (after.ball_collisions - before.ball_collisions) as f64;
    let contacts = (after.contact_points - before.contact_points) as f64;
    let steps = case.steps.max(1) as f64;
    let median = median(&mut step_ms);
    Ok(CaseResult {
        case,
        cores: available_cores(),
        threads,
        ms_per_step_median: median,
        ms_per_step_p10: quickest_tenth(&mut step_ms),
        ns_per_ball_step: median * 1e6 / case.balls.max(1) as f64,
        contacts_per_step: contacts / steps,
        collisions_per_step: collisions / steps,
        collisions_per_sim_second: collisions / (steps * DEFAULT_DT),
        collisions_per_cpu_second: collisions / (total_ms.max(f64::MIN_POSITIVE) * 1e-3),
        peak_rss_mib: peak_rss_mib(),
        rounds_ms_per_step: Vec::new(),
    })
}

/// Cores this process may run on (fewer under `taskset`).
pub fn available_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The process's peak resident set size, MiB, from `/proc/self/status` (Linux).
pub fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Runs `case` in a child process: on one core with one thread if `one_core` (via
/// `taskset`), else with a thread per core (the main thread and a worker for each other core).
pub fn run_case_in_child(case: BenchCase, one_core: bool) -> Result<CaseResult, Box<dyn Error>> {
    let threads = if one_core { 1 } else { available_cores() };
    let core = one_core.then_some(0);
    let output = bench_one_command(case, core, threads)?
        .output()
        .map_err(|e| cannot_start(&e, core))?;
    result_of_child(output, core)
}

/// Runs `case` in one child per core, started together, each pinned to its core with one
/// thread (cores `0..available_cores()`, so the process should not be held to other cores):
/// what a step whose work split perfectly could gain on this machine, the cores slowing each
/// other only through what they share. The results in the cores' order. Every child started is
/// waited for, or stopped if another cannot start, before an error is returned.
pub fn run_case_on_each_core(case: BenchCase) -> Result<Vec<CaseResult>, Box<dyn Error>> {
    let mut children: Vec<Child> = Vec::new();
    for core in 0..available_cores() {
        let started = bench_one_command(case, Some(core), 1).and_then(|mut command| {
            command
                .spawn()
                .map_err(|e| cannot_start(&e, Some(core)).into())
        });
        match started {
            Ok(child) => children.push(child),
            Err(error) => {
                for mut child in children {
                    // Stopping a child that has already ended is no error worth reporting.
                    let _ = child.kill();
                    let _ = child.wait();
                }
                return Err(error);
            }
        }
    }
    let outputs: Vec<_> = children.into_iter().map(Child::wait_with_output).collect();
    (0..)
        .zip(outputs)
        .map(|(core, output)| result_of_child(output?, Some(core)))
        .collect()
}

/// The `bench-one` child process for `case` with `threads` threads, pinned to `core` if given
/// (via `taskset`), its output captured.
fn bench_one_command(
    case: BenchCase,
    core: Option<usize>,
    threads: usize,
) -> Result<Command, Box<dyn Error>> {
    let exe = std::env::current_exe()?;
    let mut command = match core {
        Some(core) => {
            let mut taskset = Command::new("taskset");
            taskset.args(["-c", &core.to_string()]).arg(exe);
            taskset
        }
        None => Command::new(exe),
    };
    command
        .args([
            "bench-one",
            "--balls",
            &case.balls.to_string(),
            "--steps",
            &case.steps.to_string(),
        ])
        .args([
            "--broad-phase",
            &flag_value(case.broad_phase),
            "--threads",
            &threads.to_string(),
            "--collisions",
            &flag_value(case.collisions),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    Ok(command)
}

/// Why a child could not start, naming `taskset` when it was to pin one to `core`.
fn cannot_start(error: &std::io::Error, core: Option<usize>) -> String {
    let hint = if core.is_some() {
        " (is taskset installed?)"
    } else {
        ""
    };
    format!("cannot start the bench child{hint}: {error}")
}

/// A finished child's result, or how it ended and its error output (`core`: where it was
/// pinned, if it was).
fn result_of_child(output: Output, core: Option<usize>) -> Result<CaseResult, Box<dyn Error>> {
    if !output.status.success() {
        let place = core.map_or(String::new(), |core| format!(" on core {core}"));
        return Err(format!(
            "bench child{place} failed ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        )
        .into());
    }
    Ok(serde_json::from_slice(&output.stdout)?)
}

#[cfg(test)]
mod tests {
    use clap::ValueEnum;

    use super::*;

    #[test]
    fn flag_values_parse_back_to_the_same_modes() {
        for mode in CollisionMode::ALL {
            let text = flag_value(mode);
            assert_eq!(CollisionMode::from_str(&text, false), Ok(mode), "{text}");
        }
        for broad_phase in [BroadPhase::Grid, BroadPhase::AllPairs] {
            let text = flag_value(broad_phase);
            assert_eq!(
                BroadPhase::from_str(&text, false),
                Ok(broad_phase),
                "{text}"
            );
        }
        assert_eq!(flag_value(BroadPhase::AllPairs), "all-pairs");
    }
}
