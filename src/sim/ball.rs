//! The ball components: the simulation's state, one entity per ball.
//!
//! Positions and velocities are `f64`: the collision maths (and the continuous mode's time of
//! impact) keep energy to 1e-6 only with that precision. Rendering converts to `f32`.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::collision::narrow_phase::Circle;

/// Marks a simulated ball; spawning it brings the state components along.
#[derive(Component, Debug, Default, Clone, Copy)]
#[require(BallId, Position, PreviousPosition, Velocity, Radius)]
pub struct Ball;

/// A ball's stable number, in spawn order: what reports and dumps call it.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct BallId(pub u32);

/// Centre of the ball, pixels, arena coordinates (origin at the arena's centre, y up).
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct Position(pub DVec2);

/// The centre at the start of the latest fixed step, for drawing between steps.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct PreviousPosition(pub DVec2);

/// Pixels per second.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct Velocity(pub DVec2);

/// Pixels. Mass follows from it through the [`MassModel`](super::MassModel).
#[derive(Component, Debug, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct Radius(pub f64);

impl Default for Radius {
    fn default() -> Self {
        Radius(10.0)
    }
}

/// One ball's state as plain values: what scene files describe and dumps record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallState {
    pub position: DVec2,
    pub velocity: DVec2,
    pub radius: f64,
}

/// Hands out [`BallId`]s in spawn order.
#[derive(Resource, Debug, Default)]
pub struct NextBallId(pub u32);

impl NextBallId {
    pub fn take(&mut self) -> BallId {
        let id = BallId(self.0);
        self.0 += 1;
        id
    }
}

/// The components that make `state` a simulated ball with number `id`.
pub fn ball_bundle(
    id: BallId,
    state: BallState,
) -> (Ball, BallId, Position, PreviousPosition, Velocity, Radius) {
    (
        Ball,
        id,
        Position(state.position),
        PreviousPosition(state.position),
        Velocity(state.velocity),
        Radius(state.radius),
    )
}

/// Every ball after this step's movement, in query order, in contiguous arrays. The movement
/// stage writes it as it moves the balls, the collision stage searches it and the response
/// works on it by index before writing the balls it changed back to their components.
#[derive(Resource, Debug, Default)]
pub struct BallSnapshot {
    pub entities: Vec<Entity>,
    pub circles: Vec<Circle>,
    /// Pixels per second.
    pub velocities: Vec<DVec2>,
}
