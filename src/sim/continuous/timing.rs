//! When two balls on the continuous timeline meet: [`pair_time`] for one pair, and the same
//! time worked out whole for pairs timed a batch at a time, the step's first search's
//! ([`FirstPairs`]) and what a search after an impact found ([`FoundBalls`]). Whether a
//! pair meets within the step is a matter of chance, so timing each pair as it was found
//! mispredicted a branch or two a pair, and each pair's square root and division waited for
//! the branches before them; a batch is timed without a branch per pair, each pair's impact
//! written whether it holds or not and kept if it does, and the times are the same to the
//! bit (docs/performance.md, *The pairs timed a batch at a time*).
//!
//! Two balls with the same acceleration (both in free flight, or both still) close in a
//! straight line: [`approach_time`]. Otherwise (a falling ball and a still one, or one
//! sliding along a wall) the relative path is a parabola: [`time_to_touch`].

use super::impact::{Impact, Prediction, approach_time, approach_time_within};
use super::queue::ImpactQueue;
use super::state::{FOUND_BATCH, FoundBalls, Mover};
use crate::sim::geometry::circle::{Circle, overlapping};
use crate::sim::geometry::flight::time_to_touch;

/// When, at most `end` seconds into the step, the paths of `a` and `b` from `now` on first
/// bring them into contact while closing.
pub(super) fn pair_time(a: &Mover, b: &Mover, now: f64, end: f64) -> Option<f64> {
    let (center_a, center_b) = (a.center_at(now), b.center_at(now));
    let (velocity_a, velocity_b) = (a.velocity_at(now), b.velocity_at(now));
    let time = if a.accel == b.accel {
        approach_time(
            Circle::new(center_a, a.radius),
            velocity_a,
            Circle::new(center_b, b.radius),
            velocity_b,
        )
    } else {
        time_to_touch(
            center_b - center_a,
            velocity_b - velocity_a,
            b.accel - a.accel,
            a.radius + b.radius,
            end - now,
        )
    };
    time.map(|t| now + t).filter(|&t| t <= end)
}

/// [`pair_time`] as a time and whether it holds, worked out whole for two balls with the same
/// acceleration ([`approach_time_within`]): it holds exactly when `pair_time` gives a time,
/// and then it is that time to the bit.
#[inline]
pub(super) fn pair_time_within(a: &Mover, b: &Mover, now: f64, end: f64) -> (f64, bool) {
    if a.accel != b.accel {
        let time = pair_time(a, b, now, end);
        return (time.unwrap_or(0.0), time.is_some());
    }
    let (center_a, center_b) = (a.center_at(now), b.center_at(now));
    let (velocity_a, velocity_b) = (a.velocity_at(now), b.velocity_at(now));
    let (circle_a, circle_b) = (
        Circle::new(center_a, a.radius),
        Circle::new(center_b, b.radius),
    );
    let (time, holds) = approach_time_within(
        (circle_a, velocity_a),
        (circle_b, velocity_b),
        f64::INFINITY,
    );
    let time = now + time;
    (time, holds & (time <= end))
}

/// How many of the first search's pairs within reach [`FirstPairs`] times at once.
const PAIR_BATCH: usize = 64;

/// The first search's pairs within reach, timed a batch at a time without a branch per pair
/// ([`approach_time_within`]; the header says why). It finds what timing each pair alone
/// finds (the tests' `predict_pair`), in another order (a batch's impacts after its
/// overlaps), which the queue's sort undoes; the overlaps keep their order.
pub(super) struct FirstPairs {
    pairs: [(u32, u32); PAIR_BATCH],
    len: usize,
    impacts: [Impact; PAIR_BATCH],
}

impl FirstPairs {
    pub(super) fn new() -> Self {
        Self {
            pairs: [(0, 0); PAIR_BATCH],
            len: 0,
            impacts: [Impact::UNWRITTEN; PAIR_BATCH],
        }
    }

    /// Adds the pair of slots `(i, j)`, in either order, timing the batch once it is full.
    #[inline]
    pub(super) fn add(
        &mut self,
        pair: (u32, u32),
        movers: &[Mover],
        dt: f64,
        found: &mut Vec<Prediction>,
    ) {
        // `len` is below the batch's size here: the modulo only tells the compiler so.
        self.pairs[self.len % PAIR_BATCH] = pair;
        self.len += 1;
        if self.len == PAIR_BATCH {
            self.time_all(movers, dt, found);
        }
    }

