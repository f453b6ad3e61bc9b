//! Stage 3's loads ahead, continuous: what the impacts about to be taken will read, brought
//! into the cache before they read it. Impacts come in time order, so each one's balls lie
//! anywhere in memory, and at a million balls waiting for those reads is most of an impact's
//! cost (docs/performance.md, *Prefetching the coming impacts* and *The loads ahead in three
//! stages*). The timeline's loop calls
//! [`Timeline::prefetch_coming`] before each impact; nothing here changes a result.

use super::impact::Impact;
use super::state::{Mover, Timeline};
use crate::sim::cache::{PREFETCH_MIN_BALLS, prefetch};

/// How many of the step's first predictions ahead [`Timeline::prefetch_coming`] loads the
/// cells around a ball (half as many again ahead, where their rows start; twice as many, the
/// balls themselves): 2 and 8 did as well at a million balls.
const PREFETCH_DISTANCE: usize = 4;

impl Timeline {
    /// Whether this step's balls are enough for the loads to pay ([`PREFETCH_MIN_BALLS`]:
    /// below it, 1–2% at 1,000 and 10,000 balls with the plain loads the timeline first made,
    /// 1–3% with the prefetch instruction; the timeline's arrays are about 130 B a ball).
    pub(super) fn worth_prefetching(&self) -> bool {
        self.movers.len() >= PREFETCH_MIN_BALLS
    }

    /// Loads what the impacts about to be taken will read, so that it is in the cache when
    /// they are: impacts come in time order, so each one's balls lie anywhere in memory, and
    /// at a million balls waiting for those reads is most of an impact's cost
    /// (docs/performance.md, *Prefetching the coming impacts*). For the step's first
    /// predictions a few places ahead, in three stages, each reading only what the one before
    /// loaded: the balls and their cells; nearer, where the rows of cells around the first
    /// ball start; nearer still, those rows' first circles. For the earliest impact predicted
    /// since, all at once. Nothing here changes a result.
    pub(super) fn prefetch_coming(&self) {
        if let Some(&further) = self.queue.ahead(2 * PREFETCH_DISTANCE) {
            self.prefetch_balls(further);
        }
        if let Some(middle) = self.queue.ahead(PREFETCH_DISTANCE * 3 / 2) {
            self.grid.prefetch_cell_starts_around(middle.a as usize);
        }
        if let Some(nearer) = self.queue.ahead(PREFETCH_DISTANCE) {
            self.grid.prefetch_cells_around(nearer.a as usize);
        }
        if let Some(&later) = self.queue.earliest_later() {
            self.prefetch_balls(later);
            self.grid.prefetch_cells_around(later.a as usize);
        }
    }

    /// Loads the movers of `impact`'s balls and their slots in the grid (the second's circle
    /// is read to tell whether the first's search would find it).
    fn prefetch_balls(&self, impact: Impact) {
        prefetch_mover(&self.movers, impact.a);
        if impact.wall().is_none() {
            prefetch_mover(&self.movers, impact.other);
            self.grid.prefetch_slot(impact.other as usize);
        }
        self.grid.prefetch_slot(impact.a as usize);
    }
}

/// Loads the mover in `slot`, if any.
pub(super) fn prefetch_mover(movers: &[Mover], slot: u32) {
    // A mover spans two cache lines: its first field and its last but one bring both (its
    // layout is fixed: `repr(C)`).
    let mover = movers.get(slot as usize);
    prefetch(mover.map(|mover| &mover.center));
    prefetch(mover.map(|mover| &mover.hits));
}
