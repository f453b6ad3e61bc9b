//! Stage 1, movement: copy the balls into the contiguous [`BallSnapshot`] the later stages
//! work on, remembering where each ball was, for drawing between steps; then integrate every
//! ball's velocity over the step there (the response writes the balls back). One system per
//! mode:
//!
//! - discrete ([`move_and_contain`]): velocity and position (semi-implicit Euler), then the
//!   walls: a ball past a wall is mirrored back inside and bounced;
//! - continuous ([`damp_velocities`]): the damping only; each ball's path over the step
//!   is a parabola under gravity that the timeline follows impact by impact.
//!
//! Damping is one factor a step in both; [`Motion`] says why only the continuous mode's
//! flight is exact. Balls that rest or sleep ([`Rest::is_held`](super::ball::Rest::is_held))
//! are not moved here: the resting stage moves the resting ones, nothing the sleeping ones. A
//! ball meeting a wall slower than the resting speed stops against it instead of bouncing.
//!
//! Both run in pieces on the compute pool for many balls ([`parallel`](super::parallel)), each
//! piece moved as soon as it is copied in. [`Arena`] holds the walls as the discrete mode
//! meets them; its response uses it again after pushing balls apart.
//!
//! Runs in [`SimSystems::Movement`](super::SimSystems::Movement).

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{Ball, BallSnapshot, Position, PreviousPosition, SnapshotBalls};
use super::clock::SimClock;
use super::geometry::Circle;
use super::geometry::contain::{Contained, contain_in_place, contain_piece};
use super::params::{MassModel, SimParams};
use super::report::{StepLog, record_walls_met};
use super::resting::rest_speed;

/// Where the drawn balls were (the headless balls have no `PreviousPosition`).
type DrawnBalls<'w, 's> =
    Query<'w, 's, (&'static Position, &'static mut PreviousPosition), With<Ball>>;

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

/// Discrete mode: moves every ball over the step and contains it in the arena, in the
/// snapshot, each piece of balls as soon as it is copied in; records the wall hits. The balls
/// are written back by the response.
pub fn move_and_contain(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    balls: SnapshotBalls,
    mut drawn: DrawnBalls,
    mut snapshot: ResMut<BallSnapshot>,
    mut log: ResMut<StepLog>,
) {
    let motion = Motion::new(params.gravity, params.linear_damping, clock.dt);
    let arena = Arena::new(&params, clock.dt);
    remember_drawn(&mut drawn);
    let met = snapshot.fill_then(&balls, |first, (circles, velocities, held)| {
        let free = |index: usize| !held[index - first];
        arena.contain_piece(first, (circles, velocities), free, Some(motion))
    });
    arena.record(met.into_iter().flatten(), &snapshot.circles, &mut log);
}

/// The arena's walls as the discrete mode meets them at the end of a step.
#[derive(Clone, Copy, Debug)]
pub struct Arena {
    half: DVec2,
    restitution: f64,
    /// Pixels per second: slower, a ball stops against a wall.
    pub rest_speed: f64,
    mass_model: MassModel,
    /// When the hits are reported to have happened, seconds into the step.
    step_end: f64,
}

impl Arena {
    pub fn new(params: &SimParams, dt: f64) -> Self {
        Self {
            half: params.half_extents(),
            restitution: params.restitution,
            rest_speed: rest_speed(params, dt),
            mass_model: params.mass_model,
            step_end: dt,
        }
    }

    /// Contains each ball of a piece (the first of which has index `first`) that
    /// `chosen(index)` picks in the arena, after moving it by `motion` if given. Returns the
    /// balls that met a wall, for [`record`](Self::record).
    pub fn contain_piece(
        &self,
        first: usize,
        balls: (&mut [Circle], &mut [DVec2]),
        chosen: impl Fn(usize) -> bool,
        motion: Option<Motion>,
    ) -> Vec<(u32, Contained)> {
        let arena = (self.half, self.restitution, self.rest_speed);
        match motion {
            Some(motion) => {
                let moved = |center, velocity| motion.integrate(center, velocity);
                contain_piece(first, balls, &chosen, &moved, arena)
            }
            None => contain_in_place(first, balls, &chosen, arena),
        }
    }

    /// Records in `log` the wall hits and resting impulses of the balls in `met`, in the
    /// balls' order, as if found one by one.
    pub fn record(
        &self,
        met: impl IntoIterator<Item = (u32, Contained)>,
        circles: &[Circle],
        log: &mut StepLog,
    ) {
        let StepLog {
            hits,
            resting_wall_impulse,
            ..
        } = log;
        let recording = (self.half, self.restitution, self.mass_model, self.step_end);
        record_walls_met(met, circles, recording, resting_wall_impulse, |hit| {
            hits.push(hit)
        });
    }
}

/// Continuous mode: damps every ball's velocity in the snapshot, each piece as soon as it is
/// copied in (the timeline flies the balls along their parabolas, impact by impact, and
/// writes them back).
pub fn damp_velocities(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    balls: SnapshotBalls,
    mut drawn: DrawnBalls,
    mut snapshot: ResMut<BallSnapshot>,
) {
    let motion = Motion::new(params.gravity, params.linear_damping, clock.dt);
    remember_drawn(&mut drawn);
    snapshot.fill_then(&balls, |_, (_, velocities, held)| {
        for (velocity, &held) in velocities.iter_mut().zip(held.iter()) {
            if !held {
                *velocity = motion.damped(*velocity);
            }
        }
    });
}

/// Remembers where each drawn ball was, for drawing between steps.
fn remember_drawn(drawn: &mut DrawnBalls) {
    for (position, mut previous) in drawn {
        previous.0 = position.0;
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