    /// Times the pairs added since the last call: for each, an overlap at the start and an
    /// impact within the step, naming the lower slot first.
    pub(super) fn time_all(&mut self, movers: &[Mover], dt: f64, found: &mut Vec<Prediction>) {
        let mut kept = 0;
        for &(i, j) in &self.pairs[..self.len] {
            let (a, b) = (i.min(j), i.max(j));
            let (mover_a, mover_b) = (&movers[a as usize], &movers[b as usize]);
            if overlapping(mover_a.circle(), mover_b.circle()) {
                found.push(Prediction::Overlap(a, b));
            }
            let (time, holds) = first_pair_time_within(mover_a, mover_b, dt);
            let (party_a, party_b) = (mover_a.party(a as usize), mover_b.party(b as usize));
            self.impacts[kept % PAIR_BATCH] = Impact::between(time, party_a, party_b);
            kept += usize::from(holds);
        }
        let impacts = self.impacts[..kept].iter();
        found.extend(impacts.map(|&impact| Prediction::Impact(impact)));
        self.len = 0;
    }
}

/// When, within `end` seconds of the step's start, two balls that have not moved yet (each
/// mover's clock at 0) first touch while closing, as a time and whether it holds: for two
/// with the same acceleration, worked out whole from the movers' own places and velocities
/// ([`approach_time_within`]); it holds exactly when [`pair_time`] from 0 gives a time, and
/// then it is that time to the bit (tested: a zero added to a coordinate changes at most the
/// sign of a zero, which no comparison or product here tells apart).
#[inline]
fn first_pair_time_within(a: &Mover, b: &Mover, end: f64) -> (f64, bool) {
    debug_assert!(
        a.clock == 0.0 && b.clock == 0.0,
        "a ball moved before the search"
    );
    if a.accel != b.accel {
        let time = pair_time(a, b, 0.0, end);
        return (time.unwrap_or(0.0), time.is_some());
    }
    let (velocity_a, velocity_b) = (a.moving_velocity(), b.moving_velocity());
    approach_time_within((a.circle(), velocity_a), (b.circle(), velocity_b), end)
}

impl FoundBalls {
    /// Queues the impact of each ball found with the ball in `slots[k]`, redirected at `now`,
    /// if their paths meet by `end`: what `repredict.rs`'s `queue_pair_impact` queues for
    /// each, timed a batch at a time without a branch per pair ([`pair_time_within`]).
    pub(super) fn time_all(
        &mut self,
        movers: &[Mover],
        slots: [usize; 2],
        (now, end): (f64, f64),
        queue: &mut ImpactQueue,
    ) {
        let timed = &mut self.timed;
        for batch in self.listed.chunks(FOUND_BATCH) {
            let mut kept = 0;
            for &(k, other) in batch {
                // `k` is 0 or 1: the mask only spares a bounds check.
                let (slot, other) = (slots[usize::from(k & 1)], other as usize);
                let (mover, other_mover) = (&movers[slot], &movers[other]);
                let (time, holds) = pair_time_within(mover, other_mover, now, end);
                timed[kept % FOUND_BATCH] =
                    Impact::between(time, mover.party(slot), other_mover.party(other));
                kept += usize::from(holds & (other != slot));
            }
            timed[..kept].iter().for_each(|&impact| queue.push(impact));
        }
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::super::impact::{random_circles, sorted};
    use super::super::state::{StepSpec, Timeline};
    use super::*;

    /// [`pair_time`] from the start of the step, for two balls that have not moved yet (each
    /// mover's clock at 0): where they are and how fast they go are the movers' own, not worked
    /// out for the time 0 (the same numbers: a zero added to a coordinate changes at most the
    /// sign of a zero, which no comparison or product here tells apart).
    fn first_pair_time(a: &Mover, b: &Mover, end: f64) -> Option<f64> {
        debug_assert!(
            a.clock == 0.0 && b.clock == 0.0,
            "a ball moved before the search"
        );
        if a.accel != b.accel {
            return pair_time(a, b, 0.0, end);
        }
        let (velocity_a, velocity_b) = (a.moving_velocity(), b.moving_velocity());
        approach_time(a.circle(), velocity_a, b.circle(), velocity_b).filter(|&t| t <= end)
    }

    /// What the search finds for the pair of slots `(i, j)`, in either order, timed alone: an
    /// overlap at the start, an impact within the step, each naming the lower slot first.
    fn predict_pair(movers: &[Mover], (i, j): (u32, u32), dt: f64, found: &mut Vec<Prediction>) {
        let (a, b) = (i.min(j), i.max(j));
        let (mover_a, mover_b) = (&movers[a as usize], &movers[b as usize]);
        if overlapping(mover_a.circle(), mover_b.circle()) {
            found.push(Prediction::Overlap(a, b));
        }
        if let Some(time) = first_pair_time(mover_a, mover_b, dt) {
            let impact =
                Impact::between(time, mover_a.party(a as usize), mover_b.party(b as usize));
            found.push(Prediction::Impact(impact));
        }
    }

    #[test]
    fn the_first_time_of_a_pair_is_pair_time_from_the_start_to_the_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(23);
        let gravity = DVec2::new(0.0, -500.0);
        let mover = |rng: &mut ChaCha8Rng, k: usize| {
            // Centres on a zero of either sign now and then; every fifth still, every seventh
            // sliding along a floor (no gravity).
            let mut center =
                DVec2::new(rng.random_range(-30.0..30.0), rng.random_range(-30.0..30.0));
            if k.is_multiple_of(6) {
                center.x = if k.is_multiple_of(12) { -0.0 } else { 0.0 };
            }
            let velocity = DVec2::new(
                rng.random_range(-900.0..900.0),
                rng.random_range(-900.0..900.0),
            );
            let circle = Circle::new(center, rng.random_range(1.0..12.0));
            let mut mover = Mover::new(k as u32, circle, velocity, gravity, k.is_multiple_of(5));
            if k.is_multiple_of(7) {
                mover.accel = DVec2::ZERO;
            }
            mover
        };
        let (mut met, mut apart, mut met_later) = (0, 0, 0);
        let held = |(time, holds): (f64, bool)| holds.then_some(time.to_bits());
        for k in 0..20_000 {
            let (a, b) = (mover(&mut rng, k), mover(&mut rng, k / 3));
            let end = rng.random_range(0.001..0.05);
            let (first, from_start) = (first_pair_time(&a, &b, end), pair_time(&a, &b, 0.0, end));
            assert_eq!(
                first.map(f64::to_bits),
                from_start.map(f64::to_bits),
                "{a:?} {b:?}"
            );
            met += usize::from(first.is_some());
            apart += usize::from(first.is_none());
            // Worked out whole, for the batches: the same times to the bit, from any moment.
            let whole = held(first_pair_time_within(&a, &b, end));
            assert_eq!(whole, first.map(f64::to_bits), "{a:?} {b:?}");
            let now = rng.random_range(0.0..end);
            let later = pair_time(&a, &b, now, end);
            assert_eq!(
                held(pair_time_within(&a, &b, now, end)),
                later.map(f64::to_bits)
            );
            met_later += usize::from(later.is_some());
        }
        assert!(met > 1_000 && apart > 1_000, "{met} met, {apart} apart");
        assert!(met_later > 1_000, "{met_later} met from a later moment");
    }

