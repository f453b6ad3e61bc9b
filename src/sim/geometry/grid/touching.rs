//! Which pairs of balls touch: every ball's candidates in the cells, each put through the
//! exact test, in a fixed order ([`UniformGrid::for_each_touching_pair`] and its kin), and
//! that test made on a run of candidates without a branch per candidate
//! ([`TouchingRuns::for_each_touching`]). Most of a grid's candidates do not touch, and which
//! do is a matter of chance, so a branch on each test mispredicts often; testing a run of them
//! first, writing every candidate's slot and keeping it only if it touches, leaves one loop
//! whose branches are predictable and a short one over the few that touch. The test is the
//! caller's: the narrow phase's `circles_touch` (AABB, then distance), or the distance alone
//! (`within_reach`) for the continuous mode's swept circles.

use std::ops::Range;

use super::uniform::UniformGrid;
use crate::sim::geometry::circle::{Circle, circles_touch, within_reach};

/// How many touching slots the buffer holds: candidates are tested half as many at a time, so
/// that what a chunk finds fits beside what the chunks before it found, until they are
/// visited.
const RUN: usize = 32;

/// The slots found touching: one buffer for a whole search, since a fresh one for each ball's
/// runs cost a tenth of the continuous mode's first search to clear.
pub struct TouchingRuns {
    touching: [u32; RUN],
}

impl TouchingRuns {
    pub fn new() -> Self {
        Self { touching: [0; RUN] }
    }

    /// Calls `visit(slot)`, in slot order, for every slot in `slots` whose circle in
    /// `circles` (indexed by slot) touches `circle` by the test `touch`.
    #[inline]
    pub fn for_each_touching(
        &mut self,
        (circle, touch): (Circle, impl Fn(Circle, Circle) -> bool),
        slots: Range<usize>,
        circles: &[Circle],
        visit: impl FnMut(usize),
    ) {
        self.for_each_touching_in((circle, touch), [slots], circles, visit);
    }

    /// [`for_each_touching`](Self::for_each_touching) over each range of `ranges` in turn,
    /// with one pass over the slots found in them all (unless they are many): a ball's two
    /// runs of candidates in the grid, the rest of its row and the row above, so that each
    /// ball takes one short loop over what it found, not two (−1.3% of the continuous
    /// step's instructions, −1.0% of the discrete one's).
    #[inline]
    pub fn for_each_touching_in<const R: usize>(
        &mut self,
        (circle, touch): (Circle, impl Fn(Circle, Circle) -> bool),
        ranges: [Range<usize>; R],
        circles: &[Circle],
        mut visit: impl FnMut(usize),
    ) {
        const CHUNK: usize = RUN / 2;
        let touching = &mut self.touching;
        let mut found = 0;
        for range in ranges {
            let mut start = range.start;
            while start < range.end {
                // At most `CHUNK` found before a chunk of at most `CHUNK`: the buffer holds
                // them all.
                if found > CHUNK {
                    touching[..found]
                        .iter()
                        .for_each(|&slot| visit(slot as usize));
                    found = 0;
                }
                let end = (start + CHUNK).min(range.end);
                for (slot, &other) in (start..end).zip(&circles[start..end]) {
                    // `found` is below `RUN`: the modulo only tells the compiler so, sparing
                    // a bounds check a candidate.
                    touching[found % RUN] = slot as u32;
                    found += usize::from(touch(circle, other));
                }
                start = end;
            }
        }
        touching[..found]
            .iter()
            .for_each(|&slot| visit(slot as usize));
    }
}

impl UniformGrid {
    /// Calls `visit(i, j, circle_i, circle_j)` once for every pair of balls whose circles
    /// touch: the candidates, pairs in the same or adjacent cells and pairs with a big ball
    /// whose circles' boxes might meet, put through the exact test a run at a time
    /// (`touching.rs`). In a fixed order: the big balls' own pairs first, then row by row.
    /// Indices are the positions in the slice given to [`rebuild`](Self::rebuild).
    pub fn for_each_touching_pair(&self, visit: impl FnMut(u32, u32, Circle, Circle)) {
        self.for_each_touching_pair_in_rows(0..self.rows(), visit);
    }

