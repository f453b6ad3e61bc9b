//! The balls whose course changed during a continuous step, filed by grid cell, so a ball
//! redirected by an impact finds the other redirected balls near its new path. A path whose
//! swept circle is big by the grid's measure is kept apart, as the grid keeps big balls.

use bevy::math::DVec2;

use crate::sim::geometry::Circle;
use crate::sim::geometry::circle::circles_touch;
use crate::sim::geometry::grid::UniformGrid;

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
    /// Largest swept radius filed in a cell.
    reach: f64,
    /// The entries too big for the cells, searched one by one (their `next` unused).
    big: Vec<RerouteEntry>,
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
        self.big.clear();
        self.reach = 0.0;
    }

    /// Files ball `ball`, which has had `hits` hits, by the circle `swept` the rest of its
    /// path sweeps, in `grid`'s cells (or apart, if big by `grid`'s measure).
    pub fn insert(&mut self, grid: &UniformGrid, ball: u32, hits: u32, swept: Circle) {
        if swept.radius > grid.big_limit() {
            let next = Self::NONE;
            self.big.push(RerouteEntry {
                ball,
                hits,
                next,
                swept,
            });
            return;
        }
        let cell = grid.cell_index(swept.center);
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

    /// Calls `visit(ball)` for each ball filed here whose swept circle touches `swept` and
    /// whose entry is still current: `hits_of(ball)` is the hit count it was filed with.
    /// `grid` is the one the balls were filed by.
    pub fn for_each_that_may_touch(
        &self,
        grid: &UniformGrid,
        swept: Circle,
        hits_of: impl Fn(u32) -> u32,
        mut visit: impl FnMut(u32),
    ) {
        // The swept circle first, as it reads only the entry; the hit count reads the ball.
        let mut visit_current = |entry: &RerouteEntry| {
            if circles_touch(swept, entry.swept) && hits_of(entry.ball) == entry.hits {
                visit(entry.ball);
            }
        };
        let near = DVec2::splat(swept.radius + self.reach);
        grid.for_each_cell_run_in_box(swept.center - near, swept.center + near, |cells| {
            for cell in cells {
                let mut entry = self.head[cell];
                while entry != Self::NONE {
                    let filed = &self.entries[entry as usize];
                    visit_current(filed);
                    entry = filed.next;
                }
            }
        });
        self.big.iter().for_each(visit_current);
    }
}
