//! The continuous mode's working state: the [`Timeline`] resource, every ball on it as a
//! `Mover`, and what a step needs of the parameters ([`StepSpec`]). `predict.rs` (stage 2)
//! and `timeline.rs` (stage 3, with `repredict.rs` and `prefetch.rs`) each implement their
//! half of `Timeline` on it; here are what the bands (`bands/`) ask of a run: its hits by
//! ball, how far its paths reached.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::impact::{Impact, Party, Prediction};
use super::paths::Paths;
use super::queue::ImpactQueue;
use crate::sim::geometry::Circle;
use crate::sim::geometry::circle::RadiusRange;
use crate::sim::geometry::flight::{position_after, velocity_after};
use crate::sim::geometry::grid::UniformGrid;
use crate::sim::geometry::pairs::{FoundInBands, IndexedContact};
use crate::sim::params::{MAX_BALLS, MassModel, SimParams};
use crate::sim::resting::rest_speed;

/// The fewest hits a ball may take in one step ([`hit_limit`]).
pub const MIN_HITS_PER_BALL: u32 = 16;

/// The most hits a ball may take in one step, whatever the masses ([`hit_limit`]): it bounds
/// what an inelastic collapse costs a step.
pub const MAX_HITS_PER_BALL: u32 = 1024;

/// How many hits a ball may take in one step when the heaviest ball is `mass_ratio` times
/// the lightest. A light ball caught between a heavy one and a wall (or a crowd) is struck
/// about π√(M/m) times while the heavy one turns back (Galperin's billiards: 31 times for a
/// ratio of 100, 314 for 10,000), so the limit is twice that, and never under
/// [`MIN_HITS_PER_BALL`] (16, what any ratio up to 6.4 gets: the standard gas's is 3), nor
/// over [`MAX_HITS_PER_BALL`] (a ratio past 26,500). Otherwise only an inelastic collapse
/// (balls pressed together with restitution below 1, impacts repeating ever faster) goes past
/// it: the step then ends for that ball without further impacts, and the overlaps left at the
/// end get the discrete mode's response.
/// [`SimStats::cut_short_steps`](crate::sim::SimStats::cut_short_steps) counts such steps.
pub fn hit_limit(mass_ratio: f64) -> u32 {
    let chain = (2.0 * std::f64::consts::PI * mass_ratio.sqrt()).ceil();
    // A NaN ratio gives 0 (`as` saturates): the fewest.
    (chain as u32).clamp(MIN_HITS_PER_BALL, MAX_HITS_PER_BALL)
}

/// What a step's timeline needs of the simulation's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSpec {
    /// Seconds.
    pub dt: f64,
    /// Half the arena size, pixels.
    pub half: DVec2,
    pub restitution: f64,
    pub mass_model: MassModel,
    /// Pixels per second squared, the same for every ball in free flight: each one's path
    /// is a parabola.
    pub gravity: DVec2,
    /// Impacts closing slower than this, pixels per second, do not bounce: the resting rule
    /// ([`rest_speed`]).
    pub rest_speed: f64,
    /// Hits a ball may take in the step ([`hit_limit`]).
    pub hit_limit: u32,
}

impl StepSpec {
    /// The step of `dt` seconds for balls whose radii span `radii`.
    pub fn new(params: &SimParams, dt: f64, radii: RadiusRange) -> Self {
        let mass = |radius| params.mass_model.mass(radius);
        Self {
            dt,
            half: params.half_extents(),
            restitution: params.restitution,
            mass_model: params.mass_model,
            gravity: params.gravity,
            rest_speed: rest_speed(params, dt),
            hit_limit: hit_limit(mass(radii.largest) / mass(radii.smallest)),
        }
    }
}

