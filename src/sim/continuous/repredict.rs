//! Stage 3's predictions, continuous: after an impact redirects a ball, its next wall and
//! ball impacts, found through the grid, where `Paths` keeps every ball's current path. The
//! two balls of a collision touch, so their neighbourhoods are mostly the same: one search of
//! the cells around both finds both balls' impacts ([`Timeline::predict_for_both`]).

use super::impact::{Impact, swept_circle};
use super::predict::{SWEPT_MARGIN, swept_by, wall_time};
use super::prefetch::prefetch_mover;
use super::queue::ImpactQueue;
use super::state::{Mover, StepSpec, Timeline, Untimed};
use super::timing::pair_time;
use crate::sim::geometry::circle::{Circle, within_reach};

impl Timeline {
    /// Queues the next wall and ball impacts of the ball in `slot`, whose velocity changed
    /// at `now`.
    pub(super) fn predict_for(&mut self, slot: usize, now: f64, spec: StepSpec) {
        if self.movers[slot].hits == spec.hit_limit {
            // No more impacts for this ball this step: the end-of-step fallback takes over.
            self.cut_short = true;
            self.paths.end(&mut self.grid, slot as u32);
            return;
        }
        let swept = new_swept(&self.movers[slot], now, spec);
        self.take_new_path(slot, swept, now, spec);
        let (movers, queue) = (&self.movers, &mut self.queue);
        let hits_of = |other: u32| movers[other as usize].hits;
        self.paths
            .for_each_that_may_touch(&self.grid, swept, hits_of, |other| {
                queue_pair_impact(movers, (slot, other as usize), now, spec.dt, queue);
            });
    }

    /// [`predict_for`](Self::predict_for) both balls of an impact between the balls in slots `a`
    /// and `b` at `now`, which set both flying, in one search of the cells around the two: they
    /// touch, so their neighbourhoods are mostly the same. It queues what the two calls, `a`'s
    /// first, would queue, and as the impacts' order does not depend on the order they were found,
    /// the step is the same to the bit. The one thing the two calls' searches saw differently is
    /// `b` in `a`'s search, made before `b` took its new path: so the pair is left out of the one
    /// search and timed apart if `a`'s own search would have found `b`'s path until now. (A ball
    /// that has taken its last hit takes the two calls.)
    ///
    /// The balls the search finds are listed first, each one's mover loaded into the cache
    /// as it is found ([`prefetch_mover`]), and timed after: their loads overlap (at a
    /// million balls the movers lie well past the cache: −3% there, −1% at 100,000). The
    /// search comes before the two balls take their new paths, so that those loads have that
    /// long too to arrive (about −2% at both sizes), and the timing later still: the call
    /// leaves it to [`time_what_was_found`](Self::time_what_was_found), which the timeline
    /// calls once it has taken the next impact and started that one's loads (a million
    /// balls −2 to −3.5%, 100,000 about −1%).
    pub(super) fn predict_for_both(&mut self, (a, b): (usize, usize), now: f64, spec: StepSpec) {
        let spent = |slot: usize| self.movers[slot].hits == spec.hit_limit;
        if spent(a) || spent(b) {
            self.predict_for(a, now, spec);
            self.predict_for(b, now, spec);
            return;
        }
        let swept = [a, b].map(|slot| new_flying_swept(&self.movers[slot], now, spec));
        // `b`'s path until now is found in its cell (one kept apart, or a big ball's, is
        // stale by its hits since this impact); `b`'s own call finds `a`'s new path.
        let a_finds_b =
            b < self.grid.small_count() && within_reach(swept[0], self.grid.circle_in_slot(b));
        let b_finds_a = within_reach(swept[1], swept[0]);
        // Their paths until now taken out of the grid, where the search would find them
        // (they pass through the impact's point, which both new paths start from) only to
        // skip them: each such find a branch the other way, about two a collision. Neither
        // is found then (a big ball's first path, or one kept apart, is stale by its hits),
        // so it finds what it would after their new paths are filed: every other ball's path
        // lies within the reach of the paths so far.
        self.paths.end(&mut self.grid, a as u32);
        self.paths.end(&mut self.grid, b as u32);
        let movers = &self.movers;
        let hits_of = |other: u32| movers[other as usize].hits;
        let found = &mut self.found;
        found.clear();
        self.paths
            .for_each_that_may_touch_any(&self.grid, swept, hits_of, |k, other| {
                debug_assert!(other as usize != a && other as usize != b);
                prefetch_mover(movers, other);
                found.push(k as u8, other);
            });
        self.take_new_path(a, swept[0], now, spec);
        self.take_new_path(b, swept[1], now, spec);
        self.untimed = Some(Untimed {
            slots: (a, b),
            now,
            a_finds_b,
            b_finds_a,
        });
    }

