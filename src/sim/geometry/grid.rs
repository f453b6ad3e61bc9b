//! Broad phase: which pairs of balls might touch, before the exact test.
//!
//! Used by both modes' collision stages (the discrete mode sorts the balls' circles, the
//! continuous mode the circles they sweep over the step, and also queries boxes). Two methods
//! find the same pairs: [`UniformGrid`], O(N), the default, and [`for_each_pair`], O(N^2), kept
//! as the reference the grid is tested against.

use bevy::math::DVec2;

use super::circle::Circle;

/// The grid never has more cells than this many per ball, so a few tiny balls in a huge
/// arena cost little memory; the cells grow instead.
const MAX_CELLS_PER_BALL: usize = 4;

/// A uniform grid over the balls' centres, rebuilt from scratch every step by a counting sort.
///
/// The cell side is at least the largest diameter, so two touching circles always sit in the
/// same or in adjacent cells. The buffers are kept between steps to avoid reallocating.
#[derive(Debug, Default)]
pub struct UniformGrid {
    origin: DVec2,
    inverse_cell_size: f64,
    columns: usize,
    rows: usize,
    /// `cell_start[c]..cell_start[c + 1]` is cell `c`'s range in `sorted_*`.
    cell_start: Vec<u32>,
    /// Ball indices in cell order.
    sorted_index: Vec<u32>,
    /// The circles in cell order, so the pair loops read contiguous memory.
    sorted_circle: Vec<Circle>,
    cell_of: Vec<u32>,
}

impl UniformGrid {
    /// Sorts `circles` into cells.
    pub fn rebuild(&mut self, circles: &[Circle]) {
        let (mut min, mut max, mut largest_radius) = (DVec2::MAX, DVec2::MIN, 0.0_f64);
        for circle in circles {
            min = min.min(circle.center);
            max = max.max(circle.center);
            largest_radius = largest_radius.max(circle.radius);
        }
        if circles.is_empty() {
            (min, max) = (DVec2::ZERO, DVec2::ZERO);
        }
        let extent = max - min;
        let max_cells = (circles.len() * MAX_CELLS_PER_BALL).max(1);
        // Smallest cell that holds a diameter and keeps the cell count bounded.
        let cell_size = (2.0 * largest_radius)
            .max((extent.x * extent.y / max_cells as f64).sqrt())
            .max(f64::MIN_POSITIVE);
        self.origin = min;
        // The caps only bind for non-finite extents; clamping cells together never separates
        // two touching balls by more than one cell, so no pair is lost.
        self.columns = cells_along(extent.x, cell_size).min(max_cells);
        self.rows = cells_along(extent.y, cell_size).min((max_cells / self.columns).max(1));
        let cell_count = self.columns * self.rows;

        self.inverse_cell_size = 1.0 / cell_size;
        self.cell_start.clear();
        self.cell_start.resize(cell_count + 1, 0);
        self.cell_of.clear();
        for circle in circles {
            let cell = self.cell_index(circle.center);
            self.cell_of.push(cell as u32);
            self.cell_start[cell] += 1;
        }
        // Inclusive prefix sums: each entry becomes its cell's end. Scattering the balls in
        // reverse then counts each entry down to its cell's start, keeping the balls of a cell
        // in their input order, with no second copy of the table.
        let mut running = 0;
        for count in &mut self.cell_start[..cell_count] {
            running += *count;
            *count = running;
        }
        self.cell_start[cell_count] = circles.len() as u32;
        self.sorted_index.resize(circles.len(), 0);
        for (index, &cell) in self.cell_of.iter().enumerate().rev() {
            let slot = &mut self.cell_start[cell as usize];
            *slot -= 1;
            self.sorted_index[*slot as usize] = index as u32;
        }
        // Scatter only the indices, then gather the circles: independent random reads overlap
        // in the memory system far better than random writes of whole circles.
        self.sorted_circle.clear();
        self.sorted_circle.extend(
            self.sorted_index
                .iter()
                .map(|&index| circles[index as usize]),
        );
    }

    /// Hands over the balls' order in the cells (`order[slot]` is the index the ball had in
    /// the slice given to [`rebuild`](Self::rebuild)) and from now on numbers each ball by its
    /// slot: for a caller that keeps its own per-ball data in cell order, so that balls near
    /// each other in space are near each other in memory.
    pub fn renumber_by_slot(&mut self, order: &mut Vec<u32>) {
        std::mem::swap(order, &mut self.sorted_index);
        self.sorted_index.clear();
        self.sorted_index.extend(0..order.len() as u32);
    }

