//! `ballpit bench`: the standard gas (`assets/scenes/gas.ron`: radius U[5, 15] px, speed
//! U[0, 500] px/s, area fraction 0.30, dt 1/60 s) at several sizes, with figures per size: the
//! discrete mode on one core, two cores and against all pairs, then the continuous mode
//! against the discrete one.
//!
//! Each case runs in a child process (`ballpit bench-one`), so its peak memory is its own and
//! its core count can be set: one-core cases are started under `taskset -c 0`, which Bevy's
//! task pools see as one available core. Timings are compared as ratios within one run, and
//! every case runs in several rounds, each round every case once, so that a slow spell of the
//! machine falls on all of them alike; each case reports its median round
//! ([`BenchRow::median_of_rounds`]).

use std::error::Error;
use std::process::Command;

use serde::{Deserialize, Serialize};

use crate::headless::{DEFAULT_DT, counters_only, headless_app_with_threads, median, time_steps};
use crate::sim::{BroadPhase, CollisionMode, SceneFile, SimStats, Solver};

/// The standard gas, built in so the bench runs from any directory.
pub const STANDARD_GAS: &str = include_str!("../../assets/scenes/gas.ron");
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
    /// for an even count), with every round's and the highest peak RSS of them all. `None`
    /// without rounds.
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
    let exe = std::env::current_exe()?;
    let mut command = if one_core {
        let mut taskset = Command::new("taskset");
        taskset.args(["-c", "0"]).arg(exe);
        taskset
    } else {
        Command::new(exe)
    };
    let output = command
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
        .output()
        .map_err(|e| {
            format!(
                "cannot start the bench child{}: {e}",
                if one_core {
                    " (is taskset installed?)"
                } else {
                    ""
                }
            )
        })?;
    if !output.status.success() {
        return Err(format!(
            "bench child failed: {}",
            String::from_utf8_lossy(&output.stderr)
        )
        .into());
    }
    Ok(serde_json::from_slice(&output.stdout)?)
}

/// One row of the bench table: a size, on one core and on all cores, against all pairs.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRow {
    pub balls: usize,
    pub one_core: CaseResult,
    pub all_cores: CaseResult,
    /// The all-pairs reference on one core, where it was run.
    pub all_pairs: Option<CaseResult>,
    /// The same gas in continuous mode, on one core and on all.
    pub continuous_one_core: CaseResult,
    pub continuous_all_cores: CaseResult,
}

impl BenchRow {
    /// One size's rows from several rounds as one: each case its [median
    /// round](CaseResult::median_round). `None` without rounds.
    pub fn median_of_rounds(rounds: Vec<BenchRow>) -> Option<BenchRow> {
        let balls = rounds.first()?.balls;
        let median = |case: fn(&BenchRow) -> &CaseResult| {
            CaseResult::median_round(rounds.iter().map(|row| case(row).clone()).collect())
        };
        let all_pairs = rounds
            .iter()
            .filter_map(|row| row.all_pairs.clone())
            .collect();
        Some(BenchRow {
            balls,
            one_core: median(|row| &row.one_core)?,
            all_cores: median(|row| &row.all_cores)?,
            all_pairs: CaseResult::median_round(all_pairs),
            continuous_one_core: median(|row| &row.continuous_one_core)?,
            continuous_all_cores: median(|row| &row.continuous_all_cores)?,
        })
    }

    pub fn speedup_over_all_pairs(&self) -> Option<f64> {
        self.all_pairs
            .as_ref()
            .map(|all| speedup(all, &self.one_core))
    }

    pub fn speedup_from_cores(&self) -> f64 {
        speedup(&self.one_core, &self.all_cores)
    }

    /// The continuous mode's speed-up from all cores.
    pub fn continuous_speedup_from_cores(&self) -> f64 {
        speedup(&self.continuous_one_core, &self.continuous_all_cores)
    }
}

/// How many times faster `faster` ran a step than `slower`.
fn speedup(slower: &CaseResult, faster: &CaseResult) -> f64 {
    slower.ms_per_step_median / faster.ms_per_step_median
}

