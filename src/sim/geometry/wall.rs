//! The arena's walls: which wall a ball meets and when, and how it bounces. Pure functions over
//! plain values.
//!
//! The continuous mode finds each ball's exact moment at a wall ([`wall_time_of_impact`]) and
//! bounces it there ([`bounce_off_wall`]); the aiming guide uses the same time of impact. How a
//! ball that crossed a wall is put back, which the discrete mode does after moving every ball,
//! is `contain.rs`'s.

use bevy::math::DVec2;

use super::circle::{Circle, MIN_APPROACH_SPEED};
use super::flight::time_to_reach;
use super::impulse::wall_impulse;

/// The four sides of the arena.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Wall {
    Left,
    Right,
    Bottom,
    Top,
}

impl Wall {
    pub const ALL: [Wall; 4] = [Wall::Left, Wall::Right, Wall::Bottom, Wall::Top];

    /// The wall's outward normal (pointing out of the arena).
    pub fn outward_normal(self) -> DVec2 {
        match self {
            Wall::Left => DVec2::NEG_X,
            Wall::Right => DVec2::X,
            Wall::Bottom => DVec2::NEG_Y,
            Wall::Top => DVec2::Y,
        }
    }
}

/// A wall hit found by [`contain_in_arena`](super::contain::contain_in_arena).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallHit {
    pub wall: Wall,
    /// Speed into the wall before the hit, pixels per second (positive).
    pub normal_speed: f64,
    /// Slower than the resting speed: the ball stopped against the wall instead of bouncing.
    pub resting: bool,
}

/// Where a ball at `position` touches `wall` of the arena `[-half, half]`.
pub fn wall_contact_point(wall: Wall, position: DVec2, half: DVec2) -> DVec2 {
    match wall {
        Wall::Left => DVec2::new(-half.x, position.y),
        Wall::Right => DVec2::new(half.x, position.y),
        Wall::Bottom => DVec2::new(position.x, -half.y),
        Wall::Top => DVec2::new(position.x, half.y),
    }
}

/// Seconds until a ball at `position` moving at `velocity` under `gravity` touches a wall of
/// the arena `[-half, half]`, and which wall: zero if it already touches (or crosses) a wall
/// it moves into, or rests against one that gravity pushes it into. `None` if it reaches no
/// wall (slower than [`MIN_APPROACH_SPEED`] without gravity counts as not moving), or only
/// along axes where it is wider than the arena (containment centres those). Along an axis
/// with gravity the path is a parabola and the time the first root of a quadratic
/// ([`time_to_reach`]).
pub fn wall_time_of_impact(
    position: DVec2,
    velocity: DVec2,
    radius: f64,
    half: DVec2,
    gravity: DVec2,
) -> Option<(f64, Wall)> {
    let mut first: Option<(f64, Wall)> = None;
    for (axis, low_wall, high_wall) in [(0, Wall::Left, Wall::Right), (1, Wall::Bottom, Wall::Top)]
    {
        let limit = half[axis] - radius;
        if limit <= 0.0 {
            continue;
        }
        for (side, wall) in [(1.0, high_wall), (-1.0, low_wall)] {
            // Distance to the wall, speed and acceleration towards it.
            let gap = limit - side * position[axis];
            let reached = time_to_reach(
                gap,
                side * velocity[axis],
                side * gravity[axis],
                MIN_APPROACH_SPEED,
            );
            if let Some(time) = reached
                && first.is_none_or(|(earliest, _)| time < earliest)
            {
                first = Some((time, wall));
            }
        }
    }
    first
}

/// A ball's bounce off a wall: [`bounce_off_wall`]'s result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallBounce {
    /// The centre, set exactly against the wall.
    pub center: DVec2,
    pub point: DVec2,
    /// Magnitude of the wall's impulse, mass x pixels per second.
    pub impulse: f64,
    /// Speed into the wall before the bounce, pixels per second.
    pub normal_speed: f64,
}