    /// Queues the impacts of what the last [`predict_for_both`](Self::predict_for_both)
    /// found, if not yet done. It must come before any impact after that one is handled.
    pub(super) fn time_what_was_found(&mut self, end: f64) {
        let Some(Untimed {
            slots: (a, b),
            now,
            a_finds_b,
            b_finds_a,
        }) = self.untimed.take()
        else {
            return;
        };
        let (balls, queue) = (self.movers.as_slice(), &mut self.queue);
        self.found.time_all(balls, [a, b], (now, end), queue);
        if b_finds_a {
            queue_pair_impact(balls, (b, a), now, end, queue);
        }
        if a_finds_b {
            queue_pair_impact(balls, (a, b), now, end, queue);
        }
    }

    /// The ball in `slot`, redirected at `now` with hits left, takes its new path, which
    /// sweeps `swept` ([`new_swept`]): its wall impact queued, the path filed
    /// (`Paths::redirect`).
    fn take_new_path(&mut self, slot: usize, swept: Circle, now: f64, spec: StepSpec) {
        let mover = self.movers[slot];
        if let Some((time, wall)) = wall_time(&mover, swept, spec)
            && now + time <= spec.dt
        {
            let party = mover.party(slot);
            self.queue.push(Impact::with_wall(now + time, party, wall));
        }
        self.paths
            .redirect(&mut self.grid, slot as u32, mover.hits, swept);
    }
}

/// The circle a ball redirected at `now` sweeps until the step ends, grown by
/// [`SWEPT_MARGIN`].
fn new_swept(mover: &Mover, now: f64, spec: StepSpec) -> Circle {
    let mut swept = swept_by(mover, spec.dt - now);
    swept.radius += SWEPT_MARGIN;
    swept
}

/// [`new_swept`] for a ball that the impact just handled set flying ([`Mover::fly`]), to the
/// bit: its velocity is its own, so whether it holds still is not read. The impact wrote that
/// word with its hits, and reading it back at once waited, we take it, for the write to reach
/// the cache (the continuous step at 30,000 balls −1.7%, faster in eight rounds of eight).
fn new_flying_swept(mover: &Mover, now: f64, spec: StepSpec) -> Circle {
    debug_assert!(!mover.is_still(), "a ball an impact set flying holds still");
    let seconds = spec.dt - now;
    let mut swept = swept_circle(mover.circle(), mover.velocity, mover.accel, seconds);
    swept.radius += SWEPT_MARGIN;
    swept
}

