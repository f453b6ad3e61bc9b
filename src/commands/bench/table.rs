//! The bench's tables as text: the discrete mode's scaling, continuous against discrete, and
//! how the cost scales with the size and the cores. Pure formatting of [`BenchRow`]s.

use super::rows::{BenchRow, cost_per_ball_against_first};

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

/// How the cost scales: per ball against the first size, and two cores against one; with the
/// one-core cases run on every core at once, what that gives beside it ("host").
fn format_scale(rows: &[BenchRow]) -> String {
    let on_each_core = rows.iter().any(|row| row.on_each_core.is_some());
    let mut text = String::from(
        "\nScale (one core; per ball against the first size, 1.00x is flat; all cores against one):\n",
    );
    if on_each_core {
        text += "(host: a one-core run on each core at once, cores x alone / slowest, \
                 what a perfectly split step could gain)\n";
    }
    text += &format!(
        "{:>8} {:>12} {:>13} {:>12} {:>13} {:>9} {:>9}",
        "balls",
        "disc ns/ball",
        "disc vs first",
        "cont ns/ball",
        "cont vs first",
        "disc 2c",
        "cont 2c"
    );
    if on_each_core {
        text += &format!(" {:>9} {:>9}", "disc host", "cont host");
    }
    text += "\n";
    for (row, (discrete, continuous)) in rows.iter().zip(cost_per_ball_against_first(rows)) {
        text += &format!(
            "{:>8} {:>12.1} {:>12.2}x {:>12.1} {:>12.2}x {:>8.2}x {:>8.2}x",
            row.balls,
            row.one_core.ns_per_ball_step,
            discrete,
            row.continuous_one_core.ns_per_ball_step,
            continuous,
            row.speedup_from_cores(),
            row.continuous_speedup_from_cores(),
        );
        if on_each_core {
            text += &match row.speedup_on_each_core() {
                Some((discrete, continuous)) => format!(" {discrete:>8.2}x {continuous:>8.2}x"),
                None => format!(" {:>9} {:>9}", "-", "-"),
            };
        }
        text += "\n";
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::bench::case::{BenchCase, CaseResult};
    use crate::commands::bench::rows::{OnEachCore, slowest};
    use crate::sim::{BroadPhase, CollisionMode};

    /// A case of `balls` balls whose step took `ms`, on `cores` cores with as many threads.
    fn result(balls: usize, collisions: CollisionMode, cores: usize, ms: f64) -> CaseResult {
        CaseResult {
            case: BenchCase {
                balls,
                steps: 10,
                broad_phase: BroadPhase::Grid,
                collisions,
            },
            cores,
            threads: cores,
            ms_per_step_median: ms,
            ms_per_step_p10: ms,
            ns_per_ball_step: ms * 1e6 / balls as f64,
            contacts_per_step: 0.0,
            collisions_per_step: 0.0,
            collisions_per_sim_second: 0.0,
            collisions_per_cpu_second: 0.0,
            peak_rss_mib: None,
            rounds_ms_per_step: Vec::new(),
        }
    }

    #[test]
    fn the_cost_per_ball_is_taken_against_the_first_size() {
        let row = |balls, discrete_ms, continuous_ms| BenchRow {
            balls,
            one_core: result(balls, CollisionMode::Discrete, 1, discrete_ms),
            all_cores: result(balls, CollisionMode::Discrete, 1, discrete_ms / 1.5),
            all_pairs: None,
            continuous_one_core: result(balls, CollisionMode::Continuous, 1, continuous_ms),
            continuous_all_cores: result(balls, CollisionMode::Continuous, 1, continuous_ms),
            on_each_core: None,
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
            ms_per_step_p10: 0.9 * ms,
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
        // The whole of the middle round (its per-ball cost, counts and quickest tenth with
        // it), every round's median in the order run, the highest peak.
        assert_eq!(median.ms_per_step_median, 2.0);
        assert_eq!(median.ms_per_step_p10, 1.8);
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
            on_each_core: None,
        }];
        assert!(format_table(&rows).starts_with("Each case: its median of 3 rounds"));
        // A size's rows from rounds: each case from its own rounds, no all-pairs if none ran.
        let row_of_round = |k: f64| BenchRow {
            balls: 1000,
            one_core: round(1.0 + k, 40.0),
            all_cores: round(2.0 + k, 40.0),
            all_pairs: (k == 0.0).then(|| round(9.0, 40.0)),
            continuous_one_core: round(3.0 + k, 40.0),
            continuous_all_cores: round(4.0 + k, 40.0),
            on_each_core: None,
        };
        let row = BenchRow::median_of_rounds([0.3, 0.1, 0.2].map(row_of_round).to_vec()).unwrap();
        let ms = |case: &CaseResult| case.ms_per_step_median;
        assert_eq!(ms(&row.one_core), 1.0 + 0.2);
        assert_eq!(ms(&row.all_cores), 2.0 + 0.2);
        assert_eq!(ms(&row.continuous_one_core), 3.0 + 0.2);
        assert_eq!(ms(&row.continuous_all_cores), 4.0 + 0.2);
        assert_eq!(row.all_pairs, None);
        let with_all_pairs = BenchRow::median_of_rounds(vec![row_of_round(0.0)]).unwrap();
        assert_eq!(with_all_pairs.all_pairs.map(|case| ms(&case)), Some(9.0));
        assert!(BenchRow::median_of_rounds(Vec::new()).is_none());
    }

    #[test]
    fn the_host_figure_is_the_cores_times_one_core_alone_over_the_slowest_on_each_core() {
        let result = |collisions, cores, ms| result(100_000, collisions, cores, ms);
        let (discrete, continuous) = (CollisionMode::Discrete, CollisionMode::Continuous);
        // One core alone 10 and 30 ms; on each of two cores at once, the slowest 11 and 40.
        let row = |each: Option<(f64, f64)>| BenchRow {
            balls: 100_000,
            one_core: result(discrete, 1, 10.0),
            all_cores: result(discrete, 2, 6.0),
            all_pairs: None,
            continuous_one_core: result(continuous, 1, 30.0),
            continuous_all_cores: result(continuous, 2, 20.0),
            on_each_core: each.map(|(discrete_ms, continuous_ms)| OnEachCore {
                cores: 2,
                discrete: result(discrete, 1, discrete_ms),
                continuous: result(continuous, 1, continuous_ms),
            }),
        };
        let measured = row(Some((11.0, 40.0)));
        let (host_discrete, host_continuous) = measured.speedup_on_each_core().unwrap();
        assert!(
            (host_discrete - 20.0 / 11.0).abs() < 1e-12,
            "{host_discrete}"
        );
        assert!((host_continuous - 1.5).abs() < 1e-12, "{host_continuous}");
        assert_eq!(row(None).speedup_on_each_core(), None);
        let table = format_table(&[measured.clone(), row(None)]);
        assert!(
            table.contains("disc host") && table.contains("cont host"),
            "{table}"
        );
        let last_line = |table: &str| table.lines().last().unwrap_or("").to_string();
        assert!(
            table.contains("1.82x     1.50x") && last_line(&table).ends_with("-         -"),
            "{table}"
        );
        assert!(!format_table(&[row(None)]).contains("host"));
        // From rounds: each mode's median round, and none unless every round ran them.
        let rounds = [(13.0, 42.0), (11.0, 40.0), (12.0, 44.0)].map(|each| row(Some(each)));
        let median = BenchRow::median_of_rounds(rounds.to_vec()).unwrap();
        let each = median.on_each_core.unwrap();
        assert_eq!(each.discrete.ms_per_step_median, 12.0);
        assert_eq!(each.continuous.ms_per_step_median, 42.0);
        assert_eq!(each.discrete.rounds_ms_per_step, [13.0, 11.0, 12.0]);
        let missing = BenchRow::median_of_rounds(vec![measured, row(None)]).unwrap();
        assert!(missing.on_each_core.is_none());
        assert!(
            !serde_json::to_string(&row(None))
                .unwrap()
                .contains("on_each_core")
        );
        // Of the runs side by side, the slowest; of none, an error.
        let side_by_side = [11.0, 13.0, 12.0]
            .map(|ms| result(discrete, 1, ms))
            .to_vec();
        assert_eq!(slowest(side_by_side).unwrap().ms_per_step_median, 13.0);
        assert!(slowest(Vec::new()).is_err());
    }
}
