//! A persistent event-driven reference, an experiment for issue 14: what ballpit's exact mode
//! would cost if its timeline ran on from step to step instead of being predicted afresh each
//! step. Hard discs, elastic, no gravity (the standard gas; other scenes are refused).
//!
//! Every ball keeps its path (where it was at its own clock, and its velocity) and a count of
//! the times it changed. Each change schedules the ball's wall impact, the moment it leaves its
//! cell and every approaching neighbour's impact, tagged with both counts; an event whose
//! balls changed since it was scheduled is stale and skipped. A ball leaving its cell keeps its
//! path and its events and is predicted against the cells it comes next to; two balls that meet
//! are in neighbouring cells when they do, so each pair is predicted in time. A step takes
//! every event up to its end, then works out every ball's place at the end of the step, as
//! ballpit writes every ball back each step. The events wait in a calendar queue
//! (`calendar.rs`).

use std::cmp::Ordering;

use bevy::math::DVec2;

use crate::Engine;
use crate::calendar::Calendar;
use crate::scene::{Ball, Scene};

/// No ball: the end of a cell's list.
const NONE: u32 = u32::MAX;
/// An event's `other` for a wall (`WALL + axis`) or a cell left (`CROSS + axis * 2 + upward`).
const WALL: u32 = u32::MAX - 8;
const CROSS: u32 = u32::MAX - 4;

/// The cell holding `point` among `(columns, rows)` cells of side `cell_size` from the origin;
/// a point past the last ones goes to them.
fn cell_index(point: DVec2, cell_size: f64, (columns, rows): (usize, usize)) -> usize {
    let column = ((point.x / cell_size) as usize).min(columns - 1);
    let row = ((point.y / cell_size) as usize).min(rows - 1);
    row * columns + column
}

/// A scheduled event: ball `ball` meets `other` (a ball, or a wall or cell edge, see `WALL`
/// and `CROSS`) at `time`, if neither has changed since (their counts then).
#[derive(Clone, Copy, Debug)]
pub struct Event {
    pub time: f64,
    pub ball: u32,
    pub other: u32,
    pub count: u32,
    pub other_count: u32,
}

impl PartialEq for Event {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Event {}
impl PartialOrd for Event {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Event {
    /// Reversed, so that the heap gives the earliest first; ties by the balls.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .time
            .total_cmp(&self.time)
            .then(other.ball.cmp(&self.ball))
            .then(other.other.cmp(&self.other))
    }
}

/// A ball's path (where it was at its clock, and its velocity) and its place in the cells.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Disc {
    position: DVec2,
    velocity: DVec2,
    clock: f64,
    radius: f64,
    /// How many times its path changed.
    count: u32,
    cell: u32,
    next: u32,
    prev: u32,
}

pub struct Edmd {
    /// The scene's number of each ball.
    order: Vec<usize>,
    /// Each ball's path and place, one cache line a ball.
    discs: Vec<Disc>,
    inverse_mass: Vec<f64>,
    head: Vec<u32>,
    columns: usize,
    rows: usize,
    cell_size: f64,
    size: DVec2,
    now: f64,
    dt: f64,
    events: Calendar,
    /// Every ball's place at the end of the last step (at `now`).
    out: Vec<DVec2>,
}

impl Edmd {
    pub fn new(scene: &Scene) -> Result<Self, String> {
        if scene.gravity != DVec2::ZERO || scene.restitution != 1.0 {
            return Err("the event-driven reference runs elastic scenes without gravity".into());
        }
        let count = scene.balls.len();
        let largest = scene.balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        // Cells a largest diameter wide, and at most about four per ball (tiny balls in a big
        // arena make them bigger instead).
        let area_per_cell = scene.size.x * scene.size.y / (4 * count.max(1)) as f64;
        let cell_size = (2.0 * largest).max(area_per_cell.sqrt()).max(1e-9);
        let columns = ((scene.size.x / cell_size) as usize).max(1);
        let rows = ((scene.size.y / cell_size) as usize).max(1);
        let cell_size = (scene.size.x / columns as f64).max(scene.size.y / rows as f64);
        // Numbered in cell order, so that neighbours lie near each other in memory.
        let mut order: Vec<usize> = (0..count).collect();
        order.sort_by_key(|&k| cell_index(scene.balls[k].position, cell_size, (columns, rows)));
        let balls: Vec<Ball> = order.iter().map(|&k| scene.balls[k]).collect();
        let mut edmd = Edmd {
            order,
            discs: (balls.iter())
                .map(|b| Disc {
                    position: b.position,
                    velocity: b.velocity,
                    clock: 0.0,
                    radius: b.radius,
                    count: 0,
                    cell: NONE,
                    next: NONE,
                    prev: NONE,
                })
                .collect(),
            inverse_mass: (balls.iter())
                .map(|b| 1.0 / scene.mass_model.mass(b.radius))
                .collect(),
            head: vec![NONE; columns * rows],
            columns,
            rows,
            cell_size,
            size: scene.size,
            now: 0.0,
            dt: scene.dt,
            events: Calendar::new(scene.dt / (count / 400).clamp(8, 4096) as f64),
            out: balls.iter().map(|b| b.position).collect(),
        };
        for ball in 0..count {
            let cell = edmd.cell_at(edmd.discs[ball].position);
            edmd.insert(ball, cell);
        }
        for ball in 0..count {
            edmd.predict_walls_and_cells(ball);
            let cells = edmd.neighbourhood(edmd.discs[ball].cell as usize);
            edmd.predict_pairs_in(ball, cells, true);
        }
        Ok(edmd)
    }

