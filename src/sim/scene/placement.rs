//! Placing balls without overlap: an incremental grid of the balls placed so far. Used by scene
//! generation and by the ball-count slider, which adds balls to a running simulation.
//! Pure data; runs in no schedule.

use bevy::math::DVec2;
use rand::{Rng, RngExt};

use crate::sim::geometry::Circle;
use crate::sim::geometry::circle::overlapping;

/// An incremental grid of the balls placed so far: cells hold linked lists of ball indices.
pub struct PlacementGrid {
    origin: DVec2,
    cell_size: f64,
    columns: usize,
    rows: usize,
    /// First ball in each cell, or `u32::MAX`.
    head: Vec<u32>,
    /// Next ball in the same cell, per ball.
    next: Vec<u32>,
    circles: Vec<Circle>,
}

impl PlacementGrid {
    pub fn new(half: DVec2, largest_radius: f64, capacity: usize) -> Self {
        let size = half * 2.0;
        let max_cells = (4 * capacity).max(16) as f64;
        let cell_size = (2.0 * largest_radius)
            .max((size.x * size.y / max_cells).sqrt())
            .max(f64::MIN_POSITIVE);
        let columns = ((size.x / cell_size) as usize).saturating_add(1);
        let rows = ((size.y / cell_size) as usize).saturating_add(1);
        PlacementGrid {
            origin: -half,
            cell_size,
            columns,
            rows,
            head: vec![u32::MAX; columns * rows],
            next: Vec::with_capacity(capacity),
            circles: Vec::with_capacity(capacity),
        }
    }

    fn cell_of(&self, point: DVec2) -> (usize, usize) {
        let cell = (point - self.origin) / self.cell_size;
        (
            (cell.x.max(0.0) as usize).min(self.columns - 1),
            (cell.y.max(0.0) as usize).min(self.rows - 1),
        )
    }

    /// The index of a placed ball that overlaps `circle`, if any.
    pub fn first_overlap(&self, circle: Circle) -> Option<usize> {
        let (column, row) = self.cell_of(circle.center);
        for r in row.saturating_sub(1)..=(row + 1).min(self.rows - 1) {
            for c in column.saturating_sub(1)..=(column + 1).min(self.columns - 1) {
                let mut ball = self.head[r * self.columns + c];
                while ball != u32::MAX {
                    if overlapping(self.circles[ball as usize], circle) {
                        return Some(ball as usize);
                    }
                    ball = self.next[ball as usize];
                }
            }
        }
        None
    }

    pub fn insert(&mut self, circle: Circle) {
        let (column, row) = self.cell_of(circle.center);
        let cell = row * self.columns + column;
        self.next.push(self.head[cell]);
        self.head[cell] = self.circles.len() as u32;
        self.circles.push(circle);
    }

    /// A uniformly random centre for a ball of `radius` inside the arena `[-half, half]` that
    /// overlaps no placed ball, or `None` after `tries` attempts (or if the ball cannot fit).
    pub fn random_free_spot(
        &self,
        radius: f64,
        half: DVec2,
        rng: &mut impl Rng,
        tries: u32,
    ) -> Option<DVec2> {
        let limit = half - DVec2::splat(radius);
        if limit.min_element() < 0.0 {
            return None;
        }
        (0..tries).find_map(|_| {
            let position = DVec2::new(
                rng.random_range(-limit.x..=limit.x),
                rng.random_range(-limit.y..=limit.y),
            );
            self.first_overlap(Circle::new(position, radius))
                .is_none()
                .then_some(position)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn placement_grid_finds_overlaps_across_cells() {
        let mut grid = PlacementGrid::new(DVec2::splat(100.0), 5.0, 10);
        grid.insert(Circle::new(DVec2::new(9.0, 9.0), 5.0));
        assert_eq!(
            grid.first_overlap(Circle::new(DVec2::new(17.0, 9.0), 5.0)),
            Some(0)
        );
        assert_eq!(
            grid.first_overlap(Circle::new(DVec2::new(19.0, 9.0), 5.0)),
            None
        );
        // Just touching is allowed.
        assert_eq!(
            grid.first_overlap(Circle::new(DVec2::new(9.0, 19.0), 5.0)),
            None
        );
    }

    #[test]
    fn random_free_spots_are_inside_and_free() {
        let half = DVec2::new(50.0, 30.0);
        let mut grid = PlacementGrid::new(half, 5.0, 40);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        for _ in 0..30 {
            let spot = grid.random_free_spot(5.0, half, &mut rng, 1000).unwrap();
            assert!(spot.x.abs() <= 45.0 && spot.y.abs() <= 25.0);
            grid.insert(Circle::new(spot, 5.0));
        }
        assert_eq!(grid.random_free_spot(31.0, half, &mut rng, 10), None);
    }
}
