//! The discrete exchanges taken in parts of the ball arrays at once, one part to a thread,
//! with the result of taking them one after another, to the bit.
//!
//! Runs inside [`resolve_contacts`](super::resolve::resolve_contacts) for many balls on more
//! than one thread, in a step that drops its ball hits (every headless command: a step that
//! keeps them records them in the contacts' order, so it takes the contacts one after
//! another).
//!
//! The exchanges are Gauss–Seidel: each contact sees what the earlier ones left. But two
//! contacts that share no ball give the same result in either order; only each ball's own
//! order of contacts matters. The search found the contacts in bands of the grid's rows, and
//! the balls are stored in space order, so the parts are cut to match: each part takes a
//! share of the bands, in order, from its first row `R_p` on, and the balls numbered from the
//! first slot of that row (those before it are the balls of the rows before, if the order
//! holds) up to the next part's. Each part goes through its own bands' contacts in order
//! and takes *at once*, on its own slices of the arrays, those whose balls are both its own
//! and free; the rest *wait*, and make their own balls wait too. The waiting contacts are then
//! taken on the whole arrays, part after part, which is the contacts' order.
//!
//! A ball of part `p` is free unless it waits, or (for `p > 0`) it is big or lies in a row up
//! to `R_p`: an earlier band of rows `r..s` finds pairs of balls in rows `r..=s` only, so the
//! earlier parts' contacts reach no other ball of the cells.
//!
//! Why the result is the same: a contact taken at once has two free balls of its part, so
//! every contact before it on those balls is its part's (no earlier part's reaches them) and
//! was taken at once before it (a waiting one would have made them wait); every contact
//! after it on them is its part's, taken after it, or a later part's, which waits (the balls
//! are not that part's own). A waiting contact is taken after every contact before it (at
//! once, or waiting, in order), and before every later one on its balls, since those wait too
//! (its part's made them wait; a later part's cannot take another part's ball, nor its own
//! ball in the rows this contact reaches).

use bevy::math::DVec2;

use crate::sim::geometry::circle::{Circle, ContactGeometry};
use crate::sim::geometry::grid::UniformGrid;
use crate::sim::geometry::impulse::{
    Exchange, resolve_found_contacts, resolve_found_contacts_in_part,
};
use crate::sim::geometry::pairs::{FoundInBands, IndexedContact};
use crate::sim::parallel::{carve, in_pieces, split_evenly};
use crate::sim::params::MassModel;

/// The buffers of [`ExchangesInParts::resolve`], kept from step to step.
#[derive(Default)]
pub struct ExchangesInParts {
    /// For each ball, whether a waiting contact has taken it so far: all false between steps.
    waits: Vec<bool>,
    /// For each part, the contacts of its bands that wait, in order.
    waiting: Vec<Vec<IndexedContact>>,
}

/// What a part needs to know of the search: where its balls and its rows begin.
struct Part<'a> {
    /// The bands of contacts the part goes through.
    bands: Vec<&'a [IndexedContact]>,
    /// The part's balls start with this index.
    first_ball: usize,
    /// For a part after the first, its first row: the earlier parts' contacts reach up to it.
    first_row: Option<usize>,
}

