//! `ballpit bench --pile`: the pile (`assets/scenes/pile.ron`: the standard gas under gravity
//! (0, −500) px/s² with restitution 0.5) at several sizes, in both modes, on one thread, from
//! the start over a fixed number of steps: how fast it steps while it falls, settles and
//! sleeps, and how well it rests at the end. `../shared/peers` runs Box2D v3.2 and rapier on
//! the same pile (`peers --gravity -500 --restitution 0.5`), for a comparison in one run.

use std::error::Error;

use serde::Serialize;

use super::run::{RunReport, run_scene_with_threads};
use crate::headless::DEFAULT_DT;
use crate::sim::{CollisionMode, SceneFile};

/// The pile, built in so the bench runs from any directory.
pub const PILE: &str = include_str!("../../assets/scenes/pile.ron");

/// One pile case's figures: the report of `ballpit run` on it.
#[derive(Clone, Debug, Serialize)]
pub struct PileRow {
    pub collisions: CollisionMode,
    pub report: RunReport,
}

/// Runs the pile with `balls` balls in `mode` for `steps` steps on one thread.
pub fn run_pile(balls: usize, mode: CollisionMode, steps: u64) -> Result<PileRow, Box<dyn Error>> {
    let mut scene = SceneFile::parse(PILE, "pile.ron")?;
    if let Some(generate) = scene.generate.as_mut() {
        generate.count = balls;
    }
    scene.collisions = Some(mode);
    let setup = scene.build("pile.ron")?;
    let (_, report) = run_scene_with_threads(&setup, steps, DEFAULT_DT, Some(1));
    Ok(PileRow {
        collisions: mode,
        report,
    })
}

/// The rows as a table: speed over the run, then the state at its end.
pub fn format_pile_table(rows: &[PileRow]) -> String {
    let mut table = String::from(
        "balls   mode        steps  ms/step mean  median  overlap max  overlap mean  moving  asleep  ball hits\n",
    );
    for PileRow { collisions, report } in rows {
        table.push_str(&format!(
            "{:<7} {:<11} {:>5}  {:>12.3}  {:>6.3}  {:>11.4}  {:>12.5}  {:>6}  {:>6}  {:>9}\n",
            report.balls,
            format!("{collisions:?}").to_lowercase(),
            report.steps,
            report.ms_per_step_mean,
            report.ms_per_step_median,
            report.max_overlap_rel,
            report.mean_overlap_rel,
            report.moving,
            report.sleeping,
            report.ball_collisions,
        ));
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_pile_case_runs_and_reports_its_figures() {
        let row = run_pile(50, CollisionMode::Discrete, 30).unwrap();
        assert_eq!((row.report.balls, row.report.steps), (50, 30));
        let table = format_pile_table(&[row]);
        assert!(
            table
                .lines()
                .nth(1)
                .unwrap()
                .starts_with("50      discrete"),
            "{table}"
        );
    }
}