    /// The pairs [`for_each_touching_pair`](Self::for_each_touching_pair) visits from the
    /// cells of `rows`, in the same order (the big balls' own pairs with the first row).
    /// Disjoint row ranges visit disjoint pairs, so bands of rows can be searched in parallel
    /// and their results joined in row order.
    pub fn for_each_touching_pair_in_rows(
        &self,
        rows: std::ops::Range<usize>,
        visit: impl FnMut(u32, u32, Circle, Circle),
    ) {
        self.for_each_pair_in_rows_by(rows, circles_touch, visit);
    }

    /// [`for_each_touching_pair_in_rows`](Self::for_each_touching_pair_in_rows) with the
    /// squared-distance test alone ([`within_reach`]), for bounding circles: the pairs it
    /// visits, and those tangent to the last bit that the AABB test turns away.
    pub fn for_each_pair_within_reach_in_rows(
        &self,
        rows: std::ops::Range<usize>,
        visit: impl FnMut(u32, u32, Circle, Circle),
    ) {
        self.for_each_pair_in_rows_by(rows, within_reach, visit);
    }

    /// The pairs of `rows` whose circles pass `touch`, in the order of
    /// [`for_each_touching_pair_in_rows`](Self::for_each_touching_pair_in_rows).
    fn for_each_pair_in_rows_by(
        &self,
        rows: std::ops::Range<usize>,
        touch: impl Fn(Circle, Circle) -> bool + Copy,
        mut visit: impl FnMut(u32, u32, Circle, Circle),
    ) {
        // With the band that holds the first row (a band may be empty: more bands than rows).
        if rows.contains(&0) {
            self.visit_big_pairs(touch, &mut visit);
        }
        // In row-major order a cell and its right neighbour are adjacent, and the three cells
        // above (left, centre, right) are one contiguous run: each ball's candidates are two
        // contiguous slot ranges, the rest of its own cell with the right cell, and the run
        // above, each tested without a branch per candidate.
        let columns = self.cells.columns;
        let mut runs = TouchingRuns::new();
        for row in rows {
            for column in 0..columns {
                let cell = row * columns + column;
                let (start, end) = (
                    self.cell_start[cell] as usize,
                    self.cell_start[cell + 1] as usize,
                );
                if start == end {
                    continue;
                }
                let same_row_end =
                    self.cell_start[cell + usize::from(column + 1 < columns) + 1] as usize;
                let above = if row + 1 < self.cells.rows {
                    let first = cell + columns - usize::from(column > 0);
                    let last = cell + columns + usize::from(column + 1 < columns);
                    self.cell_start[first] as usize..self.cell_start[last + 1] as usize
                } else {
                    0..0
                };
                for slot in start..end {
                    let (index, circle) = (self.sorted_index[slot], self.sorted_circle[slot]);
                    let ranges = [slot + 1..same_row_end, above.clone()];
                    let probe = (circle, touch);
                    runs.for_each_touching_in(probe, ranges, &self.sorted_circle, |other| {
                        visit(
                            index,
                            self.sorted_index[other],
                            circle,
                            self.sorted_circle[other],
                        );
                    });
                }
            }
            if self.big_grid().is_some() {
                self.visit_big_with_small_in_row(row, (&mut runs, touch), &mut visit);
            }
        }
    }

    /// The pairs of two big balls that pass `touch`, through their own grid.
    fn visit_big_pairs(
        &self,
        touch: impl Fn(Circle, Circle) -> bool + Copy,
        visit: &mut dyn FnMut(u32, u32, Circle, Circle),
    ) {
        if let Some(big) = self.big_grid() {
            let index = |k: u32| self.sorted_index[self.small_count + k as usize];
            big.for_each_pair_in_rows_by(0..big.rows(), touch, |i, j, a, b| {
                visit(index(i), index(j), a, b);
            });
        }
    }

