//! The simulation's parameters, by owner, with the ranges every tuner clamps or validates
//! against:
//!
//! - [`SimParams`]: the physics a scene sets (arena, gravity, restitution, mass model, damping);
//! - [`Solver`]: how a step is solved (collision mode, broad phase);
//! - [`RunControl`]: running it (pause, time scale, pending single steps).
//!
//! The accepted ranges (what a scene file or flag may say) and the panel's slider ranges
//! (what a player drags through, always within the accepted ones) live here, so nothing
//! headless imports the UI.
//!
//! Units throughout: pixels, seconds, and mass from the [`MassModel`].

use std::ops::RangeInclusive;

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// Arena sides accepted from any source, pixels. Zero is allowed at run time (a minimised
/// window) but never in a scene file.
pub const ARENA_SIDE_RANGE: RangeInclusive<f64> = 1.0..=1.0e6;
/// Ball radii accepted from any source, pixels.
pub const RADIUS_RANGE: RangeInclusive<f64> = 0.5..=1_000.0;
/// Largest speed accepted for a ball, pixels per second.
pub const MAX_SPEED: f64 = 1.0e6;
/// Largest gravity component, pixels per second squared.
pub const MAX_GRAVITY: f64 = 10_000.0;
/// Linear damping rate, per second.
pub const DAMPING_RANGE: RangeInclusive<f64> = 0.0..=100.0;
/// Simulated seconds per real second.
pub const TIME_SCALE_RANGE: RangeInclusive<f64> = 0.0..=10.0;
/// The coefficient of restitution: 0 perfectly inelastic, 1 perfectly elastic.
pub const RESTITUTION_RANGE: RangeInclusive<f64> = 0.0..=1.0;
/// Densest packing of equal discs in the plane, `pi / (2 sqrt 3)`; no scene can beat it.
pub const DENSEST_PACKING: f64 = 0.906_899_682;
/// Most balls a scene may hold (bounds memory: about 200 bytes a ball in the simulation).
pub const MAX_BALLS: usize = 1_000_000;

/// The ball-count slider's range.
pub const BALL_COUNT_SLIDER: RangeInclusive<usize> = 0..=100_000;
/// The radius sliders' range, pixels: the smallest is the smallest ball a player adds (a
/// click or the count slider), 6 px across, large enough to see and to click.
pub const RADIUS_SLIDER: RangeInclusive<f64> = 3.0..=200.0;
/// The arena sliders' range (each side), pixels.
pub const ARENA_SLIDER: RangeInclusive<f64> = 50.0..=100_000.0;
/// The speed sliders' range, pixels per second.
pub const SPEED_SLIDER: RangeInclusive<f64> = 0.0..=3_000.0;
/// The gravity sliders' range (each component), pixels per second squared.
pub const GRAVITY_SLIDER: RangeInclusive<f64> = -3_000.0..=3_000.0;
/// The time-scale slider's range.
pub const TIME_SCALE_SLIDER: RangeInclusive<f64> = 0.0..=10.0;
/// The fixed-step rate slider's range, steps per second.
pub const STEP_RATE_SLIDER: RangeInclusive<f64> = 10.0..=480.0;
/// The damping slider's range, per second.
pub const DAMPING_SLIDER: RangeInclusive<f64> = 0.0..=10.0;
/// Fastest fling of the mouse, pixels per second: within what the simulation accepts.
pub const MAX_FLING_SPEED: f64 = 5_000.0;
const _: () = assert!(MAX_FLING_SPEED <= MAX_SPEED);
/// Fixed steps per second unless the player sets another rate.
pub const DEFAULT_STEP_RATE: f64 = 60.0;

/// How a ball's mass follows from its radius.
#[derive(Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum MassModel {
    /// Mass equals the radius, as in the tutorial.
    #[default]
    Radius,
    /// Mass equals the disc's area, `pi * r^2`: uniform density.
    Area,
    /// Every ball has mass 1.
    Unit,
}

