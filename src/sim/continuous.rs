//! Continuous collisions: each fixed step as a timeline of impacts, handled in time order.
//!
//! In continuous mode the movement stage only updates velocities (gravity, damping), so every
//! ball's path over the step is a straight segment. Then:
//!
//! - **Collision** (`predict_impacts`, in [`SimSystems::Collision`]): the circles swept
//!   along those segments go into the grid; their AABBs and distances cut the candidate
//!   pairs, and the exact quadratic ([`time_of_impact`]) gives each approaching pair's moment
//!   of contact. Each ball's first wall contact is found the same way.
//! - **Response** (`run_timeline`, in [`SimSystems::Response`]): take the earliest impact,
//!   move just its balls to that moment, exchange momentum along the line of centres (or
//!   reflect off the wall), predict anew for those balls, and repeat until the step is over;
//!   then move every ball to the end of the step and write them back.
//!
//! The [`Timeline`] does the work on plain arrays, so it is tested without an app. Balls move
//! lazily: each remembers where it was at the moment of its last hit. An
//! impact remembers how many hits each of its balls had when it was predicted; if either has
//! been hit since, the prediction is stale and skipped.
//!
//! [`SimSystems::Collision`]: super::SimSystems::Collision
//! [`SimSystems::Response`]: super::SimSystems::Response

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use bevy::math::DVec2;
use bevy::prelude::*;

use super::SimSystems;
use super::ball::{Ball, BallSnapshot, Position, Velocity};
use super::collision::broad_phase::UniformGrid;
use super::collision::narrow_phase::{
    COINCIDENT_NORMAL, Circle, circle_contact, circles_touch, collision_point, time_of_impact,
};
use super::collision::{Contact, Contacts, IndexedContact, find_contacts, search_in_bands};
use super::messages::{BallCollision, Wall, WallCollision};
use super::movement::{contain_in_arena, wall_contact_point, wall_impulse};
use super::params::{BroadPhase, CollisionMode, MassModel, SimParams};
use super::response::{normal_exchange, resolve_overlaps, separate, write_back};
use super::stats::SimStats;
use super::step_seconds;

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<Timeline>().add_systems(
        FixedUpdate,
        (
            predict_impacts.in_set(SimSystems::Collision),
            run_timeline.in_set(SimSystems::Response),
        )
            .run_if(in_mode(CollisionMode::Continuous)),
    );
}

/// A run condition: the simulation is in collision mode `mode`.
pub fn in_mode(mode: CollisionMode) -> impl FnMut(Res<SimParams>) -> bool + Clone {
    move |params: Res<SimParams>| params.collisions == mode
}

/// Pairs closing more slowly than this, pixels per second, count as resting, not approaching.
/// Without it, rounding after a perfectly inelastic hit could schedule the same pair again
/// and again at the same instant.
pub const MIN_APPROACH_SPEED: f64 = 1e-9;
/// A ball takes at most this many hits in one step. Only an inelastic collapse (a pile
/// pressed together by gravity, restitution below 1) comes near it; the step then ends for
/// that ball without further impacts, and the overlaps left at the end get the discrete
/// mode's response. [`SimStats::cut_short_steps`] counts such steps.
pub const MAX_HITS_PER_BALL: u32 = 16;
/// Pairs overlapping by more than this fraction of their summed radii at the start of a step
/// (placed so, or left by a discrete step or a cut-short one) are pushed apart at its end.
const OVERLAP_TOLERANCE: f64 = 1e-9;

/// What a step's timeline needs of the simulation's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSpec {
    /// Seconds.
    pub dt: f64,
    /// Half the arena size, pixels.
    pub half: DVec2,
    pub restitution: f64,
    pub mass_model: MassModel,
}

impl StepSpec {
    pub fn new(params: &SimParams, dt: f64) -> Self {
        Self {
            dt,
            half: params.half_extents(),
            restitution: params.restitution,
            mass_model: params.mass_model,
        }
    }
}

/// A hit the timeline handled. Times are seconds into the step; indices are positions in the
/// arrays given to [`Timeline::run`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hit {
    Ball {
        a: u32,
        b: u32,
        time: f64,
        /// The radius-weighted point, which for touching balls is where they touch.
        point: DVec2,
        /// Unit vector from `a` towards `b`.
        normal: DVec2,
        impulse: f64,
        closing_speed: f64,
    },
    Wall {
        ball: u32,
        wall: Wall,
        time: f64,
        point: DVec2,
        impulse: f64,
        normal_speed: f64,
    },
}

