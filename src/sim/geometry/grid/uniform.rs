//! [`UniformGrid`]: the balls sorted into square cells by a counting sort, rebuilt from
//! scratch every step, so that candidate pairs and the balls near a point are found in O(N).
//!
//! The cells are sized by the largest of the ordinary balls. A ball whose radius is more than
//! `BIG_RADIUS_FACTOR` (4) times the mean is big: it stays out of the cells and goes into a
//! grid of its own (and so on down, a hierarchy), so a few big balls among many small ones do
//! not make every cell big. Each big ball is paired with the small balls in the cells its
//! circle reaches, row by row ([`RowLists`]); the pairs themselves are found in `touching.rs`.

use bevy::math::DVec2;

use super::cells::CellMap;
use super::counting::{NO_CELL, cells_of_slots, sort_bands, sort_into_cells};
use super::extent::Extent;
use super::rows::RowLists;
use crate::sim::cache::{BALLS_AHEAD, FAR_PREFETCH_MIN_BALLS, prefetch_whole};
use crate::sim::geometry::circle::Circle;
use crate::sim::parallel::{
    BALLS_PER_PIECE, carve, in_pieces, piece_ranges, split_evenly, threads_at_work, worth_splitting,
};

/// A ball whose radius is more than this many times the mean radius is big: see the header.
const BIG_RADIUS_FACTOR: f64 = 4.0;

/// A uniform grid over the balls' centres, rebuilt from scratch every step by a counting sort.
///
/// The cell side is at least the largest diameter of the balls in the cells, so two touching
/// circles always sit in the same or in adjacent cells. The buffers are kept between steps.
#[derive(Debug, Default)]
pub struct UniformGrid {
    pub(super) cells: CellMap,
    /// `cell_start[c]..cell_start[c + 1]` is cell `c`'s range of slots.
    pub(super) cell_start: Vec<u32>,
    /// The ball in each slot, by its index: the balls in the cells in cell order, then the
    /// big ones in input order.
    pub(super) sorted_index: Vec<u32>,
    /// The circles in slot order, so the pair loops read contiguous memory.
    pub(super) sorted_circle: Vec<Circle>,
    /// Each ball's cell ([`NO_CELL`] for a big one): by its index while sorting, by its slot
    /// after [`renumber_by_slot`](Self::renumber_by_slot).
    pub(super) cell_of: Vec<u32>,
    /// Slots `0..small_count` are in the cells; the rest are the big balls.
    pub(super) small_count: usize,
    /// Largest radius of a ball in the cells.
    pub(super) small_reach: f64,
    /// A radius above this is big.
    big_limit: f64,
    /// The big balls' own grid, numbering them by their order among the big ones; in use
    /// while there are big balls.
    big: Option<Box<UniformGrid>>,
    /// For each row of cells, the big balls (by that order) whose circle, grown by
    /// `small_reach`, reaches into it.
    pub(super) big_rows: RowLists,
}

/// Each slot's circle from `circles`, the ball `indices` gives for it; with `AHEAD` above 0,
/// the circle `AHEAD` slots on is loaded as each is copied, both its cache lines when it
/// straddles two ([`FAR_PREFETCH_MIN_BALLS`]).
fn gather<const AHEAD: usize>(slots: &mut [Circle], indices: &[u32], circles: &[Circle]) {
    for (at, (slot, &index)) in slots.iter_mut().zip(indices).enumerate() {
        if AHEAD > 0 {
            let later = indices.get(at + AHEAD);
            prefetch_whole(later.and_then(|&later| circles.get(later as usize)));
        }
        *slot = circles[index as usize];
    }
}

/// Whether a ball of `radius` is big where the limit is `big_limit`. A NaN is not big.
fn is_big(radius: f64, big_limit: f64) -> bool {
    radius > big_limit
}

