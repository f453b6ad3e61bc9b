//! `ballpit soak`: random scenes, their parameters drawn across the panel's full ranges with
//! the extremes drawn often (restitution 0 and 1, the strongest gravity, the smallest and
//! largest radius, the fastest time scale and step rate, the densest packing random placement
//! reaches), each run headless for many steps while a simulated player changes the physics
//! and resizes the window, minimising it too. After every step the state is checked: every
//! number finite, no ball lost or outside the arena, and, without gravity, kinetic energy
//! never above the step before. A panic in a step counts as a failure of that scene.
//!
//! Each scene has its own seed, printed with its result; `--seed <that> --scenes 1` replays it.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use bevy::math::DVec2;
use bevy::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::headless::headless_app;
use crate::sim::measure::summary::kinetic_energy;
use crate::sim::params::{
    ARENA_SIDE_RANGE, DAMPING_SLIDER, GRAVITY_SLIDER, RADIUS_SLIDER, RESTITUTION_RANGE,
    SPEED_SLIDER, STEP_RATE_SLIDER, TIME_SCALE_SLIDER,
};
use crate::sim::{
    Ball, CollisionMode, MassModel, Position, Radius, RunControl, SceneFile, SceneSetup, SimParams,
    Solver, Velocity,
};

/// The densest covered fraction asked of random placement (it stalls a little above 0.5).
const DENSEST_AREA_FRACTION: f64 = 0.5;
/// Time scales drawn: the slider's range without its zero (a stopped simulation tests
/// nothing), log-uniform like the slider.
const SOAK_TIME_SCALES: std::ops::RangeInclusive<f64> = 0.01..=10.0;
/// Steps between the simulated player's actions, on average.
const STEPS_PER_ACTION: u64 = 500;
/// Steps a minimised window stays minimised.
const MINIMISED_STEPS: u64 = 50;
/// Relative slack on the energy check: rounding over one step of many hits.
const ENERGY_TOLERANCE: f64 = 1e-9;
/// Relative slack on the arena walls: rounding in the containment.
const WALL_TOLERANCE: f64 = 1e-9;

/// One random scene: what is loaded and how it is stepped.
#[derive(Clone, Debug)]
pub struct SoakScene {
    pub seed: u64,
    pub scene: SceneFile,
    /// Fixed step, seconds (from the step-rate slider).
    pub dt: f64,
    pub time_scale: f64,
}

/// How one scene's soak ended.
#[derive(Clone, Debug, PartialEq)]
pub struct SoakOutcome {
    pub steps: u64,
    pub balls: usize,
    /// The first failed check or panic, with the step it happened in.
    pub failure: Option<String>,
}