    /// The circle of the ball in `slot` of the cell order.
    pub fn circle_in_slot(&self, slot: usize) -> Circle {
        self.sorted_circle[slot]
    }

    /// Number of balls sorted in.
    pub fn len(&self) -> usize {
        self.sorted_index.len()
    }

    pub fn is_empty(&self) -> bool {
        self.sorted_index.is_empty()
    }

    /// Rows of cells: the unit [`for_each_candidate_pair_in_rows`](Self::for_each_candidate_pair_in_rows)
    /// splits work by.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Calls `visit(i, j, circle_i, circle_j)` once for every pair of balls in the same or
    /// adjacent cells, in a fixed order (cell by cell, row-major). Indices are the positions
    /// in the slice given to [`rebuild`](Self::rebuild).
    pub fn for_each_candidate_pair(&self, visit: impl FnMut(u32, u32, Circle, Circle)) {
        self.for_each_candidate_pair_in_rows(0..self.rows, visit);
    }

    /// The pairs [`for_each_candidate_pair`](Self::for_each_candidate_pair) visits from the
    /// cells of `rows`, in the same order. Disjoint row ranges visit disjoint pairs, so bands
    /// of rows can be searched in parallel and their results joined in row order.
    pub fn for_each_candidate_pair_in_rows(
        &self,
        rows: std::ops::Range<usize>,
        mut visit: impl FnMut(u32, u32, Circle, Circle),
    ) {
        // In row-major order a cell and its right neighbour are adjacent, and the three cells
        // above (left, centre, right) are one contiguous run: each ball's candidates are two
        // contiguous slot ranges, the rest of its own cell with the right cell, and the run above.
        let columns = self.columns;
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
                let above = if row + 1 < self.rows {
                    let first = cell + columns - usize::from(column > 0);
                    let last = cell + columns + usize::from(column + 1 < columns);
                    self.cell_start[first] as usize..self.cell_start[last + 1] as usize
                } else {
                    0..0
                };
                for slot in start..end {
                    let (index, circle) = (self.sorted_index[slot], self.sorted_circle[slot]);
                    // Two plain loops over slices: no bounds checks and no chained iterator.
                    for range in [slot + 1..same_row_end, above.clone()] {
                        let others = self.sorted_index[range.clone()]
                            .iter()
                            .zip(&self.sorted_circle[range]);
                        for (&other_index, &other) in others {
                            visit(index, other_index, circle, other);
                        }
                    }
                }
            }
        }
    }

    /// Number of cells: [`cell_index`](Self::cell_index) is below it.
    pub fn cell_count(&self) -> usize {
        self.columns * self.rows
    }

    /// The cell holding `point`. A point outside the grid goes to the nearest border cell, so
    /// the cell order along each axis never contradicts the points' order.
    pub fn cell_index(&self, point: DVec2) -> usize {
        let (column, row) = self.cell_coordinates(point);
        row * self.columns + column
    }

    fn cell_coordinates(&self, point: DVec2) -> (usize, usize) {
        // `as usize` saturates (and maps NaN to 0), so a stray value cannot index out of range.
        let cell = (point - self.origin) * self.inverse_cell_size;
        let column = (cell.x as usize).min(self.columns - 1);
        let row = (cell.y as usize).min(self.rows - 1);
        (column, row)
    }

    /// Calls `visit(cells)` with runs of consecutive cell indices that together cover every
    /// cell overlapping the box `[min, max]`: one run per row.
    pub fn for_each_cell_run_in_box(
        &self,
        min: DVec2,
        max: DVec2,
        mut visit: impl FnMut(std::ops::Range<usize>),
    ) {
        let (first_column, first_row) = self.cell_coordinates(min);
        let (last_column, last_row) = self.cell_coordinates(max);
        for row in first_row..=last_row {
            let start = row * self.columns;
            visit(start + first_column..start + last_column + 1);
        }
    }

    /// Calls `visit(index, circle)` for every ball whose centre lies in the box `[min, max]`,
    /// and for some just outside it (the rest of their cells). Indices are as in
    /// [`for_each_candidate_pair`](Self::for_each_candidate_pair).
    pub fn for_each_near(&self, min: DVec2, max: DVec2, mut visit: impl FnMut(u32, Circle)) {
        self.for_each_cell_run_in_box(min, max, |cells| {
            let slots = self.cell_start[cells.start] as usize..self.cell_start[cells.end] as usize;
            for (&index, &circle) in self.sorted_index[slots.clone()]
                .iter()
                .zip(&self.sorted_circle[slots])
            {
                visit(index, circle);
            }
        });
    }
}

