//! The grid's queries around a place: the cells of a box, and the balls that may touch a
//! circle, the big ones (kept apart in a grid of their own) included. The continuous mode
//! searches around its flying balls with the second, and its `Paths` read the cells of a box
//! and the big balls' part for each ball an impact redirects. Last, the loads that bring a
//! ball's place into the cache ahead of such a query.

use std::ops::Range;

use bevy::math::DVec2;

use super::counting::NO_CELL;
use super::uniform::UniformGrid;
use crate::sim::cache::{prefetch, prefetch_lines};
use crate::sim::geometry::circle::Circle;

/// From this many balls the loads ahead of a query cover four rows of four cells, every cache
/// line of each row, rather than three rows of three cells and their first two lines. At a
/// million balls the continuous search after an impact reads 0.2 rows a search outside the
/// three rows around the ball's cell (its box follows the balls' current circles, not their
/// cells). Below this count the extra loads cost more than they save. The continuous gas, one
/// thread, in turn (docs/performance.md, twenty-eighth session): a million balls −3 to −4%
/// (three rounds), 700,000 −3% (two); 400,000 +3% (two, an earlier cut of the same loads).
const WIDE_LOADS_MIN_BALLS: usize = 700_000;

impl UniformGrid {
    /// Calls `visit(cells)` with runs of consecutive cell indices that together cover every
    /// cell overlapping the box `[min, max]`: one run per row.
    pub fn for_each_cell_run_in_box(
        &self,
        min: DVec2,
        max: DVec2,
        mut visit: impl FnMut(std::ops::Range<usize>),
    ) {
        let (first_column, first_row) = self.cells.cell_coordinates(min);
        let (last_column, last_row) = self.cells.cell_coordinates(max);
        for row in first_row..=last_row {
            let start = row * self.cells.columns;
            visit(start + first_column..start + last_column + 1);
        }
    }

    /// Calls `visit(index, circle)` for every ball whose circle may touch `circle`: every one
    /// that does, and some that do not. Indices are as in
    /// [`for_each_touching_pair`](Self::for_each_touching_pair).
    pub fn for_each_that_may_touch(&self, circle: Circle, mut visit: impl FnMut(u32, Circle)) {
        let near = DVec2::splat(circle.radius + self.small_reach);
        self.visit_cells_in_box(circle.center - near, circle.center + near, &mut visit);
        self.for_each_big_that_may_touch(circle, visit);
    }

    /// The big balls' part of [`for_each_that_may_touch`](Self::for_each_that_may_touch).
    pub fn for_each_big_that_may_touch(&self, circle: Circle, mut visit: impl FnMut(u32, Circle)) {
        if let Some(big) = self.big_grid() {
            let index = |k: u32| self.sorted_index[self.small_count + k as usize];
            big.visit_may_touch_dyn(circle, &mut |k, other| visit(index(k), other));
        }
    }

    fn visit_may_touch_dyn(&self, circle: Circle, visit: &mut dyn FnMut(u32, Circle)) {
        self.for_each_that_may_touch(circle, visit);
    }

    /// Brings what a query around the ball in `slot` reads first, its cell and circle, into
    /// the cache ([`prefetch`]) before the query comes (after
    /// [`renumber_by_slot`](Self::renumber_by_slot)).
    pub fn prefetch_slot(&self, slot: usize) {
        prefetch(self.cell_of.get(slot));
        prefetch(self.sorted_circle.get(slot));
    }

    /// Brings where each row of cells around the ball in `slot` (its cell's row and the rows
    /// beside it, three cells wide; four rows of four, and where each ends, for many balls:
    /// [`WIDE_LOADS_MIN_BALLS`]) starts into the cache: what
    /// [`prefetch_cells_around`](Self::prefetch_cells_around) reads. Best some time after
    /// [`prefetch_slot`](Self::prefetch_slot), which brings the ball's cell, read here.
    #[inline]
    pub fn prefetch_cell_starts_around(&self, slot: usize) {
        if self.loads_wide() {
            self.load_wide_cell_starts_around(slot);
            return;
        }
        for cells in self.cell_runs_around(slot) {
            prefetch(self.cell_start.get(cells.start));
        }
    }

    /// [`prefetch_cell_starts_around`](Self::prefetch_cell_starts_around) for many balls:
    /// where each row of the wider region starts and ends.
    #[inline(never)]
    fn load_wide_cell_starts_around(&self, slot: usize) {
        for cells in self.wide_cell_runs_around(slot) {
            prefetch(self.cell_start.get(cells.start));
            prefetch(self.cell_start.get(cells.end));
        }
    }