/// Reflects a ball of `mass` that touches `wall` of the arena `[-half, half]` and moves into
/// it: the normal velocity is reversed and scaled by `restitution`. `None` (and no change) if
/// it moves away from the wall.
pub fn bounce_off_wall(
    circle: Circle,
    velocity: &mut DVec2,
    wall: Wall,
    half: DVec2,
    restitution: f64,
    mass: f64,
) -> Option<WallBounce> {
    let outward = wall.outward_normal();
    let normal_speed = velocity.dot(outward);
    if normal_speed <= 0.0 {
        return None;
    }
    *velocity -= outward * ((1.0 + restitution) * normal_speed);
    let axis = usize::from(outward.y != 0.0);
    let mut center = circle.center;
    center[axis] = outward[axis] * (half[axis] - circle.radius);
    Some(WallBounce {
        center,
        point: wall_contact_point(wall, center, half),
        impulse: wall_impulse(mass, restitution, normal_speed),
        normal_speed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const HALF: DVec2 = DVec2::new(100.0, 50.0);

    #[test]
    fn wall_time_is_the_gap_over_the_speed_toward_the_nearer_wall() {
        // 90 px to the right wall's limit at 30 px/s; 40 px to the top at 10 px/s.
        let (time, wall) =
            wall_time_of_impact(DVec2::ZERO, DVec2::new(30.0, 10.0), 10.0, HALF, DVec2::ZERO)
                .unwrap();
        assert_eq!((time, wall), (3.0, Wall::Right));
        let (time, wall) = wall_time_of_impact(
            DVec2::ZERO,
            DVec2::new(-1.0, -20.0),
            10.0,
            HALF,
            DVec2::ZERO,
        )
        .unwrap();
        assert_eq!((time, wall), (2.0, Wall::Bottom));
        // Already through a wall and still moving into it: now. Moving away: never.
        let past = DVec2::new(95.0, 0.0);
        assert_eq!(
            wall_time_of_impact(past, DVec2::X, 10.0, HALF, DVec2::ZERO),
            Some((0.0, Wall::Right))
        );
        assert_eq!(
            wall_time_of_impact(past, DVec2::NEG_X, 10.0, HALF, DVec2::ZERO).map(|h| h.1),
            Some(Wall::Left)
        );
        assert_eq!(
            wall_time_of_impact(DVec2::ZERO, DVec2::ZERO, 10.0, HALF, DVec2::ZERO),
            None
        );
        // Wider than the arena along y: only x counts.
        assert_eq!(
            wall_time_of_impact(DVec2::ZERO, DVec2::new(0.0, 5.0), 60.0, HALF, DVec2::ZERO),
            None
        );
    }

    #[test]
    fn under_gravity_a_ball_falls_to_the_floor_and_one_resting_on_it_is_pressed_now() {
        let g = DVec2::new(0.0, -10.0);
        // 80 px above the floor's limit (-40), at rest: sqrt(2·80/10) = 4 s.
        let hit = wall_time_of_impact(DVec2::new(0.0, 40.0), DVec2::ZERO, 10.0, HALF, g);
        assert_eq!(hit, Some((4.0, Wall::Bottom)));
        // Thrown up at 10 px/s from 10 px below the ceiling's limit: it turns back 5 px short
        // and falls to the floor; at 20 px/s it reaches the ceiling first.
        let hit = wall_time_of_impact(DVec2::new(0.0, 30.0), DVec2::new(0.0, 10.0), 10.0, HALF, g);
        assert_eq!(hit.map(|h| h.1), Some(Wall::Bottom));
        let hit = wall_time_of_impact(DVec2::new(0.0, 30.0), DVec2::new(0.0, 20.0), 10.0, HALF, g);
        assert_eq!(hit.map(|h| h.1), Some(Wall::Top));
        // Resting on the floor: pressed into it now.
        let hit = wall_time_of_impact(DVec2::new(0.0, -40.0), DVec2::ZERO, 10.0, HALF, g);
        assert_eq!(hit, Some((0.0, Wall::Bottom)));
    }

    #[test]
    fn a_bounce_reflects_the_normal_speed_and_sets_the_ball_against_the_wall() {
        let mut velocity = DVec2::new(20.0, -5.0);
        let circle = Circle::new(DVec2::new(89.5, 3.0), 10.0);
        let bounce = bounce_off_wall(circle, &mut velocity, Wall::Right, HALF, 0.5, 2.0).unwrap();
        assert_eq!(velocity, DVec2::new(-10.0, -5.0));
        assert_eq!(bounce.center, DVec2::new(90.0, 3.0));
        assert_eq!(bounce.point, DVec2::new(100.0, 3.0));
        assert_eq!((bounce.impulse, bounce.normal_speed), (60.0, 20.0));
        let mut away = DVec2::new(-1.0, 0.0);
        assert_eq!(
            bounce_off_wall(circle, &mut away, Wall::Right, HALF, 0.5, 2.0),
            None
        );
        assert_eq!(away, DVec2::new(-1.0, 0.0));
    }
}