impl UniformGrid {
    /// Sorts `circles` into cells, the big ones apart.
    pub fn rebuild(&mut self, circles: &[Circle]) {
        let count = circles.len();
        // The extent, the radii's sum and the largest radius in one pass, in pieces (on the
        // compute pool for many balls): the pieces' sums are added in their order, and a
        // piece's size is fixed, so the mean's rounding never depends on the threads.
        let parallel = worth_splitting(count);
        let by_piece = in_pieces(piece_ranges(count), parallel, |balls| {
            Extent::of(&circles[balls])
        });
        let all = by_piece.into_iter().fold(Extent::NONE, Extent::joined);
        let (mut min, mut max, radius_sum) = (all.min, all.max, all.radius_sum);
        self.big_limit = BIG_RADIUS_FACTOR * radius_sum / count.max(1) as f64;
        let big_limit = self.big_limit;
        // With big balls, the largest of the others takes another pass.
        let largest_radius = if all.largest_radius <= big_limit {
            all.largest_radius
        } else {
            let by_piece = in_pieces(piece_ranges(count), parallel, |balls| {
                circles[balls]
                    .iter()
                    .filter(|circle| !is_big(circle.radius, big_limit))
                    .fold(0.0_f64, |largest, circle| largest.max(circle.radius))
            });
            by_piece.into_iter().fold(0.0_f64, f64::max)
        };
        if count == 0 {
            (min, max) = (DVec2::ZERO, DVec2::ZERO);
        }
        self.small_reach = largest_radius;
        let cells = CellMap::covering(min, max, largest_radius, count);
        self.cells = cells;
        // Every entry of the buffers below is written before it is read: resizing them only
        // fills what they gained since the last step.
        self.cell_of.resize(count, NO_CELL);
        let cell_pieces = self
            .cell_of
            .chunks_mut(BALLS_PER_PIECE)
            .zip(piece_ranges(count));
        in_pieces(cell_pieces, parallel, |(cell_of, balls)| {
            for (cell, circle) in cell_of.iter_mut().zip(&circles[balls]) {
                *cell = if is_big(circle.radius, big_limit) {
                    NO_CELL
                } else {
                    cells.cell_index(circle.center) as u32
                };
            }
        });
        let bands = sort_bands(count, parallel);
        self.small_count = sort_into_cells(
            &self.cell_of,
            cells.cell_count(),
            (&mut self.cell_start, &mut self.sorted_index),
            bands,
        );
        // The circles gathered in slot order: independent random reads overlap in the memory
        // system far better than random writes of whole circles.
        self.sorted_circle
            .resize(count, Circle::new(DVec2::ZERO, 0.0));
        let slot_pieces = self
            .sorted_circle
            .chunks_mut(BALLS_PER_PIECE)
            .zip(self.sorted_index.chunks(BALLS_PER_PIECE));
        let loading_ahead = count >= FAR_PREFETCH_MIN_BALLS;
        in_pieces(slot_pieces, parallel, |(slots, indices)| {
            if loading_ahead {
                gather::<BALLS_AHEAD>(slots, indices, circles)
            } else {
                gather::<0>(slots, indices, circles)
            }
        });
        self.rebuild_big();
    }

    /// The big balls' grid and the rows each reaches.
    fn rebuild_big(&mut self) {
        let big_circles = &self.sorted_circle[self.small_count..];
        if big_circles.is_empty() {
            return;
        }
        let big = self.big.get_or_insert_with(Box::default);
        big.rebuild(big_circles);
        let (cells, reach) = (self.cells, self.small_reach);
        let spans = big_circles.iter().map(|&circle| {
            let ((_, first), (_, last)) = cells.corners_reached(circle, reach);
            first..=last
        });
        self.big_rows.rebuild(cells.rows, spans);
    }

    /// The big balls' grid, if there are big balls.
    pub(super) fn big_grid(&self) -> Option<&UniformGrid> {
        self.big
            .as_deref()
            .filter(|_| self.small_count < self.len())
    }

    /// Hands over the balls' order in the grid (`order[slot]` is the index the ball had in
    /// the slice given to [`rebuild`](Self::rebuild)) and from now on numbers each ball by its
    /// slot: for a caller that keeps its own per-ball data in this order, so that balls near
    /// each other in space are near each other in memory.
    pub fn renumber_by_slot(&mut self, order: &mut Vec<u32>) {
        std::mem::swap(order, &mut self.sorted_index);
        self.sorted_index.clear();
        self.sorted_index.extend(0..order.len() as u32);
        // Each slot's cell, for `reach_from_cell`: in bands of cells, each writing its slots.
        self.cell_of.resize(order.len(), NO_CELL);
        let cell_count = self.cells.cell_count();
        let parallel = worth_splitting(order.len());
        let bands = if parallel { 4 * threads_at_work() } else { 1 };
        let band_cells = split_evenly(cell_count, bands);
        let starts = &self.cell_start;
        let band_slots = band_cells
            .clone()
            .map(|cells| starts[cells.start] as usize..starts[cells.end] as usize);
        let work = band_cells.zip(carve(&mut self.cell_of, band_slots));
        in_pieces(work, parallel, |(cells, slots)| {
            cells_of_slots(starts, cells, slots)
        });
        self.cell_of[self.small_count..].fill(NO_CELL);
    }