    #[test]
    fn the_first_pairs_timed_in_batches_give_what_each_pair_timed_alone_gives() {
        // Balls of radius 3-9 crowded enough to overlap now and then, every seventh still,
        // under gravity (a still ball and a flying one accelerate differently).
        let mut rng = ChaCha8Rng::seed_from_u64(29);
        let count = 3_000;
        let circles = random_circles(&mut rng, count, 300.0, 3.0..9.0);
        let velocities: Vec<DVec2> = (0..count)
            .map(|_| DVec2::from_angle(rng.random_range(0.0..6.3)) * rng.random_range(0.0..900.0))
            .collect();
        let held: Vec<bool> = (0..count).map(|k| k % 7 == 0).collect();
        let spec = StepSpec::sixtieth(DVec2::splat(320.0), DVec2::new(0.0, -500.0));
        let mut timeline = Timeline::default();
        timeline.predict(&circles, &velocities, &held, spec);
        let (grid, movers) = (&timeline.grid, &timeline.movers);
        let (mut alone, mut batched) = (Vec::new(), Vec::new());
        let mut pairs = FirstPairs::new();
        let mut found = 0;
        grid.for_each_pair_within_reach_in_rows(0..grid.rows(), |i, j, _, _| {
            predict_pair(movers, (i, j), spec.dt, &mut alone);
            pairs.add((i, j), movers, spec.dt, &mut batched);
            found += 1;
        });
        pairs.time_all(movers, spec.dt, &mut batched);
        assert_eq!(sorted(&batched), sorted(&alone));
        // The overlaps in the order found: the step pushes them apart in that order.
        let overlaps = |found: &[Prediction]| -> Vec<(u32, u32)> {
            let overlap = |p: &Prediction| match *p {
                Prediction::Overlap(a, b) => Some((a, b)),
                Prediction::Impact(_) => None,
            };
            found.iter().filter_map(overlap).collect()
        };
        assert_eq!(overlaps(&batched), overlaps(&alone));
        // Many batches, many impacts and overlaps, some pairs of a still and a flying ball.
        let mixed = alone.iter().any(|p| {
            matches!(*p, Prediction::Impact(Impact { a, other, .. })
                if movers[a as usize].is_still() != movers[other as usize].is_still())
        });
        let impacts = alone.len() - overlaps(&alone).len();
        assert!(
            found > 10 * PAIR_BATCH && impacts > 200 && overlaps(&alone).len() > 20 && mixed,
            "{found} pairs, {impacts} impacts, {} overlaps",
            overlaps(&alone).len()
        );
    }
}
