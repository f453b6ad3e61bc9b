//! The balls whose course changed during a continuous step, filed by grid cell, so a ball
//! redirected by an impact finds the other redirected balls near its new path.

use crate::sim::geometry::Circle;

/// The balls whose velocity changed during the step, filed by the grid cell of the circle
/// swept by the rest of their path: an intrusive list per cell. An entry is current while
/// its ball's hit count is still the one it was filed with.
#[derive(Debug, Default)]
pub struct Rerouted {
    /// First entry of each cell's list, or `NONE`.
    head: Vec<u32>,
    entries: Vec<RerouteEntry>,
    /// Cells whose `head` is set, to clear them cheaply.
    used_cells: Vec<u32>,
    /// Largest swept radius filed.
    pub reach: f64,
}

#[derive(Clone, Copy, Debug)]
struct RerouteEntry {
    ball: u32,
    hits: u32,
    next: u32,
    /// The circle the rest of the ball's path sweeps.
    swept: Circle,
}

impl Rerouted {
    const NONE: u32 = u32::MAX;

    pub fn reset(&mut self, cell_count: usize) {
        for &cell in &self.used_cells {
            self.head[cell as usize] = Self::NONE;
        }
        self.head.resize(cell_count, Self::NONE);
        self.used_cells.clear();
        self.entries.clear();
        self.reach = 0.0;
    }

    pub fn insert(&mut self, cell: usize, ball: u32, hits: u32, swept: Circle) {
        if self.head[cell] == Self::NONE {
            self.used_cells.push(cell as u32);
        }
        self.entries.push(RerouteEntry {
            ball,
            hits,
            next: self.head[cell],
            swept,
        });
        self.head[cell] = (self.entries.len() - 1) as u32;
        self.reach = self.reach.max(swept.radius);
    }

    /// Calls `visit(ball, swept)` for the balls whose entry in `cells` passes `filter` and is
    /// still current: `hits_of(ball)` is the hit count it was filed with. `filter` comes
    /// first, as it reads only the entry.
    pub fn for_each_in_cells(
        &self,
        cells: std::ops::Range<usize>,
        filter: impl Fn(Circle) -> bool,
        hits_of: impl Fn(u32) -> u32,
        mut visit: impl FnMut(u32, Circle),
    ) {
        for cell in cells {
            let mut entry = self.head[cell];
            while entry != Self::NONE {
                let RerouteEntry {
                    ball,
                    hits,
                    next,
                    swept,
                } = self.entries[entry as usize];
                if filter(swept) && hits_of(ball) == hits {
                    visit(ball, swept);
                }
                entry = next;
            }
        }
    }
}
