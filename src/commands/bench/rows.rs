//! One size's row of the bench ([`BenchRow`]): its cases on one core and on all, the
//! all-pairs reference, the continuous mode, each run in its own child; the row from several
//! rounds, and the ratios the tables print.

use std::error::Error;

use serde::Serialize;

use super::case::{BenchCase, CaseResult, run_case_in_child};
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
}

impl BenchRow {
    /// The row of `balls` balls: each case once, `steps` steps, in its own child process; the
    /// all-pairs reference up to `all_pairs_max` balls.
    pub fn measure(balls: usize, steps: u64, all_pairs_max: u64) -> Result<Self, Box<dyn Error>> {
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
