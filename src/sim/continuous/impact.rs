//! Predicted impacts: what the continuous mode's collision stage finds for each pair and
//! each ball against the walls, ordered by time so the timeline can take the earliest first.

use std::cmp::Ordering;

use bevy::math::DVec2;

use crate::sim::geometry::circle::{Circle, MIN_APPROACH_SPEED, time_of_impact};
use crate::sim::geometry::wall::Wall;

/// A circle holding `circle` wherever it is while flying at `velocity` under `gravity` for
/// `seconds`: centred halfway along the chord of its parabola, wide enough for the chord and
/// for the parabola's bulge from it (`|g|·T²/8`). Without gravity, the smallest such circle.
#[inline]
pub fn swept_circle(circle: Circle, velocity: DVec2, gravity: DVec2, seconds: f64) -> Circle {
    swept_circle_under(circle, velocity, (gravity, gravity.length()), seconds)
}

/// [`swept_circle`] with gravity's length given: the same circle to the bit.
#[inline]
pub fn swept_circle_under(
    circle: Circle,
    velocity: DVec2,
    (gravity, gravity_length): (DVec2, f64),
    seconds: f64,
) -> Circle {
    let half = 0.5 * seconds;
    Circle::new(
        circle.center + velocity * half + gravity * (half * half),
        circle.radius + velocity.length() * half + gravity_length * (1.5 * half * half),
    )
}

/// [`time_of_impact`] for pairs closing faster than [`MIN_APPROACH_SPEED`].
#[inline]
pub fn approach_time(a: Circle, velocity_a: DVec2, b: Circle, velocity_b: DVec2) -> Option<f64> {
    let offset = b.center - a.center;
    let closing = (velocity_a - velocity_b).dot(offset);
    if closing <= 0.0
        || closing * closing <= MIN_APPROACH_SPEED * MIN_APPROACH_SPEED * offset.length_squared()
    {
        return None;
    }
    time_of_impact(a, velocity_a, b, velocity_b)
}

/// [`approach_time`] within `end` seconds, worked out whole whatever the pair does, for pairs
/// timed a batch at a time: the time, and whether it holds. It holds exactly when
/// `approach_time(..).filter(|&t| t <= end)` gives a time, and then it is that time to the
/// bit: the same operations in the same order, with the early returns turned into tests that
/// are all made (a negative discriminant's root is NaN, which no test passes).
#[inline]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x <= 0.0)` lets NaN through as the returns do
pub fn approach_time_within(
    (a, velocity_a): (Circle, DVec2),
    (b, velocity_b): (Circle, DVec2),
    end: f64,
) -> (f64, bool) {
    let offset = b.center - a.center;
    let closing = (velocity_a - velocity_b).dot(offset);
    let min_speed = MIN_APPROACH_SPEED * MIN_APPROACH_SPEED;
    let closes = !(closing <= 0.0) & !(closing * closing <= min_speed * offset.length_squared());
    // `time_of_impact`'s steps.
    let velocity = velocity_b - velocity_a;
    let reach = a.radius + b.radius;
    let half_b = offset.dot(velocity);
    let c = offset.length_squared() - reach * reach;
    let discriminant = half_b * half_b - velocity.length_squared() * c;
    let time = if c <= 0.0 {
        0.0
    } else {
        c / (-half_b + discriminant.sqrt())
    };
    (time, closes & !(half_b >= 0.0) & (time <= end))
}

/// `other` values from here up name a wall, below it a ball.
const WALL_BASE: u32 = u32::MAX - 3;

/// The code by which an impact names `wall` in the place of a ball.
pub fn wall_code(wall: Wall) -> u32 {
    WALL_BASE + wall as u32
}