impl ExchangesInParts {
    /// Takes `contacts` (found in bands of the rows of `grid`, which sorted the same
    /// `circles`) in up to `parts` parts of the arrays at once, then the waiting ones,
    /// marking in `touched` the balls of each contact, with the result of
    /// [`resolve_found_contacts`] band after band. Returns how many exchanges there were: the
    /// ball hits the step counts.
    pub fn resolve(
        &mut self,
        (contacts, grid): (&FoundInBands<IndexedContact>, &UniformGrid),
        parts: usize,
        touched: &mut [bool],
        (circles, velocities, held): (&mut [Circle], &mut [DVec2], &mut [bool]),
        constants: (MassModel, f64, f64),
    ) -> u64 {
        let parts = cut_into_parts(contacts, grid, parts, circles.len());
        let count = circles.len();
        self.waits.resize(count, false);
        self.waiting.resize_with(parts.len(), Vec::new);
        let ends = parts
            .iter()
            .skip(1)
            .map(|next| next.first_ball)
            .chain([count]);
        let ranges: Vec<_> = parts
            .iter()
            .zip(ends)
            .map(|(part, end)| part.first_ball..end)
            .collect();
        let carved = || ranges.iter().cloned();
        let arrays = carve(touched, carved())
            .zip(carve(circles, carved()))
            .zip(carve(velocities, carved()))
            .zip(carve(held, carved()));
        let work = parts
            .iter()
            .zip(carve(&mut self.waits, carved()))
            .zip(&mut self.waiting)
            .zip(arrays);
        let row_of = |index: usize| grid.row_of_ball(index);
        let exchanges_at_once = in_pieces(
            work,
            parts.len() > 1,
            |(((part, waits), waiting), (((touched, circles), velocities), held))| {
                waiting.clear();
                let mut exchanges = 0;
                let count_exchange = |_, _, _, _| exchanges += 1;
                let arrays = (circles, velocities, held);
                let waits = (waits, waiting);
                take_at_once(
                    (part, row_of),
                    waits,
                    touched,
                    arrays,
                    constants,
                    count_exchange,
                );
                exchanges
            },
        );
        let mut exchanges: u64 = exchanges_at_once.iter().sum();
        let arrays = (&mut circles[..], &mut velocities[..], &mut held[..]);
        let count_exchange = |_, _, _, _| exchanges += 1;
        let waiting: Vec<IndexedContact> = self.waiting.iter().flatten().copied().collect();
        resolve_found_contacts(&waiting, touched, arrays, constants, count_exchange);
        for contact in &waiting {
            self.waits[contact.a as usize] = false;
            self.waits[contact.b as usize] = false;
        }
        exchanges
    }
}

/// The parts, at most `parts` of them, each with a share of the bands in order, and its balls:
/// from the first slot of its first row (the balls before it in space order), so the balls
/// of a strip of the arena are mostly its own.
fn cut_into_parts<'a>(
    contacts: &'a FoundInBands<IndexedContact>,
    grid: &UniformGrid,
    parts: usize,
    balls: usize,
) -> Vec<Part<'a>> {
    let bands: Vec<(usize, &[IndexedContact])> = contacts.bands_from_rows().collect();
    let mut last_first_ball = 0;
    split_evenly(bands.len(), parts.clamp(1, bands.len().max(1)))
        .enumerate()
        .map(|(part, shares)| {
            let first_row = bands.get(shares.start).map_or(grid.rows(), |band| band.0);
            let first_ball = if part == 0 {
                0
            } else {
                grid.first_slot_of_row(first_row)
                    .clamp(last_first_ball, balls)
            };
            last_first_ball = first_ball;
            Part {
                bands: bands[shares].iter().map(|band| band.1).collect(),
                first_ball,
                first_row: (part > 0).then_some(first_row),
            }
        })
        .collect()
}

