//! The arena's walls: which wall a ball meets and when, how it bounces, and how a ball that
//! crossed one is put back. Pure functions over plain values.
//!
//! The discrete mode contains every ball after moving it ([`contain_in_arena`]); the
//! continuous mode finds each ball's exact moment at a wall ([`wall_time_of_impact`]) and
//! bounces it there ([`bounce_off_wall`]), then contains at the end of the step against
//! rounding; the aiming guide uses the same time of impact. Both contain many balls a piece at
//! a time ([`contain_piece`]; [`contain_all`] runs the pieces in parallel for many balls).

use bevy::math::DVec2;

use super::circle::{Circle, MIN_APPROACH_SPEED};
use super::flight::time_to_reach;
use super::impulse::wall_impulse;
use crate::sim::parallel::{BALLS_PER_PIECE, in_pieces, worth_splitting};

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

/// A wall hit found by [`contain_in_arena`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallHit {
    pub wall: Wall,
    /// Speed into the wall before the hit, pixels per second (positive).
    pub normal_speed: f64,
    /// Slower than the resting speed: the ball stopped against the wall instead of bouncing.
    pub resting: bool,
}

/// The outcome of [`contain_in_arena`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contained {
    pub position: DVec2,
    pub velocity: DVec2,
    /// At most one hit per axis (a corner gives two).
    pub hits: [Option<WallHit>; 2],
}

impl Contained {
    /// The impulse the walls gave a ball of `mass` in its resting stops: `m·v_n` each.
    pub fn resting_impulse(&self, mass: f64) -> f64 {
        self.hits
            .iter()
            .flatten()
            .filter(|hit| hit.resting)
            .map(|hit| wall_impulse(mass, 0.0, hit.normal_speed))
            .sum()
    }
}

/// Puts a ball whose circle crosses a wall of the arena `[-half, half]` back inside.
///
/// A ball moving into the wall is mirrored back by the restitution-scaled overshoot and its
/// normal velocity reflected and scaled by `restitution`; one already moving away (pushed out
/// by a neighbour) is only moved back to the wall. A ball wider than the arena is centred on
/// that axis and stopped along it.
pub fn contain_in_arena(
    position: DVec2,
    velocity: DVec2,
    radius: f64,
    half: DVec2,
    restitution: f64,
) -> Contained {
    contain_at_rest(position, velocity, radius, half, restitution, 0.0)
}

/// Whether [`contain_at_rest`] leaves a ball at `position` of `radius` where it is, whatever
/// its velocity: it lies wholly within the arena `[-half, half]` (a NaN does not), so no
/// wall has anything to do with it.
pub fn lies_inside(position: DVec2, radius: f64, half: DVec2) -> bool {
    // The same sums as `contain_at_rest`'s: the limit, and the overshoot on either side.
    let limit = half - DVec2::splat(radius);
    let above = limit.cmpgt(DVec2::ZERO);
    let within = (position - limit).cmple(DVec2::ZERO) & (-position - limit).cmple(DVec2::ZERO);
    (above & within).all()
}