#[cfg(test)]
impl StepSpec {
    /// Tests' step: 1/60 s in the arena `[-half, half]`, elastic, mass = radius, under
    /// `gravity`, no resting rule.
    pub fn sixtieth(half: DVec2, gravity: DVec2) -> Self {
        Self {
            dt: 1.0 / 60.0,
            half,
            restitution: 1.0,
            mass_model: MassModel::Radius,
            gravity,
            rest_speed: 0.0,
            hit_limit: MIN_HITS_PER_BALL,
        }
    }
}

/// A ball on the step's timeline: where it is `clock` seconds into the step, and how many hits
/// it has taken.
///
/// A ball in free flight accelerates at gravity. One that stopped against a wall slides
/// along it, with gravity's push into the wall taken away; one that is `still` (held by the
/// resting stage, or stopped on a ball that holds still) does not move at all until a hit
/// sets it flying: its `velocity` is then only what it will have at the end of the step.
///
/// Its fields lie in the order written (`repr(C)`, 72 B): the timeline's prefetching loads
/// its first and its last lines by `center` and `hits`. They are plain numbers
/// (`bytemuck::Pod`: whether it is still is a bit, not a `bool`), so that the timeline's
/// buffer of movers can hold the step's swept circles while the grid is built
/// ([`Timeline::predict`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub(super) struct Mover {
    pub center: DVec2,
    pub velocity: DVec2,
    /// Pixels per second squared.
    pub accel: DVec2,
    pub radius: f64,
    pub clock: f64,
    pub hits: u32,
    /// Its ball's index in the step's input ([`party`](Self::party)), and [`STILL`] while it
    /// holds still ([`is_still`](Self::is_still)). The impacts name a ball by that index too,
    /// and read it here, beside the hits, rather than from `Timeline::order` at scattered
    /// slots (4 MB at a million balls): a million balls' step −2 to −5%, 100,000's −1 to −4%.
    index_and_still: u32,
}

/// The bit of `Mover::index_and_still` that says the ball holds still: the top one, far above
/// any index (each below [`MAX_BALLS`]).
const STILL: u32 = 1 << 31;
const _: () = assert!(MAX_BALLS <= STILL as usize);

impl Mover {
    /// The ball of index `index` in the step's input, at the start of the step.
    pub fn new(index: u32, circle: Circle, velocity: DVec2, gravity: DVec2, still: bool) -> Self {
        Self {
            center: circle.center,
            velocity,
            accel: if still { DVec2::ZERO } else { gravity },
            radius: circle.radius,
            clock: 0.0,
            hits: 0,
            index_and_still: index | if still { STILL } else { 0 },
        }
    }

    /// The ball, in `slot`, as an impact predicted now names it.
    #[inline]
    pub fn party(&self, slot: usize) -> Party {
        Party {
            slot,
            index: self.index_and_still & !STILL,
            hits: self.hits,
        }
    }

    /// Whether it holds still (see the type's header).
    #[inline]
    pub fn is_still(&self) -> bool {
        self.index_and_still & STILL != 0
    }

    /// Holds still from now on, with its acceleration gone.
    pub fn hold_still(&mut self) {
        self.index_and_still |= STILL;
        self.accel = DVec2::ZERO;
    }

    pub fn circle(&self) -> Circle {
        Circle::new(self.center, self.radius)
    }

    /// The velocity it moves at now: zero while still.
    #[inline]
    pub fn moving_velocity(&self) -> DVec2 {
        if self.is_still() {
            DVec2::ZERO
        } else {
            self.velocity
        }
    }

    /// Where the ball is `time` seconds into the step.
    #[inline]
    pub fn center_at(&self, time: f64) -> DVec2 {
        position_after(
            self.center,
            self.moving_velocity(),
            self.accel,
            time - self.clock,
        )
    }

    /// The velocity it moves at then.
    #[inline]
    pub fn velocity_at(&self, time: f64) -> DVec2 {
        velocity_after(self.moving_velocity(), self.accel, time - self.clock)
    }

