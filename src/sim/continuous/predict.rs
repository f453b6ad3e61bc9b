//! Stage 2, continuous: predicting impacts. At the start of the step every ball goes on the
//! timeline as a `Mover` (held balls still), and the circles swept along each one's path go
//! into the grid; their distances cut the candidate pairs, and the exact time of impact gives
//! each approaching pair's moment of contact within the step (`timing.rs`, a batch of pairs
//! at a time), and each ball's first wall contact. On one thread the movers are made a row of
//! cells ahead of the pair search, so the search finds them in the cache; on more, all of
//! them first, in parallel. During the timeline, a ball redirected by an impact is predicted
//! for again against the balls near the rest of its path (`repredict.rs`), with the same
//! pieces: the pairs' times, the swept circle, the wall's time.

use std::ops::Range;

use bevy::math::DVec2;

use super::impact::{Impact, Prediction, swept_circle, swept_circle_under};
use super::prefetch::{INPUTS_AHEAD, prefetch_inputs};
use super::state::{Mover, StepSpec, Timeline};
use super::timing::FirstPairs;
use crate::sim::geometry::circle::{Circle, within_reach};
use crate::sim::geometry::grid::UniformGrid;
use crate::sim::geometry::pairs::search_in_bands;
use crate::sim::geometry::wall::wall_time_of_impact;
use crate::sim::parallel::{BALLS_PER_PIECE, in_pieces, piece_ranges, worth_splitting};

/// Pixels added to a redirected ball's swept circle, so rounding can never make the swept
/// circles' test reject a pair that touches at the very edge of the step.
pub(super) const SWEPT_MARGIN: f64 = 1e-6;

impl Timeline {
    /// The collision stage's part: every impact of the coming step that the balls' current
    /// paths lead to. `circles` are the balls at the start of the step, `velocities` their
    /// velocities for the whole step; `held` balls hold still.
    pub fn predict(
        &mut self,
        circles: &[Circle],
        velocities: &[DVec2],
        held: &[bool],
        spec: StepSpec,
    ) {
        // Each ball's swept circle, made once for the grid's three passes over them (its
        // extent, its cells, its gather), in the first third of the movers' buffer: the movers
        // are all made again once the grid is built, so the copy costs no memory (24 B a ball,
        // 24 MB at a million; making each circle in each pass took 7% more instructions).
        self.movers.resize(circles.len(), Mover::default());
        let swept = &mut bytemuck::cast_slice_mut(&mut self.movers)[..circles.len()];
        make_swept_circles(swept, (circles, velocities, held), spec);
        self.grid.rebuild(swept);
        // From here on every ball is known by its slot in the grid's cell order.
        self.grid.renumber_by_slot(&mut self.order);
        self.predictions.clear();
        let inputs = (circles, velocities, held);
        let flying = held.iter().filter(|&&held| !held).count();
        if flying * FEW_FLYING < held.len() {
            self.place_every_mover(inputs, spec);
            self.predict_around_the_flying(spec.dt);
        } else if worth_splitting(self.order.len()) {
            self.place_every_mover(inputs, spec);
            self.predict_every_pair(spec.dt);
        } else {
            self.predict_row_after_row(inputs, spec);
        }
    }

    /// Each ball on the timeline, and its first wall impact, in pieces of slots on the compute
    /// pool for many balls (every mover is written: resizing only sized them).
    fn place_every_mover(&mut self, inputs: Inputs, spec: StepSpec) {
        let (grid, order) = (&self.grid, self.order.as_slice());
        let pieces = self
            .movers
            .chunks_mut(BALLS_PER_PIECE)
            .zip(piece_ranges(order.len()));
        let walls = in_pieces(pieces, worth_splitting(order.len()), |(movers, slots)| {
            let mut walls = Vec::new();
            place_movers((movers, slots), (grid, order), inputs, spec, &mut walls);
            walls
        });
        // The walls first: the pair search then grows the buffer by exactly what it finds.
        self.predictions
            .reserve_exact(walls.iter().map(Vec::len).sum());
        self.predictions.extend(walls.into_iter().flatten());
    }