/// Queues the impact of the balls in `slot` and `other`, redirected at `now`, if their paths
/// meet by `end` (none for a ball with itself).
fn queue_pair_impact(
    movers: &[Mover],
    (slot, other): (usize, usize),
    now: f64,
    end: f64,
    queue: &mut ImpactQueue,
) {
    if other == slot {
        return;
    }
    let (mover, other_mover) = (&movers[slot], &movers[other]);
    let Some(time) = pair_time(mover, other_mover, now, end) else {
        return;
    };
    queue.push(Impact::between(
        time,
        mover.party(slot),
        other_mover.party(other),
    ));
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    #[test]
    fn a_flying_ball_s_new_swept_circle_is_the_one_any_ball_s_is_to_the_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let spec = StepSpec::sixtieth(DVec2::splat(410.0), DVec2::new(0.0, -400.0));
        let mut differing = 0;
        for _ in 0..10_000 {
            let now = rng.random_range(0.0..spec.dt);
            let mut random = |scale: f64| {
                DVec2::new(
                    rng.random_range(-scale..scale),
                    rng.random_range(-scale..scale),
                )
            };
            let circle = Circle::new(random(400.0), 1.0 + random(8.0).x.abs());
            let velocity = random(900.0);
            let mut mover = Mover::new(7, circle, random(50.0), spec.gravity, true);
            mover.advance(now);
            mover.fly(velocity, spec.gravity);
            let (flying, any) = (
                new_flying_swept(&mover, now, spec),
                new_swept(&mover, now, spec),
            );
            assert_eq!(
                flying.center.to_array().map(f64::to_bits),
                any.center.to_array().map(f64::to_bits)
            );
            assert_eq!(flying.radius.to_bits(), any.radius.to_bits());
            // Held still, the same mover would sweep another circle: the two are not alike.
            mover.hold_still();
            differing += usize::from(new_swept(&mover, now, spec) != flying);
        }
        assert_eq!(differing, 10_000);
    }

    #[test]
    fn predicting_for_both_balls_of_an_impact_at_once_queues_what_one_at_a_time_does() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        // Balls of radius 3-9 and, one in a hundred, 40 (big: kept apart in the grid); one in
        // twenty ten times as fast, whose paths reach too far for the cells (kept apart too).
        let circles: Vec<Circle> = (0..2_000_usize)
            .map(|k| {
                let center = DVec2::new(
                    rng.random_range(-400.0..400.0),
                    rng.random_range(-400.0..400.0),
                );
                let big = k.is_multiple_of(100);
                Circle::new(
                    center,
                    if big {
                        40.0
                    } else {
                        rng.random_range(3.0..9.0)
                    },
                )
            })
            .collect();
        let mut velocity = |k: usize| {
            let speed =
                rng.random_range(0.0..900.0) * if k.is_multiple_of(20) { 10.0 } else { 1.0 };
            DVec2::from_angle(rng.random_range(0.0..6.3)) * speed
        };
        let velocities: Vec<DVec2> = (0..2_000).map(&mut velocity).collect();
        let held = vec![false; 2_000];
        let spec = StepSpec::sixtieth(DVec2::splat(410.0), DVec2::new(0.0, -400.0));
        let mut one_at_a_time = Timeline::default();
        let mut both = Timeline::default();
        for timeline in [&mut one_at_a_time, &mut both] {
            timeline.predict(&circles, &velocities, &held, spec);
            timeline.start(spec.dt);
        }
        // Each ball impact gives its balls new velocities, at random (so that they may still
        // approach); every fifth one's second ball takes its last hit, which the search for
        // both leaves to one at a time.
        let (mut redirected, mut taken) = (0_u32, 0);
        let (mut with_big, mut kept_apart) = (0, 0);
        loop {
            let next = one_at_a_time.queue.pop();
            assert_eq!(next, both.queue.pop(), "after {taken} impacts");
            let Some(impact) = next else { break };
            taken += 1;
            let (a, b) = (impact.a as usize, impact.other as usize);
            let current = |timeline: &Timeline| {
                impact.wall().is_none()
                    && timeline.movers[a].hits == impact.hits_a
                    && timeline.movers[b].hits == impact.hits_other
                    && impact.hits_other < spec.hit_limit
            };
            if !current(&both) {
                continue;
            }
            redirected += 1;
            with_big += usize::from(b >= both.grid.small_count());
            kept_apart += usize::from(both.paths.keeps_some_apart());
            let new = [velocity(a), velocity(b)];
            for timeline in [&mut one_at_a_time, &mut both] {
                let movers = &mut timeline.movers;
                movers[a].advance(impact.time);
                movers[b].advance(impact.time);
                (movers[a].velocity, movers[b].velocity) = (new[0], new[1]);
                movers[a].hits += 1;
                movers[b].hits = if redirected.is_multiple_of(5) {
                    spec.hit_limit
                } else {
                    movers[b].hits + 1
                };
            }
            one_at_a_time.predict_for(a, impact.time, spec);
            one_at_a_time.predict_for(b, impact.time, spec);
            both.predict_for_both((a, b), impact.time, spec);
            both.time_what_was_found(spec.dt);
        }
        assert!(
            redirected > 500 && taken > redirected && with_big > 5 && kept_apart > 100,
            "{redirected} of {taken}, {with_big} with a big ball, {kept_apart} with paths apart"
        );
    }
}