/// Seconds until a ball at `position` moving at `velocity` touches a wall of the arena
/// `[-half, half]`, and which wall: zero if it already touches (or crosses) a wall it moves
/// into. `None` if it moves into no wall, or only along axes where it is wider than the arena
/// (the end-of-step containment centres those).
pub fn wall_time_of_impact(
    position: DVec2,
    velocity: DVec2,
    radius: f64,
    half: DVec2,
) -> Option<(f64, Wall)> {
    let mut first: Option<(f64, Wall)> = None;
    for (axis, low_wall, high_wall) in [(0, Wall::Left, Wall::Right), (1, Wall::Bottom, Wall::Top)]
    {
        let limit = half[axis] - radius;
        let speed = velocity[axis];
        if limit <= 0.0 || speed.abs() <= MIN_APPROACH_SPEED {
            continue;
        }
        let (gap, wall) = if speed > 0.0 {
            (limit - position[axis], high_wall)
        } else {
            (limit + position[axis], low_wall)
        };
        let time = (gap / speed.abs()).max(0.0);
        if first.is_none_or(|(earliest, _)| time < earliest) {
            first = Some((time, wall));
        }
    }
    first
}

/// The smallest circle holding `circle` wherever it is while moving at `velocity` for
/// `seconds`: centred halfway along the path.
#[inline]
fn swept_circle(circle: Circle, velocity: DVec2, seconds: f64) -> Circle {
    Circle::new(
        circle.center + velocity * (0.5 * seconds),
        circle.radius + velocity.length() * (0.5 * seconds),
    )
}

/// [`time_of_impact`] for pairs closing faster than [`MIN_APPROACH_SPEED`].
#[inline]
fn approach_time(a: Circle, velocity_a: DVec2, b: Circle, velocity_b: DVec2) -> Option<f64> {
    let offset = b.center - a.center;
    let closing = (velocity_a - velocity_b).dot(offset);
    if closing <= 0.0
        || closing * closing <= MIN_APPROACH_SPEED * MIN_APPROACH_SPEED * offset.length_squared()
    {
        return None;
    }
    time_of_impact(a, velocity_a, b, velocity_b)
}

/// Pixels added to a redirected ball's swept circle, so rounding can never make the swept
/// circles' test reject a pair that touches at the very edge of the step.
const SWEPT_MARGIN: f64 = 1e-6;

/// `other` values from here up name a wall, below it a ball.
const WALL_BASE: u32 = u32::MAX - 3;
const WALLS: [Wall; 4] = [Wall::Left, Wall::Right, Wall::Bottom, Wall::Top];

/// A predicted impact: ball `a` with ball `other` (then `a < other`) or with a wall.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Impact {
    /// Seconds into the step.
    time: f64,
    a: u32,
    other: u32,
    /// How many hits `a` and `other` had had when this was predicted.
    hits_a: u32,
    hits_other: u32,
}

impl Impact {
    /// Ball `ball`, which has had `hits` hits, reaching `wall` at `time`.
    fn with_wall(time: f64, ball: usize, hits: u32, wall: Wall) -> Self {
        Self {
            time,
            a: ball as u32,
            other: WALL_BASE + wall as u32,
            hits_a: hits,
            hits_other: 0,
        }
    }

    /// Balls `i` and `j`, with `hits_i` and `hits_j` hits, meeting at `time`; stored with the
    /// lower index first, so a pair has one key whichever ball it was found from.
    fn between(time: f64, (i, hits_i): (usize, u32), (j, hits_j): (usize, u32)) -> Self {
        let ((a, hits_a), (b, hits_other)) = if i < j {
            ((i, hits_i), (j, hits_j))
        } else {
            ((j, hits_j), (i, hits_i))
        };
        Self {
            time,
            a: a as u32,
            other: b as u32,
            hits_a,
            hits_other,
        }
    }

    fn key(&self) -> (u32, u32, u32, u32) {
        (self.a, self.other, self.hits_a, self.hits_other)
    }
}

impl Eq for Impact {}

impl Ord for Impact {
    /// Earliest first; equal times in a fixed order of the balls, so the result never depends
    /// on the order in which the impacts were found.
    fn cmp(&self, other: &Self) -> Ordering {
        self.time
            .total_cmp(&other.time)
            .then_with(|| self.key().cmp(&other.key()))
    }
}