    /// Whether the loads ahead cover the wider region ([`WIDE_LOADS_MIN_BALLS`]). Its loads
    /// are kept out of line: chosen between in one function with the narrow ones, they kept
    /// the narrow ones from being inlined into the timeline's loop, 1.4% more instructions at
    /// 30,000 balls.
    fn loads_wide(&self) -> bool {
        self.len() >= WIDE_LOADS_MIN_BALLS
    }

    /// Brings the first circles of each row of cells around the ball in `slot` (its cell's
    /// row and the rows beside it, three cells wide; every circle's line of four rows of four
    /// for many balls: [`WIDE_LOADS_MIN_BALLS`]) into the cache, as
    /// [`prefetch_slot`](Self::prefetch_slot) does: where a query around the ball will read.
    /// A row of three cells holds four or five circles of the gas, 24 B each: the first and
    /// the fourth fall in its first two cache lines. Best some time after
    /// [`prefetch_cell_starts_around`](Self::prefetch_cell_starts_around), which brings what
    /// is read here.
    #[inline]
    pub fn prefetch_cells_around(&self, slot: usize) {
        if self.loads_wide() {
            self.load_wide_cells_around(slot);
            return;
        }
        for cells in self.cell_runs_around(slot) {
            let first_slot = self.cell_start.get(cells.start).map(|&slot| slot as usize);
            for offset in [0, 3] {
                prefetch(first_slot.and_then(|slot| self.sorted_circle.get(slot + offset)));
            }
        }
    }

    /// [`prefetch_cells_around`](Self::prefetch_cells_around) for many balls: every line of
    /// the circles of each row of the wider region.
    #[inline(never)]
    fn load_wide_cells_around(&self, slot: usize) {
        for cells in self.wide_cell_runs_around(slot) {
            if let Some(circles) = self.sorted_circle.get(self.slots_of(cells)) {
                prefetch_lines(circles);
            }
        }
    }

    /// The cells around the ball in `slot` (after [`renumber_by_slot`](Self::renumber_by_slot)):
    /// its cell's row and the rows beside it, each a run of three cells centred on its column
    /// (fewer at the grid's edges). No runs for a big ball, or a slot past the last. From the
    /// ball's cell, not its current circle through
    /// [`for_each_cell_run_in_box`](Self::for_each_cell_run_in_box): that was 3% slower at a
    /// million balls (seven rounds).
    fn cell_runs_around(&self, slot: usize) -> impl Iterator<Item = Range<usize>> + use<> {
        let cell = self.cell_in_row_and_column(slot);
        let (row, column) = cell.unwrap_or((0, 0));
        let (columns, rows) = (self.cells.columns, self.cells.rows);
        let near_rows = if cell.is_some() {
            row.saturating_sub(1)..(row + 2).min(rows)
        } else {
            0..0
        };
        let near_columns = column.saturating_sub(1)..(column + 2).min(columns);
        near_rows
            .map(move |row| row * columns + near_columns.start..row * columns + near_columns.end)
    }

    /// [`cell_runs_around`](Self::cell_runs_around)'s three rows of three cells and the row and
    /// the column beyond them on the side of the ball's cell where its current circle's centre
    /// lies: four rows of four cells (fewer at the grid's edges).
    fn wide_cell_runs_around(&self, slot: usize) -> impl Iterator<Item = Range<usize>> + use<> {
        let cell = self.cell_in_row_and_column(slot);
        let (row, column) = cell.unwrap_or((0, 0));
        let (columns, rows) = (self.cells.columns, self.cells.rows);
        let within = self.sorted_circle.get(slot).map_or(DVec2::ZERO, |circle| {
            self.cells.position_in_cells(circle.center)
        });
        // Two back if the centre lies in the lower half of its cell, along each axis.
        let around = |at: usize, within: f64, count: usize| {
            let back = if within - at as f64 >= 0.5 { 1 } else { 2 };
            at.saturating_sub(back)..(at + 4 - back).min(count)
        };
        let near_rows = if cell.is_some() {
            around(row, within.y, rows)
        } else {
            0..0
        };
        let near_columns = around(column, within.x, columns);
        near_rows
            .map(move |row| row * columns + near_columns.start..row * columns + near_columns.end)
    }

    /// The row and column of the cell of the ball in `slot`: none for a big ball, or a slot past
    /// the last.
    fn cell_in_row_and_column(&self, slot: usize) -> Option<(usize, usize)> {
        let cell = self
            .cell_of
            .get(slot)
            .copied()
            .filter(|&cell| cell != NO_CELL)?;
        Some(self.cells.row_and_column(cell as usize))
    }