/// Takes, band after band, the contacts of `part` whose balls are both its own and free, on
/// its slices; the others go to `waiting` and make their balls of this part wait. A ball is
/// free unless it `waits`, or its row by `row_of(index)` (`None` for a big ball) is not past
/// the part's first row.
fn take_at_once(
    (part, row_of): (&Part, impl Fn(usize) -> Option<usize>),
    (waits, waiting): (&mut [bool], &mut Vec<IndexedContact>),
    touched: &mut [bool],
    (circles, velocities, held): (&mut [Circle], &mut [DVec2], &mut [bool]),
    constants: (MassModel, f64, f64),
    mut on_exchange: impl FnMut(u32, u32, ContactGeometry, Exchange),
) {
    let len = circles.len() as u32;
    for band in &part.bands {
        let take = |contact: &IndexedContact, (a, b): (u32, u32)| {
            let (own_a, own_b) = (a < len, b < len);
            let free = |ball: u32, index: u32| {
                !waits[ball as usize]
                    && part.first_row.is_none_or(|first_row| {
                        row_of(index as usize).is_some_and(|row| row > first_row)
                    })
            };
            if own_a && own_b && free(a, contact.a) && free(b, contact.b) {
                return true;
            }
            waiting.push(*contact);
            for (own, ball) in [(own_a, a), (own_b, b)] {
                if own {
                    waits[ball as usize] = true;
                }
            }
            false
        };
        let first = (part.first_ball as u32, take);
        let arrays = (&mut *circles, &mut *velocities, &mut *held);
        resolve_found_contacts_in_part(band, first, touched, arrays, constants, &mut on_exchange);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::geometry::pairs::find_contacts;
    use crate::sim::parallel::{PARALLEL_MIN_BALLS, threads_at_work};
    use crate::sim::params::BroadPhase;

    /// A lattice numbered row by row, as balls stored in space order are, each ball touching
    /// about one neighbour in three (fewer, and the contacts' chains do not run on across the
    /// lattice), but with one ball in 97 swapped with its mirror at the other end of the
    /// numbering, and three big balls.
    fn in_space_order_mostly() -> Vec<Circle> {
        let side = 160;
        let mut circles: Vec<Circle> = (0..side * 150)
            .map(|k| {
                let (x, y) = ((k % side) as f64 * 4.0, (k / side) as f64 * 4.0);
                let jitter = ((k * 7919) % 11) as f64 * 0.05;
                Circle::new(DVec2::new(x + jitter, y - jitter), 1.6 + jitter)
            })
            .collect();
        let count = circles.len();
        for k in (0..count / 2).step_by(97) {
            circles.swap(k, count - 1 - k);
        }
        for (x, y) in [(100.0, 50.0), (320.0, 300.0), (500.0, 560.0)] {
            circles.push(Circle::new(DVec2::new(x, y), 30.0));
        }
        circles
    }

    #[test]
    fn parts_at_once_give_the_exchanges_one_after_another_to_the_bit() {
        let mut circles = in_space_order_mostly();
        let mut grid = UniformGrid::default();
        let mut contacts = FoundInBands::default();
        find_contacts(&circles, BroadPhase::Grid, &mut grid, &mut contacts);
        // The second of two parts' first row emptied of small balls: the big ball at
        // (320, 300) reaches across it, so it meets the balls of both parts but none in that
        // row, and only being big makes it wait in the second part.
        let bands: Vec<usize> = contacts.bands_from_rows().map(|(row, _)| row).collect();
        let second_part_row = bands[bands.len() / 2];
        let mut index = 0;
        circles.retain(|_| {
            index += 1;
            grid.row_of_ball(index - 1) != Some(second_part_row)
        });
        find_contacts(&circles, BroadPhase::Grid, &mut grid, &mut contacts);
        let count = circles.len();
        assert!(count >= PARALLEL_MIN_BALLS);
        let velocities: Vec<DVec2> = (0..count)
            .map(|k| DVec2::new((k % 13) as f64 - 6.0, (k % 7) as f64 - 3.0) * 40.0)
            .collect();
        let held: Vec<bool> = (0..count).map(|k| k % 17 == 0).collect();
        assert!(contacts.len() > count / 4, "{} contacts", contacts.len());
        let constants = (MassModel::Radius, 0.8, 5.0);
        let fresh = || {
            (
                circles.clone(),
                velocities.clone(),
                held.clone(),
                vec![false; count],
            )
        };
        let (mut c, mut v, mut h, mut touched) = fresh();
        let mut exchanges = 0;
        for band in contacts.bands() {
            let arrays = (&mut c[..], &mut v[..], &mut h[..]);
            let count_one = |_, _, _, _| exchanges += 1;
            resolve_found_contacts(band, &mut touched, arrays, constants, count_one);
        }
        assert!(exchanges > count as u64 / 8, "{exchanges} exchanges");
        let one_after_another = (c, v, h, touched, exchanges);
        let mut in_parts = ExchangesInParts::default();
        for parts in [1, 2, 3, 8] {
            let (mut c, mut v, mut h, mut touched) = fresh();
            let arrays = (&mut c[..], &mut v[..], &mut h[..]);
            let found = (&contacts, &grid);
            let exchanges = in_parts.resolve(found, parts, &mut touched, arrays, constants);
            assert!(
                (c, v, h, touched, exchanges) == one_after_another,
                "{parts} parts"
            );
            assert!(in_parts.waits.iter().all(|&waits| !waits), "{parts} parts");
            let waiting: usize = in_parts.waiting.iter().map(Vec::len).sum();
            if parts > 1 && threads_at_work() > 1 {
                // The swapped balls' contacts and those near the parts' edges wait.
                assert!(waiting > 100, "{waiting} waiting with {parts} parts");
                assert!(
                    waiting < contacts.len() / 5,
                    "{waiting} waiting, {parts} parts"
                );
            }
        }
    }
}