impl PartialOrd for Impact {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// What the collision stage's search finds for a pair.
#[derive(Clone, Copy, Debug)]
enum Prediction {
    Impact(Impact),
    /// Overlapping at the start of the step.
    Overlap(u32, u32),
}

/// The balls whose velocity changed during the step, filed by the grid cell of the circle
/// swept by the rest of their path: an intrusive list per cell. An entry is current while
/// its ball's hit count is still the one it was filed with.
#[derive(Debug, Default)]
struct Rerouted {
    /// First entry of each cell's list, or `NONE`.
    head: Vec<u32>,
    entries: Vec<RerouteEntry>,
    /// Cells whose `head` is set, to clear them cheaply.
    used_cells: Vec<u32>,
    /// Largest swept radius filed.
    reach: f64,
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

    fn reset(&mut self, cell_count: usize) {
        for &cell in &self.used_cells {
            self.head[cell as usize] = Self::NONE;
        }
        self.head.resize(cell_count, Self::NONE);
        self.used_cells.clear();
        self.entries.clear();
        self.reach = 0.0;
    }

    fn insert(&mut self, cell: usize, ball: u32, hits: u32, swept: Circle) {
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

    /// Calls `visit(ball, swept)` for the balls whose current entry is in `cells`.
    fn for_each_in_cells(
        &self,
        cells: std::ops::Range<usize>,
        movers: &[Mover],
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
                if movers[ball as usize].hits == hits {
                    visit(ball, swept);
                }
                entry = next;
            }
        }
    }
}

/// A ball on the step's timeline: where it is `clock` seconds into the step, and how many hits
/// it has taken.
#[derive(Clone, Copy, Debug)]
struct Mover {
    center: DVec2,
    velocity: DVec2,
    radius: f64,
    clock: f64,
    hits: u32,
}

impl Mover {
    fn circle(&self) -> Circle {
        Circle::new(self.center, self.radius)
    }

    /// Where the ball is `time` seconds into the step.
    #[inline]
    fn center_at(&self, time: f64) -> DVec2 {
        self.center + self.velocity * (time - self.clock)
    }

    fn advance(&mut self, time: f64) {
        self.center = self.center_at(time);
        self.clock = time;
    }
}

/// The continuous mode's working state, kept between steps to reuse its buffers.
#[derive(Resource, Debug, Default)]
pub struct Timeline {
    /// Each ball's circle swept over the whole step, sorted into cells.
    grid: UniformGrid,
    swept: Vec<Circle>,
    /// Largest radius in `swept`.
    grid_reach: f64,
    predictions: Vec<Prediction>,
    queue: BinaryHeap<Reverse<Impact>>,
    overlapping: Vec<(u32, u32)>,
    /// Every ball on this step's timeline, by index: all a prediction reads of one ball in
    /// one cache line.
    movers: Vec<Mover>,
    rerouted: Rerouted,
    /// Contacts for the discrete response of a step cut short.
    fallback: Vec<IndexedContact>,
    /// Whether some ball in the last run reached [`MAX_HITS_PER_BALL`].
    pub cut_short: bool,
}

impl Timeline {
    /// The collision stage's part: every impact of the coming step that the balls' current
    /// paths lead to. `circles` are the balls at the start of the step, `velocities` their
    /// velocities for the whole step.
    pub fn predict(&mut self, circles: &[Circle], velocities: &[DVec2], spec: StepSpec) {
        let dt = spec.dt;
        self.swept.clear();
        self.swept.extend(
            circles
                .iter()
                .zip(velocities)
                .map(|(circle, velocity)| swept_circle(*circle, *velocity, dt)),
        );
        self.grid_reach = self.swept.iter().map(|s| s.radius).fold(0.0, f64::max);
        self.grid.rebuild(&self.swept);
        self.predictions.clear();
        search_in_bands(&self.grid, &mut self.predictions, |grid, rows, found| {
            grid.for_each_candidate_pair_in_rows(rows, |i, j, swept_i, swept_j| {
                // The swept circles bound the paths: if they do not touch, the balls cannot.
                if !circles_touch(swept_i, swept_j) {
                    return;
                }
                let (a, b) = (i.min(j), i.max(j));
                let (ca, cb) = (circles[a as usize], circles[b as usize]);
                let (va, vb) = (velocities[a as usize], velocities[b as usize]);
                let reach = (ca.radius + cb.radius) * (1.0 - OVERLAP_TOLERANCE);
                if ca.center.distance_squared(cb.center) < reach * reach {
                    found.push(Prediction::Overlap(a, b));
                }
                if let Some(time) = approach_time(ca, va, cb, vb).filter(|&t| t <= dt) {
                    let impact = Impact::between(time, (a as usize, 0), (b as usize, 0));
                    found.push(Prediction::Impact(impact));
                }
            });
        });
        for (index, (circle, velocity)) in circles.iter().zip(velocities).enumerate() {
            if let Some((time, wall)) =
                wall_time_of_impact(circle.center, *velocity, circle.radius, spec.half)
                && time <= dt
            {
                let impact = Impact::with_wall(time, index, 0, wall);
                self.predictions.push(Prediction::Impact(impact));
            }
        }
    }

