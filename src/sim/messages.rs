//! Outward notices from the simulation: one [`BallCollision`] per ball–ball hit and one
//! [`WallCollision`] per wall hit, written by the report stage at the end of each step, for
//! effects and tests. Nothing inside the simulation's own stages reads them.

use bevy::math::DVec2;
use bevy::prelude::*;

pub use super::geometry::Wall;

/// Two balls that were approaching along their line of centres and exchanged momentum.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct BallCollision {
    pub a: Entity,
    pub b: Entity,
    /// Simulated seconds since the scene was loaded: the exact moment of impact in continuous
    /// mode, the end of the step in discrete mode (which only sees the overlap afterwards).
    pub time: f64,
    /// Radius-weighted collision point, pixels: where the balls touch in continuous mode.
    pub point: DVec2,
    /// Unit vector from `a` towards `b`.
    pub normal: DVec2,
    /// Magnitude of the impulse along the normal, mass x pixels per second.
    pub impulse: f64,
    /// Speed at which the balls were closing along the normal, pixels per second.
    pub normal_speed: f64,
}

/// A ball that reached a wall while moving into it and bounced.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct WallCollision {
    pub ball: Entity,
    pub wall: Wall,
    /// Simulated seconds since the scene was loaded, as in [`BallCollision::time`].
    pub time: f64,
    /// Where the ball touched the wall, pixels.
    pub point: DVec2,
    /// Magnitude of the wall's impulse on the ball, mass x pixels per second.
    pub impulse: f64,
    /// Speed into the wall before the hit, pixels per second.
    pub normal_speed: f64,
}