    /// Each big ball that reaches `row` with every ball it touches (by `touch`) in the cells
    /// of `row` it reaches.
    fn visit_big_with_small_in_row(
        &self,
        row: usize,
        (runs, touch): (&mut TouchingRuns, impl Fn(Circle, Circle) -> bool + Copy),
        visit: &mut impl FnMut(u32, u32, Circle, Circle),
    ) {
        for &k in self.big_rows.in_row(row) {
            let slot = self.small_count + k as usize;
            let (index, circle) = (self.sorted_index[slot], self.sorted_circle[slot]);
            let ((first, _), (last, _)) = self.cells.corners_reached(circle, self.small_reach);
            let start = row * self.cells.columns;
            let slots = self.slots_of(start + first..start + last + 1);
            runs.for_each_touching((circle, touch), slots, &self.sorted_circle, |other| {
                visit(
                    index,
                    self.sorted_index[other],
                    circle,
                    self.sorted_circle[other],
                );
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::*;
    use crate::sim::geometry::grid::{for_each_pair, mixed_sizes};

    /// `count` circles of radius 1 along a line, one a pixel, every third one 50 px off it.
    fn along_a_line(count: usize) -> Vec<Circle> {
        (0..count)
            .map(|k| {
                let y = if k % 3 == 0 { 50.0 } else { 0.0 };
                Circle::new(DVec2::new(k as f64, y), 1.0)
            })
            .collect()
    }

    #[test]
    fn every_touching_slot_is_visited_once_in_order_and_no_other() {
        // Slots 5..100 are tested in chunks 5..21, 21..37, 37..53 and so on.
        let circles = along_a_line(100);
        let visited = |probe: Circle, slots: Range<usize>| {
            let mut visited = Vec::new();
            let mut runs = TouchingRuns::new();
            let probe = (probe, circles_touch);
            runs.for_each_touching(probe, slots, &circles, |slot| visited.push(slot));
            visited
        };
        // Across two chunks: 35, 37 and 38 lie within 3 px (36 and 39 are far off).
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

    #[test]
    fn the_pairs_within_reach_are_the_references_whatever_the_bands() {
        // Mixed sizes (big balls apart, and the biggest apart again), and a row of tangent
        // pairs: centres 1.1 apart with radii 0.55, which rounding may put either way.
        let mut circles = mixed_sizes();
        circles.extend((0..40).map(|k| Circle::new(DVec2::new(k as f64 * 1.1, -30.0), 0.55)));
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        let rows = grid.rows();
        let mut all = Vec::new();
        grid.for_each_pair_within_reach_in_rows(0..rows, |i, j, a, b| {
            assert_eq!((a, b), (circles[i as usize], circles[j as usize]));
            all.push((i.min(j), i.max(j)));
        });
        let mut expected = Vec::new();
        for_each_pair(&circles, |i, j, a, b| {
            if within_reach(a, b) {
                expected.push((i, j));
            }
        });
        let mut sorted = all.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, expected);
        assert!(expected.len() > 300, "{} pairs", expected.len());
        for bands in [2, 5, rows + 3] {
            let mut joined = Vec::new();
            for band in 0..bands {
                let band_rows = rows * band / bands..rows * (band + 1) / bands;
                grid.for_each_pair_within_reach_in_rows(band_rows, |i, j, _, _| {
                    joined.push((i.min(j), i.max(j)));
                });
            }
            assert_eq!(joined, all, "{bands} bands");
        }
    }

    #[test]
    fn several_ranges_visit_each_one_s_touching_slots_in_turn_however_many() {
        let circles = along_a_line(200);
        let mut runs = TouchingRuns::new();
        let mut most = 0;
        // Few found, none, and more than the buffer holds (so it is emptied on the way), in
        // ranges taken in any order, empty ones too.
        let cases = [
            (2.0, [5..40, 60..70]),
            (5.0, [10..10, 30..31]),
            (60.0, [0..100, 120..200]),
            (300.0, [150..200, 0..120]),
            (300.0, [7..7, 0..200]),
        ];
        for (radius, ranges) in cases {
            let probe = Circle::new(DVec2::new(64.0, 0.0), radius);
            let mut visited = Vec::new();
            let each = ranges.clone();
            runs.for_each_touching_in((probe, circles_touch), each, &circles, |slot| {
                visited.push(slot);
            });
            let expected: Vec<usize> = ranges
                .iter()
                .flat_map(|range| range.clone())
                .filter(|&slot| circles_touch(probe, circles[slot]))
                .collect();
            assert_eq!(visited, expected, "radius {radius}, {ranges:?}");
            most = most.max(visited.len());
        }
        assert!(most > 4 * RUN, "{most} at most");
    }
}