/// [`contain_in_arena`] with the resting rule: a ball meeting a wall slower than
/// `rest_speed` (pixels per second) does not bounce but stops against it (restitution 0,
/// and its [`WallHit`] says `resting`).
pub fn contain_at_rest(
    mut position: DVec2,
    mut velocity: DVec2,
    radius: f64,
    half: DVec2,
    restitution: f64,
    rest_speed: f64,
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
                let resting = speed_into_wall < rest_speed;
                let restitution = if resting { 0.0 } else { restitution };
                position[axis] = side * (limit - restitution * overshoot);
                velocity[axis] = -side * restitution * speed_into_wall;
                hits[axis] = Some(WallHit {
                    wall,
                    normal_speed: speed_into_wall,
                    resting,
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

/// [`contain_at_rest`] for every ball, with the arena's `(half, restitution, rest_speed)`:
/// `circles` and `velocities` updated in place, in pieces on the compute pool for many balls.
/// Returns the balls that met a wall, in index order.
pub fn contain_all(
    (circles, velocities): (&mut [Circle], &mut [DVec2]),
    arena: (DVec2, f64, f64),
) -> Vec<(u32, Contained)> {
    let parallel = worth_splitting(circles.len());
    let pieces = circles
        .chunks_mut(BALLS_PER_PIECE)
        .zip(velocities.chunks_mut(BALLS_PER_PIECE));
    let by_piece = in_pieces(pieces.enumerate(), parallel, |(piece, balls)| {
        let (all, as_they_are) = (|_| true, |center, velocity| (center, velocity));
        contain_piece(piece * BALLS_PER_PIECE, balls, &all, &as_they_are, arena)
    });
    by_piece.into_iter().flatten().collect()
}

/// [`contain_at_rest`] for each ball of a piece (whose first has index `first`) that
/// `chosen(index)` picks, where `moved(center, velocity)` takes it first (the discrete mode's
/// movement; for a ball already moved, the two as they are), with the arena's `(half,
/// restitution, rest_speed)`. Updates `circles` and `velocities` in place and returns the
/// balls that met a wall, in index order.
pub fn contain_piece(
    first: usize,
    (circles, velocities): (&mut [Circle], &mut [DVec2]),
    chosen: &impl Fn(usize) -> bool,
    moved: &impl Fn(DVec2, DVec2) -> (DVec2, DVec2),
    (half, restitution, rest_speed): (DVec2, f64, f64),
) -> Vec<(u32, Contained)> {
    let mut at_walls = Vec::new();
    for (offset, (circle, velocity)) in circles.iter_mut().zip(velocities).enumerate() {
        if !chosen(first + offset) {
            continue;
        }
        let (center, new_velocity) = moved(circle.center, *velocity);
        let contained = contain_at_rest(
            center,
            new_velocity,
            circle.radius,
            half,
            restitution,
            rest_speed,
        );
        (circle.center, *velocity) = (contained.position, contained.velocity);
        if contained.hits != [None, None] {
            at_walls.push(((first + offset) as u32, contained));
        }
    }
    at_walls
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
    fn a_ball_that_lies_inside_is_one_the_walls_leave_as_it_is() {
        // Centres on a lattice across the walls and past them, a hair from each limit, radii
        // up to wider than the arena, a NaN; velocities into each wall and out of it.
        let hair = 1e-12;
        // The limits for a radius of 10 are 90 (x) and 40 (y).
        let across = |limit: f64| {
            let near = [limit - hair, limit, limit + hair];
            [-1.4 * limit, 0.0, 0.4 * limit, 1.3 * limit, f64::NAN]
                .into_iter()
                .chain(near.into_iter().flat_map(|x| [x, -x]))
        };
        let (mut inside, mut contained) = (0, 0);
        for x in across(90.0) {
            for y in across(40.0) {
                for radius in [10.0, 60.0, 150.0] {
                    for velocity in [DVec2::new(30.0, -20.0), DVec2::new(-30.0, 20.0)] {
                        let position = DVec2::new(x, y);
                        let c = contain_at_rest(position, velocity, radius, HALF, 0.8, 5.0);
                        let left_alone = c.position.to_array().map(f64::to_bits)
                            == position.to_array().map(f64::to_bits)
                            && c.velocity == velocity
                            && c.hits == [None, None];
                        if lies_inside(position, radius, HALF) {
                            assert!(left_alone, "{position} r {radius}: {c:?}");
                            inside += 1;
                        } else {
                            contained += usize::from(!left_alone);
                        }
                    }
                }
            }
        }
        assert!(
            inside > 40 && contained > 200,
            "{inside} inside, {contained} contained"
        );
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
                    normal_speed: 30.0,
                    resting: false,
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
