//! Stage 1, movement: integrate every ball's velocity and position over the step, then keep it
//! in the arena by bouncing it off the walls.
//!
//! Runs in [`SimSystems::Movement`](super::SimSystems::Movement). The response stage applies
//! the same [`contain_in_arena`] to the balls it separated, since that can push one into a wall.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{Ball, BallSnapshot, Position, PreviousPosition, Radius, Velocity};
use super::collision::narrow_phase::Circle;
use super::messages::{Wall, WallCollision};
use super::params::{CollisionMode, SimParams};
use super::stats::SimStats;
use super::{SimSystems, step_seconds};

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<BallSnapshot>()
        .add_systems(FixedUpdate, move_balls.in_set(SimSystems::Movement));
}

/// A wall hit as plain values, before it becomes a [`WallCollision`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallHit {
    pub wall: Wall,
    /// Speed into the wall before the hit, pixels per second (positive).
    pub normal_speed: f64,
}

/// The outcome of [`contain_in_arena`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contained {
    pub position: DVec2,
    pub velocity: DVec2,
    /// At most one hit per axis (a corner gives two).
    pub hits: [Option<WallHit>; 2],
}

/// One step's motion: semi-implicit Euler with gravity and exponential damping over `dt`
/// seconds. The constants are worked out once per step, not once per ball.
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

    /// The velocity at the end of the step: gravity first, then damping.
    #[inline]
    pub fn velocity(&self, velocity: DVec2) -> DVec2 {
        (velocity + self.gravity_gain) * self.decay
    }

    /// Position and velocity at the end of the step, moving at the new velocity.
    #[inline]
    pub fn integrate(&self, position: DVec2, velocity: DVec2) -> (DVec2, DVec2) {
        let velocity = self.velocity(velocity);
        (position + velocity * self.dt, velocity)
    }
}

/// Puts a ball whose circle crosses a wall of the arena `[-half, half]` back inside.
///
/// A ball moving into the wall is mirrored back by the restitution-scaled overshoot and its
/// normal velocity reflected and scaled by `restitution`; one already moving away (pushed out
/// by a neighbour) is only moved back to the wall. A ball wider than the arena is centred on
/// that axis and stopped along it.
pub fn contain_in_arena(
    mut position: DVec2,
    mut velocity: DVec2,
    radius: f64,
    half: DVec2,
    restitution: f64,
) -> Contained {
    let mut hits = [None, None];
    for (axis, (low_wall, high_wall)) in [(Wall::Left, Wall::Right), (Wall::Bottom, Wall::Top)]
        .into_iter()
        .enumerate()
    {
        let limit = half[axis] - radius;
        if limit <= 0.0 {
            position[axis] = 0.0;
            velocity[axis] = 0.0;
            continue;
        }
        for (side, wall) in [(1.0, high_wall), (-1.0, low_wall)] {
            let overshoot = side * position[axis] - limit;
            if overshoot <= 0.0 {
                continue;
            }
            let speed_into_wall = side * velocity[axis];
            if speed_into_wall > 0.0 {
                position[axis] = side * (limit - restitution * overshoot);
                velocity[axis] = -side * restitution * speed_into_wall;
                hits[axis] = Some(WallHit {
                    wall,
                    normal_speed: speed_into_wall,
                });
            }
            position[axis] = position[axis].clamp(-limit, limit);
        }
    }
    Contained {
        position,
        velocity,
        hits,
    }
}

/// Where a ball of `radius` at `position` touches `wall` of the arena `[-half, half]`.
pub fn wall_contact_point(wall: Wall, position: DVec2, half: DVec2) -> DVec2 {
    match wall {
        Wall::Left => DVec2::new(-half.x, position.y),
        Wall::Right => DVec2::new(half.x, position.y),
        Wall::Bottom => DVec2::new(position.x, -half.y),
        Wall::Top => DVec2::new(position.x, half.y),
    }
}

/// Remembers where each ball was (for drawing between steps), integrates it, keeps it in the
/// arena and records it in the [`BallSnapshot`]: one pass over the balls. In continuous mode
/// only the velocity changes here; the response stage's timeline moves the balls.
fn move_balls(
    time: Res<Time>,
    params: Res<SimParams>,
    mut balls: Query<
        (
            Entity,
            &mut Position,
            &mut PreviousPosition,
            &mut Velocity,
            &Radius,
        ),
        With<Ball>,
    >,
    stats: Res<SimStats>,
    mut wall_hits: MessageWriter<WallCollision>,
    mut snapshot: ResMut<BallSnapshot>,
) {
    let BallSnapshot {
        entities,
        circles,
        velocities,
    } = &mut *snapshot;
    entities.clear();
    circles.clear();
    velocities.clear();
    let motion = Motion::new(
        params.gravity,
        params.linear_damping,
        step_seconds(&time, &params),
    );
    let half = params.half_extents();
    let step_end = stats.sim_time + motion.dt;
    let continuous = params.collisions == CollisionMode::Continuous;
    for (ball, mut position, mut previous, mut velocity, radius) in &mut balls {
        previous.0 = position.0;
        if continuous {
            // The timeline moves the balls, impact by impact.
            velocity.0 = motion.velocity(velocity.0);
        } else {
            let (moved, new_velocity) = motion.integrate(position.0, velocity.0);
            let contained =
                contain_in_arena(moved, new_velocity, radius.0, half, params.restitution);
            (position.0, velocity.0) = (contained.position, contained.velocity);
            if contained.hits != [None, None] {
                wall_hits.write_batch(wall_collisions(
                    ball, &contained, radius.0, &params, step_end,
                ));
            }
        }
        entities.push(ball);
        circles.push(Circle::new(position.0, radius.0));
        velocities.push(velocity.0);
    }
}

