//! The grid's counting sort: balls into cells, stable (a cell's balls keep their input
//! order), so the slots are the same however the work is split. For many balls it runs on the
//! compute pool in bands of cells: each band counts and places only its own cells' balls, in
//! its own part of the slots. Each band reads every ball to find its own, so bands pay only
//! once the balls no longer fit in a core's cache ([`sort_bands`]).

use std::ops::Range;

use crate::sim::cache::{BALLS_AHEAD, FAR_PREFETCH_MIN_BALLS, prefetch};
use crate::sim::parallel::{carve, in_pieces, split_evenly, threads_at_work};

/// Marks a big ball, which has no cell.
pub const NO_CELL: u32 = u32::MAX;

/// Below this many balls the sort is one band, threads or not: every band reads every ball,
/// and while the buffers (about 13 bytes a ball) fit in a core's 1 MB cache one band is as
/// fast as two. The standard gas on this project's two cores, the whole step on two threads,
/// two bands against one, alternate steps of one run (three to six runs of 400 steps a
/// size): 1.00–1.05× at 30,000 and 50,000 balls, 0.97–1.02× at 75,000, 0.95–1.02× (most
/// 0.95–0.96×) at 100,000. (Before the calling thread took its pieces itself and spun at the
/// join, each pass's join cost up to 50 µs, and the sort alone took 0.32 ms in one band
/// against 0.45–0.56 in two at 100,000 balls, 0.70 against 0.73–0.93 at 200,000, 1.35–1.71
/// against 1.19–1.46 at 300,000: the limit was 250,000.)
const BANDED_SORT_MIN_BALLS: usize = 75_000;

/// The bands of cells to sort `balls` balls in when the work is split (`parallel`) or not:
/// one for each thread at work from [`BANDED_SORT_MIN_BALLS`] balls, else one.
pub fn sort_bands(balls: usize, parallel: bool) -> usize {
    if parallel && balls >= BANDED_SORT_MIN_BALLS {
        threads_at_work()
    } else {
        1
    }
}

/// Sorts the balls whose cells `cell_of` gives (by index; [`NO_CELL`] for a big ball) into
/// `cell_count` cells: afterwards `cell_start[c]..cell_start[c + 1]` is cell `c`'s range of
/// slots and `sorted_index[slot]` the ball in each slot, the balls in the cells first, in cell
/// order, then the big ones in input order. Returns how many are in the cells. With `bands`
/// above 1, the cells are split into that many bands, sorted in parallel.
pub fn sort_into_cells(
    cell_of: &[u32],
    cell_count: usize,
    (cell_start, sorted_index): (&mut Vec<u32>, &mut Vec<u32>),
    bands: usize,
) -> usize {
    // Every entry is written below: resizing only fills what the buffers gained.
    cell_start.resize(cell_count + 1, 0);
    sorted_index.resize(cell_of.len(), 0);
    let bands = bands.clamp(1, cell_count.max(1));
    let band_cells = split_evenly(cell_count, bands);
    let parallel = bands > 1;
    let loading_ahead = cell_of.len() >= FAR_PREFETCH_MIN_BALLS;
    // Each band counts its cells' balls: `cell_start` then holds each cell's end within the band.
    let totals = in_pieces(
        band_cells
            .clone()
            .zip(carve(&mut cell_start[..cell_count], band_cells.clone())),
        parallel,
        |(cells, ends)| {
            if loading_ahead {
                count_ends::<BALLS_AHEAD>(cell_of, cells, ends)
            } else {
                count_ends::<0>(cell_of, cells, ends)
            }
        },
    );
    let small_count: u32 = totals.iter().sum();
    let mut band_first = 0;
    let band_slots: Vec<Range<usize>> = totals
        .iter()
        .map(|&total| {
            let slots = band_first as usize..(band_first + total) as usize;
            band_first += total;
            slots
        })
        .collect();
    // Then places them in reverse, counting each end down to its cell's start.
    let bands_work = band_cells
        .clone()
        .zip(carve(&mut cell_start[..cell_count], band_cells))
        .zip(carve(sorted_index, band_slots.iter().cloned()))
        .zip(&band_slots);
    in_pieces(bands_work, parallel, |(((cells, ends), slots), range)| {
        let (band, first_slot) = ((cells, ends), range.start as u32);
        if loading_ahead {
            place::<BALLS_AHEAD>(cell_of, band, slots, first_slot)
        } else {
            place::<0>(cell_of, band, slots, first_slot)
        }
    });
    cell_start[cell_count] = small_count;
    let big_balls = (0..cell_of.len() as u32).filter(|&index| cell_of[index as usize] == NO_CELL);
    for (slot, index) in sorted_index[small_count as usize..]
        .iter_mut()
        .zip(big_balls)
    {
        *slot = index;
    }
    small_count as usize
}