    /// [`place_every_mover`](Self::place_every_mover), then
    /// [`predict_every_pair`](Self::predict_every_pair), on one thread: each row's movers
    /// made just before the search reaches the row below it, so that the search reads them
    /// from the cache rather than from memory. The impacts found are the same, in another
    /// order (walls and pairs mixed), which the queue's sort undoes.
    fn predict_row_after_row(&mut self, inputs: Inputs, spec: StepSpec) {
        let (grid, order) = (&self.grid, self.order.as_slice());
        let (movers, found) = (&mut self.movers, &mut self.predictions);
        let place = |slots: Range<usize>, movers: &mut [Mover], found: &mut Vec<Prediction>| {
            let movers = &mut movers[slots.clone()];
            place_movers((movers, slots), (grid, order), inputs, spec, found);
        };
        // The big balls' pairs are searched with the first row.
        place(grid.small_count()..order.len(), movers, found);
        place(grid.slots_of_row(0), movers, found);
        let mut pairs = FirstPairs::new();
        for row in 0..grid.rows() {
            if row + 1 < grid.rows() {
                place(grid.slots_of_row(row + 1), movers, found);
            }
            grid.for_each_pair_within_reach_in_rows(row..row + 1, |i, j, _, _| {
                pairs.add((i, j), movers, spec.dt, found);
            });
        }
        pairs.time_all(movers, spec.dt, found);
    }

    /// Every pair's impact, through the pairs of swept circles the grid finds touching (the
    /// swept circles bound the paths: if they do not touch, the balls cannot), by their
    /// distance alone ([`within_reach`]), in parallel bands for many balls.
    fn predict_every_pair(&mut self, dt: f64) {
        let movers = &self.movers;
        search_in_bands(&self.grid, &mut self.predictions, |grid, rows, found| {
            let mut pairs = FirstPairs::new();
            grid.for_each_pair_within_reach_in_rows(rows, |i, j, _, _| {
                pairs.add((i, j), movers, dt, found);
            });
            pairs.time_all(movers, dt, found);
        });
    }

    /// The impacts of a step where most balls hold still (a pile resting): two still balls
    /// never meet, so only the flying balls' neighbourhoods are searched, each pair once. It
    /// finds what [`predict_every_pair`](Self::predict_every_pair) finds (tested), but the
    /// overlaps of two still balls, which the timeline leaves to the resting stage.
    fn predict_around_the_flying(&mut self, dt: f64) {
        // The flying balls in the order of the step's input, not by slot: the overlaps found
        // here are pushed apart in the order found, as before the timeline knew slots.
        self.slot_of.clear();
        self.slot_of.resize(self.order.len(), 0);
        for (slot, &index) in self.order.iter().enumerate() {
            self.slot_of[index as usize] = slot as u32;
        }
        let (movers, order, found) = (&self.movers, &self.order, &mut self.predictions);
        let mut pairs = FirstPairs::new();
        for &slot in &self.slot_of {
            let slot = slot as usize;
            if movers[slot].is_still() {
                continue;
            }
            let own = self.grid.circle_in_slot(slot);
            self.grid
                .for_each_that_may_touch(own, |other, other_swept| {
                    let other = other as usize;
                    // A pair of flying balls is taken from the one of lower index.
                    if other == slot
                        || (!movers[other].is_still() && order[other] < order[slot])
                        || !within_reach(own, other_swept)
                    {
                        return;
                    }
                    pairs.add((slot as u32, other as u32), movers, dt, found);
                });
        }
        pairs.time_all(movers, dt, found);
    }
}

/// What the collision stage is given: the balls' circles at the start of the step, their
/// velocities, and which hold still.
type Inputs<'a> = (&'a [Circle], &'a [DVec2], &'a [bool]);

/// Each ball's circle swept over the step, by its index in `inputs`, in pieces on the compute
/// pool for many balls. A new mover accelerates at gravity, or not at all if still; gravity's
/// length, a square root, is taken once for the step.
fn make_swept_circles(swept: &mut [Circle], inputs: Inputs, spec: StepSpec) {
    let (circles, velocities, held) = inputs;
    let (gravity_length, count) = (spec.gravity.length(), swept.len());
    let pieces = swept.chunks_mut(BALLS_PER_PIECE).zip(piece_ranges(count));
    in_pieces(pieces, worth_splitting(count), |(swept, balls)| {
        for (swept, ball) in swept.iter_mut().zip(balls) {
            let (circle, velocity) = (circles[ball], velocities[ball]);
            let mover = Mover::new(ball as u32, circle, velocity, spec.gravity, held[ball]);
            let accel_length = if mover.is_still() {
                0.0
            } else {
                gravity_length
            };
            let accel = (mover.accel, accel_length);
            *swept = swept_circle_under(mover.circle(), mover.moving_velocity(), accel, spec.dt);
        }
    });
}

