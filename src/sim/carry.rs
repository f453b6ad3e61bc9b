//! The player's hand: a carried ball follows the pointer through a bounded spring. Running,
//! [`steer_carried`] (in the [`SimSchedule`](super::SimSchedule), before the movement stage)
//! gives it each step the velocity that closes a fixed fraction of its gap to the pointer,
//! never faster than [`MAX_CARRY_SPEED`] (in the discrete mode, which does not sweep paths,
//! never further than [`DISCRETE_CARRY_REACH`] of its radius a step), so it moves through the
//! stages like any ball: it pushes the balls it meets, bounces off walls and never tunnels.
//! Paused, the [`Intent::Carry`](super::Intent) moves it along the straight path to the
//! pointer and stops it at the first ball or wall on the way ([`paused_carry_stop`]), so it
//! never passes through one either.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::aim::{AimTarget, predict_first_hit, time_to_wall};
use super::ball::{Position, Radius, Rest, RestState, Velocity};
use super::clock::SimClock;
use super::geometry::Circle;
use super::params::{CollisionMode, Solver};
use super::resting::RestingState;

/// The share of its gap to the pointer a carried ball closes per second: a quarter per step
/// at 60 steps a second, never more than all of it in one step.
pub const CARRY_RATE: f64 = 15.0;
/// The fastest a carried ball moves towards the pointer, pixels per second.
pub const MAX_CARRY_SPEED: f64 = 2_000.0;

/// In the discrete mode a carried ball moves at most this fraction of its radius a step:
/// an overlap found after the move is then shallower than half the pair's radii, and the
/// separation pushes it back the way it came, never through.
pub const DISCRETE_CARRY_REACH: f64 = 0.5;

/// A ball the player holds, heading for `target` (arena pixels).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Carried {
    pub target: DVec2,
}

/// The velocity that takes a ball at `from` towards `target` in a step of `dt` seconds: the
/// gap times [`CARRY_RATE`] (at most the whole gap in the step), at most [`MAX_CARRY_SPEED`].
pub fn carry_velocity(from: DVec2, target: DVec2, dt: f64) -> DVec2 {
    let rate = if dt > 0.0 {
        CARRY_RATE.min(1.0 / dt)
    } else {
        CARRY_RATE
    };
    ((target - from) * rate).clamp_length_max(MAX_CARRY_SPEED)
}

/// Each step, every carried ball gets its spring's velocity; a sleeping one wakes with its
/// island. A carried ball that rests stays in the resting solver, which moves it at that
/// velocity and pushes the resting balls around it out of its way (a flying one would only
/// be stopped against them).
pub fn steer_carried(
    clock: Res<SimClock>,
    solver: Res<Solver>,
    mut balls: Query<(&Carried, &Position, &Radius, &mut Velocity, &mut Rest)>,
    mut resting: ResMut<RestingState>,
) {
    for (carried, position, radius, mut velocity, mut rest) in &mut balls {
        velocity.0 = carry_velocity(position.0, carried.target, clock.dt);
        if solver.collisions == CollisionMode::Discrete && clock.dt > 0.0 {
            let reach = DISCRETE_CARRY_REACH * radius.0 / clock.dt;
            velocity.0 = velocity.0.clamp_length_max(reach);
        }
        wake_if_asleep(&mut rest, &mut resting);
    }
}

/// Wakes a sleeping ball and its island (a resting or flying one stays as it is).
pub fn wake_if_asleep(rest: &mut Rest, resting: &mut RestingState) {
    if rest.is_asleep() {
        set_free(rest, resting);
    }
}

/// Sets a ball flying; if it slept, its island wakes at the next step.
pub fn set_free(rest: &mut Rest, resting: &mut RestingState) {
    if let RestState::Asleep { island } = std::mem::take(rest).state {
        resting.wake_requests.push(island);
    }
}

/// Where a ball `moving` from its centre straight to `target` stops while the simulation is
/// paused: at `target`, or touching the first of `others` or the first wall of the arena
/// `[-half, half]` on the way.
pub fn paused_carry_stop(
    moving: Circle,
    target: DVec2,
    others: impl IntoIterator<Item = Circle>,
    half: DVec2,
) -> DVec2 {
    let path = target - moving.center;
    let still = others.into_iter().map(|circle| AimTarget {
        id: (),
        circle,
        velocity: DVec2::ZERO,
        inverse_mass: 1.0,
    });
    let to_ball = predict_first_hit(moving, path, 1.0, still, 1.0, 1.0).map_or(1.0, |hit| hit.time);
    let to_wall = time_to_wall(moving.center, path, moving.radius, half);
    moving.center + path * to_ball.min(to_wall).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spring_closes_a_share_of_the_gap_and_is_bounded() {
        let v = carry_velocity(DVec2::ZERO, DVec2::new(10.0, 0.0), 1.0 / 60.0);
        assert_eq!(v, DVec2::new(150.0, 0.0));
        // Never past the target in one step, however long the step.
        let v = carry_velocity(DVec2::ZERO, DVec2::new(10.0, 0.0), 0.5);
        assert_eq!(v, DVec2::new(20.0, 0.0));
        let far = carry_velocity(DVec2::ZERO, DVec2::new(0.0, -1e6), 1.0 / 60.0);
        assert!((far.length() - MAX_CARRY_SPEED).abs() < 1e-9 && far.y < 0.0);
    }

    #[test]
    fn a_paused_carry_stops_at_the_first_ball_or_wall_on_the_way() {
        let half = DVec2::splat(100.0);
        let moving = Circle::new(DVec2::ZERO, 10.0);
        let blocker = Circle::new(DVec2::new(50.0, 0.0), 10.0);
        // Through a ball: stopped touching it.
        let stop = paused_carry_stop(moving, DVec2::new(80.0, 0.0), [blocker], half);
        assert!((stop - DVec2::new(30.0, 0.0)).length() < 1e-9, "{stop}");
        // Past a wall: stopped touching it.
        let stop = paused_carry_stop(moving, DVec2::new(0.0, 500.0), [blocker], half);
        assert!((stop - DVec2::new(0.0, 90.0)).length() < 1e-9, "{stop}");
        // A free path: at the target.
        let stop = paused_carry_stop(moving, DVec2::new(-40.0, 20.0), [blocker], half);
        assert_eq!(stop, DVec2::new(-40.0, 20.0));
    }
}