    /// The balls in the cells that overlap the box `[min, max]`.
    fn visit_cells_in_box(&self, min: DVec2, max: DVec2, visit: &mut impl FnMut(u32, Circle)) {
        self.for_each_cell_run_in_box(min, max, |cells| {
            let slots = self.slots_of(cells);
            for (&index, &circle) in self.sorted_index[slots.clone()]
                .iter()
                .zip(&self.sorted_circle[slots])
            {
                visit(index, circle);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::geometry::grid::mixed_sizes;

    /// 400 balls of radius 1-5 scattered over about 330 x 280 px.
    fn scattered() -> Vec<Circle> {
        (0..400)
            .map(|i| {
                let (x, y) = ((i * 37 % 101) as f64 * 3.3, (i * 61 % 97) as f64 * 2.9);
                Circle::new(DVec2::new(x, y), 1.0 + (i % 5) as f64)
            })
            .collect()
    }

    #[test]
    fn the_wide_loads_ahead_hold_the_narrow_ones_and_reach_towards_the_ball_s_circle() {
        let circles = scattered();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        let mut order = Vec::new();
        grid.renumber_by_slot(&mut order);
        let (columns, rows) = (grid.cells.columns, grid.cells.rows);
        assert!(columns > 8 && rows > 8, "{columns} x {rows} cells");
        let cells_of = |slot: usize, wide: bool| -> Vec<usize> {
            if wide {
                grid.wide_cell_runs_around(slot).flatten().collect()
            } else {
                grid.cell_runs_around(slot).flatten().collect()
            }
        };
        let mut reached = [0; 2];
        for slot in 0..grid.small_count() {
            let (narrow, wide) = (cells_of(slot, false), cells_of(slot, true));
            assert!(narrow.iter().all(|cell| wide.contains(cell)), "slot {slot}");
            assert!(narrow.len() <= 9 && wide.len() <= 16);
            let cell = grid.cell_of[slot] as usize;
            let (row, column) = (cell / columns, cell % columns);
            let within = grid
                .cells
                .position_in_cells(grid.circle_in_slot(slot).center);
            assert_eq!((within.x as usize, within.y as usize), (column, row));
            // The extra row lies on the side of the cell where the circle's centre is.
            let upper = within.y - row as f64 >= 0.5;
            let extra = if upper { row + 2 } else { row.wrapping_sub(2) };
            if (2..rows - 2).contains(&row) && (2..columns - 2).contains(&column) {
                assert_eq!(wide.len(), 16, "slot {slot}");
                assert!(wide.iter().any(|&c| c / columns == extra), "slot {slot}");
                reached[usize::from(upper)] += 1;
            }
        }
        assert!(reached[0] > 20 && reached[1] > 20, "{reached:?}");
        // Loading them, for every slot, big balls' and past the last too, reads nothing amiss.
        for slot in 0..grid.len() + 3 {
            grid.load_wide_cell_starts_around(slot);
            grid.load_wide_cells_around(slot);
        }
    }

    #[test]
    fn a_circle_query_finds_every_ball_it_touches_inside_across_and_outside_the_grid() {
        let circles = scattered();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        // Probes inside, across and wholly outside the grid's extent.
        for probe in [
            Circle::new(DVec2::new(85.0, 65.0), 40.0),
            Circle::new(DVec2::new(-100.0, 300.0), 140.0),
            Circle::new(DVec2::new(700.0, 700.0), 300.0),
        ] {
            let mut visited = std::collections::HashSet::new();
            grid.for_each_that_may_touch(probe, |index, circle| {
                assert_eq!(circle, circles[index as usize]);
                assert!(visited.insert(index), "ball {index} visited twice");
            });
            let touching = circles
                .iter()
                .enumerate()
                .filter(|(_, c)| c.center.distance(probe.center) <= c.radius + probe.radius);
            let mut count = 0;
            for (index, _) in touching {
                count += 1;
                assert!(visited.contains(&(index as u32)), "missed {index}");
            }
            assert!(
                count > 0 || probe.center.x > 600.0,
                "the probe touches something"
            );
        }
    }

    #[test]
    fn a_circle_query_finds_every_ball_it_touches_big_or_small() {
        let circles = mixed_sizes();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        for probe in [
            Circle::new(DVec2::new(100.0, 95.0), 3.0),
            Circle::new(DVec2::new(30.0, 400.0), 40.0),
            Circle::new(DVec2::new(300.0, 120.0), 1.0),
        ] {
            let mut visited = std::collections::HashSet::new();
            grid.for_each_that_may_touch(probe, |index, circle| {
                assert_eq!(circle, circles[index as usize]);
                assert!(visited.insert(index), "ball {index} visited twice");
            });
            let touched: Vec<usize> = (0..circles.len())
                .filter(|&k| {
                    circles[k].center.distance(probe.center) <= circles[k].radius + probe.radius
                })
                .collect();
            assert!(
                touched.iter().any(|&k| circles[k].radius >= 12.0),
                "a big one touched"
            );
            for k in touched {
                assert!(visited.contains(&(k as u32)), "missed {k}");
            }
        }
    }

    /// `circles` in a grid that numbers them by slot.
    fn renumbered(circles: &[Circle]) -> UniformGrid {
        let mut grid = UniformGrid::default();
        grid.rebuild(circles);
        grid.renumber_by_slot(&mut Vec::new());
        grid
    }

    #[test]
    fn the_cells_prefetched_around_a_ball_hold_it_and_its_neighbours_rows() {
        let grid = renumbered(&mixed_sizes());
        let (columns, rows) = (grid.cells.columns, grid.cells.rows);
        assert!(columns > 3 && rows > 3, "{columns} x {rows} cells");
        let mut inner = 0;
        for slot in 0..grid.small_count() {
            let cell = grid.cell_of[slot] as usize;
            let runs: Vec<Range<usize>> = grid.cell_runs_around(slot).collect();
            assert!(runs.iter().any(|run| run.contains(&cell)), "slot {slot}");
            let (row, column) = (cell / columns, cell % columns);
            let inside = |k: usize, last: usize| usize::from(k > 0) + usize::from(k < last);
            assert_eq!(runs.len(), 1 + inside(row, rows - 1), "slot {slot}");
            for run in &runs {
                assert_eq!(run.len(), 1 + inside(column, columns - 1), "slot {slot}");
                assert_eq!(run.start / columns, (run.end - 1) / columns, "one row");
            }
            inner += usize::from(runs.len() == 3 && runs[0].len() == 3);
            grid.prefetch_slot(slot);
            grid.prefetch_cell_starts_around(slot);
            grid.prefetch_cells_around(slot);
        }
        assert!(inner > 0);
        // Big balls have no cell, and a slot past the last is nothing: both load nothing.
        for slot in grid.small_count()..grid.len() + 3 {
            assert_eq!(grid.cell_runs_around(slot).count(), 0, "slot {slot}");
            assert_eq!(grid.wide_cell_runs_around(slot).count(), 0, "slot {slot}");
            grid.prefetch_slot(slot);
            grid.prefetch_cell_starts_around(slot);
            grid.prefetch_cells_around(slot);
        }
        assert!(grid.small_count() < grid.len(), "some big balls");
    }

    /// Whether a query around `probe` grown by `reach` reads the cell of `slot`.
    fn query_reads(grid: &UniformGrid, probe: Circle, reach: f64, slot: usize) -> bool {
        let near = DVec2::splat(probe.radius + reach);
        let mut found = false;
        grid.for_each_cell_run_in_box(probe.center - near, probe.center + near, |cells| {
            found |= grid.slots_of(cells).contains(&slot);
        });
        found
    }

    #[test]
    fn a_circle_put_in_a_slot_is_found_by_a_query_grown_by_its_reach_from_the_cell() {
        let circles = scattered();
        let grid = renumbered(&circles);
        let (mut missed_by_radius_alone, mut cases) = (0, 0);
        for k in 0..4000_usize {
            let slot = k * 7 % grid.small_count();
            let first = grid.circle_in_slot(slot);
            // Moved up to 30 px, and a probe just touching it from one of 16 directions.
            let shift = DVec2::new((k % 13) as f64 - 6.0, (k % 11) as f64 - 5.0) * 5.0;
            let moved = Circle::new(first.center + shift, 0.5 + (k % 7) as f64);
            let direction = DVec2::from_angle((k % 16) as f64 * std::f64::consts::TAU / 16.0);
            let probe_radius = 0.5 + (k % 3) as f64;
            let gap = moved.radius + probe_radius;
            let probe = Circle::new(moved.center + direction * gap * 0.999, probe_radius);
            let reach = grid.reach_from_cell(slot, moved);
            assert!(
                query_reads(&grid, probe, reach, slot),
                "case {k}: {moved:?}"
            );
            missed_by_radius_alone += usize::from(!query_reads(&grid, probe, moved.radius, slot));
            cases += 1;
        }
        // The distance from the cell matters: without it many would be missed.
        assert!(
            missed_by_radius_alone > cases / 10,
            "{missed_by_radius_alone} of {cases}"
        );
    }
}