fn cells_along(extent: f64, cell_size: f64) -> usize {
    // Saturating casts: a non-finite extent collapses to one cell rather than panicking.
    ((extent / cell_size) as usize).saturating_add(1).max(1)
}

/// Calls `visit(i, j, circle_i, circle_j)` for every pair `i < j`: the O(N^2) reference.
pub fn for_each_pair(circles: &[Circle], mut visit: impl FnMut(u32, u32, Circle, Circle)) {
    for (i, &a) in circles.iter().enumerate() {
        for (j, &b) in circles.iter().enumerate().skip(i + 1) {
            visit(i as u32, j as u32, a, b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_visits_each_nearby_pair_once() {
        let circles: Vec<Circle> = (0..30)
            .map(|i| Circle::new(DVec2::new((i % 6) as f64 * 7.0, (i / 6) as f64 * 7.0), 5.0))
            .collect();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        let mut seen = std::collections::HashSet::new();
        grid.for_each_candidate_pair(|i, j, _, _| {
            assert_ne!(i, j);
            assert!(
                seen.insert((i.min(j), i.max(j))),
                "pair ({i}, {j}) visited twice"
            );
        });
        // Every pair within one diameter must be among the candidates.
        for_each_pair(&circles, |i, j, a, b| {
            if a.center.distance(b.center) <= a.radius + b.radius {
                assert!(seen.contains(&(i, j)), "grid missed pair ({i}, {j})");
            }
        });
    }

    #[test]
    fn grid_survives_empty_single_and_non_finite_input() {
        let mut grid = UniformGrid::default();
        grid.rebuild(&[]);
        grid.for_each_candidate_pair(|_, _, _, _| panic!("no pairs in an empty grid"));
        grid.rebuild(&[Circle::new(DVec2::ZERO, 1.0)]);
        grid.for_each_candidate_pair(|_, _, _, _| panic!("no pairs with one ball"));
        let strange = [
            Circle::new(DVec2::new(f64::NAN, 0.0), 1.0),
            Circle::new(DVec2::new(f64::INFINITY, 0.0), 1.0),
            Circle::new(DVec2::ZERO, 1.0),
        ];
        grid.rebuild(&strange);
        let mut pairs = 0;
        grid.for_each_candidate_pair(|_, _, _, _| pairs += 1);
        assert!(pairs <= 3);
    }

    #[test]
    fn cell_count_stays_bounded_for_tiny_balls_far_apart() {
        let circles = [
            Circle::new(DVec2::new(-1.0e6, -1.0e6), 0.5),
            Circle::new(DVec2::new(1.0e6, 1.0e6), 0.5),
        ];
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        assert!(grid.columns * grid.rows <= 2 * MAX_CELLS_PER_BALL + 4);
    }

    #[test]
    fn a_box_query_finds_every_centre_inside_it() {
        let circles: Vec<Circle> = (0..400)
            .map(|i| {
                let (x, y) = ((i * 37 % 101) as f64 * 3.3, (i * 61 % 97) as f64 * 2.9);
                Circle::new(DVec2::new(x, y), 1.0 + (i % 5) as f64)
            })
            .collect();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        // Boxes inside, across and wholly outside the grid's extent.
        for (min, max) in [
            (DVec2::new(50.0, 40.0), DVec2::new(120.0, 90.0)),
            (DVec2::new(-500.0, 200.0), DVec2::new(30.0, 1_000.0)),
            (DVec2::new(400.0, 400.0), DVec2::new(900.0, 900.0)),
        ] {
            let mut visited = std::collections::HashSet::new();
            grid.for_each_near(min, max, |index, circle| {
                assert_eq!(circle, circles[index as usize]);
                assert!(visited.insert(index), "ball {index} visited twice");
            });
            for (index, circle) in circles.iter().enumerate() {
                let inside = circle.center.cmpge(min).all() && circle.center.cmple(max).all();
                assert!(
                    !inside || visited.contains(&(index as u32)),
                    "missed {index}"
                );
            }
        }
    }
}
