//! Stages 2 and 3, continuous, for many balls: the timeline in horizontal bands of the arena,
//! at once on the compute pool, with exactly the single timeline's result.
//!
//! An impact involves only balls whose paths meet, and within a step a path reaches only so
//! far from its ball's start, so far-apart parts of the arena have independent timelines.
//! 1. [`Bands::predict`] cuts the arena into bands of about as many balls each
//!    (`layout.rs`). Each band takes the balls starting in it (its own) and those within a
//!    halo `HALO_DIAMETERS` largest diameters wide on each side, and predicts their impacts
//!    with the single timeline's code on its balls alone.
//! 2. [`Bands::run`] runs each band's impacts in time order. The halo's outer balls miss
//!    their neighbours beyond it, so their histories may be wrong; a wrong history can reach
//!    a band's own balls only through balls starting within `Δ` of its edge, where `Δ`
//!    bounds how far apart two balls whose paths may meet start (`Timeline::reach_bound`).
//!    So every ball starting within `Δ` of an edge is compared, bit for bit (hits, position,
//!    velocity), in the two bands that hold it.
//! 3. If every comparison holds, every ball takes its own band's end of step, and the hits
//!    are reported by time, then balls: the single timeline's order, as no band handled an
//!    impact after a later one. Otherwise — or if a band's step was cut short, began with
//!    overlaps, stopped a ball against a wall or kept a path apart — the caller runs the step
//!    as one timeline. Held balls, the resting rule and big balls keep the single timeline.
//!    After bands that miss, the next steps are taken as one timeline (1, then 2, 4, … up to
//!    `MOST_STEPS_WITHOUT_BANDS` after misses in a row) before the bands are tried again.
//!
//! The result is the single timeline's whether the bands hold or not, so it never depends on
//! how many bands (or threads) there are (tested) — short of a wrong history that ends, in
//! every ball compared, with the same hits, position and velocity to the bit.

use bevy::math::DVec2;
use bevy::prelude::Resource;
use crossbeam_utils::CachePadded;

mod band;
mod layout;

use band::{Band, alike_where};
use layout::Survey;

use super::impact::wall_code;
use super::state::{StepSpec, Timeline};
use crate::sim::geometry::Circle;
use crate::sim::parallel::{
    BALLS_PER_PIECE, PARALLEL_MIN_BALLS, in_pieces, one_thread_each, piece_ranges, threads_at_work,
    worth_splitting,
};
use crate::sim::report::Hit;

/// Below this many balls the step is one timeline: the other stages split their work from
/// here on too.
const MIN_BALLS: usize = PARALLEL_MIN_BALLS;

/// Above this many balls the step is one timeline: each band's buffers are its own, and at a
/// million balls the bands' together passed the memory target (524 against 369 MiB).
const MAX_BALLS: usize = 400_000;

/// The halo on each side of a band, in largest diameters.
const HALO_DIAMETERS: f64 = 10.0;

/// After bands that did not hold, the steps taken as one timeline before trying them again
/// double with each miss in a row, up to this many (a second at 60 steps a second): a step
/// run twice costs more than the bands save, and what made them miss (a crowd, say) lasts.
const MOST_STEPS_WITHOUT_BANDS: u32 = 64;

/// The bands of the current step, kept between steps to reuse their buffers: the
/// continuous mode's second resource beside the [`Timeline`].
#[derive(Resource, Debug, Default)]
pub struct Bands {
    /// Each on cache lines of its own: a band's thread writes its fields all through the step
    /// (its hits, counts and queue), and two bands sharing a line slowed both, the second
    /// by 13% (the line passed back and forth between the cores).
    bands: Vec<CachePadded<Band>>,
    /// Whether this step is taken in bands.
    in_use: bool,
    /// Steps left to take as one timeline before trying the bands again, and how many the
    /// next miss sets (see [`MOST_STEPS_WITHOUT_BANDS`]).
    steps_without: u32,
    next_steps_without: u32,
    /// Pixels.
    halo: f64,
    /// Steps whose impacts the bands took, and steps run again as one timeline because the
    /// bands did not hold.
    pub steps_in_bands: u64,
    pub steps_run_again: u64,
}