/// A predicted impact: ball `a` with ball `other` or with a wall. The timeline knows its balls
/// by slot (their place in the grid's cell order); `indices` holds the same balls' indices in
/// the step's input, by which impacts at the same time are ordered, as they were before the
/// timeline knew slots. (A pile's history depends on that order; any order settles the
/// 10,000-ball piles as often over many seeds: docs/performance.md, *Balls are stored in space
/// order*.)
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact {
    /// Seconds into the step.
    pub time: f64,
    /// Slots.
    pub a: u32,
    pub other: u32,
    /// How many hits `a` and `other` had had when this was predicted.
    pub hits_a: u32,
    pub hits_other: u32,
    /// The input indices of `a` and `other` (a wall's code for a wall); `a`'s is the lower
    /// when both are balls.
    pub indices: (u32, u32),
}

/// A ball on the timeline, as an impact names it.
#[derive(Clone, Copy, Debug)]
pub struct Party {
    pub slot: usize,
    /// Its index in the step's input.
    pub index: u32,
    /// Its hits so far.
    pub hits: u32,
}

impl Impact {
    /// Ball `ball` reaching `wall` at `time`.
    pub fn with_wall(time: f64, ball: Party, wall: Wall) -> Self {
        let other = wall_code(wall);
        Self {
            time,
            a: ball.slot as u32,
            other,
            hits_a: ball.hits,
            hits_other: 0,
            indices: (ball.index, other),
        }
    }

    /// Balls `i` and `j` meeting at `time`; stored with the lower index first, so a pair has
    /// one key whichever ball it was found from.
    pub fn between(time: f64, i: Party, j: Party) -> Self {
        let (first, second) = if i.index < j.index { (i, j) } else { (j, i) };
        Self {
            time,
            a: first.slot as u32,
            other: second.slot as u32,
            hits_a: first.hits,
            hits_other: second.hits,
            indices: (first.index, second.index),
        }
    }

    /// An impact that names nothing, for buffers whose every entry is written before it is
    /// read (the batches that time pairs).
    pub const UNWRITTEN: Self = Self {
        time: 0.0,
        a: 0,
        other: 0,
        hits_a: 0,
        hits_other: 0,
        indices: (0, 0),
    };

    /// The wall this impact is with, if it is with a wall.
    pub fn wall(&self) -> Option<Wall> {
        (self.other >= WALL_BASE).then(|| Wall::ALL[(self.other - WALL_BASE) as usize])
    }

    fn key(&self) -> (u32, u32, u32, u32) {
        (self.indices.0, self.indices.1, self.hits_a, self.hits_other)
    }
}

impl Eq for Impact {}

impl Ord for Impact {
    /// Earliest first; equal times in a fixed order of the balls, so the result never depends
    /// on the order in which the impacts were found.
    fn cmp(&self, other: &Self) -> Ordering {
        self.time
            .total_cmp(&other.time)
            .then_with(|| self.key().cmp(&other.key()))
    }
}

