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
    /// `1 / inverse_cell_size`, worked out once: a query's reach reads it for every ball an
    /// impact redirects.
    cell_size: f64,
    pub columns: usize,
    /// Divides a cell's number by `columns` without a division instruction.
    by_columns: Divisor,
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
        let inverse_cell_size = 1.0 / cell_size;
        Self {
            origin: min,
            inverse_cell_size,
            cell_size: 1.0 / inverse_cell_size,
            columns,
            // At most `u32::MAX` columns (`max_cells`), and at least one.
            by_columns: Divisor::new(columns as u32),
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
        self.cell_size
    }

    /// `(row, column)` of cell `cell`, one of this map's.
    #[inline]
    pub fn row_and_column(&self, cell: usize) -> (usize, usize) {
        debug_assert!(cell < self.cell_count(), "cell {cell} past the map");
        let (row, column) = self.by_columns.quotient_and_remainder(cell as u32);
        (row as usize, column as usize)
    }

    /// How far, along either axis, `point` lies outside cell `cell` (zero inside), with a
    /// margin against rounding: a box around `point` grown by this reaches the cell.
    pub fn distance_to_cell(&self, cell: usize, point: DVec2) -> f64 {
        let size = self.cell_size();
        let (row, column) = self.row_and_column(cell);
        let corner = DVec2::new(column as f64, row as f64);
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

/// Division by a `u32` fixed in advance, through a multiplication: the quotient and remainder
/// of any `u32` (D. Lemire, O. Kaser, N. Kurz, *Faster remainder by direct computation*,
/// 2019: a 64-bit reciprocal is exact for 32-bit numerators). A division instruction takes a
/// dozen cycles or more, on the path of every query that starts from a ball's cell.
#[derive(Clone, Copy, Debug, Default)]
struct Divisor {
    divisor: u32,
    /// `ceil(2^64 / divisor)`, or 0 for a divisor of 1 (which would need 2^64).
    reciprocal: u64,
}

impl Divisor {
    /// Dividing by `divisor`, at least 1.
    fn new(divisor: u32) -> Self {
        assert!(divisor > 0, "a division by zero");
        Self {
            divisor,
            reciprocal: (u64::MAX / u64::from(divisor)).wrapping_add(1),
        }
    }

    /// `(n / divisor, n % divisor)`.
    #[inline]
    fn quotient_and_remainder(self, n: u32) -> (u32, u32) {
        if self.divisor == 1 {
            return (n, 0);
        }
        let quotient = (u128::from(self.reciprocal) * u128::from(n)) >> 64;
        let fraction = self.reciprocal.wrapping_mul(u64::from(n));
        let remainder = (u128::from(fraction) * u128::from(self.divisor)) >> 64;
        (quotient as u32, remainder as u32)
    }
}

fn cells_along(extent: f64, cell_size: f64) -> usize {
    // Saturating casts: a non-finite extent collapses to one cell rather than panicking.
    ((extent / cell_size) as usize).saturating_add(1).max(1)
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

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
    fn dividing_through_the_reciprocal_gives_what_division_gives() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut divisors = vec![1, 2, 3, 5, 7, 10, 64, 641, 1 << 16, 65_537, u32::MAX - 1];
        divisors.extend([u32::MAX, (1 << 31) + 1, 1 << 31]);
        divisors.extend((0..200).map(|_| rng.random_range(1..=u32::MAX)));
        divisors.extend((0..200).map(|_| rng.random_range(1..5_000)));
        for divisor in divisors {
            let by = Divisor::new(divisor);
            let mut numerators = vec![0, 1, divisor - 1, divisor, u32::MAX, u32::MAX - 1];
            numerators.extend(divisor.checked_mul(3).map(|n| n - 1));
            numerators.extend((0..500).map(|_| rng.random_range(0..=u32::MAX)));
            for n in numerators {
                let expected = (n / divisor, n % divisor);
                assert_eq!(by.quotient_and_remainder(n), expected, "{n} / {divisor}");
            }
        }
    }

    #[test]
    fn a_cell_s_row_and_column_are_its_number_s_quotient_and_remainder() {
        let map = CellMap::covering(DVec2::splat(-100.0), DVec2::new(230.0, 90.0), 3.0, 10_000);
        assert!(map.columns > 1 && map.rows > 1 && map.columns != map.rows);
        for cell in 0..map.cell_count() {
            assert_eq!(
                map.row_and_column(cell),
                (cell / map.columns, cell % map.columns)
            );
        }
        assert_eq!(
            map.cell_size().to_bits(),
            (1.0 / map.inverse_cell_size).to_bits()
        );
        let column = CellMap::covering(DVec2::ZERO, DVec2::new(1.0, 100.0), 1.0, 100);
        assert_eq!(column.columns, 1);
        assert_eq!(column.row_and_column(column.rows - 1), (column.rows - 1, 0));
    }

    #[test]
    fn cell_count_stays_bounded_for_tiny_balls_far_apart() {
        let map = CellMap::covering(DVec2::splat(-1.0e6), DVec2::splat(1.0e6), 0.5, 2);
        assert!(map.cell_count() <= 2 * MAX_CELLS_PER_BALL + 4);
    }
}