    fn cell_at(&self, point: DVec2) -> usize {
        cell_index(point, self.cell_size, (self.columns, self.rows))
    }

    fn insert(&mut self, ball: usize, cell: usize) {
        let first = self.head[cell];
        self.discs[ball].next = first;
        self.discs[ball].prev = NONE;
        if first != NONE {
            self.discs[first as usize].prev = ball as u32;
        }
        self.head[cell] = ball as u32;
        self.discs[ball].cell = cell as u32;
    }

    fn remove(&mut self, ball: usize) {
        let (prev, next) = (self.discs[ball].prev, self.discs[ball].next);
        if prev != NONE {
            self.discs[prev as usize].next = next;
        } else {
            self.head[self.discs[ball].cell as usize] = next;
        }
        if next != NONE {
            self.discs[next as usize].prev = prev;
        }
    }

    /// The cells around `cell` (itself included), as (columns, rows) ranges.
    fn neighbourhood(&self, cell: usize) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
        let (column, row) = (cell % self.columns, cell / self.columns);
        (
            column.saturating_sub(1)..(column + 2).min(self.columns),
            row.saturating_sub(1)..(row + 2).min(self.rows),
        )
    }

    fn at(&self, ball: usize, time: f64) -> DVec2 {
        self.discs[ball].position + self.discs[ball].velocity * (time - self.discs[ball].clock)
    }

    fn advance(&mut self, ball: usize, time: f64) {
        self.discs[ball].position = self.at(ball, time);
        self.discs[ball].clock = time;
    }

    fn schedule(&mut self, time: f64, ball: usize, other: u32, other_count: u32) {
        self.events.push(Event {
            time,
            ball: ball as u32,
            other,
            count: self.discs[ball].count,
            other_count,
        });
    }

    /// The ball's next wall impact (if it comes before it leaves its cell: it is predicted
    /// again from the next one) and the moment it leaves its cell.
    fn predict_walls_and_cells(&mut self, ball: usize) {
        let (p, v, r) = (
            self.at(ball, self.now),
            self.discs[ball].velocity,
            self.discs[ball].radius,
        );
        let cell = self.discs[ball].cell as usize;
        let corner = DVec2::new(
            (cell % self.columns) as f64 * self.cell_size,
            (cell / self.columns) as f64 * self.cell_size,
        );
        let last = DVec2::new((self.columns - 1) as f64, (self.rows - 1) as f64) * self.cell_size;
        let (mut wall, mut wall_axis) = (f64::INFINITY, 0);
        let (mut cross, mut cross_code) = (f64::INFINITY, 0);
        for axis in 0..2 {
            let speed = v[axis];
            if speed > 0.0 {
                let t = ((self.size[axis] - r - p[axis]) / speed).max(0.0);
                if t < wall {
                    (wall, wall_axis) = (t, axis);
                }
                if corner[axis] < last[axis] {
                    let t = ((corner[axis] + self.cell_size - p[axis]) / speed).max(0.0);
                    if t < cross {
                        (cross, cross_code) = (t, axis * 2 + 1);
                    }
                }
            } else if speed < 0.0 {
                let t = ((r - p[axis]) / speed).max(0.0);
                if t < wall {
                    (wall, wall_axis) = (t, axis);
                }
                if corner[axis] > 0.0 {
                    let t = ((corner[axis] - p[axis]) / speed).max(0.0);
                    if t < cross {
                        (cross, cross_code) = (t, axis * 2);
                    }
                }
            }
        }
        if wall.is_finite() && wall <= cross {
            self.schedule(self.now + wall, ball, WALL + wall_axis as u32, 0);
        }
        if cross.is_finite() {
            self.schedule(self.now + cross, ball, CROSS + cross_code as u32, 0);
        }
    }

    /// Every approaching ball in the cells `(columns, rows)`; at the start, each pair once.
    fn predict_pairs_in(
        &mut self,
        ball: usize,
        (columns, rows): (std::ops::Range<usize>, std::ops::Range<usize>),
        only_later: bool,
    ) {
        let (p, v, r) = (
            self.at(ball, self.now),
            self.discs[ball].velocity,
            self.discs[ball].radius,
        );
        for row in rows {
            for column in columns.clone() {
                let mut other = self.head[row * self.columns + column];
                while other != NONE {
                    let o = other as usize;
                    other = self.discs[o].next;
                    if o == ball || (only_later && o < ball) {
                        continue;
                    }
                    let dp = self.at(o, self.now) - p;
                    let dv = self.discs[o].velocity - v;
                    let b = dp.dot(dv);
                    if b >= 0.0 {
                        continue;
                    }
                    let sigma = r + self.discs[o].radius;
                    let c = dp.length_squared() - sigma * sigma;
                    let a = dv.length_squared();
                    let discriminant = b * b - a * c;
                    if discriminant < 0.0 {
                        continue;
                    }
                    let t = (c / (-b + discriminant.sqrt())).max(0.0);
                    self.schedule(self.now + t, ball, o as u32, self.discs[o].count);
                }
            }
        }
    }

    fn changed(&mut self, ball: usize) {
        self.discs[ball].count += 1;
        self.predict_around(ball);
    }

    fn predict_around(&mut self, ball: usize) {
        self.predict_walls_and_cells(ball);
        let cells = self.neighbourhood(self.discs[ball].cell as usize);
        self.predict_pairs_in(ball, cells, false);
    }

    fn handle(&mut self, event: Event) {
        let ball = event.ball as usize;
        if self.discs[ball].count != event.count {
            return;
        }
        self.now = event.time;
        if event.other >= CROSS {
            self.advance(ball, event.time);
            let code = (event.other - CROSS) as usize;
            let (axis, upward) = (code / 2, code % 2 == 1);
            let cell = self.discs[ball].cell as usize;
            let step = if axis == 0 { 1 } else { self.columns };
            let new_cell = if upward { cell + step } else { cell - step };
            self.remove(ball);
            self.insert(ball, new_cell);
            // Its paths stay, and so do its events: only the cells it now comes next to.
            let (mut columns, mut rows) = self.neighbourhood(new_cell);
            let (column, row) = (new_cell % self.columns, new_cell / self.columns);
            let far_side = |at: usize, up: bool, limit: usize| {
                let far = if up { at + 1 } else { at.wrapping_sub(1) };
                if far < limit { far..far + 1 } else { 0..0 }
            };
            if axis == 0 {
                columns = far_side(column, upward, self.columns);
            } else {
                rows = far_side(row, upward, self.rows);
            }
            self.predict_walls_and_cells(ball);
            self.predict_pairs_in(ball, (columns, rows), false);
        } else if event.other >= WALL {
            let axis = (event.other - WALL) as usize;
            self.advance(ball, event.time);
            self.discs[ball].velocity[axis] = -self.discs[ball].velocity[axis];
            self.changed(ball);
        } else {
            let other = event.other as usize;
            if self.discs[other].count != event.other_count {
                return;
            }
            self.advance(ball, event.time);
            self.advance(other, event.time);
            let offset = self.discs[other].position - self.discs[ball].position;
            let normal = offset.normalize_or(DVec2::X);
            let closing = (self.discs[other].velocity - self.discs[ball].velocity).dot(normal);
            if closing < 0.0 {
                let (ia, ib) = (self.inverse_mass[ball], self.inverse_mass[other]);
                let impulse = -2.0 * closing / (ia + ib);
                self.discs[ball].velocity -= normal * (impulse * ia);
                self.discs[other].velocity += normal * (impulse * ib);
            }
            self.changed(ball);
            self.changed(other);
        }
    }
}

impl Engine for Edmd {
    fn step(&mut self) {
        let end = self.now + self.dt;
        loop {
            let discs = &self.discs;
            let is_current = |event: &Event| {
                discs[event.ball as usize].count == event.count
                    && (event.other >= WALL
                        || discs[event.other as usize].count == event.other_count)
            };
            let Some(event) = self.events.pop_until(end, is_current) else {
                break;
            };
            self.handle(event);
        }
        self.now = end;
        for ball in 0..self.out.len() {
            self.out[ball] = self.at(ball, end);
        }
    }

    fn balls(&mut self) -> Vec<Ball> {
        let mut balls = vec![
            Ball {
                position: DVec2::ZERO,
                velocity: DVec2::ZERO,
                radius: 0.0
            };
            self.out.len()
        ];
        for ball in 0..self.out.len() {
            balls[self.order[ball]] = Ball {
                position: self.out[ball],
                velocity: self.discs[ball].velocity,
                radius: self.discs[ball].radius,
            };
        }
        balls
    }
}