impl MassModel {
    pub const ALL: [MassModel; 3] = [MassModel::Radius, MassModel::Area, MassModel::Unit];

    /// The mass of a ball of `radius` pixels.
    #[inline]
    pub fn mass(self, radius: f64) -> f64 {
        match self {
            MassModel::Radius => radius,
            MassModel::Area => std::f64::consts::PI * radius * radius,
            MassModel::Unit => 1.0,
        }
    }

    /// `1 / mass`, what the collision response works with.
    #[inline]
    pub fn inverse_mass(self, radius: f64) -> f64 {
        1.0 / self.mass(radius)
    }
}

/// How the collision stage finds candidate pairs. Also a command-line value (`grid`,
/// `all-pairs`).
#[derive(
    Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum,
)]
pub enum BroadPhase {
    /// A uniform grid rebuilt every step, cells about the largest diameter: O(N).
    #[default]
    Grid,
    /// Every pair: O(N^2). The reference the grid is tested against.
    AllPairs,
}

/// How a step finds and treats collisions. Also a command-line value (`continuous`,
/// `discrete`).
#[derive(
    Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum,
)]
pub enum CollisionMode {
    /// Every impact at its exact time, in time order (the default).
    ///
    /// Each step is a timeline: every impact (ball or wall) is found at its exact time of
    /// impact and handled in time order, so nothing tunnels or overlaps and, with restitution
    /// 1, energy is kept. The default: the toy's flings reach several diameters a step.
    #[default]
    Continuous,
    /// The tutorial's method: move, find overlaps, respond, separate.
    ///
    /// Move every ball, find the pairs that overlap, exchange momentum and push them apart.
    /// Fast balls can pass through each other.
    Discrete,
}

impl CollisionMode {
    pub const ALL: [CollisionMode; 2] = [CollisionMode::Continuous, CollisionMode::Discrete];
}

/// The physics a scene sets: the arena and how balls move and bounce.
#[derive(Resource, Reflect, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource)]
pub struct SimParams {
    /// Width and height of the arena, pixels; the arena is centred on the origin, x right, y up.
    pub arena_size: DVec2,
    /// Pixels per second squared.
    pub gravity: DVec2,
    /// For ball–ball and ball–wall hits alike, in [0, 1].
    pub restitution: f64,
    pub mass_model: MassModel,
    /// Velocity decays as `exp(-linear_damping * t)`; per second.
    pub linear_damping: f64,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            arena_size: DVec2::new(800.0, 600.0),
            gravity: DVec2::ZERO,
            restitution: 1.0,
            mass_model: MassModel::Radius,
            linear_damping: 0.0,
        }
    }
}

impl SimParams {
    /// Half the arena size: a ball of radius `r` is inside when `|x| + r <= half.x` and
    /// `|y| + r <= half.y`.
    #[inline]
    pub fn half_extents(&self) -> DVec2 {
        self.arena_size * 0.5
    }

    /// Whether the arena has room for the simulation to run: both sides at least the smallest
    /// accepted side. A minimised window leaves it without; the stages then wait.
    #[inline]
    pub fn has_room(&self) -> bool {
        self.arena_size.min_element() >= *ARENA_SIDE_RANGE.start()
    }

    /// Brings every value into its accepted range, replacing non-finite ones with the default,
    /// so that no tuner can hand the simulation a NaN or an out-of-range value.
    pub fn clamp_to_limits(&mut self) {
        let defaults = SimParams::default();
        for axis in 0..2 {
            self.arena_size[axis] =
                clamp_finite(self.arena_size[axis], 0.0..=*ARENA_SIDE_RANGE.end(), 0.0);
            self.gravity[axis] = clamp_finite(self.gravity[axis], -MAX_GRAVITY..=MAX_GRAVITY, 0.0);
        }
        self.restitution = clamp_finite(self.restitution, RESTITUTION_RANGE, defaults.restitution);
        self.linear_damping =
            clamp_finite(self.linear_damping, DAMPING_RANGE, defaults.linear_damping);
    }
}

