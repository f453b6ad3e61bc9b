//! One size's row of the bench ([`BenchRow`]): its cases on one core and on all, the
//! all-pairs reference, the continuous mode, each run in its own child, and if asked the
//! one-core cases on every core at once ([`OnEachCore`]); the row from several rounds, and the
//! ratios the tables print.

use std::error::Error;

use serde::Serialize;

use super::case::{BenchCase, CaseResult, run_case_in_child, run_case_on_each_core};
use crate::sim::{BroadPhase, CollisionMode};

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
    /// The one-core cases run on every core at once, where asked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub on_each_core: Option<OnEachCore>,
}

/// A size's one-core cases run on every core, one child pinned to each, started together: in
/// each mode the slowest of them, the pace of a step whose work split perfectly over the cores.
#[derive(Clone, Debug, Serialize)]
pub struct OnEachCore {
    /// How many ran side by side.
    pub cores: usize,
    pub discrete: CaseResult,
    pub continuous: CaseResult,
}

impl BenchRow {
    /// The row of `balls` balls: each case once, `steps` steps, in its own child process; the
    /// all-pairs reference up to `all_pairs_max` balls; the one-core cases on every core at
    /// once if `on_each_core`.
    pub fn measure(
        balls: usize,
        steps: u64,
        all_pairs_max: u64,
        on_each_core: bool,
    ) -> Result<Self, Box<dyn Error>> {
        let discrete = BenchCase {
            balls,
            steps,
            broad_phase: BroadPhase::Grid,
            collisions: CollisionMode::Discrete,
        };
        let all_pairs = (balls as u64 <= all_pairs_max).then_some(BenchCase {
            steps: (steps / 10).max(5),
            broad_phase: BroadPhase::AllPairs,
            ..discrete
        });
        let continuous = BenchCase {
            collisions: CollisionMode::Continuous,
            ..discrete
        };
        Ok(BenchRow {
            balls,
            one_core: run_case_in_child(discrete, true)?,
            all_cores: run_case_in_child(discrete, false)?,
            all_pairs: all_pairs
                .map(|case| run_case_in_child(case, true))
                .transpose()?,
            continuous_one_core: run_case_in_child(continuous, true)?,
            continuous_all_cores: run_case_in_child(continuous, false)?,
            on_each_core: on_each_core
                .then(|| OnEachCore::measure(discrete, continuous))
                .transpose()?,
        })
    }

    /// One size's rows from several rounds as one: each case its [median
    /// round](CaseResult::median_round). `None` without rounds.
    pub fn median_of_rounds(rounds: Vec<BenchRow>) -> Option<BenchRow> {
        let balls = rounds.first()?.balls;
        let median_of = |case: fn(&BenchRow) -> &CaseResult| {
            CaseResult::median_round(rounds.iter().map(|row| case(row).clone()).collect())
        };
        let all_pairs = rounds
            .iter()
            .filter_map(|row| row.all_pairs.clone())
            .collect();
        Some(BenchRow {
            balls,
            one_core: median_of(|row| &row.one_core)?,
            all_cores: median_of(|row| &row.all_cores)?,
            all_pairs: CaseResult::median_round(all_pairs),
            continuous_one_core: median_of(|row| &row.continuous_one_core)?,
            continuous_all_cores: median_of(|row| &row.continuous_all_cores)?,
            on_each_core: rounds
                .iter()
                .map(|row| row.on_each_core.clone())
                .collect::<Option<Vec<OnEachCore>>>()
                .and_then(OnEachCore::median_of_rounds),
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

    /// What the machine gives a perfectly split step, discrete then continuous, where the
    /// one-core cases ran on every core: as many as ran side by side, times the one-core step
    /// alone over the slowest of them.
    pub fn speedup_on_each_core(&self) -> Option<(f64, f64)> {
        let each = self.on_each_core.as_ref()?;
        let cores = each.cores as f64;
        Some((
            cores * speedup(&self.one_core, &each.discrete),
            cores * speedup(&self.continuous_one_core, &each.continuous),
        ))
    }
}

impl OnEachCore {
    /// The `discrete` and `continuous` cases, each run on every core, one child pinned to each.
    fn measure(discrete: BenchCase, continuous: BenchCase) -> Result<Self, Box<dyn Error>> {
        let discrete = run_case_on_each_core(discrete)?;
        Ok(OnEachCore {
            cores: discrete.len(),
            discrete: slowest(discrete)?,
            continuous: slowest(run_case_on_each_core(continuous)?)?,
        })
    }

    /// Each mode's median round; `None` without rounds.
    fn median_of_rounds(rounds: Vec<OnEachCore>) -> Option<OnEachCore> {
        let cores = rounds.first()?.cores;
        let (discrete, continuous) = rounds
            .into_iter()
            .map(|each| (each.discrete, each.continuous))
            .unzip();
        Some(OnEachCore {
            cores,
            discrete: CaseResult::median_round(discrete)?,
            continuous: CaseResult::median_round(continuous)?,
        })
    }
}

/// The slowest of `results`, by the step's median.
pub(super) fn slowest(results: Vec<CaseResult>) -> Result<CaseResult, Box<dyn Error>> {
    results
        .into_iter()
        .max_by(|a, b| a.ms_per_step_median.total_cmp(&b.ms_per_step_median))
        .ok_or_else(|| "no core to run the bench on".into())
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