/// Puts the balls in `slots` on the timeline (`movers`, one for each slot), each with its
/// first wall impact, if any, pushed to `walls`. `order` gives each slot's ball.
fn place_movers(
    (movers, slots): (&mut [Mover], Range<usize>),
    (grid, order): (&UniformGrid, &[u32]),
    (circles, velocities, held): Inputs,
    spec: StepSpec,
    walls: &mut Vec<Prediction>,
) {
    for (mover, slot) in movers.iter_mut().zip(slots) {
        prefetch_inputs((circles, velocities, held), order, slot + INPUTS_AHEAD);
        let ball = order[slot] as usize;
        let (circle, velocity) = (circles[ball], velocities[ball]);
        *mover = Mover::new(ball as u32, circle, velocity, spec.gravity, held[ball]);
        if let Some((time, wall)) = wall_time(mover, grid.circle_in_slot(slot), spec)
            && time <= spec.dt
        {
            let impact = Impact::with_wall(time, mover.party(slot), wall);
            walls.push(Prediction::Impact(impact));
        }
    }
}

/// The circle `mover` sweeps over the next `seconds`.
pub(super) fn swept_by(mover: &Mover, seconds: f64) -> Circle {
    swept_circle(
        mover.circle(),
        mover.moving_velocity(),
        mover.accel,
        seconds,
    )
}

/// When a moving `mover` first meets a wall, from its clock on; a still one meets none, and
/// nor does one whose path, bounded by the circle `swept`, stays clear of every wall by
/// [`SWEPT_MARGIN`] (its own margin, against rounding).
pub(super) fn wall_time(
    mover: &Mover,
    swept: Circle,
    spec: StepSpec,
) -> Option<(f64, crate::sim::geometry::Wall)> {
    let clear = (swept.center.abs() + DVec2::splat(swept.radius + SWEPT_MARGIN)).cmplt(spec.half);
    if mover.is_still() || clear.all() {
        return None;
    }
    wall_time_of_impact(
        mover.center,
        mover.velocity,
        mover.radius,
        spec.half,
        mover.accel,
    )
}