    /// The circle of the ball in `slot`.
    pub fn circle_in_slot(&self, slot: usize) -> Circle {
        self.sorted_circle[slot]
    }

    /// Puts `circle` in the place of the ball in `slot`, in its cell (after
    /// [`renumber_by_slot`](Self::renumber_by_slot), for a ball in the cells): a query grown
    /// by [`reach_from_cell`](Self::reach_from_cell) finds it. The continuous mode keeps each
    /// ball's current path so during its timeline.
    pub fn replace_circle_in_slot(&mut self, slot: usize, circle: Circle) {
        self.sorted_circle[slot] = circle;
    }

    /// How far, along either axis, `circle` reaches from the cell of the ball in `slot` (after
    /// [`renumber_by_slot`](Self::renumber_by_slot), for a ball in the cells): a query around
    /// a circle grown by this much finds `circle` filed in that cell if the two touch.
    pub fn reach_from_cell(&self, slot: usize, circle: Circle) -> f64 {
        let cell = self.cell_of[slot] as usize;
        circle.radius + self.cells.distance_to_cell(cell, circle.center)
    }

    /// Every ball's circle, by slot.
    pub fn circles_by_slot(&self) -> &[Circle] {
        &self.sorted_circle
    }

    /// How many balls are in the cells: slots `0..small_count()`; the big ones follow.
    pub fn small_count(&self) -> usize {
        self.small_count
    }

    /// The largest radius of a ball in the cells.
    pub fn small_reach(&self) -> f64 {
        self.small_reach
    }

    /// The side of a cell, pixels.
    pub fn cell_size(&self) -> f64 {
        self.cells.cell_size()
    }

    /// Whether each ball in the cells lies in its own cell: no cap on the number of cells
    /// made the border cells hold balls beyond them.
    pub fn cells_hold_their_balls(&self) -> bool {
        !self.cells.capped
    }

    /// Number of balls sorted in.
    pub fn len(&self) -> usize {
        self.sorted_index.len()
    }

    pub fn is_empty(&self) -> bool {
        self.sorted_index.is_empty()
    }

    /// Rows of cells: the unit [`for_each_touching_pair_in_rows`](Self::for_each_touching_pair_in_rows)
    /// splits work by.
    pub fn rows(&self) -> usize {
        self.cells.rows
    }

    /// The row of cells the ball of `index` (in the slice given to [`rebuild`](Self::rebuild))
    /// is filed in, or `None` for a big ball, which has no cell. Not after
    /// [`renumber_by_slot`](Self::renumber_by_slot), which numbers the balls otherwise.
    pub fn row_of_ball(&self, index: usize) -> Option<usize> {
        let cell = self.cell_of[index];
        (cell != NO_CELL).then(|| cell as usize / self.cells.columns)
    }

    /// The first slot of the balls in the cells of `row` and the rows after it: how many balls
    /// in the cells lie in the rows before it (all of them for a row past the last).
    pub fn first_slot_of_row(&self, row: usize) -> usize {
        let cell = (row * self.cells.columns).min(self.cells.cell_count());
        self.cell_start.get(cell).map_or(0, |&slot| slot as usize)
    }

    /// A radius above this is big (see the header): a caller filing its own circles by this
    /// grid's cells keeps those apart too.
    pub fn big_limit(&self) -> f64 {
        self.big_limit
    }

    /// The slots of the balls in the cells of `row`.
    pub fn slots_of_row(&self, row: usize) -> std::ops::Range<usize> {
        let columns = self.cells.columns;
        self.slots_of(row * columns..(row + 1) * columns)
    }

