//! The exact test on a run of candidates without a branch per candidate:
//! [`TouchingRuns::for_each_touching`]. Most of a grid's candidates do not touch, and which do
//! is a matter of chance, so a branch on each test mispredicts often; testing a run of them
//! first, writing every candidate's place in the run and keeping it only if it touches, leaves
//! one loop whose branches are predictable and a short one over the few that touch.

use std::ops::Range;

use crate::sim::geometry::circle::{Circle, circles_touch};

/// How many candidates are tested at once.
const RUN: usize = 32;

/// The places in a run found touching: one buffer for a whole search, since a fresh one for
/// each ball's runs cost a tenth of the continuous mode's first search to clear.
pub struct TouchingRuns {
    touching: [u32; RUN],
}

impl TouchingRuns {
    pub fn new() -> Self {
        Self { touching: [0; RUN] }
    }

    /// Calls `visit(slot)`, in slot order, for every slot in `slots` whose circle in
    /// `circles` (indexed by slot) touches `circle`.
    #[inline]
    pub fn for_each_touching(
        &mut self,
        circle: Circle,
        slots: Range<usize>,
        circles: &[Circle],
        mut visit: impl FnMut(usize),
    ) {
        let touching = &mut self.touching;
        let mut start = slots.start;
        while start < slots.end {
            let end = (start + RUN).min(slots.end);
            let mut found = 0;
            for (offset, &other) in circles[start..end].iter().enumerate() {
                // `found` is at most `offset`, so below `RUN`: the modulo only tells the
                // compiler so, sparing a bounds check a candidate.
                touching[found % RUN] = offset as u32;
                found += usize::from(circles_touch(circle, other));
            }
            touching[..found]
                .iter()
                .for_each(|&offset| visit(start + offset as usize));
            start = end;
        }
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::*;

    #[test]
    fn every_touching_slot_is_visited_once_in_order_and_no_other() {
        // 100 circles of radius 1 along a line, every third one far off; slots 5..100 are
        // tested in runs 5..37, 37..69 and 69..100.
        let circles: Vec<Circle> = (0..100)
            .map(|k| {
                let y = if k % 3 == 0 { 50.0 } else { 0.0 };
                Circle::new(DVec2::new(k as f64, y), 1.0)
            })
            .collect();
        let visited = |probe: Circle, slots: Range<usize>| {
            let mut visited = Vec::new();
            let mut runs = TouchingRuns::new();
            runs.for_each_touching(probe, slots, &circles, |slot| visited.push(slot));
            visited
        };
        // Across the first two runs: 35, 37 and 38 lie within 3 px (36 and 39 are far off).
        let probe = Circle::new(DVec2::new(37.0, 2.0), 2.0);
        assert_eq!(visited(probe, 5..100), vec![35, 37, 38]);
        let expected: Vec<usize> = (5..100)
            .filter(|&slot| circles_touch(probe, circles[slot]))
            .collect();
        assert_eq!(visited(probe, 5..100), expected);
        // Touching at the very edge counts; slots outside the range are not tested.
        let edge = Circle::new(DVec2::new(37.0, 3.0), 2.0);
        assert_eq!(visited(edge, 5..100), vec![37]);
        assert!(visited(probe, 36..37).is_empty());
        assert!(visited(probe, 60..60).is_empty());
        assert_eq!(visited(probe, 38..39), vec![38]);
    }
}
