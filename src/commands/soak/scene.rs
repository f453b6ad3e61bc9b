//! The soak's random scenes: parameters drawn across the panel's full ranges, the extremes
//! drawn often ([`SoakScene::draw`]).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::sim::params::{
    ARENA_SIDE_RANGE, DAMPING_SLIDER, GRAVITY_SLIDER, RESTITUTION_RANGE, SPEED_SLIDER,
    STEP_RATE_SLIDER,
};
use crate::sim::{CollisionMode, MassModel, SceneFile, SceneSetup};

/// The densest covered fraction asked of random placement (it stalls a little above 0.5).
pub(super) const DENSEST_AREA_FRACTION: f64 = 0.5;
/// Time scales drawn: the slider's range without its zero (a stopped simulation tests
/// nothing), log-uniform like the slider.
pub(super) const SOAK_TIME_SCALES: std::ops::RangeInclusive<f64> = 0.01..=10.0;

/// One random scene: what is loaded and how it is stepped.
#[derive(Clone, Debug)]
pub struct SoakScene {
    pub seed: u64,
    pub scene: SceneFile,
    /// Fixed step, seconds (from the step-rate slider).
    pub dt: f64,
    pub time_scale: f64,
}

/// A value from `range`: a quarter of the time its low end, a quarter its high end, else
/// uniform (log-uniform when `log` and the range is positive).
pub(super) fn extreme(
    rng: &mut ChaCha8Rng,
    range: &std::ops::RangeInclusive<f64>,
    log: bool,
) -> f64 {
    let (low, high) = (*range.start(), *range.end());
    match rng.random_range(0..4) {
        0 => low,
        1 => high,
        _ if log && low > 0.0 => rng
            .random_range(low.ln()..=high.ln())
            .exp()
            .clamp(low, high),
        _ => rng.random_range(low..=high),
    }
}

/// The radii scenes are drawn from, pixels: from the smallest a scene file may hold to the
/// largest the radius sliders reach.
const SOAK_RADII: std::ops::RangeInclusive<f64> = 0.5..=200.0;

impl SoakScene {
    /// Draws scene number `seed`, with at most `max_balls` balls.
    pub fn draw(seed: u64, max_balls: usize) -> SoakScene {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let r_min = extreme(&mut rng, &SOAK_RADII, true);
        let r_max = extreme(&mut rng, &(r_min..=*SOAK_RADII.end()), true);
        let s_min = extreme(&mut rng, &SPEED_SLIDER, false);
        let s_max = extreme(&mut rng, &(s_min..=*SPEED_SLIDER.end()), false);
        let count = extreme(&mut rng, &(2.0..=max_balls.max(2) as f64), true).round() as usize;
        // The loosest packing still fits the largest arena.
        let mean_square_radius = (r_min * r_min + r_min * r_max + r_max * r_max) / 3.0;
        let disc_area = count as f64 * std::f64::consts::PI * mean_square_radius;
        let loosest = (2.0 * disc_area / ARENA_SIDE_RANGE.end().powi(2)).max(0.001);
        let fraction = extreme(&mut rng, &(loosest..=DENSEST_AREA_FRACTION), true);
        let gravity = if rng.random_bool(0.4) {
            (0.0, 0.0)
        } else {
            (
                extreme(&mut rng, &GRAVITY_SLIDER, false),
                extreme(&mut rng, &GRAVITY_SLIDER, false),
            )
        };
        let damping = if rng.random_bool(0.5) {
            0.0
        } else {
            extreme(&mut rng, &DAMPING_SLIDER, false)
        };
        let scene = SceneFile {
            arena: None,
            gravity,
            restitution: extreme(&mut rng, &RESTITUTION_RANGE, false),
            mass_model: MassModel::ALL[rng.random_range(0..MassModel::ALL.len())],
            linear_damping: damping,
            collisions: Some(CollisionMode::ALL[rng.random_range(0..CollisionMode::ALL.len())]),
            balls: Vec::new(),
            generate: Some(crate::sim::scene::Generate {
                count,
                radius: (r_min, r_max),
                speed: (s_min, s_max),
                area_fraction: Some(fraction),
                seed,
            }),
        };
        SoakScene {
            seed,
            scene,
            dt: 1.0 / extreme(&mut rng, &STEP_RATE_SLIDER, false),
            time_scale: extreme(&mut rng, &SOAK_TIME_SCALES, true),
        }
    }

    /// Builds the scene; when random placement cannot reach the drawn packing, asks for a
    /// looser one (as a player would), down to a tenth of it.
    pub fn build(&mut self) -> Result<SceneSetup, String> {
        let mut last_error = String::new();
        for _ in 0..8 {
            match self.scene.build("soak") {
                Ok(setup) => return Ok(setup),
                Err(error) => last_error = error.to_string(),
            }
            let generate = self.scene.generate.as_mut().expect("soak scenes generate");
            generate.area_fraction = generate.area_fraction.map(|f| f * 0.75);
        }
        Err(last_error)
    }

    /// One line describing the scene.
    pub fn describe(&self) -> String {
        let s = &self.scene;
        let g = s.generate.expect("soak scenes generate");
        format!(
            "seed {}: {} balls r {:.3}..{:.3} speed {:.0}..{:.0} cover {:.4}, {:?}, e {:.3}, \
             g ({:.0}, {:.0}), damping {:.2}, mass {:?}, dt {:.5} x time scale {:.3}",
            self.seed,
            g.count,
            g.radius.0,
            g.radius.1,
            g.speed.0,
            g.speed.1,
            g.area_fraction.unwrap_or(0.0),
            s.collisions.unwrap_or_default(),
            s.restitution,
            s.gravity.0,
            s.gravity.1,
            s.linear_damping,
            s.mass_model,
            self.dt,
            self.time_scale
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::params::TIME_SCALE_SLIDER;

    #[test]
    fn drawn_scenes_cover_the_extremes_and_build() {
        let scenes: Vec<SoakScene> = (0..200).map(|seed| SoakScene::draw(seed, 300)).collect();
        let restitutions: Vec<f64> = scenes.iter().map(|s| s.scene.restitution).collect();
        assert!(restitutions.contains(&0.0) && restitutions.contains(&1.0));
        let radii = scenes.iter().map(|s| s.scene.generate.unwrap().radius);
        assert!(radii.clone().any(|r| r.0 == *SOAK_RADII.start()));
        assert!(radii.clone().any(|r| r.1 == *SOAK_RADII.end()));
        assert!(
            scenes
                .iter()
                .any(|s| s.scene.gravity.1 == *GRAVITY_SLIDER.start())
        );
        assert_eq!(*SOAK_TIME_SCALES.end(), *TIME_SCALE_SLIDER.end());
        assert!(
            scenes
                .iter()
                .any(|s| s.time_scale == *TIME_SCALE_SLIDER.end())
        );
        assert!(
            scenes.iter().any(|s| {
                s.scene.generate.unwrap().area_fraction == Some(DENSEST_AREA_FRACTION)
            })
        );
        for mut soak in scenes.into_iter().take(20) {
            let setup = soak
                .build()
                .unwrap_or_else(|e| panic!("{}: {e}", soak.describe()));
            assert_eq!(setup.balls.len(), soak.scene.generate.unwrap().count);
        }
    }
}