    /// The slots of the balls in the consecutive cells `cells` (the cells hold the slots
    /// `0..small_count()`).
    pub fn slots_of(&self, cells: std::ops::Range<usize>) -> std::ops::Range<usize> {
        self.cell_start[cells.start] as usize..self.cell_start[cells.end] as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::geometry::circle::circles_touch;
    use crate::sim::geometry::grid::{for_each_pair, mixed_sizes};

    #[test]
    fn grid_visits_each_nearby_pair_once() {
        let circles: Vec<Circle> = (0..30)
            .map(|i| Circle::new(DVec2::new((i % 6) as f64 * 7.0, (i / 6) as f64 * 7.0), 5.0))
            .collect();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        let mut seen = std::collections::HashSet::new();
        grid.for_each_touching_pair(|i, j, a, b| {
            assert_ne!(i, j);
            assert!(circles_touch(a, b), "({i}, {j}) do not touch");
            assert!(
                seen.insert((i.min(j), i.max(j))),
                "pair ({i}, {j}) visited twice"
            );
        });
        // Every pair within one diameter must be among the pairs visited.
        for_each_pair(&circles, |i, j, a, b| {
            if a.center.distance(b.center) <= a.radius + b.radius {
                assert!(seen.contains(&(i, j)), "grid missed pair ({i}, {j})");
            }
        });
    }

    #[test]
    fn so_many_balls_that_the_gather_loads_ahead_each_slot_holds_its_ball() {
        // A lattice 500 balls wide, each ball stored some 16 rows from the one before.
        let count = FAR_PREFETCH_MIN_BALLS + 1000;
        let circles: Vec<Circle> = (0..count)
            .map(|k| (k * 7919) % count)
            .map(|k| Circle::new(DVec2::new((k % 500) as f64, (k / 500) as f64) * 3.0, 1.0))
            .collect();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        let mut seen = vec![false; count];
        let cells: Vec<usize> = (0..count)
            .map(|slot| {
                let index = grid.sorted_index[slot] as usize;
                assert_eq!(grid.sorted_circle[slot], circles[index], "slot {slot}");
                assert!(
                    !std::mem::replace(&mut seen[index], true),
                    "ball {index} twice"
                );
                grid.cells.cell_index(circles[index].center)
            })
            .collect();
        assert!(
            cells.windows(2).all(|pair| pair[0] <= pair[1]),
            "in cell order"
        );
    }

    #[test]
    fn grid_survives_empty_single_and_non_finite_input() {
        let mut grid = UniformGrid::default();
        grid.rebuild(&[]);
        grid.for_each_touching_pair(|_, _, _, _| panic!("no pairs in an empty grid"));
        grid.rebuild(&[Circle::new(DVec2::ZERO, 1.0)]);
        grid.for_each_touching_pair(|_, _, _, _| panic!("no pairs with one ball"));
        let strange = [
            Circle::new(DVec2::new(f64::NAN, 0.0), 1.0),
            Circle::new(DVec2::new(f64::INFINITY, 0.0), 1.0),
            Circle::new(DVec2::ZERO, 1.0),
        ];
        grid.rebuild(&strange);
        let mut pairs = 0;
        grid.for_each_touching_pair(|_, _, _, _| pairs += 1);
        assert!(pairs <= 3);
    }

    #[test]
    fn big_balls_apart_every_touching_pair_is_visited_once_whatever_the_bands() {
        let circles = mixed_sizes();
        let mut grid = UniformGrid::default();
        grid.rebuild(&circles);
        assert_eq!(grid.len() - grid.small_count, 9, "the big ones are apart");
        let big = grid.big_grid().expect("a grid of big balls");
        assert_eq!(
            big.len() - big.small_count,
            1,
            "and the biggest apart again"
        );
        let mut all = Vec::new();
        grid.for_each_touching_pair(|i, j, a, b| {
            assert_eq!((a, b), (circles[i as usize], circles[j as usize]));
            all.push((i.min(j), i.max(j)));
        });
        let unique: std::collections::HashSet<_> = all.iter().copied().collect();
        assert_eq!(unique.len(), all.len(), "a pair visited twice");
        let mut touching = 0;
        for_each_pair(&circles, |i, j, a, b| {
            if a.center.distance(b.center) <= a.radius + b.radius {
                touching += 1;
                assert!(
                    unique.contains(&(i, j)),
                    "missed ({i}, {j}) of radii {}, {}",
                    a.radius,
                    b.radius
                );
            }
        });
        assert!(touching > 300, "{touching} touching pairs");
        // Bands of rows, joined in row order, give the same pairs in the same order.
        let rows = grid.rows();
        // More bands than rows, too: some bands are then empty.
        for bands in [2, 3, 7, rows + 3] {
            let mut joined = Vec::new();
            for band in 0..bands {
                grid.for_each_touching_pair_in_rows(
                    rows * band / bands..rows * (band + 1) / bands,
                    |i, j, _, _| {
                        joined.push((i.min(j), i.max(j)));
                    },
                );
            }
            assert_eq!(joined, all, "{bands} bands");
        }
    }
}
