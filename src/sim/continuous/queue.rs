//! The timeline's queue of impacts, earliest first. Most of a step's impacts are predicted
//! at its start: those are sorted once and read in order, and only the ones predicted during
//! the step (after an impact redirects a ball) go into a heap, which stays small. Taking the
//! earlier of the two heads gives the order one heap of them all would give.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::impact::Impact;

/// Impacts, taken earliest first (then by [`Impact`]'s order of the balls).
#[derive(Debug, Default)]
pub struct ImpactQueue {
    /// The impacts predicted at the start of the step, in order; `sorted[next..]` are left.
    sorted: Vec<Impact>,
    next: usize,
    /// The impacts predicted since.
    later: BinaryHeap<Reverse<Impact>>,
}

impl ImpactQueue {
    /// Empties the queue and fills it with the step's first predictions.
    pub fn start(&mut self, impacts: impl Iterator<Item = Impact> + Clone) {
        self.sorted.clear();
        // Exactly what is needed: the buffer is kept from step to step.
        self.sorted.reserve_exact(impacts.clone().count());
        self.sorted.extend(impacts);
        self.sorted.sort_unstable();
        self.next = 0;
        self.later.clear();
    }

    /// Adds an impact predicted during the step.
    pub fn push(&mut self, impact: Impact) {
        self.later.push(Reverse(impact));
    }

    /// The step's first prediction `distance` places after the next one left: most likely
    /// taken soon (an impact predicted since may come first, or make it stale).
    pub fn ahead(&self, distance: usize) -> Option<&Impact> {
        self.sorted.get(self.next + distance)
    }

    /// The earliest impact predicted during the step: it may be taken next.
    pub fn earliest_later(&self) -> Option<&Impact> {
        self.later.peek().map(|Reverse(impact)| impact)
    }

    /// Takes the earliest impact left.
    pub fn pop(&mut self) -> Option<Impact> {
        let first = self.sorted.get(self.next);
        match (first, self.later.peek()) {
            (Some(first), Some(Reverse(later))) if later < first => {
                self.later.pop().map(|Reverse(impact)| impact)
            }
            (Some(&first), _) => {
                self.next += 1;
                Some(first)
            }
            (None, _) => self.later.pop().map(|Reverse(impact)| impact),
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::sim::continuous::impact::Party;

    #[test]
    fn the_two_sources_come_out_as_one_heap_of_them_all_would() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut impact = |time: f64| {
            let ball = |rng: &mut ChaCha8Rng| {
                let index = rng.random_range(0..50u32);
                Party {
                    slot: index as usize,
                    index,
                    hits: rng.random_range(0..3),
                }
            };
            let (i, j) = (ball(&mut rng), ball(&mut rng));
            Impact::between(time, i, j)
        };
        // Equal times on purpose: the balls' order must break the ties the same way.
        let first: Vec<Impact> = (0..300).map(|k| impact((k % 40) as f64 * 0.01)).collect();
        let mut queue = ImpactQueue::default();
        queue.start(first.iter().copied());
        let mut heap: BinaryHeap<Reverse<Impact>> = first.iter().copied().map(Reverse).collect();
        let (mut taken, mut expected) = (Vec::new(), Vec::new());
        for round in 0..600 {
            // Now and then an impact predicted during the step, never before the last taken.
            if round % 3 == 0 {
                let now = taken.last().map_or(0.0, |i: &Impact| i.time);
                let later = impact(now + (round % 7) as f64 * 0.005);
                queue.push(later);
                heap.push(Reverse(later));
            }
            match (queue.pop(), heap.pop()) {
                (Some(a), Some(Reverse(b))) => {
                    taken.push(a);
                    expected.push(b);
                }
                (None, None) => break,
                (a, b) => panic!("one source ran dry first: {a:?} {b:?}"),
            }
        }
        assert!(taken.len() > 400, "{} taken", taken.len());
        assert_eq!(taken, expected);
    }
}
