//! Putting back a ball that crossed a wall of the arena: the discrete mode contains every ball
//! after moving it ([`contain_in_arena`], many a piece at a time: [`contain_piece`]); the
//! continuous mode contains its balls at the end of the step against rounding
//! ([`contain_all`], in parallel for many balls), unless each [`lies_inside`]. Pure functions
//! over plain values; `wall.rs` has the walls themselves, their times of impact and bounces.

use bevy::math::DVec2;

use super::circle::Circle;
use super::impulse::wall_impulse;
use super::wall::{Wall, WallHit};
use crate::sim::parallel::{BALLS_PER_PIECE, in_pieces, worth_splitting};

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

/// True only if [`contain_at_rest`] leaves a ball at `position` of `radius` as it is
/// (position, velocity, no hit), whatever its velocity: it lies wholly within the arena
/// `[-half, half]` (a NaN does not). Some balls it leaves alone are not counted here (one
/// past a wall that moves away is still moved back, but a still one wider than the arena at
/// its centre is not): a false answer only means containing the ball.
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
        // A NaN limit too (a NaN radius): clamping to it below would panic.
        if limit <= 0.0 || limit.is_nan() {
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
        contain_in_place(piece * BALLS_PER_PIECE, balls, &|_| true, arena)
    });
    by_piece.into_iter().flatten().collect()
}

/// [`contain_at_rest`] for each ball of a piece (whose first has index `first`) that
/// `chosen(index)` picks, where `moved(center, velocity)` takes it first (the discrete mode's
/// movement), with the arena's `(half, restitution, rest_speed)`. Updates `circles` and
/// `velocities` in place and returns the balls that met a wall, in index order. A ball that
/// [`lies_inside`] once moved, as most do, skips `contain_at_rest`'s sums, which would leave
/// it as it is (11% of the discrete step at 100,000 balls).
pub fn contain_piece(
    first: usize,
    (circles, velocities): (&mut [Circle], &mut [DVec2]),
    chosen: &impl Fn(usize) -> bool,
    moved: &impl Fn(DVec2, DVec2) -> (DVec2, DVec2),
    arena: (DVec2, f64, f64),
) -> Vec<(u32, Contained)> {
    let mut at_walls = Vec::new();
    for (offset, (circle, velocity)) in circles.iter_mut().zip(velocities).enumerate() {
        if !chosen(first + offset) {
            continue;
        }
        (circle.center, *velocity) = moved(circle.center, *velocity);
        if !lies_inside(circle.center, circle.radius, arena.0) {
            let index = (first + offset) as u32;
            contain_one(index, (circle, velocity), arena, &mut at_walls);
        }
    }
    at_walls
}

/// [`contain_piece`] for balls that nothing moves first: only a chosen ball that no longer
/// [`lies_inside`] can change. Both are asked of every ball and the one branch on the two
/// together is rarely taken, where a branch on `chosen` alone mispredicts whenever the
/// choice is a matter of chance (after the discrete response, the balls in a contact: about
/// a third of them, anywhere).
pub fn contain_in_place(
    first: usize,
    (circles, velocities): (&mut [Circle], &mut [DVec2]),
    chosen: &impl Fn(usize) -> bool,
    arena: (DVec2, f64, f64),
) -> Vec<(u32, Contained)> {
    let mut at_walls = Vec::new();
    for (offset, (circle, velocity)) in circles.iter_mut().zip(velocities).enumerate() {
        // `|`, not `||`: both are worked out, so the branch is taken only for a ball to contain.
        if !chosen(first + offset) | lies_inside(circle.center, circle.radius, arena.0) {
            continue;
        }
        let index = (first + offset) as u32;
        contain_one(index, (circle, velocity), arena, &mut at_walls);
    }
    at_walls
}

/// [`contain_at_rest`] for ball `index`, its circle and velocity updated in place; if it met
/// a wall, it goes into `at_walls`.
fn contain_one(
    index: u32,
    (circle, velocity): (&mut Circle, &mut DVec2),
    (half, restitution, rest_speed): (DVec2, f64, f64),
    at_walls: &mut Vec<(u32, Contained)>,
) {
    let contained = contain_at_rest(
        circle.center,
        *velocity,
        circle.radius,
        half,
        restitution,
        rest_speed,
    );
    (circle.center, *velocity) = (contained.position, contained.velocity);
    if contained.hits != [None, None] {
        at_walls.push((index, contained));
    }
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
            let near = [limit - hair, limit, limit + hair, f64::INFINITY];
            [-1.4 * limit, 0.0, -0.0, 0.4 * limit, 1.3 * limit, f64::NAN]
                .into_iter()
                .chain(near.into_iter().flat_map(|x| [x, -x]))
        };
        let (mut inside, mut contained) = (0, 0);
        for x in across(90.0) {
            for y in across(40.0) {
                // 50 makes the limit on y exactly 0.
                for radius in [10.0, 50.0, 60.0, 150.0, f64::NAN] {
                    let velocities = [(30.0, -20.0), (-30.0, 20.0), (0.0, -0.0), (f64::NAN, 1.0)];
                    for velocity in velocities.map(|(x, y)| DVec2::new(x, y)) {
                        let position = DVec2::new(x, y);
                        let c = contain_at_rest(position, velocity, radius, HALF, 0.8, 5.0);
                        let bits = |v: DVec2| v.to_array().map(f64::to_bits);
                        let left_alone = bits(c.position) == bits(position)
                            && bits(c.velocity) == bits(velocity)
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
    fn containing_in_place_is_containing_a_piece_that_nothing_moves() {
        // Balls across the arena and past its walls, at rest and fast, every third chosen.
        let circles: Vec<Circle> = (0..600)
            .map(|k| {
                let place = DVec2::new((k % 30) as f64 * 8.0 - 118.0, (k / 30) as f64 * 6.0 - 58.0);
                Circle::new(place, 1.0 + (k % 7) as f64)
            })
            .collect();
        let velocities: Vec<DVec2> = (0..600)
            .map(|k| DVec2::new((k % 11) as f64 - 5.0, (k % 5) as f64 - 2.0) * 30.0)
            .collect();
        let chosen = |index: usize| index % 3 == 1;
        let arena = (HALF, 0.9, 20.0);
        let (mut piece, mut in_place) =
            ((circles.clone(), velocities.clone()), (circles, velocities));
        let as_they_are = |center, velocity| (center, velocity);
        let met = contain_piece(
            7,
            (&mut piece.0, &mut piece.1),
            &chosen,
            &as_they_are,
            arena,
        );
        let met_in_place = contain_in_place(7, (&mut in_place.0, &mut in_place.1), &chosen, arena);
        assert_eq!(format!("{met:?}"), format!("{met_in_place:?}"));
        assert_eq!(format!("{piece:?}"), format!("{in_place:?}"));
        // Some chosen balls met a wall, and some not chosen were left outside.
        assert!(met.len() > 20, "{} met a wall", met.len());
        let outside =
            |(k, c): (usize, &Circle)| !chosen(k + 7) && !lies_inside(c.center, c.radius, HALF);
        assert!(
            in_place
                .0
                .iter()
                .enumerate()
                .filter(|&b| outside(b))
                .count()
                > 20
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
}
