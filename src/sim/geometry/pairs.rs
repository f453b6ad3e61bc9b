//! Touching pairs: the grid's candidate pairs put through the exact circle test, each pair
//! once, in an order fixed by the input whatever the number of threads. The discrete mode's
//! detection, the continuous mode's fallback and the overlap measurement use it.

use std::ops::Range;

use super::circle::{Circle, ContactGeometry, circle_contact, circles_touch};
use super::grid::{UniformGrid, for_each_pair};
use crate::sim::parallel::{compute_pool, split_evenly, threads_at_work, worth_splitting};
use crate::sim::params::BroadPhase;

/// A contact between balls `a < b`, numbered by their position in the input slice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndexedContact {
    pub a: u32,
    pub b: u32,
    pub geometry: ContactGeometry,
}

/// Bands of rows per thread at work, so an unlucky band does not leave a thread idle.
const BANDS_PER_THREAD: usize = 4;

/// Finds every touching pair among `circles` and appends it to `found`, each pair once with
/// `a < b` and the normal from `a` to `b`. The order is fixed by the input and the method,
/// whatever the number of threads: the grid is searched in bands of rows, in parallel for
/// large inputs, and the bands' contacts are joined in row order.
pub fn find_contacts(
    circles: &[Circle],
    method: BroadPhase,
    grid: &mut UniformGrid,
    found: &mut Vec<IndexedContact>,
) {
    match method {
        BroadPhase::Grid => {
            grid.rebuild(circles);
            search_in_bands(grid, found, |grid, rows, local| {
                grid.for_each_touching_pair_in_rows(rows, keep_touching(local));
            });
        }
        BroadPhase::AllPairs => for_each_pair(circles, keep_touching(found)),
    }
}

/// Appends to `found` every touching pair among `circles` as `(a, b)`, `a < b`: the pairs
/// [`find_contacts`] finds with the grid, in its order, without their geometry (for callers
/// that measure the pairs themselves).
pub fn find_touching_pairs(
    circles: &[Circle],
    grid: &mut UniformGrid,
    found: &mut Vec<(u32, u32)>,
) {
    grid.rebuild(circles);
    search_in_bands(grid, found, |grid, rows, local| {
        grid.for_each_touching_pair_in_rows(rows, |i, j, _, _| {
            local.push((i.min(j), i.max(j)));
        });
    });
}

/// Runs `search(grid, rows, out)` over bands of the grid's rows and appends what the bands
/// find to `found` in row order, so the result does not depend on the thread count. The bands
/// run in parallel on the compute pool once the grid holds `PARALLEL_MIN_BALLS` (20,000) balls
/// and more than one thread is at work; otherwise one pass over every row finds the same,
/// in the same order, with no band's buffer beside `found` (10 MB at a million balls).
pub fn search_in_bands<T: Send + 'static>(
    grid: &UniformGrid,
    found: &mut Vec<T>,
    search: impl Fn(&UniformGrid, Range<usize>, &mut Vec<T>) + Sync,
) {
    let rows = grid.rows();
    if !worth_splitting(grid.len()) {
        search(grid, 0..rows, found);
        return;
    }
    let band_count = threads_at_work() * BANDS_PER_THREAD;
    let search = &search;
    // `found` kept last step's size: each band starts with its share and an eighth more, so
    // the bands' buffers, all alive until joined, are not doubled past what they hold; made
    // here, not on the pool's threads, whose own heaps would keep them after.
    let share = found.capacity() / band_count;
    let mut bands: Vec<Vec<T>> = (0..band_count)
        .map(|_| Vec::with_capacity(share + share / 8))
        .collect();
    compute_pool().scope(|scope| {
        for (band_rows, local) in split_evenly(rows, band_count).zip(&mut bands) {
            scope.spawn(async move { search(grid, band_rows, local) });
        }
    });
    // Exactly what is needed: the buffer is kept from step to step, and doubling it would
    // leave up to half of it unused (megabytes at a million balls).
    found.reserve_exact(bands.iter().map(Vec::len).sum());
    found.extend(bands.into_iter().flatten());
}

/// A visitor for the broad phase that runs the narrow phase and keeps touching pairs.
fn keep_touching(found: &mut Vec<IndexedContact>) -> impl FnMut(u32, u32, Circle, Circle) + '_ {
    move |i, j, ci, cj| {
        if !circles_touch(ci, cj) {
            return;
        }
        let (a, b, ca, cb) = if i < j {
            (i, j, ci, cj)
        } else {
            (j, i, cj, ci)
        };
        if let Some(geometry) = circle_contact(ca, cb) {
            found.push(IndexedContact { a, b, geometry });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::parallel::PARALLEL_MIN_BALLS;
    use bevy::math::DVec2;

    #[test]
    fn parallel_grid_search_gives_the_sequential_order() {
        // A jittered lattice, dense enough to touch often, large enough to run in parallel.
        let side = 200;
        let circles: Vec<Circle> = (0..side * side)
            .map(|k| {
                let (x, y) = ((k % side) as f64, (k / side) as f64);
                let jitter = ((k * 7919) % 13) as f64 * 0.1;
                Circle::new(
                    DVec2::new(x * 9.0 + jitter, y * 9.0 - jitter),
                    4.0 + jitter * 0.2,
                )
            })
            .collect();
        assert!(circles.len() >= PARALLEL_MIN_BALLS);
        let mut parallel = Vec::new();
        find_contacts(
            &circles,
            BroadPhase::Grid,
            &mut UniformGrid::default(),
            &mut parallel,
        );
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        let mut sequential = Vec::new();
        grid.for_each_touching_pair(keep_touching(&mut sequential));
        assert!(sequential.len() > 10_000, "{} contacts", sequential.len());
        assert_eq!(parallel, sequential);
    }
}