/// A value from `range`: a quarter of the time its low end, a quarter its high end, else
/// uniform (log-uniform when `log` and the range is positive).
fn extreme(rng: &mut ChaCha8Rng, range: &std::ops::RangeInclusive<f64>, log: bool) -> f64 {
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

impl SoakScene {
    /// Draws scene number `seed`, with at most `max_balls` balls.
    pub fn draw(seed: u64, max_balls: usize) -> SoakScene {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let r_min = extreme(&mut rng, &RADIUS_SLIDER, true);
        let r_max = extreme(&mut rng, &(r_min..=*RADIUS_SLIDER.end()), true);
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

/// What the checks after a step need to know of the step before.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepCheck {
    pub balls: usize,
    /// Kinetic energy after the previous step.
    pub kinetic_energy: f64,
}

impl StepCheck {
    /// Checks `balls` (position, velocity, radius) after a step in an arena of `params`:
    /// the count, finiteness, containment and, when `energy_kept` (no gravity, restitution
    /// at most 1), that kinetic energy did not grow. Returns the figures for the next check.
    pub fn check(
        &self,
        balls: &[(DVec2, DVec2, f64)],
        params: &SimParams,
        energy_kept: bool,
    ) -> Result<StepCheck, String> {
        if balls.len() != self.balls {
            return Err(format!("{} balls, {} before", balls.len(), self.balls));
        }
        let half = params.half_extents();
        let mut energy = 0.0;
        for (index, &(position, velocity, radius)) in balls.iter().enumerate() {
            if !(position.is_finite() && velocity.is_finite() && radius.is_finite()) {
                return Err(format!(
                    "ball {index}: position {position}, velocity {velocity}, radius {radius}"
                ));
            }
            // A minimised window stops the simulation; balls keep their places until it
            // returns.
            if params.has_room() {
                let room = (half - DVec2::splat(radius)).max(DVec2::ZERO);
                let slack = half * WALL_TOLERANCE;
                if position.x.abs() > room.x + slack.x || position.y.abs() > room.y + slack.y {
                    return Err(format!(
                        "ball {index} at {position} (radius {radius}) is outside the {} x {} arena",
                        params.arena_size.x, params.arena_size.y
                    ));
                }
            }
            energy += kinetic_energy(params.mass_model.mass(radius), velocity);
        }
        if !energy.is_finite() {
            return Err(format!("kinetic energy {energy}"));
        }
        if energy_kept && energy > self.kinetic_energy * (1.0 + ENERGY_TOLERANCE) {
            return Err(format!(
                "kinetic energy grew from {} to {energy} (relative {:.3e})",
                self.kinetic_energy,
                energy / self.kinetic_energy - 1.0
            ));
        }
        Ok(StepCheck {
            balls: balls.len(),
            kinetic_energy: energy,
        })
    }
}

fn read_balls(world: &mut World, into: &mut Vec<(DVec2, DVec2, f64)>) {
    into.clear();
    into.extend(
        world
            .query_filtered::<(&Position, &Velocity, &Radius), With<Ball>>()
            .iter(world)
            .map(|(p, v, r)| (p.0, v.0, r.0)),
    );
}

/// What the simulated player does between steps.
enum Action {
    /// Resize the window: the arena scales by this factor on each axis.
    Resize(DVec2),
    /// Minimise the window for [`MINIMISED_STEPS`] steps.
    Minimise,
    /// Drag a physics slider somewhere new.
    Retune,
}

/// Loads `setup` and runs it for `steps` steps, checking after each. Never panics: a panic
/// inside a step is caught and reported as the failure.
pub fn soak_scene(soak: &SoakScene, setup: &SceneSetup, steps: u64) -> SoakOutcome {
    let mut done = 0;
    let mut balls = Vec::new();
    let result = catch_unwind(AssertUnwindSafe(|| -> Result<(), String> {
        let mut app = headless_app(soak.dt);
        setup.apply(app.world_mut());
        app.world_mut().resource_mut::<RunControl>().time_scale = soak.time_scale;
        let scene_arena = setup.params.arena_size;
        let mut rng = ChaCha8Rng::seed_from_u64(soak.seed ^ 0x5eed);
        read_balls(app.world_mut(), &mut balls);
        let params = app.world().resource::<SimParams>().clone();
        let mut check = StepCheck {
            balls: balls.len(),
            kinetic_energy: 0.0,
        }
        .check(&balls, &params, false)?;
        let mut restore_at = None;
        while done < steps {
            if restore_at == Some(done) {
                app.world_mut().resource_mut::<SimParams>().arena_size = scene_arena;
                restore_at = None;
            } else if restore_at.is_none() && rng.random_range(0..STEPS_PER_ACTION) == 0 {
                let world = app.world_mut();
                match player_action(&mut rng) {
                    Action::Resize(factor) => {
                        world.resource_mut::<SimParams>().arena_size = (scene_arena * factor).clamp(
                            DVec2::splat(*ARENA_SIDE_RANGE.start()),
                            DVec2::splat(*ARENA_SIDE_RANGE.end()),
                        )
                    }
                    Action::Minimise => {
                        world.resource_mut::<SimParams>().arena_size = DVec2::ZERO;
                        restore_at = Some(done + MINIMISED_STEPS);
                    }
                    Action::Retune => retune(world, &mut rng),
                }
                world.resource_mut::<SimParams>().clamp_to_limits();
                world.resource_mut::<RunControl>().clamp_to_limits();
            }
            app.update();
            done += 1;
            read_balls(app.world_mut(), &mut balls);
            let params = app.world().resource::<SimParams>();
            check = check
                .check(&balls, params, params.gravity == DVec2::ZERO)
                .map_err(|error| format!("step {done}: {error}"))?;
        }
        Ok(())
    }));
    let failure = match result {
        Ok(Ok(())) => None,
        Ok(Err(error)) => Some(error),
        Err(panic) => Some(format!(
            "step {}: panicked: {}",
            done + 1,
            panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("(no message)")
        )),
    };
    SoakOutcome {
        steps: done,
        balls: setup.balls.len(),
        failure,
    }
}

fn player_action(rng: &mut ChaCha8Rng) -> Action {
    match rng.random_range(0..3) {
        0 => Action::Resize(DVec2::new(
            rng.random_range(0.3..=1.5),
            rng.random_range(0.3..=1.5),
        )),
        1 => Action::Minimise,
        _ => Action::Retune,
    }
}

/// Moves one physics slider to a new value from its range (extremes often).
fn retune(world: &mut World, rng: &mut ChaCha8Rng) {
    match rng.random_range(0..5) {
        0 => {
            world.resource_mut::<SimParams>().restitution = extreme(rng, &RESTITUTION_RANGE, false)
        }
        1 => world.resource_mut::<SimParams>().gravity.y = extreme(rng, &GRAVITY_SLIDER, false),
        2 => {
            world.resource_mut::<RunControl>().time_scale = extreme(rng, &TIME_SCALE_SLIDER, false)
        }
        3 => {
            world.resource_mut::<SimParams>().linear_damping = extreme(rng, &DAMPING_SLIDER, false)
        }
        _ => world.resource_mut::<Solver>().collisions = CollisionMode::ALL[rng.random_range(0..2)],
    }
}

/// Soaks scenes `first_seed..first_seed + scenes`, printing a line for each; returns how many
/// failed.
pub fn soak(first_seed: u64, scenes: u64, steps: u64, max_balls: usize) -> u64 {
    let mut failed = 0;
    for seed in first_seed..first_seed.saturating_add(scenes) {
        let mut soak = SoakScene::draw(seed, max_balls);
        let started = Instant::now();
        let (outcome, description) = match soak.build() {
            Ok(setup) => (soak_scene(&soak, &setup, steps), soak.describe()),
            Err(error) => (
                SoakOutcome {
                    steps: 0,
                    balls: 0,
                    failure: Some(format!("the scene did not build: {error}")),
                },
                soak.describe(),
            ),
        };
        let seconds = started.elapsed().as_secs_f64();
        match &outcome.failure {
            None => println!(
                "ok    {description}: {} steps in {seconds:.1} s",
                outcome.steps
            ),
            Some(failure) => {
                failed += 1;
                println!("FAIL  {description}: {failure}");
            }
        }
    }
    failed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> SimParams {
        SimParams {
            arena_size: DVec2::new(100.0, 50.0),
            ..default()
        }
    }

    #[test]
    fn the_step_check_catches_each_kind_of_failure() {
        let start = StepCheck {
            balls: 2,
            kinetic_energy: 10.0,
        };
        let ball = |x: f64, vx: f64| (DVec2::new(x, 0.0), DVec2::new(vx, 0.0), 5.0);
        // Mass 5 (radius model): energies 2.5 vx^2 summed.
        let fine = start.check(&[ball(0.0, 1.0), ball(20.0, 1.0)], &params(), true);
        assert_eq!(fine.unwrap().kinetic_energy, 5.0);
        let error =
            |balls: &[(DVec2, DVec2, f64)], kept| start.check(balls, &params(), kept).unwrap_err();
        assert!(error(&[ball(0.0, 1.0)], true).contains("1 balls, 2 before"));
        assert!(error(&[ball(f64::NAN, 1.0), ball(0.0, 0.0)], true).contains("ball 0"));
        assert!(error(&[ball(0.0, 0.0), ball(45.1, 0.0)], true).contains("ball 1 at"));
        assert!(error(&[ball(0.0, 2.0), ball(0.0, 1.0)], true).contains("grew"));
        // Without the energy check the same state passes; a minimised arena checks no walls.
        assert!(
            start
                .check(&[ball(0.0, 2.0), ball(0.0, 1.0)], &params(), false)
                .is_ok()
        );
        let minimised = SimParams {
            arena_size: DVec2::ZERO,
            ..params()
        };
        assert!(
            start
                .check(&[ball(0.0, 0.0), ball(45.1, 0.0)], &minimised, true)
                .is_ok()
        );
    }

    #[test]
    fn drawn_scenes_cover_the_extremes_and_build() {
        let scenes: Vec<SoakScene> = (0..200).map(|seed| SoakScene::draw(seed, 300)).collect();
        let restitutions: Vec<f64> = scenes.iter().map(|s| s.scene.restitution).collect();
        assert!(restitutions.contains(&0.0) && restitutions.contains(&1.0));
        let radii = scenes.iter().map(|s| s.scene.generate.unwrap().radius);
        assert!(radii.clone().any(|r| r.0 == *RADIUS_SLIDER.start()));
        assert!(radii.clone().any(|r| r.1 == *RADIUS_SLIDER.end()));
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

    #[test]
    fn a_short_soak_of_a_few_scenes_passes() {
        for seed in 0..4 {
            let mut soak = SoakScene::draw(seed, 50);
            let setup = soak.build().unwrap();
            let outcome = soak_scene(&soak, &setup, 300);
            assert_eq!(outcome.failure, None, "{}", soak.describe());
            assert_eq!(outcome.steps, 300);
        }
    }
}
