//! The grid's queries around a place: the cells of a box, and the balls that may touch a
//! circle, the big ones (kept apart in a grid of their own) included. The continuous mode
//! searches around its flying balls with the second, and its `Paths` read the cells of a box
//! and the big balls' part for each ball an impact redirects.

use bevy::math::DVec2;

use super::uniform::UniformGrid;
use crate::sim::geometry::circle::Circle;

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
    /// [`for_each_candidate_pair`](Self::for_each_candidate_pair).
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
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        grid.renumber_by_slot(&mut Vec::new());
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