/// How a step is solved.
#[derive(Resource, Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[reflect(Resource)]
pub struct Solver {
    pub collisions: CollisionMode,
    /// Used by the discrete mode's detection; the continuous mode always uses the grid.
    pub broad_phase: BroadPhase,
}

/// Running the simulation: pause, speed and single steps. The toy's controls set it.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq)]
#[reflect(Resource)]
pub struct RunControl {
    /// While paused the fixed-step stages do not run (but for pending single steps).
    pub paused: bool,
    /// Simulated seconds per fixed step = fixed timestep x `time_scale`.
    pub time_scale: f64,
    /// Steps to run although paused: the panel's and the N key's single step.
    pub pending_steps: u32,
}

impl Default for RunControl {
    fn default() -> Self {
        Self {
            paused: false,
            time_scale: 1.0,
            pending_steps: 0,
        }
    }
}

impl RunControl {
    /// Whether a step runs now: not paused, or a single step is pending.
    pub fn wants_step(&self) -> bool {
        !self.paused || self.pending_steps > 0
    }

    /// Pauses and asks for one more step.
    pub fn step_once(&mut self) {
        self.paused = true;
        self.pending_steps += 1;
    }

    /// Brings the time scale into its accepted range (NaN to the default).
    pub fn clamp_to_limits(&mut self) {
        self.time_scale = clamp_finite(
            self.time_scale,
            TIME_SCALE_RANGE,
            RunControl::default().time_scale,
        );
    }
}

/// `value` clamped into `range`; `fallback` if it is not finite.
pub fn clamp_finite(value: f64, range: RangeInclusive<f64>, fallback: f64) -> f64 {
    if value.is_finite() {
        value.clamp(*range.start(), *range.end())
    } else {
        fallback
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mass_models_follow_the_radius() {
        assert_eq!(MassModel::Radius.mass(10.0), 10.0);
        assert!((MassModel::Area.mass(2.0) - 4.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(MassModel::Unit.mass(123.0), 1.0);
        assert_eq!(MassModel::Radius.inverse_mass(4.0), 0.25);
    }

    #[test]
    fn clamping_replaces_nan_and_bounds_every_value() {
        let mut params = SimParams {
            arena_size: DVec2::new(f64::NAN, -5.0),
            gravity: DVec2::new(1e9, f64::NEG_INFINITY),
            restitution: 3.0,
            linear_damping: f64::NAN,
            ..default()
        };
        params.clamp_to_limits();
        assert_eq!(params.arena_size, DVec2::ZERO);
        assert_eq!(params.gravity, DVec2::new(MAX_GRAVITY, 0.0));
        assert_eq!(params.restitution, 1.0);
        assert_eq!(params.linear_damping, 0.0);
        let mut run = RunControl {
            time_scale: -1.0,
            ..default()
        };
        run.clamp_to_limits();
        assert_eq!(run.time_scale, 0.0);
    }

    #[test]
    fn every_slider_lies_within_what_the_simulation_accepts() {
        let within = |inner: &RangeInclusive<f64>, outer: &RangeInclusive<f64>| {
            outer.contains(inner.start()) && outer.contains(inner.end())
        };
        assert!(within(&RADIUS_SLIDER, &RADIUS_RANGE));
        assert!(within(&SPEED_SLIDER, &(0.0..=MAX_SPEED)));
        assert!(within(&GRAVITY_SLIDER, &(-MAX_GRAVITY..=MAX_GRAVITY)));
        assert!(within(&TIME_SCALE_SLIDER, &TIME_SCALE_RANGE));
        assert!(within(&DAMPING_SLIDER, &DAMPING_RANGE));
        assert!(*STEP_RATE_SLIDER.start() > 0.0);
        assert!(*BALL_COUNT_SLIDER.end() <= MAX_BALLS);
    }
}