    /// The response stage's part: handles the predicted impacts in time order, predicting
    /// anew for every ball hit, then moves every ball to the end of the step. `circles` and
    /// `velocities` must be what [`predict`](Self::predict) was given; they are updated in
    /// place. Calls `on_hit` for each hit, in the order handled.
    pub fn run(
        &mut self,
        circles: &mut [Circle],
        velocities: &mut [DVec2],
        spec: StepSpec,
        mut on_hit: impl FnMut(Hit),
    ) {
        self.movers.clear();
        self.movers.extend(
            circles
                .iter()
                .zip(velocities.iter())
                .map(|(circle, velocity)| Mover {
                    center: circle.center,
                    velocity: *velocity,
                    radius: circle.radius,
                    clock: 0.0,
                    hits: 0,
                }),
        );
        self.rerouted.reset(self.grid.cell_count());
        self.queue.clear();
        self.overlapping.clear();
        for prediction in &self.predictions {
            match *prediction {
                Prediction::Impact(impact) => self.queue.push(Reverse(impact)),
                Prediction::Overlap(a, b) => self.overlapping.push((a, b)),
            }
        }
        self.cut_short = false;
        while let Some(Reverse(impact)) = self.queue.pop() {
            let a = impact.a as usize;
            let is_wall = impact.other >= WALL_BASE;
            let hits_other = if is_wall {
                0
            } else {
                self.movers[impact.other as usize].hits
            };
            if self.movers[a].hits != impact.hits_a || hits_other != impact.hits_other {
                continue; // stale: a ball in it has been hit since
            }
            if self.movers[a].hits == MAX_HITS_PER_BALL || hits_other == MAX_HITS_PER_BALL {
                self.cut_short = true;
                continue;
            }
            let now = impact.time;
            self.movers[a].advance(now);
            if is_wall {
                let wall = WALLS[(impact.other - WALL_BASE) as usize];
                let mover = &mut self.movers[a];
                if let Some(bounce) =
                    bounce_off_wall(mover.circle(), &mut mover.velocity, wall, spec)
                {
                    mover.center = bounce.center;
                    mover.hits += 1;
                    on_hit(Hit::Wall {
                        ball: impact.a,
                        wall,
                        time: now,
                        point: bounce.point,
                        impulse: bounce.impulse,
                        normal_speed: bounce.normal_speed,
                    });
                    self.predict_for(a, now, spec);
                }
            } else {
                let b = impact.other as usize;
                self.movers[b].advance(now);
                let (ma, mb) = (self.movers[a], self.movers[b]);
                let offset = mb.center - ma.center;
                let distance = offset.length();
                let normal = if distance > 0.0 {
                    offset / distance
                } else {
                    COINCIDENT_NORMAL
                };
                let Some(exchange) = normal_exchange(
                    ma.velocity,
                    mb.velocity,
                    spec.mass_model.inverse_mass(ma.radius),
                    spec.mass_model.inverse_mass(mb.radius),
                    normal,
                    spec.restitution,
                ) else {
                    continue;
                };
                self.movers[a].velocity = exchange.velocity_a;
                self.movers[b].velocity = exchange.velocity_b;
                self.movers[a].hits += 1;
                self.movers[b].hits += 1;
                on_hit(Hit::Ball {
                    a: impact.a,
                    b: impact.other,
                    time: now,
                    point: collision_point(ma.circle(), mb.circle()),
                    normal,
                    impulse: exchange.impulse,
                    closing_speed: exchange.closing_speed,
                });
                self.predict_for(a, now, spec);
                self.predict_for(b, now, spec);
            }
        }
        for ((circle, velocity), mover) in circles
            .iter_mut()
            .zip(velocities.iter_mut())
            .zip(&mut self.movers)
        {
            mover.advance(spec.dt);
            (circle.center, *velocity) = (mover.center, mover.velocity);
        }
        if self.cut_short {
            // Some balls stopped taking hits: whatever overlaps now gets the discrete response.
            self.fallback.clear();
            find_contacts(
                circles,
                BroadPhase::Grid,
                &mut self.grid,
                &mut self.fallback,
            );
            let pairs = self.fallback.iter().map(|contact| (contact.a, contact.b));
            resolve_overlaps(
                pairs,
                circles,
                velocities,
                spec.mass_model,
                spec.restitution,
                |a, b, geometry, exchange| {
                    on_hit(Hit::Ball {
                        a,
                        b,
                        time: spec.dt,
                        point: geometry.point,
                        normal: geometry.normal,
                        impulse: exchange.impulse,
                        closing_speed: exchange.closing_speed,
                    });
                },
            );
        }
        self.push_apart_overlaps(circles, spec);
        // Rounding can leave a ball a hair past a wall, and pushing overlaps apart can push
        // one into it: the same containment as the discrete mode puts it back.
        for (index, (circle, velocity)) in circles.iter_mut().zip(velocities.iter_mut()).enumerate()
        {
            let contained = contain_in_arena(
                circle.center,
                *velocity,
                circle.radius,
                spec.half,
                spec.restitution,
            );
            (circle.center, *velocity) = (contained.position, contained.velocity);
            for wall_hit in contained.hits.into_iter().flatten() {
                on_hit(Hit::Wall {
                    ball: index as u32,
                    wall: wall_hit.wall,
                    time: spec.dt,
                    point: wall_contact_point(wall_hit.wall, circle.center, spec.half),
                    impulse: wall_impulse(
                        spec.mass_model.mass(circle.radius),
                        spec.restitution,
                        wall_hit.normal_speed,
                    ),
                    normal_speed: wall_hit.normal_speed,
                });
            }
        }
    }

