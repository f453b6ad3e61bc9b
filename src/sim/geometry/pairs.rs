//! Touching pairs: the grid's candidate pairs put through the exact circle test, each pair
//! once, in an order fixed by the input whatever the number of threads. The discrete mode's
//! detection, the continuous mode's fallback and the overlap measurement use it.

use std::ops::Range;

use crossbeam_utils::CachePadded;

use super::circle::{Circle, ContactGeometry, circle_contact, circles_touch};
use super::grid::{UniformGrid, for_each_pair};
use crate::sim::parallel::{in_pieces, split_evenly, threads_at_work, worth_splitting};
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

/// Touching pairs as the bands of rows that found them keep them: read band after band
/// ([`iter`](Self::iter)), they are one list in the order [`find_contacts`] fixes. Kept from
/// step to step, each band keeps its buffer, so no list is joined, and none is made again
/// while the number of bands and the pairs' count stay about the same.
#[derive(Debug)]
pub struct FoundInBands<T> {
    /// Each band's buffer on cache lines of its own: the threads push to their bands at once,
    /// and two buffers' lengths on one line would pass it back and forth between the cores.
    bands: Vec<CachePadded<Vec<T>>>,
    /// Each band's first row of the grid's cells (one band, from row 0, when the search was
    /// not by rows).
    first_rows: Vec<usize>,
}

impl<T> Default for FoundInBands<T> {
    fn default() -> Self {
        Self {
            bands: Vec::new(),
            first_rows: Vec::new(),
        }
    }
}

impl<T> FoundInBands<T> {
    /// Every pair found, band after band.
    pub fn iter(&self) -> impl Iterator<Item = &T> + Clone {
        self.bands.iter().flat_map(|band| band.iter())
    }

    /// The bands' pairs, band after band.
    pub fn bands(&self) -> impl Iterator<Item = &[T]> {
        self.bands.iter().map(|band| band.as_slice())
    }

    /// The bands' pairs, band after band, each with the first row of the grid's cells its
    /// band searched: a band of rows `r..s` finds pairs of balls in rows `r..=s` (a ball's
    /// candidates are in its own row and the row above), and the big balls.
    pub fn bands_from_rows(&self) -> impl Iterator<Item = (usize, &[T])> {
        self.first_rows.iter().copied().zip(self.bands())
    }

    /// How many pairs were found.
    pub fn len(&self) -> usize {
        self.bands.iter().map(|band| band.len()).sum()
    }

    /// Whether no pair was found.
    pub fn is_empty(&self) -> bool {
        self.bands.iter().all(|band| band.is_empty())
    }

    /// Empties every band, their buffers kept.
    pub fn clear(&mut self) {
        self.bands.iter_mut().for_each(|band| band.clear());
    }

    /// Empties every band and keeps one for each of `band_rows` (at least one, from row 0),
    /// their buffers kept.
    fn clear_to(
        &mut self,
        band_rows: impl Iterator<Item = Range<usize>>,
    ) -> &mut [CachePadded<Vec<T>>] {
        self.first_rows.clear();
        self.first_rows.extend(band_rows.map(|rows| rows.start));
        if self.first_rows.is_empty() {
            self.first_rows.push(0);
        }
        let count = self.first_rows.len();
        self.bands.truncate(count);
        self.clear();
        self.bands.resize_with(count, CachePadded::default);
        &mut self.bands
    }
}

/// Finds every touching pair among `circles` and keeps it in `found` (emptied first), each
/// pair once with `a < b` and the normal from `a` to `b`. The order is fixed by the input and
/// the method, whatever the number of threads: the grid is searched in bands of rows, in
/// parallel for large inputs, and read band after band the pairs are in row order.
pub fn find_contacts(
    circles: &[Circle],
    method: BroadPhase,
    grid: &mut UniformGrid,
    found: &mut FoundInBands<IndexedContact>,
) {
    match method {
        BroadPhase::Grid => {
            grid.rebuild(circles);
            let rows = band_rows(grid);
            let bands = found.clear_to(rows.clone());
            search_bands(grid, rows.zip(bands), |grid, rows, local| {
                grid.for_each_touching_pair_in_rows(rows, keep_touching(local));
            });
        }
        BroadPhase::AllPairs => {
            let only = &mut found.clear_to(std::iter::empty())[0];
            for_each_pair(circles, keep_touching(only));
        }
    }
}

/// Every touching pair among `circles`, as [`find_contacts`] finds them with the grid, searched
/// with a grid of its own: for a measurement made once, not a stage's every step.
pub fn contacts_among(circles: &[Circle]) -> FoundInBands<IndexedContact> {
    let mut found = FoundInBands::default();
    find_contacts(
        circles,
        BroadPhase::Grid,
        &mut UniformGrid::default(),
        &mut found,
    );
    found
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
    let rows = band_rows(grid);
    let band_count = rows.len();
    if band_count == 1 {
        search(grid, 0..grid.rows(), found);
        return;
    }
    // `found` kept last step's size: each band starts with its share and an eighth more, so
    // the bands' buffers, all alive until joined, are not doubled past what they hold; made
    // here, not on the pool's threads, whose own heaps would keep them after.
    let share = found.capacity() / band_count;
    let mut bands: Vec<CachePadded<Vec<T>>> = (0..band_count)
        .map(|_| CachePadded::new(Vec::with_capacity(share + share / 8)))
        .collect();
    search_bands(grid, rows.zip(&mut bands), search);
    // Exactly what is needed: the buffer is kept from step to step, and doubling it would
    // leave up to half of it unused (megabytes at a million balls).
    found.reserve_exact(bands.iter().map(|band| band.len()).sum());
    found.extend(bands.into_iter().flat_map(CachePadded::into_inner));
}

/// How many bands of rows the grid is searched in: one on one thread or for few balls, else
/// [`BANDS_PER_THREAD`] for each thread at work.
fn band_count(grid: &UniformGrid) -> usize {
    if worth_splitting(grid.len()) {
        threads_at_work() * BANDS_PER_THREAD
    } else {
        1
    }
}

/// The rows of each of the [`band_count`] bands the grid is searched in.
fn band_rows(grid: &UniformGrid) -> impl ExactSizeIterator<Item = Range<usize>> + Clone {
    split_evenly(grid.rows(), band_count(grid))
}

/// Runs `search(grid, rows, band)` for each band and its rows, in row order, on the compute
/// pool when there is more than one band.
fn search_bands<'a, T: Send + 'a>(
    grid: &UniformGrid,
    bands: impl ExactSizeIterator<Item = (Range<usize>, &'a mut CachePadded<Vec<T>>)>,
    search: impl Fn(&UniformGrid, Range<usize>, &mut Vec<T>) + Sync,
) {
    let parallel = bands.len() > 1;
    in_pieces(bands, parallel, |(rows, band)| search(grid, rows, band));
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
        let mut parallel = contacts_among(&circles);
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        let mut sequential = Vec::new();
        grid.for_each_touching_pair(keep_touching(&mut sequential));
        assert!(sequential.len() > 10_000, "{} contacts", sequential.len());
        assert_eq!(parallel.iter().copied().collect::<Vec<_>>(), sequential);
        // Kept for a smaller input, searched in one band, it holds that input's pairs only.
        let few = &circles[..1000];
        find_contacts(few, BroadPhase::Grid, &mut grid, &mut parallel);
        let alone = contacts_among(few);
        assert!(!alone.is_empty());
        assert_eq!(parallel.len(), alone.len());
        assert!(parallel.iter().eq(alone.iter()));
    }
}