/// Each row's cost per ball-step on one core against the first row's, discrete then
/// continuous: 1.0 is a flat cost per ball.
pub fn cost_per_ball_against_first(rows: &[BenchRow]) -> Vec<(f64, f64)> {
    let Some(first) = rows.first() else {
        return Vec::new();
    };
    let per_ball = |result: &CaseResult| result.ns_per_ball_step;
    rows.iter()
        .map(|row| {
            (
                per_ball(&row.one_core) / per_ball(&first.one_core),
                per_ball(&row.continuous_one_core) / per_ball(&first.continuous_one_core),
            )
        })
        .collect()
}

/// The bench tables as text: the discrete mode's scaling, then continuous against discrete.
pub fn format_table(rows: &[BenchRow]) -> String {
    let mut text = match rows
        .first()
        .map(|row| row.one_core.rounds_ms_per_step.len())
    {
        Some(rounds @ 2..) => format!(
            "Each case: its median of {rounds} rounds, run alternately (every round in --json).\n\n"
        ),
        _ => String::new(),
    };
    text += "Discrete mode (move, find overlaps, respond), grid broad phase:\n";
    text += &format!(
        "{:>8} {:>12} {:>14} {:>14} {:>12} {:>10} {:>13} {:>11}\n",
        "balls",
        "ms/step 1c",
        "ns/ball-step",
        "contacts/step",
        "peak RSS MB",
        "ms/step 2c",
        "speed-up 2c",
        "vs all-pairs"
    );
    for row in rows {
        let rss = row
            .one_core
            .peak_rss_mib
            .map_or("-".to_string(), |mib| format!("{:.1}", mib * 1.048_576));
        let versus = row
            .speedup_over_all_pairs()
            .map_or("-".to_string(), |s| format!("{s:.1}x"));
        text += &format!(
            "{:>8} {:>12.3} {:>14.1} {:>14.0} {:>12} {:>10.3} {:>12.2}x {:>11}\n",
            row.balls,
            row.one_core.ms_per_step_median,
            row.one_core.ns_per_ball_step,
            row.one_core.contacts_per_step,
            rss,
            row.all_cores.ms_per_step_median,
            row.speedup_from_cores(),
            versus
        );
    }
    text += "\nContinuous against discrete (collisions = momentum exchanges between balls):\n";
    text += &format!(
        "{:>8} {:>10} {:>10} {:>12} {:>14} {:>14} {:>10} {:>12} {:>14} {:>14} {:>12}\n",
        "balls",
        "cont 1c ms",
        "cont 2c ms",
        "cont coll/st",
        "cont coll/sim-s",
        "cont coll/cpu-s",
        "disc 1c ms",
        "disc coll/st",
        "disc coll/sim-s",
        "disc coll/cpu-s",
        "cont RSS MB"
    );
    for row in rows {
        let (continuous, discrete) = (&row.continuous_one_core, &row.one_core);
        text += &format!(
            "{:>8} {:>10.3} {:>10.3} {:>12.0} {:>14.0} {:>14.0} {:>10.3} {:>12.0} {:>14.0} {:>14.0} {:>12}\n",
            row.balls,
            continuous.ms_per_step_median,
            row.continuous_all_cores.ms_per_step_median,
            continuous.collisions_per_step,
            continuous.collisions_per_sim_second,
            continuous.collisions_per_cpu_second,
            discrete.ms_per_step_median,
            discrete.collisions_per_step,
            discrete.collisions_per_sim_second,
            discrete.collisions_per_cpu_second,
            continuous
                .peak_rss_mib
                .map_or("-".to_string(), |mib| format!("{:.1}", mib * 1.048_576)),
        );
    }
    text + &format_scale(rows)
}

