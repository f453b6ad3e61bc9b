//! Broad phase: which pairs of balls might touch, before the exact test.
//!
//! Used by both modes' collision stages (the discrete mode sorts the balls' circles, the
//! continuous mode the circles they sweep over the step, and also queries around a circle).
//! Two methods find the same pairs: [`UniformGrid`] (`uniform.rs`), O(N), the default, with
//! its first pass over the balls in `extent.rs`, its counting sort in `counting.rs`, its
//! queries around a place in `queries.rs`, its cells' geometry in `cells.rs`, its pair search
//! (each ball's candidates, a run of them tested at once) in `touching.rs` and the few big
//! balls kept apart by rows in `rows.rs`; and [`for_each_pair`], O(N^2), kept as the
//! reference the grid is tested against.

mod cells;
mod counting;
mod extent;
mod queries;
mod rows;
mod touching;
mod uniform;

pub use extent::Extent;
pub use uniform::UniformGrid;

use super::circle::Circle;

/// Calls `visit(i, j, circle_i, circle_j)` for every pair `i < j`: the O(N^2) reference.
pub fn for_each_pair(circles: &[Circle], mut visit: impl FnMut(u32, u32, Circle, Circle)) {
    for (i, &a) in circles.iter().enumerate() {
        for (j, &b) in circles.iter().enumerate().skip(i + 1) {
            visit(i as u32, j as u32, a, b);
        }
    }
}

/// 600 small balls (radius 1-3) scattered over 400 x 400 px, eight of radius 12 and one
/// of 200: big by the grid's measure, and the 200 big among the big ones.
#[cfg(test)]
pub fn mixed_sizes() -> Vec<Circle> {
    let mut circles: Vec<Circle> = (0..600)
        .map(|i| {
            let (x, y) = ((i * 37 % 211) as f64 * 1.9, (i * 61 % 197) as f64 * 2.03);
            Circle::new(bevy::math::DVec2::new(x, y), 1.0 + (i % 3) as f64)
        })
        .collect();
    let at = bevy::math::DVec2::new;
    circles.extend((0..8).map(|k| Circle::new(at(40.0 + 45.0 * k as f64, 90.0), 12.0)));
    circles.push(Circle::new(at(210.0, 260.0), 200.0));
    circles
}
