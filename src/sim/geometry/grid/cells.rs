//! The grid's cells as geometry: where they start, how big they are, and which cell holds a
//! point. [`CellMap`] is a plain value, so the grid's passes copy it and borrow nothing.

use bevy::math::DVec2;

use crate::sim::geometry::circle::Circle;

/// The grid never has more cells than this many per ball, so a few tiny balls in a huge
/// arena cost little memory; the cells grow instead.
const MAX_CELLS_PER_BALL: usize = 4;

/// Square cells in rows and columns over a rectangle, numbered row-major from `origin`.
#[derive(Clone, Copy, Debug, Default)]
pub struct CellMap {
    origin: DVec2,
    inverse_cell_size: f64,
    pub columns: usize,
    pub rows: usize,
    /// Whether the cap on cells left the rectangle's last columns or rows to share the border
    /// cells (see [`cell_index`](Self::cell_index)).
    pub capped: bool,
}

impl CellMap {
    /// The smallest cells over `[min, max]` that hold a circle of radius `largest_radius`
    /// (so two touching circles sit in the same or adjacent cells), at most
    /// `MAX_CELLS_PER_BALL` (4) cells for each of `balls`.
    pub fn covering(min: DVec2, max: DVec2, largest_radius: f64, balls: usize) -> Self {
        let extent = max - min;
        // At most `u32::MAX` along an axis, which `cell_coordinates` counts on.
        let max_cells = (balls * MAX_CELLS_PER_BALL).clamp(1, u32::MAX as usize);
        let cell_size = (2.0 * largest_radius)
            .max((extent.x * extent.y / max_cells as f64).sqrt())
            .max(f64::MIN_POSITIVE);
        // The caps only bind for non-finite extents; clamping cells together never separates
        // two touching balls by more than one cell, so no pair is lost.
        let (columns_needed, rows_needed) = (
            cells_along(extent.x, cell_size),
            cells_along(extent.y, cell_size),
        );
        let columns = columns_needed.min(max_cells);
        let rows = rows_needed.min((max_cells / columns).max(1));
        Self {
            origin: min,
            inverse_cell_size: 1.0 / cell_size,
            columns,
            rows,
            capped: columns < columns_needed || rows < rows_needed,
        }
    }

    /// Where `point` lies, in cells from the origin: its cell's column and row are the whole
    /// parts.
    pub fn position_in_cells(&self, point: DVec2) -> DVec2 {
        (point - self.origin) * self.inverse_cell_size
    }

    /// The side of a cell.
    pub fn cell_size(&self) -> f64 {
        1.0 / self.inverse_cell_size
    }

    /// How far, along either axis, `point` lies outside cell `cell` (zero inside), with a
    /// margin against rounding: a box around `point` grown by this reaches the cell.
    pub fn distance_to_cell(&self, cell: usize, point: DVec2) -> f64 {
        let size = self.cell_size();
        let corner = DVec2::new((cell % self.columns) as f64, (cell / self.columns) as f64);
        let low = self.origin + corner * size;
        let outside = (low - point).max(point - (low + size)).max(DVec2::ZERO);
        let margin = 1e-9 * (size + point.abs().max_element() + self.origin.abs().max_element());
        outside.max_element() + margin
    }

    pub fn cell_count(&self) -> usize {
        self.columns * self.rows
    }

    /// The cell holding `point`. A point outside the grid goes to the nearest border cell, so
    /// the cell order along each axis never contradicts the points' order.
    pub fn cell_index(&self, point: DVec2) -> usize {
        let (column, row) = self.cell_coordinates(point);
        row * self.columns + column
    }

    /// `(column, row)` of the first and last cells that `circle`, grown by `reach`, overlaps:
    /// the cells holding every ball of radius up to `reach` it may touch.
    pub fn corners_reached(&self, circle: Circle, reach: f64) -> ((usize, usize), (usize, usize)) {
        let near = DVec2::splat(circle.radius + reach);
        (
            self.cell_coordinates(circle.center - near),
            self.cell_coordinates(circle.center + near),
        )
    }

    /// `(column, row)` of the cell holding `point`, clamped to the grid as
    /// [`cell_index`](Self::cell_index) is.
    pub fn cell_coordinates(&self, point: DVec2) -> (usize, usize) {
        // `as u32` saturates (and maps NaN to 0), so a stray value cannot index out of range;
        // through `u32` rather than straight to `usize`, whose conversion takes more
        // instructions (−2% a continuous step), for the same cells: no grid has more than
        // `u32::MAX` along an axis (`covering`).
        let cell = self.position_in_cells(point);
        let column = (cell.x as u32 as usize).min(self.columns - 1);
        let row = (cell.y as u32 as usize).min(self.rows - 1);
        (column, row)
    }
}

fn cells_along(extent: f64, cell_size: f64) -> usize {
    // Saturating casts: a non-finite extent collapses to one cell rather than panicking.
    ((extent / cell_size) as usize).saturating_add(1).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_anywhere_lands_where_the_straight_conversion_puts_it() {
        let map = CellMap::covering(DVec2::splat(-100.0), DVec2::splat(100.0), 1.0, 10_000);
        let straight = |point: DVec2| {
            let cell = (point - map.origin) * map.inverse_cell_size;
            let column = (cell.x as usize).min(map.columns - 1);
            (column, (cell.y as usize).min(map.rows - 1))
        };
        let values = [
            f64::NAN,
            f64::NEG_INFINITY,
            -1e300,
            -101.0,
            -100.0,
            -0.0,
            37.5,
            99.99,
            100.0,
            1e12,
            1e300,
            f64::INFINITY,
        ];
        for x in values {
            for y in values {
                let point = DVec2::new(x, y);
                assert_eq!(map.cell_coordinates(point), straight(point), "{point}");
            }
        }
        // However many cells a degenerate extent asks for, at most `u32::MAX` along an axis.
        let line = CellMap::covering(
            DVec2::new(-1e300, 0.0),
            DVec2::new(1e300, 0.0),
            1e-300,
            1 << 40,
        );
        assert_eq!((line.columns, line.rows), (u32::MAX as usize, 1));
        assert_eq!(
            line.cell_coordinates(DVec2::new(1e300, 0.0)).0,
            u32::MAX as usize - 1
        );
    }

    #[test]
    fn cell_count_stays_bounded_for_tiny_balls_far_apart() {
        let map = CellMap::covering(DVec2::splat(-1.0e6), DVec2::splat(1.0e6), 0.5, 2);
        assert!(map.cell_count() <= 2 * MAX_CELLS_PER_BALL + 4);
    }
}