    /// Where it is and how fast it moves `time` seconds into the step (a still ball's
    /// velocity is the one it will have at the end of the step).
    #[inline]
    pub fn state_at(&self, time: f64) -> (DVec2, DVec2) {
        if self.is_still() {
            (self.center, self.velocity)
        } else {
            (self.center_at(time), self.velocity_at(time))
        }
    }

    /// Moves it to `time` seconds into the step ([`state_at`](Self::state_at)).
    pub fn advance(&mut self, time: f64) {
        (self.center, self.velocity) = self.state_at(time);
        self.clock = time;
    }

    /// Sets it flying from now at `velocity` under `gravity`.
    pub fn fly(&mut self, velocity: DVec2, gravity: DVec2) {
        self.velocity = velocity;
        self.accel = gravity;
        self.index_and_still &= !STILL;
    }
}

/// A collision between the balls in `slots` at `now` whose search's finds wait to be timed
/// (`Timeline::time_what_was_found`), and whether the two balls' own pair is timed apart,
/// from either side (`Timeline::predict_for_both`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Untimed {
    pub slots: (usize, usize),
    pub now: f64,
    pub a_finds_b: bool,
    pub b_finds_a: bool,
}

/// How many found balls [`FoundBalls::time_all`] (`timing.rs`) times at once.
pub(super) const FOUND_BATCH: usize = 16;

/// What a search after an impact found, `(k, slot)`: the ball in `slot` near the new path of
/// the impact's ball `k` (0 or 1), listed as found and timed later
/// ([`time_all`](Self::time_all), in `timing.rs`). The batch the times are written to is
/// kept from one impact to the next: made afresh for each, its 512 B were cleared at every
/// collision.
#[derive(Debug)]
pub(super) struct FoundBalls {
    pub(super) listed: Vec<(u8, u32)>,
    pub(super) timed: [Impact; FOUND_BATCH],
}

impl Default for FoundBalls {
    fn default() -> Self {
        Self {
            listed: Vec::new(),
            timed: [Impact::UNWRITTEN; FOUND_BATCH],
        }
    }
}

impl FoundBalls {
    /// Nothing found yet: a new search.
    pub(super) fn clear(&mut self) {
        self.listed.clear();
    }

    /// The ball in `slot` was found near the new path of the impact's ball `k`.
    pub(super) fn push(&mut self, k: u8, slot: u32) {
        self.listed.push((k, slot));
    }
}

/// The continuous mode's working state, kept between steps to reuse its buffers.
#[derive(Resource, Debug, Default)]
pub struct Timeline {
    /// Each ball's circle swept over the whole step, sorted into cells; during the timeline,
    /// in each slot the circle of the rest of that ball's current path (`paths.rs`). The
    /// timeline knows every ball by its slot in this cell order, so the balls an impact's
    /// neighbourhood reads lie close together in memory.
    pub(super) grid: UniformGrid,
    /// The ball in each slot: `order[slot]` is its index in the arrays the step was given.
    pub(super) order: Vec<u32>,
    /// The inverse of `order`, when a step needs it (a pile's search around the flying).
    pub(super) slot_of: Vec<u32>,
    pub(super) predictions: Vec<Prediction>,
    pub(super) queue: ImpactQueue,
    /// The pairs that overlapped at the start of the step, by input index, lower first.
    pub(super) overlapping: Vec<(u32, u32)>,
    /// Every ball on this step's timeline, by slot: all a prediction reads of one ball in
    /// one place (72 B, two cache lines). After a run they are not necessarily moved to the
    /// end of the step (only when that was split between threads): the step's arrays are.
    pub(super) movers: Vec<Mover>,
    pub(super) paths: Paths,
    /// Contacts for the discrete response of a step cut short.
    pub(super) fallback: FoundInBands<IndexedContact>,
    /// The balls the search after an impact found, before each is timed
    /// (`Timeline::predict_for_both`, `Timeline::time_what_was_found`).
    pub(super) found: FoundBalls,
    /// The impact whose found balls are still to be timed (`Timeline::time_what_was_found`).
    pub(super) untimed: Option<Untimed>,
    /// How many of the step's first predictions had been taken when the loads ahead last
    /// loaded the ones ahead of them (`prefetch.rs`): until that changes, they are loaded.
    pub(super) first_loaded: Option<usize>,
    /// The earliest of the impacts predicted during the step, as the loads ahead last saw it,
    /// and how many of their stages they have taken for it (`prefetch.rs`).
    pub(super) later_loaded: Option<(Impact, u8)>,
    /// Whether the last run handled some impact after one that comes later in the impacts'
    /// order (see `Impact`'s `Ord`): then its hits are not in that order.
    pub(super) out_of_order: bool,
    /// Whether every ball the last run moved to the end of the step lay inside the walls
    /// then (`lies_inside`), so that only the balls moved since may need containing.
    pub(super) ends_inside: bool,
    /// Whether some ball in the last run reached its hits for the step ([`hit_limit`]).
    pub cut_short: bool,
    /// The walls' impulse on balls that stopped against them by the resting rule in the last
    /// run, mass x pixels per second: pressure, not hits.
    pub resting_wall_impulse: f64,
}