/// Below one flying ball in this many, the collision stage searches around the flying balls
/// only.
const FEW_FLYING: usize = 4;

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::super::impact::{random_circles, sorted};
    use super::*;

    #[test]
    fn searching_around_the_flying_balls_finds_what_every_pair_finds() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let circles = random_circles(&mut rng, 400, 300.0, 3.0..12.0);
        let held: Vec<bool> = (0..400).map(|k| k % 8 != 0).collect();
        let velocities: Vec<DVec2> = (0..400)
            .map(|_| {
                DVec2::new(
                    rng.random_range(-900.0..900.0),
                    rng.random_range(-900.0..900.0),
                )
            })
            .collect();
        let spec = StepSpec {
            restitution: 0.5,
            rest_speed: 16.7,
            ..StepSpec::sixtieth(DVec2::splat(320.0), DVec2::new(0.0, -500.0))
        };
        let mut timeline = Timeline::default();
        timeline.predict(&circles, &velocities, &held, spec);
        timeline.predictions.clear();
        timeline.predict_around_the_flying(spec.dt);
        let around = sorted(&timeline.predictions);
        timeline.predictions.clear();
        timeline.predict_every_pair(spec.dt);
        // Overlaps of two still balls are the resting stage's: the timeline skips them.
        let still = |slot: u32| timeline.movers[slot as usize].is_still();
        timeline
            .predictions
            .retain(|p| !matches!(*p, Prediction::Overlap(a, b) if still(a) && still(b)));
        let every = sorted(&timeline.predictions);
        assert!(around.len() > 20, "{} predictions", around.len());
        assert_eq!(around, every);
    }

    #[test]
    fn the_search_row_after_row_finds_what_the_movers_first_then_the_search_find() {
        // Balls of radius 3-9, one in a hundred of 60 (big: kept apart in the grid), some
        // overlapping, every tenth still, one in five ten times as fast; under gravity.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let circles: Vec<Circle> = (0..1_000_usize)
            .map(|k| {
                let center = DVec2::new(
                    rng.random_range(-390.0..390.0),
                    rng.random_range(-390.0..390.0),
                );
                let radius = if k % 100 == 1 {
                    60.0
                } else {
                    rng.random_range(3.0..9.0)
                };
                Circle::new(center, radius)
            })
            .collect();
        let velocities: Vec<DVec2> = (0..1_000_usize)
            .map(|k| {
                let fast = if k.is_multiple_of(5) { 10.0 } else { 1.0 };
                DVec2::from_angle(rng.random_range(0.0..6.3)) * rng.random_range(0.0..600.0) * fast
            })
            .collect();
        let held: Vec<bool> = (0..1_000).map(|k| k % 10 == 3).collect();
        let spec = StepSpec::sixtieth(DVec2::splat(400.0), DVec2::new(0.0, -500.0));
        let mut timeline = Timeline::default();
        timeline.predict(&circles, &velocities, &held, spec);
        let row_after_row = sorted(&timeline.predictions);
        let movers = format!("{:?}", timeline.movers);
        timeline.movers.fill(Mover::default());
        timeline.predictions.clear();
        timeline.place_every_mover((&circles, &velocities, &held), spec);
        timeline.predict_every_pair(spec.dt);
        assert_eq!(format!("{:?}", timeline.movers), movers);
        assert_eq!(row_after_row, sorted(&timeline.predictions));
        // Walls, overlaps and big balls' pairs among them.
        let big = timeline.grid.small_count() as u32;
        let (mut walls, mut overlaps, mut with_big) = (0, 0, 0);
        for prediction in &timeline.predictions {
            match *prediction {
                Prediction::Impact(impact) if impact.wall().is_some() => walls += 1,
                Prediction::Impact(Impact { a, other, .. }) => {
                    with_big += usize::from(a.max(other) >= big)
                }
                Prediction::Overlap(a, b) => {
                    overlaps += 1;
                    with_big += usize::from(a.max(b) >= big);
                }
            }
        }
        assert!(
            walls > 10 && overlaps > 10 && with_big > 5,
            "{walls} walls, {overlaps} overlaps, {with_big} with a big ball"
        );
    }

    #[test]
    fn skipping_the_walls_out_of_reach_finds_every_wall_impact_the_full_search_finds() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let spec = StepSpec::sixtieth(DVec2::new(200.0, 150.0), DVec2::new(0.0, -900.0));
        let mut reached = 0;
        for case in 0..4000 {
            let radius = rng.random_range(2.0..20.0);
            let limit = spec.half - DVec2::splat(radius);
            // Anywhere inside, a few on or just past a wall.
            let center = DVec2::new(
                rng.random_range(-limit.x..limit.x),
                rng.random_range(-limit.y..limit.y),
            ) * if case % 10 == 0 { 1.02 } else { 1.0 };
            let velocity = DVec2::new(
                rng.random_range(-3000.0..3000.0),
                rng.random_range(-3000.0..3000.0),
            );
            let circle = Circle::new(center, radius);
            let mut mover = Mover::new(case as u32, circle, velocity, spec.gravity, false);
            if case % 7 == 0 {
                // Sliding along the floor, as after stopping against it.
                mover.center.y = -limit.y;
                mover.velocity.y = 0.0;
                mover.accel = DVec2::ZERO;
            }
            let horizon = rng.random_range(0.001..spec.dt);
            let mut swept = swept_by(&mover, horizon);
            swept.radius += SWEPT_MARGIN;
            let within = |found: Option<(f64, crate::sim::geometry::Wall)>| {
                found.filter(|&(time, _)| time <= horizon)
            };
            let full = within(wall_time_of_impact(
                mover.center,
                mover.velocity,
                mover.radius,
                spec.half,
                mover.accel,
            ));
            reached += usize::from(full.is_some());
            assert_eq!(within(wall_time(&mover, swept, spec)), full, "case {case}");
        }
        assert!(reached > 200, "{reached} of the cases reach a wall");
    }
}