impl Bands {
    /// Stage 2 for a step: in bands for many balls and more than one thread, else as one
    /// `timeline` (`Timeline::predict`).
    pub fn predict_step(
        &mut self,
        timeline: &mut Timeline,
        circles: &[Circle],
        velocities: &[DVec2],
        held: &[bool],
        spec: StepSpec,
    ) {
        let count = Bands::count_for(circles.len());
        let bands = (count, HALO_DIAMETERS);
        self.predict_in_bands(bands, timeline, circles, velocities, held, spec);
    }

    /// [`predict_step`](Self::predict_step) in `count` bands with halos `halo_diameters`
    /// largest diameters wide (one timeline if `count` is 1, while backing off after a miss,
    /// or if they cannot be used).
    fn predict_in_bands(
        &mut self,
        bands: (usize, f64),
        timeline: &mut Timeline,
        circles: &[Circle],
        velocities: &[DVec2],
        held: &[bool],
        spec: StepSpec,
    ) {
        let waited = self.steps_without == 0;
        self.steps_without = self.steps_without.saturating_sub(1);
        self.in_use = waited && self.predict(bands, circles, velocities, held, spec);
        if !self.in_use {
            timeline.predict(circles, velocities, held, spec);
        }
    }

    /// Stage 3 for a step predicted by [`predict_step`](Self::predict_step): what
    /// `Timeline::run` does, in the bands if they were used and hold, else as one `timeline`
    /// (predicted again if need be). Hands every hit to `on_hit` in the single timeline's
    /// order, but, unless `keep_ball_hits`, only counts the ball hits of a step taken in
    /// bands: returns how many it only counted.
    pub fn run_step(
        &mut self,
        timeline: &mut Timeline,
        (circles, velocities): (&mut [Circle], &mut [DVec2]),
        (held, stopped): (&mut [bool], &mut [bool]),
        spec: StepSpec,
        keep_ball_hits: bool,
        mut on_hit: impl FnMut(Hit),
    ) -> u64 {
        if self.in_use {
            let balls = (&mut *held, &mut *stopped);
            if let Some(counted) = self.run(
                circles,
                velocities,
                balls,
                spec,
                keep_ball_hits,
                &mut on_hit,
            ) {
                let ends_inside = self.bands.iter().all(|band| band.timeline.ends_inside);
                let balls = (&mut *circles, &mut *velocities);
                timeline.finish_after_bands(balls, ends_inside, spec, on_hit);
                return counted;
            }
            // The bands did not hold: the step as one timeline.
            timeline.predict(circles, velocities, held, spec);
        }
        timeline.run(circles, velocities, (held, stopped), spec, on_hit);
        0
    }

    /// How many bands a step of `balls` balls takes: one for each thread at work, or 1 (the
    /// single timeline) for few balls, very many, or one thread.
    fn count_for(balls: usize) -> usize {
        if (MIN_BALLS..=MAX_BALLS).contains(&balls) {
            threads_at_work()
        } else {
            1
        }
    }