impl PartialOrd for Impact {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// What the collision stage's search finds for a pair.
#[derive(Clone, Copy, Debug)]
pub enum Prediction {
    Impact(Impact),
    /// Overlapping at the start of the step: the two balls' slots.
    Overlap(u32, u32),
}

/// The predictions in a fixed order, for the tests that compare two searches.
#[cfg(test)]
pub(super) fn sorted(predictions: &[Prediction]) -> Vec<String> {
    let mut all: Vec<String> = predictions.iter().map(|p| format!("{p:?}")).collect();
    all.sort();
    all
}

/// `count` circles for the tests, centred at random in the square of half-side `half` about
/// the origin, of radius in `radii`: each one's x, y and radius drawn from `rng` in turn.
#[cfg(test)]
pub(super) fn random_circles(
    rng: &mut impl rand::RngExt,
    count: usize,
    half: f64,
    radii: std::ops::Range<f64>,
) -> Vec<Circle> {
    (0..count)
        .map(|_| {
            let center = DVec2::new(rng.random_range(-half..half), rng.random_range(-half..half));
            Circle::new(center, rng.random_range(radii.clone()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::sim::geometry::flight::position_after;

    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    use super::*;

    #[test]
    fn impacts_come_out_by_time_then_by_the_balls_input_indices_not_their_slots() {
        // Slots in the opposite order to the indices, so ordering by slot would differ.
        let party = |index: u32| Party {
            slot: 100 - index as usize,
            index,
            hits: 0,
        };
        let impact = |time, i, j| Impact::between(time, party(i), party(j));
        let mut queue: BinaryHeap<Reverse<Impact>> = [
            impact(0.5, 3, 4),
            impact(0.25, 9, 7),
            impact(0.5, 8, 1),
            impact(0.5, 1, 2),
        ]
        .into_iter()
        .map(Reverse)
        .collect();
        let order: Vec<(u32, u32)> =
            std::iter::from_fn(|| queue.pop().map(|Reverse(i)| i.indices)).collect();
        assert_eq!(order, [(7, 9), (1, 2), (1, 8), (3, 4)]);
        let slots = impact(0.5, 8, 1);
        assert_eq!(
            (slots.a, slots.other),
            (99, 92),
            "the lower index's slot first"
        );
    }

    #[test]
    fn the_approach_time_worked_out_whole_is_approach_time_to_the_bit() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(41);
        let (mut met, mut touching, mut passing, mut apart) = (0, 0, 0, 0);
        for case in 0..40_000 {
            let mut point =
                || DVec2::new(rng.random_range(-40.0..40.0), rng.random_range(-40.0..40.0));
            let (a, b) = (Circle::new(point(), 6.0), Circle::new(point(), 9.0));
            let (mut velocity_a, velocity_b) = (point() * 30.0, point() * 30.0);
            match case % 50 {
                0 => velocity_a = velocity_b, // not closing at all
                1 => velocity_a = velocity_b + DVec2::new(1e-12, 0.0), // closing too slowly
                2 => velocity_a.x = f64::NAN,
                _ => {}
            }
            let end = rng.random_range(0.001..0.2);
            let alone = approach_time(a, velocity_a, b, velocity_b).filter(|&t| t <= end);
            let (time, holds) = approach_time_within((a, velocity_a), (b, velocity_b), end);
            assert_eq!(
                holds.then_some(time.to_bits()),
                alone.map(f64::to_bits),
                "{a:?} {velocity_a} {b:?} {velocity_b} {end}"
            );
            met += usize::from(alone.is_some_and(|t| t > 0.0));
            touching += usize::from(alone == Some(0.0));
            passing += usize::from(
                alone.is_none() && approach_time(a, velocity_a, b, velocity_b).is_some(),
            );
            apart += usize::from(alone.is_none());
        }
        assert!(
            met > 1_000 && touching > 100 && passing > 100 && apart > 1_000,
            "{met} met, {touching} touching, {passing} too late, {apart} apart"
        );
    }

    #[test]
    fn the_swept_circle_holds_the_whole_parabola() {
        let circle = Circle::new(DVec2::new(3.0, -7.0), 2.5);
        for (velocity, gravity) in [
            (DVec2::new(300.0, 40.0), DVec2::new(0.0, -500.0)),
            (DVec2::new(0.0, 0.0), DVec2::new(-3000.0, 3000.0)),
            (DVec2::new(-50.0, 900.0), DVec2::new(0.0, -10000.0)),
            (DVec2::new(20.0, -20.0), DVec2::ZERO),
        ] {
            let seconds = 1.0 / 60.0;
            let swept = swept_circle(circle, velocity, gravity, seconds);
            for k in 0..=100 {
                let t = seconds * k as f64 / 100.0;
                let center = position_after(circle.center, velocity, gravity, t);
                let reach = center.distance(swept.center) + circle.radius;
                assert!(
                    reach <= swept.radius * (1.0 + 1e-12),
                    "{velocity} {gravity} at {t}"
                );
            }
        }
    }
}