    /// Queues ball `index`'s next wall and ball impacts after its velocity changed at `now`.
    fn predict_for(&mut self, index: usize, now: f64, spec: StepSpec) {
        let mover = self.movers[index];
        if mover.hits == MAX_HITS_PER_BALL {
            // No more impacts for this ball this step: the end-of-step fallback takes over.
            self.cut_short = true;
            return;
        }
        let (circle, velocity) = (mover.circle(), mover.velocity);
        let queue = &mut self.queue;
        if let Some((time, wall)) =
            wall_time_of_impact(circle.center, velocity, circle.radius, spec.half)
            && now + time <= spec.dt
        {
            queue.push(Reverse(Impact::with_wall(
                now + time,
                index,
                mover.hits,
                wall,
            )));
        }
        let rest = spec.dt - now;
        let mut swept = swept_circle(circle, velocity, rest);
        swept.radius += SWEPT_MARGIN;
        self.rerouted.insert(
            self.grid.cell_index(swept.center),
            index as u32,
            mover.hits,
            swept,
        );
        let movers = &self.movers;
        let mut consider = |other: u32| {
            let other_index = other as usize;
            if other_index == index {
                return;
            }
            let other_mover = &movers[other_index];
            let other_circle = Circle::new(other_mover.center_at(now), other_mover.radius);
            let Some(time) = approach_time(circle, velocity, other_circle, other_mover.velocity)
                .map(|t| now + t)
                .filter(|&t| t <= spec.dt)
            else {
                return;
            };
            queue.push(Reverse(Impact::between(
                time,
                (index, mover.hits),
                (other_index, other_mover.hits),
            )));
        };
        // Balls on their first path of the step are filed in the grid by the circle that path
        // sweeps; the ones that changed course since, in `rerouted`. Both filters are the
        // swept circles: if they do not touch, neither can the balls.
        let near = DVec2::splat(swept.radius + self.grid_reach);
        self.grid.for_each_near(
            swept.center - near,
            swept.center + near,
            |other, other_swept| {
                if movers[other as usize].hits == 0 && circles_touch(swept, other_swept) {
                    consider(other);
                }
            },
        );
        let near = DVec2::splat(swept.radius + self.rerouted.reach);
        let rerouted = &self.rerouted;
        self.grid
            .for_each_cell_run_in_box(swept.center - near, swept.center + near, |cells| {
                rerouted.for_each_in_cells(cells, movers, |other, other_swept| {
                    if circles_touch(swept, other_swept) {
                        consider(other);
                    }
                });
            });
    }