    /// Stage 2 in `count` bands with halos `halo_diameters` largest diameters wide: each
    /// band's balls gathered and their impacts predicted. Returns false if the step cannot be
    /// taken in bands.
    fn predict(
        &mut self,
        (count, halo_diameters): (usize, f64),
        circles: &[Circle],
        velocities: &[DVec2],
        held: &[bool],
        spec: StepSpec,
    ) -> bool {
        // The resting rule sums the walls' stops in the order handled, and a band of still
        // balls searches around its flying ones only, as a pile's step does, finding fewer
        // overlaps than the single timeline's search of every pair.
        if spec.rest_speed != 0.0 || count < 2 || held.iter().any(|&held| held) {
            return false;
        }
        let survey = Survey::of(circles, spec.half.y);
        if survey.may_have_big_balls() {
            return false;
        }
        self.halo = halo_diameters * 2.0 * survey.largest;
        let Some(edges) = survey.edges(count, self.halo) else {
            return false;
        };
        self.bands.resize_with(count, CachePadded::default);
        for (band, pair) in self.bands.iter_mut().zip(edges.windows(2)) {
            (band.low, band.high) = (pair[0], pair[1]);
        }
        let halo = self.halo;
        let parallel = threads_at_work() > 1;
        one_thread_each(self.bands.iter_mut(), parallel, |band| {
            band.predict((circles, velocities, held), halo, spec);
        });
        let own: usize = self.bands.iter().map(|band| band.own_count).sum();
        // Every ball in some band (none lost to a NaN), no big ball in any.
        own == circles.len()
            && self
                .bands
                .iter()
                .all(|band| band.timeline.has_no_big_ball())
    }

    /// Stage 3 in the bands [`predict`](Self::predict) made: each band's impacts, then, if
    /// the bands hold, every ball's end of the timeline written to the arrays (as
    /// `Timeline::run_impacts` writes it) and the hits handed to `on_hit` in the single
    /// timeline's order — every ball hit if `keep_ball_hits`, else only the wall hits. Returns
    /// the ball hits only counted, or `None`, having changed nothing, if the bands do not
    /// hold.
    fn run(
        &mut self,
        circles: &mut [Circle],
        velocities: &mut [DVec2],
        (held, stopped): (&mut [bool], &mut [bool]),
        spec: StepSpec,
        keep_ball_hits: bool,
        mut on_hit: impl FnMut(Hit),
    ) -> Option<u64> {
        let parallel = threads_at_work() > 1;
        one_thread_each(self.bands.iter_mut(), parallel, |band| {
            band.run(spec, keep_ball_hits);
        });
        if !self.hold(circles) {
            self.steps_run_again += 1;
            self.steps_without = self.next_steps_without.max(1);
            self.next_steps_without = (2 * self.steps_without).min(MOST_STEPS_WITHOUT_BANDS);
            return None;
        }
        self.steps_in_bands += 1;
        self.next_steps_without = 1;
        self.write_own_ends(circles, velocities, (held, stopped));
        let mut hits = Vec::new();
        let mut counted = 0;
        for band in &mut self.bands {
            hits.append(&mut band.hits);
            counted += band.ball_hits_counted;
        }
        hits.sort_unstable_by(|a, b| {
            let (time_a, key_a) = order_of(a);
            let (time_b, key_b) = order_of(b);
            time_a.total_cmp(&time_b).then(key_a.cmp(&key_b))
        });
        hits.into_iter().for_each(&mut on_hit);
        Some(counted)
    }

    /// Every ball's end of step, from its own band, in pieces of the arrays on the compute
    /// pool for many balls (each band's balls are in index order, so each piece reads a run
    /// of each band's).
    fn write_own_ends(
        &self,
        circles: &mut [Circle],
        velocities: &mut [DVec2],
        (held, stopped): (&mut [bool], &mut [bool]),
    ) {
        let count = circles.len();
        let pieces = circles
            .chunks_mut(BALLS_PER_PIECE)
            .zip(velocities.chunks_mut(BALLS_PER_PIECE))
            .zip(held.chunks_mut(BALLS_PER_PIECE))
            .zip(stopped.chunks_mut(BALLS_PER_PIECE))
            .zip(piece_ranges(count));
        in_pieces(
            pieces,
            worth_splitting(count),
            |((((circles, velocities), held), stopped), range)| {
                for band in &self.bands {
                    let first = band
                        .balls
                        .partition_point(|&index| (index as usize) < range.start);
                    let last = band
                        .balls
                        .partition_point(|&index| (index as usize) < range.end);
                    for local in first..last {
                        if band.own[local] {
                            let at = band.balls[local] as usize - range.start;
                            circles[at].center = band.circles[local].center;
                            velocities[at] = band.velocities[local];
                            held[at] = band.held[local];
                            stopped[at] = band.stopped[local];
                        }
                    }
                }
            },
        );
    }