/// `ends[c - cells.start]` set to how many balls in `cell_of` are in cells `cells.start..=c`;
/// returns how many are in `cells`. With `AHEAD` above 0, the count of the cell of the ball
/// `AHEAD` on is loaded as each is counted ([`FAR_PREFETCH_MIN_BALLS`]).
fn count_ends<const AHEAD: usize>(cell_of: &[u32], cells: Range<usize>, ends: &mut [u32]) -> u32 {
    ends.fill(0);
    let (first, last) = (cells.start as u32, cells.end as u32);
    for (index, &cell) in cell_of.iter().enumerate() {
        if AHEAD > 0 {
            load_cell_ahead(cell_of.get(index + AHEAD), first, ends);
        }
        if (first..last).contains(&cell) {
            ends[(cell - first) as usize] += 1;
        }
    }
    let mut running = 0;
    for end in ends.iter_mut() {
        running += *end;
        *end = running;
    }
    running
}

/// Places the balls of `cells` in `slots` (which start at slot `first_slot`), going through
/// the balls in reverse so each cell keeps its balls in input order; `ends`, each cell's end
/// within the band, become each cell's start slot. `AHEAD` as in [`count_ends`].
fn place<const AHEAD: usize>(
    cell_of: &[u32],
    (cells, ends): (Range<usize>, &mut [u32]),
    slots: &mut [u32],
    first_slot: u32,
) {
    let (first, last) = (cells.start as u32, cells.end as u32);
    for (index, &cell) in cell_of.iter().enumerate().rev() {
        if AHEAD > 0 {
            let coming = index.checked_sub(AHEAD);
            load_cell_ahead(coming.and_then(|coming| cell_of.get(coming)), first, ends);
        }
        if (first..last).contains(&cell) {
            let end = &mut ends[(cell - first) as usize];
            *end -= 1;
            slots[*end as usize] = index as u32;
        }
    }
    for end in ends.iter_mut() {
        *end += first_slot;
    }
}

/// Loads the entry of `ends` (the band's cells from `first` on) for the cell `coming`, if the
/// ball is coming and its cell is the band's.
fn load_cell_ahead(coming: Option<&u32>, first: u32, ends: &[u32]) {
    if let Some(&cell) = coming {
        prefetch(ends.get(cell.wrapping_sub(first) as usize));
    }
}

/// Each slot's cell into `slots`, the slots of the consecutive `cells` (cell `c` holds the
/// slots `starts[c]..starts[c + 1]`). Most cells hold 0 to 3 balls, at random, so a branch on
/// each cell's count would often be mispredicted: each cell, in order, writes its number into
/// the [`RUN_WRITTEN`] slots from its first, and the cells after it overwrite what lies past
/// its own. Only a cell of more balls, rare, writes just its own slots. (Before, each
/// cell wrote its number at its first slot and each slot then took the highest number
/// written up to it: a chain of dependent steps, 2.6% of the continuous step at 100,000
/// balls, now 0.45%.)
pub fn cells_of_slots(starts: &[u32], cells: Range<usize>, slots: &mut [u32]) {
    let first = starts[cells.start] as usize;
    for cell in cells {
        let (head, next) = (
            starts[cell] as usize - first,
            starts[cell + 1] as usize - first,
        );
        let number = cell as u32;
        match slots.get_mut(head..head + RUN_WRITTEN) {
            Some(run) if next - head <= RUN_WRITTEN => run.copy_from_slice(&[number; RUN_WRITTEN]),
            _ => slots[head..next].fill(number),
        }
    }
}