    /// Pushes apart, shared by inverse mass, the pairs that overlapped at the start of the
    /// step and still do.
    fn push_apart_overlaps(&self, circles: &mut [Circle], spec: StepSpec) {
        for &(a, b) in &self.overlapping {
            let (a, b) = (a as usize, b as usize);
            let Some(geometry) = circle_contact(circles[a], circles[b]) else {
                continue;
            };
            let inverse_masses = (
                spec.mass_model.inverse_mass(circles[a].radius),
                spec.mass_model.inverse_mass(circles[b].radius),
            );
            separate(circles, (a, b), geometry, inverse_masses);
        }
    }
}

/// A ball's bounce off a wall: [`bounce_off_wall`]'s result.
struct WallBounce {
    /// The centre, set exactly against the wall.
    center: DVec2,
    point: DVec2,
    impulse: f64,
    normal_speed: f64,
}

/// Reflects a ball that touches `wall` and moves into it: the normal velocity is reversed and
/// scaled by the restitution. `None` (and no change) if it moves away from the wall.
fn bounce_off_wall(
    circle: Circle,
    velocity: &mut DVec2,
    wall: Wall,
    spec: StepSpec,
) -> Option<WallBounce> {
    let outward = wall.outward_normal();
    let normal_speed = velocity.dot(outward);
    if normal_speed <= 0.0 {
        return None;
    }
    *velocity -= outward * ((1.0 + spec.restitution) * normal_speed);
    let axis = usize::from(outward.y != 0.0);
    let mut center = circle.center;
    center[axis] = outward[axis] * (spec.half[axis] - circle.radius);
    Some(WallBounce {
        center,
        point: wall_contact_point(wall, center, spec.half),
        impulse: wall_impulse(
            spec.mass_model.mass(circle.radius),
            spec.restitution,
            normal_speed,
        ),
        normal_speed,
    })
}

fn predict_impacts(
    time: Res<Time>,
    params: Res<SimParams>,
    snapshot: Res<BallSnapshot>,
    mut timeline: ResMut<Timeline>,
) {
    let spec = StepSpec::new(&params, step_seconds(&time, &params));
    timeline.predict(&snapshot.circles, &snapshot.velocities, spec);
}