/// The impulse a wall gives a ball of `mass` arriving at `normal_speed` with restitution
/// `restitution`: its normal momentum reversed and scaled, `m (1 + e) v_n`.
#[inline]
pub fn wall_impulse(mass: f64, restitution: f64, normal_speed: f64) -> f64 {
    mass * (1.0 + restitution) * normal_speed
}

/// The [`WallCollision`]s of a containment: one per wall hit.
pub fn wall_collisions(
    ball: Entity,
    contained: &Contained,
    radius: f64,
    params: &SimParams,
    time: f64,
) -> impl Iterator<Item = WallCollision> {
    let (half, mass, restitution) = (
        params.half_extents(),
        params.mass_model.mass(radius),
        params.restitution,
    );
    let position = contained.position;
    contained
        .hits
        .into_iter()
        .flatten()
        .map(move |hit| WallCollision {
            ball,
            wall: hit.wall,
            time,
            point: wall_contact_point(hit.wall, position, half),
            impulse: wall_impulse(mass, restitution, hit.normal_speed),
            normal_speed: hit.normal_speed,
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HALF: DVec2 = DVec2::new(100.0, 50.0);

    #[test]
    fn integration_applies_gravity_before_moving() {
        let (p, v) = Motion::new(DVec2::new(0.0, -10.0), 0.0, 0.5)
            .integrate(DVec2::ZERO, DVec2::new(10.0, 0.0));
        assert_eq!(v, DVec2::new(10.0, -5.0));
        assert_eq!(p, DVec2::new(5.0, -2.5));
    }

    #[test]
    fn damping_decays_velocity_exponentially() {
        let v = Motion::new(DVec2::ZERO, 2.0, 0.5).velocity(DVec2::new(8.0, 0.0));
        assert!((v.x - 8.0 * (-1.0f64).exp()).abs() < 1e-12);
    }

    #[test]
    fn ball_past_the_right_wall_is_mirrored_back_and_reflected() {
        let c = contain_in_arena(
            DVec2::new(95.0, 0.0),
            DVec2::new(30.0, 7.0),
            10.0,
            HALF,
            1.0,
        );
        assert_eq!(c.position, DVec2::new(85.0, 0.0));
        assert_eq!(c.velocity, DVec2::new(-30.0, 7.0));
        assert_eq!(
            c.hits,
            [
                Some(WallHit {
                    wall: Wall::Right,
                    normal_speed: 30.0
                }),
                None
            ]
        );
    }

    #[test]
    fn restitution_scales_the_normal_velocity_only() {
        let c = contain_in_arena(
            DVec2::new(0.0, -45.0),
            DVec2::new(3.0, -20.0),
            10.0,
            HALF,
            0.5,
        );
        assert_eq!(c.velocity, DVec2::new(3.0, 10.0));
        assert_eq!(c.position, DVec2::new(0.0, -37.5));
        assert_eq!(c.hits[1].unwrap().wall, Wall::Bottom);
    }

    #[test]
    fn a_corner_gives_two_hits() {
        let c = contain_in_arena(
            DVec2::new(-99.0, 49.0),
            DVec2::new(-1.0, 1.0),
            2.0,
            HALF,
            1.0,
        );
        assert_eq!(c.hits[0].unwrap().wall, Wall::Left);
        assert_eq!(c.hits[1].unwrap().wall, Wall::Top);
        assert_eq!(c.velocity, DVec2::new(1.0, -1.0));
    }

    #[test]
    fn ball_moving_away_is_only_put_back() {
        let c = contain_in_arena(
            DVec2::new(93.0, 0.0),
            DVec2::new(-5.0, 0.0),
            10.0,
            HALF,
            1.0,
        );
        assert_eq!(c.position, DVec2::new(90.0, 0.0));
        assert_eq!(c.velocity, DVec2::new(-5.0, 0.0));
        assert_eq!(c.hits, [None, None]);
    }

    #[test]
    fn huge_overshoot_still_ends_inside() {
        let c = contain_in_arena(
            DVec2::new(5000.0, 0.0),
            DVec2::new(1e5, 0.0),
            10.0,
            HALF,
            1.0,
        );
        assert!(c.position.x.abs() <= 90.0);
    }

    #[test]
    fn ball_wider_than_the_arena_is_centred_without_nan() {
        let c = contain_in_arena(DVec2::new(3.0, 3.0), DVec2::new(5.0, 5.0), 60.0, HALF, 1.0);
        assert_eq!(c.position.y, 0.0);
        assert_eq!(c.velocity.y, 0.0);
        assert!(c.position.is_finite() && c.velocity.is_finite());
        let c = contain_in_arena(
            DVec2::new(3.0, 3.0),
            DVec2::new(5.0, 5.0),
            1.0,
            DVec2::ZERO,
            1.0,
        );
        assert_eq!((c.position, c.velocity), (DVec2::ZERO, DVec2::ZERO));
    }
}
