//! One size's row of the bench ([`BenchRow`]): its cases on one core and on all, the
//! all-pairs reference, the continuous mode; the row from several rounds, and the ratios the
//! tables print.

use serde::Serialize;

use super::case::CaseResult;

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
