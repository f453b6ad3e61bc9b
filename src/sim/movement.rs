//! Stage 1, movement: integrate every ball's velocity over the step and copy the balls into
//! the contiguous [`BallSnapshot`] the later stages work on; remember where each ball was, for
//! drawing between steps. One system per mode, one pass over the balls each:
//!
//! - discrete ([`move_and_contain`]): velocity and position (semi-implicit Euler), then the
//!   walls: a ball past a wall is mirrored back inside and bounced;
//! - continuous ([`damp_velocities`]): the damping only; each ball's path over the step
//!   is a parabola under gravity that the timeline follows impact by impact.
//!
//! Damping is one factor a step in both; [`Motion`] says why only the continuous mode's
//! flight is exact. Balls that rest or sleep ([`Rest::is_held`]) are not moved here: the
//! resting stage moves the resting ones, nothing the sleeping ones. A ball meeting a wall
//! slower than the resting speed stops against it instead of bouncing.
//!
//! Runs in [`SimSystems::Movement`](super::SimSystems::Movement).

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{Ball, BallSnapshot, Position, PreviousPosition, Radius, Rest, Velocity};
use super::clock::SimClock;
use super::geometry::Circle;
use super::geometry::wall::contain_at_rest;
use super::params::SimParams;
use super::report::{Hit, StepLog};
use super::resting::rest_speed;

/// The balls as the movement stage sees them.
type MovingBalls<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static mut Position,
        Option<&'static mut PreviousPosition>,
        &'static mut Velocity,
        &'static Radius,
        &'static Rest,
    ),
    With<Ball>,
>;

/// One step's motion, with the constants worked out once per step, not once per ball.
///
/// - The continuous mode only [`damped`](Self::damped)s here, once at the start of the step;
///   its timeline then flies each ball along its exact parabola.
/// - The discrete mode [`integrate`](Self::integrate)s with semi-implicit Euler: gravity, then
///   damping, then the position at the new velocity. Exact flight here would pair badly with
///   the discrete wall containment, which mirrors a ball back by its overshoot at the
///   velocity it has *past* the wall: it gained energy at every bounce (a ball bouncing
///   100 s under gravity ended with 6 times its energy), where semi-implicit Euler's own
///   drift and the mirror nearly cancel (−1.4% over the same 100 s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Velocity gained from gravity over the step.
    gravity_gain: DVec2,
    /// Factor the velocity keeps after damping: `exp(-damping * dt)`.
    decay: f64,
    /// Seconds.
    pub dt: f64,
}

impl Motion {
    pub fn new(gravity: DVec2, damping: f64, dt: f64) -> Self {
        Self {
            gravity_gain: gravity * dt,
            decay: (-damping * dt).exp(),
            dt,
        }
    }

    /// The velocity the continuous mode's flight starts the step with: damped.
    #[inline]
    pub fn damped(&self, velocity: DVec2) -> DVec2 {
        velocity * self.decay
    }

    /// The discrete mode's position and velocity at the end of the step: gravity first, then
    /// damping, then the move at the new velocity.
    #[inline]
    pub fn integrate(&self, position: DVec2, velocity: DVec2) -> (DVec2, DVec2) {
        let velocity = (velocity + self.gravity_gain) * self.decay;
        (position + velocity * self.dt, velocity)
    }
}

/// Discrete mode: moves every ball over the step and contains it in the arena, recording its
/// wall hits; fills the snapshot.
pub fn move_and_contain(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    mut balls: MovingBalls,
    mut snapshot: ResMut<BallSnapshot>,
    mut log: ResMut<StepLog>,
) {
    let motion = Motion::new(params.gravity, params.linear_damping, clock.dt);
    let half = params.half_extents();
    let rest_speed = rest_speed(&params, clock.dt);
    let (snapshot, log) = (&mut *snapshot, &mut *log);
    snapshot.clear();
    for (ball, mut position, mut previous, mut velocity, radius, rest) in &mut balls {
        if let Some(previous) = previous.as_mut() {
            previous.0 = position.0;
        }
        let held = rest.is_held();
        if !held {
            let (moved, new_velocity) = motion.integrate(position.0, velocity.0);
            let contained = contain_at_rest(
                moved,
                new_velocity,
                radius.0,
                half,
                params.restitution,
                rest_speed,
            );
            (position.0, velocity.0) = (contained.position, contained.velocity);
            if contained.hits != [None, None] {
                let mass = params.mass_model.mass(radius.0);
                log.resting_wall_impulse += contained.resting_impulse(mass);
                log.hits.extend(Hit::walls_of(
                    snapshot.entities.len() as u32,
                    &contained,
                    motion.dt,
                    half,
                    params.restitution,
                    mass,
                ));
            }
        }
        snapshot.push(ball, Circle::new(position.0, radius.0), velocity.0, held);
    }
}

/// Continuous mode: damps every ball's velocity (the timeline flies the balls along their
/// parabolas, impact by impact); fills the snapshot.
pub fn damp_velocities(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    mut balls: MovingBalls,
    mut snapshot: ResMut<BallSnapshot>,
) {
    let motion = Motion::new(params.gravity, params.linear_damping, clock.dt);
    let snapshot = &mut *snapshot;
    snapshot.clear();
    for (ball, position, mut previous, mut velocity, radius, rest) in &mut balls {
        if let Some(previous) = previous.as_mut() {
            previous.0 = position.0;
        }
        let held = rest.is_held();
        if !held {
            velocity.0 = motion.damped(velocity.0);
        }
        snapshot.push(ball, Circle::new(position.0, radius.0), velocity.0, held);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integration_applies_gravity_before_moving() {
        let (p, v) = Motion::new(DVec2::new(0.0, -10.0), 0.0, 0.5)
            .integrate(DVec2::ZERO, DVec2::new(10.0, 0.0));
        assert_eq!(v, DVec2::new(10.0, -5.0));
        assert_eq!(p, DVec2::new(5.0, -2.5));
    }

    #[test]
    fn damping_decays_velocity_exponentially() {
        let v = Motion::new(DVec2::ZERO, 2.0, 0.5).damped(DVec2::new(8.0, 0.0));
        assert!((v.x - 8.0 * (-1.0f64).exp()).abs() < 1e-12);
    }
}