impl Timeline {
    /// Whether the grid keeps no ball apart as big.
    pub(super) fn has_no_big_ball(&self) -> bool {
        self.grid.small_count() == self.grid.len()
    }

    /// How far apart, along either axis, two balls whose paths could meet in the last run
    /// started, at most; `None` if the grid's cells do not hold their balls. Each path lies
    /// within [`Paths::reach`] of its ball's cell, which holds the centre of the ball's first
    /// path, itself within that reach of its start; two paths meet only if their balls' cells
    /// lie within twice the reach of each other.
    pub(super) fn reach_bound(&self) -> Option<f64> {
        let bound = 2.0 * self.grid.cell_size() + 4.0 * self.paths.reach();
        self.grid.cells_hold_their_balls().then_some(bound)
    }

    /// Each ball's hits in the last run, by its index in the run's arrays, into `hits`.
    pub(super) fn hits_by_index(&self, hits: &mut Vec<u32>) {
        hits.clear();
        hits.resize(self.order.len(), 0);
        for (mover, &index) in self.movers.iter().zip(&self.order) {
            hits[index as usize] = mover.hits;
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::super::impact::random_circles;

    use super::*;
    use crate::sim::continuous::predict::swept_by;

    #[test]
    fn a_step_ends_with_every_flying_ball_unstopped_whatever_the_flags_came_in_as() {
        // The end of the step writes a flying ball's flags only when some ball was held, and
        // otherwise clears `stopped` first: flags that come in dirty must leave clean, with
        // none held and with one.
        let spec = StepSpec::sixtieth(DVec2::splat(300.0), DVec2::ZERO);
        for held_first in [false, true] {
            let mut rng = ChaCha8Rng::seed_from_u64(21);
            let mut circles = random_circles(&mut rng, 1000, 290.0, 3.0..8.0);
            let mut velocities: Vec<DVec2> = (0..1000)
                .map(|_| DVec2::from_angle(rng.random_range(0.0..6.3)) * 900.0)
                .collect();
            // The balls near the first head for it.
            for k in 1..1000 {
                let towards = circles[0].center - circles[k].center;
                if towards.length() < 40.0 {
                    velocities[k] = towards.normalize() * 900.0;
                }
            }
            let (mut held, mut stopped) = (vec![false; 1000], vec![true; 1000]);
            held[0] = held_first;
            let mut timeline = Timeline::default();
            timeline.predict(&circles, &velocities, &held, spec);
            let mut hits = 0;
            let flags = (&mut held[..], &mut stopped[..]);
            timeline.run(&mut circles, &mut velocities, flags, spec, |_| hits += 1);
            assert!(hits > 100, "{hits} hits");
            assert!(!stopped.contains(&true), "held first: {held_first}");
            assert!(!held[1..].contains(&true));
            // The first ball is hit and ends not held: if it came in held, the hit set it flying.
            let mut hits_by_index = Vec::new();
            timeline.hits_by_index(&mut hits_by_index);
            assert!(hits_by_index[0] > 0, "{} hits", hits_by_index[0]);
            assert!(!held[0]);
        }
    }

    #[test]
    fn a_mover_names_its_ball_by_its_index_whether_it_holds_still_or_flies() {
        let circle = Circle::new(DVec2::ZERO, 1.0);
        let last = MAX_BALLS as u32 - 1;
        for (index, still) in [(0, false), (7, true), (last, true), (last, false)] {
            let mut mover = Mover::new(index, circle, DVec2::X, DVec2::NEG_Y, still);
            assert_eq!(mover.is_still(), still, "{index}");
            mover.hold_still();
            assert!(mover.is_still() && mover.accel == DVec2::ZERO);
            assert_eq!(mover.party(3).index, index);
            mover.fly(DVec2::Y, DVec2::NEG_Y);
            mover.hits = 5;
            assert!(!mover.is_still());
            let party = mover.party(3);
            assert_eq!((party.slot, party.index, party.hits), (3, index, 5));
        }
    }

    #[test]
    fn the_grid_holds_each_swept_circle_and_every_mover_is_made_again_after_the_loan() {
        // The movers' buffer holds the swept circles while the grid is built: afterwards the
        // grid must hold each ball's swept circle and every slot its own mover, as the count
        // grows, shrinks and grows again (every seventh ball held still, under gravity).
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let spec = StepSpec::sixtieth(DVec2::splat(400.0), DVec2::new(30.0, -600.0));
        let mut timeline = Timeline::default();
        for count in [1_500, 3_000, 500, 2_000] {
            let circles = random_circles(&mut rng, count, 390.0, 2.0..6.0);
            let velocities: Vec<DVec2> = (0..count)
                .map(|_| DVec2::from_angle(rng.random_range(0.0..6.3)) * 400.0)
                .collect();
            let held: Vec<bool> = (0..count).map(|ball| ball % 7 == 3).collect();
            timeline.predict(&circles, &velocities, &held, spec);
            assert_eq!(timeline.movers.len(), count);
            for slot in 0..count {
                let ball = timeline.order[slot] as usize;
                let mover = Mover::new(
                    ball as u32,
                    circles[ball],
                    velocities[ball],
                    spec.gravity,
                    held[ball],
                );
                let swept = swept_by(&mover, spec.dt);
                assert_eq!(timeline.grid.circle_in_slot(slot), swept, "slot {slot}");
                assert_eq!(timeline.movers[slot], mover, "slot {slot}");
            }
        }
    }

    #[test]
    fn the_hit_limit_covers_twice_a_light_ball_s_chain_of_hits_between_a_heavy_one_and_a_wall() {
        // Up to a ratio of 6.4 (the standard gas's is 3), the fewest.
        for ratio in [1.0, 3.0, 6.4] {
            assert_eq!(hit_limit(ratio), MIN_HITS_PER_BALL, "ratio {ratio}");
        }
        // Galperin's 31 hits for a ratio of 100, 314 for 10,000: twice π√ratio, rounded up.
        assert_eq!(hit_limit(100.0), 63);
        assert_eq!(hit_limit(10_000.0), 629);
        // The mixed scene's radius-40 balls among radius-1.2 ones, mass = radius.
        assert_eq!(hit_limit(40.0 / 1.2), 37);
        // Past any ratio a step can afford, and for no ratio at all, the bounds.
        for ratio in [1e6, f64::INFINITY] {
            assert_eq!(hit_limit(ratio), MAX_HITS_PER_BALL, "ratio {ratio}");
        }
        for ratio in [0.5, 0.0, f64::NAN] {
            assert_eq!(hit_limit(ratio), MIN_HITS_PER_BALL, "ratio {ratio}");
        }
    }
}
