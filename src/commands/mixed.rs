//! `ballpit bench --mixed`: mixed sizes (`assets/scenes/mixed.ron`: small balls of radius
//! 1.2–3.5 px with three of radius 40) against the same small balls alone, in both modes, on
//! one thread: what a few big balls cost every small one. The grid's cell is the largest
//! diameter, so today the big balls make every cell hold many small ones.

use std::error::Error;

use serde::Serialize;

use super::run::run_scene_with_threads;
use crate::headless::DEFAULT_DT;
use crate::sim::{CollisionMode, SceneFile};

/// The mixed scene, built in so the bench runs from any directory.
pub const MIXED: &str = include_str!("../../assets/scenes/mixed.ron");

/// One mode's figures: the small balls alone, then with the big ones.
#[derive(Clone, Debug, Serialize)]
pub struct MixedRow {
    pub collisions: CollisionMode,
    pub small_balls: usize,
    pub small_ms_per_step: f64,
    pub mixed_balls: usize,
    pub mixed_ms_per_step: f64,
    /// Cost per ball with the big balls over cost per ball without them.
    pub cost_per_ball_ratio: f64,
}

/// Times `small` small balls alone and with the scene's big ones, `steps` steps each (median
/// ms a step), in `mode`.
pub fn run_mixed(
    small: usize,
    mode: CollisionMode,
    steps: u64,
) -> Result<MixedRow, Box<dyn Error>> {
    let time = |with_big: bool| -> Result<(usize, f64), Box<dyn Error>> {
        let mut scene = SceneFile::parse(MIXED, "mixed.ron")?;
        if let Some(generate) = scene.generate.as_mut() {
            generate.count = small;
        }
        if !with_big {
            scene.balls.clear();
        }
        scene.collisions = Some(mode);
        let setup = scene.build("mixed.ron")?;
        let (_, report) = run_scene_with_threads(&setup, steps, DEFAULT_DT, Some(1));
        Ok((report.balls, report.ms_per_step_median))
    };
    let (small_balls, small_ms_per_step) = time(false)?;
    let (mixed_balls, mixed_ms_per_step) = time(true)?;
    Ok(MixedRow {
        collisions: mode,
        small_balls,
        small_ms_per_step,
        mixed_balls,
        mixed_ms_per_step,
        cost_per_ball_ratio: (mixed_ms_per_step / mixed_balls as f64)
            / (small_ms_per_step / small_balls as f64),
    })
}

/// The rows as a table.
pub fn format_mixed_table(rows: &[MixedRow]) -> String {
    let mut table = String::from(
        "mode        small balls  ms/step  with 3 big  ms/step  cost per ball, mixed / small\n",
    );
    for row in rows {
        table.push_str(&format!(
            "{:<11} {:>11}  {:>7.3}  {:>10}  {:>7.3}  {:>28.2}\n",
            format!("{:?}", row.collisions).to_lowercase(),
            row.small_balls,
            row.small_ms_per_step,
            row.mixed_balls,
            row.mixed_ms_per_step,
            row.cost_per_ball_ratio,
        ));
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_mixed_case_runs_with_and_without_the_big_balls() {
        // Too few small balls leave an arena too small for the big ones: a clear error.
        let error = run_mixed(300, CollisionMode::Discrete, 10).unwrap_err();
        assert!(error.to_string().contains("outside"), "{error}");
        let row = run_mixed(2000, CollisionMode::Discrete, 10).unwrap();
        assert_eq!((row.small_balls, row.mixed_balls), (2000, 2003));
        assert!(row.small_ms_per_step > 0.0 && row.mixed_ms_per_step > 0.0);
        assert!(row.cost_per_ball_ratio.is_finite() && row.cost_per_ball_ratio > 0.0);
        let table = format_mixed_table(&[row]);
        assert!(
            table.lines().nth(1).unwrap().starts_with("discrete"),
            "{table}"
        );
    }
}