    /// Whether every band's result for its own balls is the single timeline's (see the
    /// header).
    fn hold(&self, circles: &[Circle]) -> bool {
        let none_needs_one_timeline = self.bands.iter().all(|band| {
            let timeline = &band.timeline;
            !timeline.cut_short
                && !timeline.out_of_order
                && timeline.overlapping.is_empty()
                && timeline.resting_wall_impulse == 0.0
                && !timeline.paths.keeps_some_apart()
        });
        let mut reaches = self.bands.iter().map(|band| band.timeline.reach_bound());
        let Some(reach) = reaches.try_fold(0.0_f64, |most, reach| Some(most.max(reach?))) else {
            return false;
        };
        none_needs_one_timeline
            && reach < self.halo
            && self.bands.windows(2).all(|pair| {
                let near =
                    |index: u32| (circles[index as usize].center.y - pair[0].high).abs() <= reach;
                alike_where(&pair[0], &pair[1], near)
            })
    }
}

/// A hit's place in the impacts' order: its time, then its balls' indices (a wall's code for
/// a wall), as [`Impact`](super::impact::Impact)s are ordered. The single timeline hands its
/// hits on in this order unless it took an impact out of it (`Timeline::out_of_order`).
fn order_of(hit: &Hit) -> (f64, (u32, u32)) {
    match *hit {
        Hit::Ball { a, b, time, .. } => (time, (a, b)),
        Hit::Wall {
            ball, wall, time, ..
        } => (time, (ball, wall_code(wall))),
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// `count` balls of radius 5–15 px, about 30% of a square arena, stored row by row as a
    /// scene spawns them, at up to 500 px/s: the standard gas.
    fn gas(count: usize) -> (Vec<Circle>, Vec<DVec2>, StepSpec) {
        let side = (count as f64 * std::f64::consts::PI * 108.3 / 0.3).sqrt();
        let columns = (count as f64).sqrt().ceil() as usize;
        let pitch = side / columns as f64;
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let circles = (0..count)
            .map(|k| {
                let cell = DVec2::new((k % columns) as f64, (k / columns) as f64);
                let jitter = DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                let center = (cell + DVec2::splat(0.5)) * pitch - DVec2::splat(side / 2.0) + jitter;
                Circle::new(center, rng.random_range(5.0..15.0))
            })
            .collect();
        let velocities = (0..count)
            .map(|_| DVec2::from_angle(rng.random_range(0.0..6.3)) * rng.random_range(0.0..500.0))
            .collect();
        let spec = StepSpec::sixtieth(DVec2::splat(side / 2.0), DVec2::ZERO);
        (circles, velocities, spec)
    }

    /// Eight steps of `count` balls in `bands` (count, halo in largest diameters): the balls
    /// at the end, the hits kept, the ball hits only counted (if not `keep_ball_hits`), and
    /// the steps the bands took and ran again.
    fn steps(bands: (usize, f64), keep_ball_hits: bool) -> (String, Vec<String>, u64, (u64, u64)) {
        let (mut circles, mut velocities, spec) = gas(6_000);
        let (mut held, mut stopped) = (vec![false; 6_000], vec![false; 6_000]);
        let (mut timeline, mut in_bands) = (Timeline::default(), Bands::default());
        let (mut hits, mut counted) = (Vec::new(), 0);
        for _ in 0..8 {
            in_bands.predict_in_bands(bands, &mut timeline, &circles, &velocities, &held, spec);
            let flags = (&mut held[..], &mut stopped[..]);
            let record = |hit: Hit| hits.push(format!("{hit:?}"));
            counted += in_bands.run_step(
                &mut timeline,
                (&mut circles, &mut velocities),
                flags,
                spec,
                keep_ball_hits,
                record,
            );
        }
        let state = format!("{circles:?} {velocities:?} {held:?} {stopped:?}");
        let taken = (in_bands.steps_in_bands, in_bands.steps_run_again);
        (state, hits, counted, taken)
    }

    #[test]
    fn bands_give_the_single_timeline_s_steps_to_the_bit_whether_they_hold_or_not() {
        let (state, hits, counted, taken) = steps((1, HALO_DIAMETERS), true);
        assert_eq!((counted, taken), (0, (0, 0)));
        let ball_hits = hits.iter().filter(|hit| hit.starts_with("Ball")).count();
        assert!(ball_hits > 5_000, "{ball_hits} ball hits");
        // Three bands with the step's halos hold every step.
        let held = steps((3, HALO_DIAMETERS), true);
        assert!(held.0 == state, "the balls differ");
        assert!(held.1 == hits, "the hits differ");
        assert_eq!((held.2, held.3), (0, (8, 0)));
        // Halos too narrow to hold: steps 1, 3 and 6 are run again as one timeline, the others
        // are the back-off's one, two and four steps without bands (the last cut short).
        let narrow = steps((3, 1.5), true);
        assert!(narrow.0 == state && narrow.1 == hits);
        assert_eq!(narrow.3, (0, 3));
        // Ball hits only counted: as many, and the wall hits alone, in order.
        let counting = steps((3, HALO_DIAMETERS), false);
        let wall_hits: Vec<String> = hits
            .iter()
            .filter(|hit| hit.starts_with("Wall"))
            .cloned()
            .collect();
        assert!(counting.0 == state);
        assert_eq!((counting.1, counting.2 as usize), (wall_hits, ball_hits));
    }

    #[test]
    fn a_timeline_notices_when_it_takes_an_impact_after_a_later_one() {
        // Ball 1 rests touching ball 0; ball 2 hits ball 1, which meets ball 0 at that very
        // moment: the impact of balls 0 and 1 comes before that of 1 and 2 in the impacts' order.
        let circles = [
            Circle::new(DVec2::new(-10.0, 0.0), 5.0),
            Circle::new(DVec2::ZERO, 5.0),
            Circle::new(DVec2::new(12.0, 0.0), 5.0),
        ];
        let fling = DVec2::new(-600.0, 0.0);
        let mut velocities = [DVec2::ZERO, DVec2::ZERO, fling];
        let spec = StepSpec::sixtieth(DVec2::splat(500.0), DVec2::ZERO);
        let (mut held, mut stopped) = ([false; 3], [false; 3]);
        let mut timeline = Timeline::default();
        timeline.predict(&circles, &velocities, &held, spec);
        let mut hits = Vec::new();
        let mut moved = circles;
        let flags = (&mut held[..], &mut stopped[..]);
        timeline.run_impacts(&mut moved, &mut velocities, flags, spec, &mut |hit| {
            hits.push(order_of(&hit))
        });
        let keys: Vec<(u32, u32)> = hits.iter().map(|&(_, key)| key).collect();
        assert_eq!(keys, [(1, 2), (0, 1)]);
        assert_eq!(hits[0].0, hits[1].0);
        assert!((hits[0].0 - 1.0 / 300.0).abs() < 1e-12, "{hits:?}");
        assert!(timeline.out_of_order);
        // Without ball 0, nothing is out of order.
        let mut timeline = Timeline::default();
        let (circles, mut velocities) = ([circles[1], circles[2]], [DVec2::ZERO, fling]);
        timeline.predict(&circles, &velocities, &held[..2], spec);
        let mut moved = circles;
        let flags = (&mut held[..2], &mut stopped[..2]);
        let mut count = 0;
        timeline.run_impacts(&mut moved, &mut velocities, flags, spec, &mut |_| {
            count += 1
        });
        assert_eq!(count, 1);
        assert!(!timeline.out_of_order);
    }
}