/// How many slots [`cells_of_slots`] writes for each cell: a cell rarely holds more balls.
const RUN_WRITTEN: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sort_is_split_only_for_many_balls_and_split_work() {
        assert_eq!(sort_bands(BANDED_SORT_MIN_BALLS - 1, true), 1);
        assert_eq!(sort_bands(BANDED_SORT_MIN_BALLS, false), 1);
        assert_eq!(sort_bands(BANDED_SORT_MIN_BALLS, true), threads_at_work());
    }

    #[test]
    fn each_slot_gets_its_cell_however_many_cells_are_empty() {
        // Cells holding 0 to 6 balls, empty ones first, last and in runs.
        let count = |c: u32| {
            if c >= 495 {
                0
            } else {
                [0, 1, 0, 0, 2, 3, 1, 0, 6, 4, 5][(c * 7 % 11) as usize]
            }
        };
        let counts: Vec<u32> = (0..500).map(count).collect();
        let mut starts = vec![0];
        for count in &counts {
            starts.push(starts.last().unwrap() + count);
        }
        let expected: Vec<u32> = (0..500_u32)
            .flat_map(|c| std::iter::repeat_n(c, counts[c as usize] as usize))
            .collect();
        for cells in [0..500, 0..2, 3..4, 0..37, 37..500, 490..500, 5..480] {
            let slots = starts[cells.start] as usize..starts[cells.end] as usize;
            let mut found = vec![NO_CELL; slots.len()];
            cells_of_slots(&starts, cells.clone(), &mut found);
            assert_eq!(found, expected[slots], "cells {cells:?}");
        }
    }

    #[test]
    fn any_number_of_bands_sorts_stably_with_the_big_balls_last() {
        // 3,000 balls in 97 cells, every seventh big.
        sorts_stably_in_bands(3000, 97, &[2, 3, 8, 500]);
    }

    #[test]
    fn so_many_balls_that_the_sort_loads_ahead_sort_alike() {
        // Enough balls for the loads ahead, in 50,021 cells: the counts they load lie far apart.
        let count = FAR_PREFETCH_MIN_BALLS as u32 + 3000;
        sorts_stably_in_bands(count, 50_021, &[2, 3]);
    }

    /// Sorts `count` balls into `cells` cells, every seventh big, the others spread over the
    /// cells, and checks the sort in one band, then that each of `more_bands` sorts alike.
    fn sorts_stably_in_bands(count: u32, cells: u32, more_bands: &[usize]) {
        let cell_of: Vec<u32> = (0..count)
            .map(|k| if k % 7 == 3 { NO_CELL } else { k * 31 % cells })
            .collect();
        let sort = |bands: usize| {
            let (mut starts, mut slots) = (Vec::new(), Vec::new());
            let small = sort_into_cells(&cell_of, cells as usize, (&mut starts, &mut slots), bands);
            (small, starts, slots)
        };
        let (small, starts, slots) = sort(1);
        let big = (0..count).filter(|k| k % 7 == 3).count();
        assert_eq!(small, count as usize - big);
        for cell in 0..cells as usize {
            let balls = &slots[starts[cell] as usize..starts[cell + 1] as usize];
            assert!(balls.iter().all(|&k| cell_of[k as usize] == cell as u32));
            assert!(balls.windows(2).all(|pair| pair[0] < pair[1]), "stable");
        }
        assert!(slots[small..].iter().all(|&k| k % 7 == 3));
        assert!(slots[small..].windows(2).all(|pair| pair[0] < pair[1]));
        for &bands in more_bands {
            assert_eq!(
                sort(bands),
                (small, starts.clone(), slots.clone()),
                "{bands}"
            );
        }
    }
}