/// How the cost scales: per ball against the first size, and two cores against one.
fn format_scale(rows: &[BenchRow]) -> String {
    let mut text = String::from(
        "\nScale (one core; per ball against the first size, 1.00x is flat; all cores against one):\n",
    );
    text += &format!(
        "{:>8} {:>12} {:>13} {:>12} {:>13} {:>9} {:>9}\n",
        "balls",
        "disc ns/ball",
        "disc vs first",
        "cont ns/ball",
        "cont vs first",
        "disc 2c",
        "cont 2c"
    );
    for (row, (discrete, continuous)) in rows.iter().zip(cost_per_ball_against_first(rows)) {
        text += &format!(
            "{:>8} {:>12.1} {:>12.2}x {:>12.1} {:>12.2}x {:>8.2}x {:>8.2}x\n",
            row.balls,
            row.one_core.ns_per_ball_step,
            discrete,
            row.continuous_one_core.ns_per_ball_step,
            continuous,
            row.speedup_from_cores(),
            row.continuous_speedup_from_cores(),
        );
    }
    text
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

    #[test]
    fn the_cost_per_ball_is_taken_against_the_first_size() {
        let result = |balls: usize, collisions, ms: f64| CaseResult {
            case: BenchCase {
                balls,
                steps: 10,
                broad_phase: BroadPhase::Grid,
                collisions,
            },
            cores: 1,
            threads: 1,
            ms_per_step_median: ms,
            ns_per_ball_step: ms * 1e6 / balls as f64,
            contacts_per_step: 0.0,
            collisions_per_step: 0.0,
            collisions_per_sim_second: 0.0,
            collisions_per_cpu_second: 0.0,
            peak_rss_mib: None,
            rounds_ms_per_step: Vec::new(),
        };
        let row = |balls, discrete_ms, continuous_ms| BenchRow {
            balls,
            one_core: result(balls, CollisionMode::Discrete, discrete_ms),
            all_cores: result(balls, CollisionMode::Discrete, discrete_ms / 1.5),
            all_pairs: None,
            continuous_one_core: result(balls, CollisionMode::Continuous, continuous_ms),
            continuous_all_cores: result(balls, CollisionMode::Continuous, continuous_ms),
        };
        // 10x the balls: discrete 13x the time (1.3x a ball), continuous 20x (2x a ball).
        let rows = [row(100_000, 10.0, 30.0), row(1_000_000, 130.0, 600.0)];
        let ratios = cost_per_ball_against_first(&rows);
        assert!((ratios[0].0 - 1.0).abs() < 1e-12 && (ratios[0].1 - 1.0).abs() < 1e-12);
        assert!((ratios[1].0 - 1.3).abs() < 1e-9, "{:?}", ratios[1]);
        assert!((ratios[1].1 - 2.0).abs() < 1e-9, "{:?}", ratios[1]);
        assert!((rows[0].speedup_from_cores() - 1.5).abs() < 1e-12);
        let table = format_table(&rows);
        assert!(
            table.contains("1.30x") && table.contains("2.00x"),
            "{table}"
        );
        assert!(cost_per_ball_against_first(&[]).is_empty());
    }

    #[test]
    fn each_case_reports_its_median_round_and_the_highest_peak() {
        let round = |ms: f64, rss: f64| CaseResult {
            case: BenchCase {
                balls: 1000,
                steps: 10,
                broad_phase: BroadPhase::Grid,
                collisions: CollisionMode::Continuous,
            },
            cores: 2,
            threads: 2,
            ms_per_step_median: ms,
            ns_per_ball_step: ms * 1e3,
            contacts_per_step: ms * 10.0,
            collisions_per_step: 0.0,
            collisions_per_sim_second: 0.0,
            collisions_per_cpu_second: 0.0,
            peak_rss_mib: Some(rss),
            rounds_ms_per_step: Vec::new(),
        };
        let median =
            CaseResult::median_round(vec![round(3.0, 40.0), round(1.0, 45.0), round(2.0, 41.0)])
                .unwrap();
        // The whole of the middle round (its per-ball cost and counts with it), every
        // round's median in the order run, the highest peak.
        assert_eq!(median.ms_per_step_median, 2.0);
        assert_eq!(median.ns_per_ball_step, 2000.0);
        assert_eq!(median.contacts_per_step, 20.0);
        assert_eq!(median.rounds_ms_per_step, [3.0, 1.0, 2.0]);
        assert_eq!(median.peak_rss_mib, Some(45.0));
        // Of an even count, the faster of the middle two; of none, nothing.
        let four = [4.0, 1.0, 3.0, 2.0].map(|ms| round(ms, 40.0)).to_vec();
        assert_eq!(
            CaseResult::median_round(four).unwrap().ms_per_step_median,
            2.0
        );
        assert_eq!(CaseResult::median_round(Vec::new()), None);
        let one = CaseResult::median_round(vec![round(5.0, 40.0)]).unwrap();
        assert_eq!(one.ms_per_step_median, 5.0);
        let rows = [BenchRow {
            balls: 1000,
            one_core: median.clone(),
            all_cores: median.clone(),
            all_pairs: None,
            continuous_one_core: median.clone(),
            continuous_all_cores: median,
        }];
        assert!(format_table(&rows).starts_with("Each case: its median of 3 rounds"));
    }
}