fn run_timeline(
    time: Res<Time>,
    params: Res<SimParams>,
    mut stats: ResMut<SimStats>,
    mut timeline: ResMut<Timeline>,
    mut snapshot: ResMut<BallSnapshot>,
    mut balls: Query<(Entity, &mut Position, &mut Velocity), With<Ball>>,
    mut contacts: ResMut<Contacts>,
    mut collisions: MessageWriter<BallCollision>,
    mut wall_hits: MessageWriter<WallCollision>,
) {
    let spec = StepSpec::new(&params, step_seconds(&time, &params));
    let step_start = stats.sim_time;
    let BallSnapshot {
        entities,
        circles,
        velocities,
    } = &mut *snapshot;
    contacts.0.clear();
    timeline.run(circles, velocities, spec, |hit| match hit {
        Hit::Ball {
            a,
            b,
            time,
            point,
            normal,
            impulse,
            closing_speed,
        } => {
            let (entity_a, entity_b) = (entities[a as usize], entities[b as usize]);
            contacts.0.push(Contact {
                a: entity_a,
                b: entity_b,
                index_a: a,
                index_b: b,
                normal,
                depth: 0.0,
                point,
            });
            collisions.write(BallCollision {
                a: entity_a,
                b: entity_b,
                time: step_start + time,
                point,
                normal,
                impulse,
                normal_speed: closing_speed,
            });
        }
        Hit::Wall {
            ball,
            wall,
            time,
            point,
            impulse,
            normal_speed,
        } => {
            wall_hits.write(WallCollision {
                ball: entities[ball as usize],
                wall,
                time: step_start + time,
                point,
                impulse,
                normal_speed,
            });
        }
    });
    if timeline.cut_short {
        stats.cut_short_steps += 1;
    }
    write_back(entities, &mut balls, |index| {
        Some((circles[index].center, velocities[index]))
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    const HALF: DVec2 = DVec2::new(100.0, 50.0);

    #[test]
    fn wall_time_is_the_gap_over_the_speed_toward_the_nearer_wall() {
        // 90 px to the right wall's limit at 30 px/s; 40 px to the top at 10 px/s.
        let (time, wall) =
            wall_time_of_impact(DVec2::ZERO, DVec2::new(30.0, 10.0), 10.0, HALF).unwrap();
        assert_eq!((time, wall), (3.0, Wall::Right));
        let (time, wall) =
            wall_time_of_impact(DVec2::ZERO, DVec2::new(-1.0, -20.0), 10.0, HALF).unwrap();
        assert_eq!((time, wall), (2.0, Wall::Bottom));
        // Already through a wall and still moving into it: now. Moving away: never.
        let past = DVec2::new(95.0, 0.0);
        assert_eq!(
            wall_time_of_impact(past, DVec2::X, 10.0, HALF),
            Some((0.0, Wall::Right))
        );
        assert_eq!(
            wall_time_of_impact(past, DVec2::NEG_X, 10.0, HALF).map(|h| h.1),
            Some(Wall::Left)
        );
        assert_eq!(
            wall_time_of_impact(DVec2::ZERO, DVec2::ZERO, 10.0, HALF),
            None
        );
        // Wider than the arena along y: only x counts.
        assert_eq!(
            wall_time_of_impact(DVec2::ZERO, DVec2::new(0.0, 5.0), 60.0, HALF),
            None
        );
    }

    #[test]
    fn impacts_come_out_by_time_then_by_ball() {
        let impact = |time, a, other| Impact {
            time,
            a,
            other,
            hits_a: 0,
            hits_other: 0,
        };
        let mut queue: BinaryHeap<Reverse<Impact>> = [
            impact(0.5, 3, 4),
            impact(0.25, 7, 9),
            impact(0.5, 1, 8),
            impact(0.5, 1, 2),
        ]
        .into_iter()
        .map(Reverse)
        .collect();
        let order: Vec<(u32, u32)> =
            std::iter::from_fn(|| queue.pop().map(|Reverse(i)| (i.a, i.other))).collect();
        assert_eq!(order, [(7, 9), (1, 2), (1, 8), (3, 4)]);
    }

    #[test]
    fn a_timeline_on_plain_arrays_bounces_a_fast_pair_and_keeps_energy() {
        let spec = StepSpec {
            dt: 1.0,
            half: DVec2::new(1_000.0, 1_000.0),
            restitution: 1.0,
            mass_model: MassModel::Radius,
        };
        let mut circles = vec![
            Circle::new(DVec2::new(-100.0, 0.0), 5.0),
            Circle::new(DVec2::new(100.0, 3.0), 10.0),
        ];
        let mut velocities = vec![DVec2::new(300.0, 0.0), DVec2::new(-300.0, 0.0)];
        let energy = |v: &[DVec2], c: &[Circle]| -> f64 {
            v.iter()
                .zip(c)
                .map(|(v, c)| 0.5 * c.radius * v.length_squared())
                .sum()
        };
        let before = energy(&velocities, &circles);
        let mut timeline = Timeline::default();
        timeline.predict(&circles, &velocities, spec);
        let mut hits = Vec::new();
        timeline.run(&mut circles, &mut velocities, spec, |hit| hits.push(hit));
        assert_eq!(hits.len(), 1);
        let Hit::Ball { time, point, .. } = hits[0] else {
            panic!("a ball hit")
        };
        // Closing 600 px/s over 200 - sqrt(15^2 - 3^2) px.
        let expected = (200.0 - (15.0f64 * 15.0 - 9.0).sqrt()) / 600.0;
        assert!((time - expected).abs() < 1e-12, "{time} vs {expected}");
        assert!(point.x.abs() < 15.0);
        assert!((energy(&velocities, &circles) - before).abs() < 1e-9 * before);
        assert!(circles[0].center.distance(circles[1].center) >= 15.0 - 1e-9);
        assert!(velocities[0].x < 0.0 && velocities[1].x > 0.0);
    }
}
