//! [`SimParams`]: everything about the simulation that a scene file, the command line or the
//! panel may tune, in one resource, with the bounds every tuner clamps or validates against.
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
/// Most balls a scene may hold (bounds memory: about 200 bytes a ball in the simulation).
pub const MAX_BALLS: usize = 1_000_000;

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

/// How the collision stage finds candidate pairs.
#[derive(Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum BroadPhase {
    /// A uniform grid rebuilt every step, cells about the largest diameter: O(N).
    #[default]
    Grid,
    /// Every pair: O(N^2). The reference the grid is tested against.
    AllPairs,
}

/// How a step finds and treats collisions.
#[derive(Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CollisionMode {
    /// Each step is a timeline: every impact (ball or wall) is found at its exact time of
    /// impact and handled in time order, so nothing tunnels or overlaps and, with restitution
    /// 1, energy is kept. The default: the toy's flings reach several diameters a step.
    #[default]
    Continuous,
    /// The tutorial's method: move every ball, find the pairs that overlap, exchange momentum
    /// and push them apart. Fast balls can pass through each other.
    Discrete,
}

impl CollisionMode {
    pub const ALL: [CollisionMode; 2] = [CollisionMode::Continuous, CollisionMode::Discrete];
}

/// The simulation's tunables.
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
    /// Simulated seconds per fixed step = fixed timestep x `time_scale`.
    pub time_scale: f64,
    /// While paused the fixed-step stages do not run.
    pub paused: bool,
    pub collisions: CollisionMode,
    pub broad_phase: BroadPhase,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            arena_size: DVec2::new(800.0, 600.0),
            gravity: DVec2::ZERO,
            restitution: 1.0,
            mass_model: MassModel::Radius,
            linear_damping: 0.0,
            time_scale: 1.0,
            paused: false,
            collisions: CollisionMode::Continuous,
            broad_phase: BroadPhase::Grid,
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
        let clamp = |value: f64, range: RangeInclusive<f64>, fallback: f64| {
            if value.is_finite() {
                value.clamp(*range.start(), *range.end())
            } else {
                fallback
            }
        };
        for axis in 0..2 {
            self.arena_size[axis] =
                clamp(self.arena_size[axis], 0.0..=*ARENA_SIDE_RANGE.end(), 0.0);
            self.gravity[axis] = clamp(self.gravity[axis], -MAX_GRAVITY..=MAX_GRAVITY, 0.0);
        }
        self.restitution = clamp(self.restitution, RESTITUTION_RANGE, defaults.restitution);
        self.linear_damping = clamp(self.linear_damping, DAMPING_RANGE, defaults.linear_damping);
        self.time_scale = clamp(self.time_scale, TIME_SCALE_RANGE, defaults.time_scale);
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
            time_scale: -1.0,
            ..default()
        };
        params.clamp_to_limits();
        assert_eq!(params.arena_size, DVec2::ZERO);
        assert_eq!(params.gravity, DVec2::new(MAX_GRAVITY, 0.0));
        assert_eq!(params.restitution, 1.0);
        assert_eq!(params.linear_damping, 0.0);
        assert_eq!(params.time_scale, 0.0);
    }
}
