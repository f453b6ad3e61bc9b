//! Stage 3's loads ahead, continuous: what the impacts about to be taken will read, brought
//! into the cache before they read it. Impacts come in time order, so each one's balls lie
//! anywhere in memory, and at a million balls waiting for those reads is most of an impact's
//! cost (docs/performance.md, *Prefetching the coming impacts* and *The loads ahead in three
//! stages*). The timeline's loop calls
//! [`Timeline::prefetch_coming`] before each impact, and the pass that puts the balls on the
//! timeline calls [`prefetch_inputs`] a few balls ahead; nothing here changes a result.

use bevy::math::DVec2;

use super::impact::Impact;
use super::state::{Mover, Timeline};
use crate::sim::cache::{PREFETCH_MIN_BALLS, prefetch, prefetch_whole};
use crate::sim::geometry::circle::Circle;

/// How many of the step's first predictions ahead [`Timeline::prefetch_coming`] loads the
/// cells around a ball (half as many again ahead, where their rows start; twice as many, the
/// balls themselves): 2 and 8 did as well at a million balls.
const PREFETCH_DISTANCE: usize = 4;

impl Timeline {
    /// Whether this step's balls are enough for the loads to pay ([`PREFETCH_MIN_BALLS`]:
    /// below it, 1–2% at 1,000 and 10,000 balls with the plain loads the timeline first made,
    /// 1–3% with the prefetch instruction; the timeline's arrays are about 130 B a ball).
    pub(super) fn worth_prefetching(&self) -> bool {
        self.movers.len() >= PREFETCH_MIN_BALLS
    }

    /// Loads what the impacts about to be taken will read, so that it is in the cache when
    /// they are: impacts come in time order, so each one's balls lie anywhere in memory, and
    /// at a million balls waiting for those reads is most of an impact's cost
    /// (docs/performance.md, *Prefetching the coming impacts*). In three stages, each reading
    /// only what the one before loaded: the balls and their cells; then where the rows of
    /// cells around the first ball start; then those rows' first circles (every circle of a
    /// wider region for very many balls: `UniformGrid::prefetch_cells_around`). For the step's
    /// first predictions, a few places ahead, a stage each, once for each of them taken (an
    /// impact predicted since, taken, leaves them where they were); for the earliest impact
    /// predicted since, a stage at each call while it stays the earliest, so that no stage
    /// waits for what the one before is still loading. A first prediction already stale
    /// when its later stages come due (a ball of it hit since) has them skipped: it will be
    /// skipped when taken. Nothing here changes a result.
    pub(super) fn prefetch_coming(&mut self) {
        let taken = self.queue.first_taken();
        if self.first_loaded != Some(taken) {
            self.first_loaded = Some(taken);
            self.prefetch_first_ahead();
        }
        self.prefetch_earliest_later();
    }

    /// The three stages of the loads for the step's first predictions a few places ahead.
    fn prefetch_first_ahead(&self) {
        if let Some(&further) = self.queue.ahead(2 * PREFETCH_DISTANCE) {
            self.prefetch_balls(further);
        }
        if let Some(middle) = self.queue.ahead(PREFETCH_DISTANCE * 3 / 2)
            && self.still_holds(middle)
        {
            self.grid.prefetch_cell_starts_around(middle.a as usize);
        }
        if let Some(nearer) = self.queue.ahead(PREFETCH_DISTANCE)
            && self.still_holds(nearer)
        {
            self.grid.prefetch_cells_around(nearer.a as usize);
        }
    }

    /// The next stage of the loads for the earliest impact predicted during the step: its
    /// balls when it is new, then where the rows around its first ball start, then their
    /// first circles, then nothing more.
    fn prefetch_earliest_later(&mut self) {
        let Some(&later) = self.queue.earliest_later() else {
            return;
        };
        let stage = match self.later_loaded {
            Some((seen, stage)) if seen == later => stage,
            _ => 0,
        };
        match stage {
            0 => self.prefetch_balls(later),
            1 => self.grid.prefetch_cell_starts_around(later.a as usize),
            2 => self.grid.prefetch_cells_around(later.a as usize),
            _ => {}
        }
        self.later_loaded = Some((later, stage.saturating_add(1)));
    }

    /// Loads the movers of `impact`'s balls and their slots in the grid (the second's circle
    /// is read to tell whether the first's search would find it).
    fn prefetch_balls(&self, impact: Impact) {
        prefetch_mover(&self.movers, impact.a);
        if impact.wall().is_none() {
            prefetch_mover(&self.movers, impact.other);
            self.grid.prefetch_slot(impact.other as usize);
        }
        self.grid.prefetch_slot(impact.a as usize);
    }
}

/// How many slots ahead of the ball it is placing the pass that puts the balls on the
/// timeline (`predict.rs`, `place_movers`) loads a ball's inputs ([`prefetch_inputs`]). At a
/// million balls a ball takes that pass about 8 ns, far less than a read from memory: 16
/// ahead was 0.4–1.5% slower there, and the same at 100,000 (64 ahead no better than 32).
pub(super) const INPUTS_AHEAD: usize = 32;

