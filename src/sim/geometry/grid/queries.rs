//! The grid's queries around a place: the cells of a box, the balls whose centres lie in a
//! box, and the balls that may touch a circle, the big ones (kept apart in a grid of their
//! own) included. The continuous mode asks them for each ball an impact redirects.

use bevy::math::DVec2;

use super::uniform::UniformGrid;
use crate::sim::geometry::circle::Circle;

impl UniformGrid {
    /// Number of cells: [`cell_index`](Self::cell_index) is below it.
    pub fn cell_count(&self) -> usize {
        self.cells.cell_count()
    }

    /// The cell holding `point`. A point outside the grid goes to the nearest border cell, so
    /// the cell order along each axis never contradicts the points' order.
    pub fn cell_index(&self, point: DVec2) -> usize {
        self.cells.cell_index(point)
    }

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

    /// Calls `visit(index, circle)` for every ball whose centre lies in the box `[min, max]`,
    /// and for some just outside it (the rest of their cells). Indices are as in
    /// [`for_each_candidate_pair`](Self::for_each_candidate_pair).
    pub fn for_each_near(&self, min: DVec2, max: DVec2, mut visit: impl FnMut(u32, Circle)) {
        self.visit_cells_in_box(min, max, &mut visit);
        if let Some(big) = self.big_grid() {
            let index = |k: u32| self.sorted_index[self.small_count + k as usize];
            big.visit_near_dyn(min, max, &mut |k, circle| visit(index(k), circle));
        }
    }

    fn visit_near_dyn(&self, min: DVec2, max: DVec2, visit: &mut dyn FnMut(u32, Circle)) {
        self.for_each_near(min, max, visit);
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
}