/// Loads what the collision stage was given for the ball in `slot` (its circle, both lines of
/// it when it straddles two, as a quarter of them do; its velocity and whether it is held),
/// for many balls: the movers are made in the grid's slot order, which reads the inputs by
/// each ball's index, scattered in memory. At 100,000 balls that pass spent most of its time
/// waiting for those reads (docs/performance.md, *The inputs loaded ahead of the movers*);
/// the circle's second line took another 0.8–1% off at 100,000 balls and a million (the
/// fortieth session).
pub(super) fn prefetch_inputs(
    (circles, velocities, held): (&[Circle], &[DVec2], &[bool]),
    order: &[u32],
    slot: usize,
) {
    let Some(&ball) = order
        .get(slot)
        .filter(|_| order.len() >= PREFETCH_MIN_BALLS)
    else {
        return;
    };
    let ball = ball as usize;
    prefetch_whole(circles.get(ball));
    prefetch(velocities.get(ball));
    prefetch(held.get(ball));
}

/// Loads the mover in `slot`, if any: both cache lines a mover (72 B) spans.
pub(super) fn prefetch_mover(movers: &[Mover], slot: u32) {
    prefetch_whole(movers.get(slot as usize));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::continuous::impact::Party;

    #[test]
    fn loading_the_inputs_ahead_asks_only_for_balls_that_are_there() {
        // Many balls (loads asked for) and few (none), slots past the end, and an order that
        // names a ball past the inputs: nothing is read out of bounds.
        for count in [10, PREFETCH_MIN_BALLS + 10] {
            let circles = vec![Circle::new(DVec2::ZERO, 1.0); count];
            let velocities = vec![DVec2::ZERO; count];
            let held = vec![false; count];
            let mut order: Vec<u32> = (0..count as u32).rev().collect();
            order[0] = count as u32 + 5;
            let inputs = (&circles[..], &velocities[..], &held[..]);
            for slot in [0, 1, count - 1, count, count + INPUTS_AHEAD, usize::MAX] {
                prefetch_inputs(inputs, &order, slot);
            }
        }
    }

    #[test]
    fn an_impact_holds_for_the_loads_until_one_of_its_balls_is_hit_again() {
        let party = |slot: usize, hits: u32| Party {
            slot,
            index: slot as u32,
            hits,
        };
        let mut timeline = Timeline {
            movers: vec![Mover::default(); 4],
            ..Timeline::default()
        };
        let between = Impact::between(0.003, party(1, 0), party(2, 0));
        let wall = Impact::with_wall(0.004, party(3, 0), crate::sim::geometry::Wall::Left);
        assert!(timeline.still_holds(&between) && timeline.still_holds(&wall));
        // Either ball of a pair hit since: stale; a wall's impact looks at its ball alone.
        timeline.movers[2].hits = 1;
        assert!(!timeline.still_holds(&between));
        assert!(timeline.still_holds(&Impact::between(0.005, party(1, 0), party(2, 1))));
        timeline.movers[1].hits = 1;
        assert!(!timeline.still_holds(&Impact::between(0.005, party(1, 0), party(2, 1))));
        timeline.movers[3].hits = 2;
        assert!(!timeline.still_holds(&wall));
        assert!(timeline.still_holds(&Impact::with_wall(0.006, party(3, 2), wall.wall().unwrap())));
        // A slot past the movers (never so on the timeline) holds nothing.
        assert!(!timeline.still_holds(&Impact::between(0.007, party(1, 1), party(9, 0))));
    }

    #[test]
    fn the_loads_ahead_follow_what_is_taken_and_the_earliest_later_one_by_stages() {
        let party = |slot: usize| Party {
            slot,
            index: slot as u32,
            hits: 0,
        };
        let impact = |time, a, b| Impact::between(time, party(a), party(b));
        let mut timeline = Timeline::default();
        let first = [impact(0.002, 0, 1), impact(0.014, 4, 5)];
        timeline.queue.start(first.into_iter(), 1.0 / 60.0);
        let stage = |timeline: &Timeline| timeline.later_loaded.map(|(_, stage)| stage);
        timeline.prefetch_coming();
        assert_eq!(timeline.first_loaded, Some(0));
        assert_eq!(stage(&timeline), None, "nothing predicted since the start");
        let (later, earlier) = (impact(0.010, 0, 1), impact(0.005, 2, 3));
        timeline.queue.push(later);
        let stages: Vec<_> = (0..5)
            .map(|_| {
                timeline.prefetch_coming();
                stage(&timeline)
            })
            .collect();
        assert_eq!(stages, [Some(1), Some(2), Some(3), Some(4), Some(5)]);
        assert_eq!(timeline.later_loaded.map(|(seen, _)| seen), Some(later));
        // An earlier one predicted: it starts from its balls.
        timeline.queue.push(earlier);
        timeline.prefetch_coming();
        assert_eq!(timeline.later_loaded, Some((earlier, 1)));
        // The first prediction taken: the ones ahead of it are loaded anew.
        assert_eq!(timeline.queue.pop(), Some(first[0]));
        timeline.prefetch_coming();
        assert_eq!(timeline.first_loaded, Some(1));
        // One predicted since taken: the first ones stay as loaded, and the next earliest
        // later one starts again from its balls.
        assert_eq!(timeline.queue.pop(), Some(earlier));
        timeline.prefetch_coming();
        assert_eq!(timeline.first_loaded, Some(1));
        assert_eq!(timeline.later_loaded, Some((later, 1)));
    }
}
