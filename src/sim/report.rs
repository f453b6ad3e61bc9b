//! Stage 4, report: what the earlier stages recorded in the [`StepLog`] becomes the
//! [`SimStats`] counters and, unless [`HitReports`] is off, the outward [`BallCollision`] and
//! [`WallCollision`] messages and the overlay's [`ContactPoints`]. The stages themselves
//! write no messages and no counters.
//!
//! Runs in [`SimSystems::Report`](super::SimSystems::Report), after the response. In debug
//! builds the same stage asserts that every position and velocity is finite.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::BallSnapshot;
#[cfg(debug_assertions)]
use super::ball::{Ball, Position, Velocity};
use super::clock::SimClock;
use super::geometry::circle::{Circle, ContactGeometry};
use super::geometry::contain::Contained;
use super::geometry::impulse::{Exchange, wall_impulse};
use super::geometry::wall::{Wall, wall_contact_point};
use super::measure::SimStats;
use super::messages::{BallCollision, WallCollision};
use super::params::MassModel;

/// A hit a stage handled. Times are seconds into the step; indices are places in this step's
/// [`BallSnapshot`] (or in the arrays given to the continuous timeline).
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

impl Hit {
    /// The hit a ball–ball exchange at `time` into the step records.
    pub fn ball(a: u32, b: u32, time: f64, geometry: ContactGeometry, exchange: Exchange) -> Hit {
        Hit::Ball {
            a,
            b,
            time,
            point: geometry.point,
            normal: geometry.normal,
            impulse: exchange.impulse,
            closing_speed: exchange.closing_speed,
        }
    }

    /// The same hit with each ball's index `index` replaced by `renumber(index)`.
    pub fn renumbered(mut self, renumber: impl Fn(u32) -> u32) -> Hit {
        match &mut self {
            Hit::Ball { a, b, .. } => (*a, *b) = (renumber(*a), renumber(*b)),
            Hit::Wall { ball, .. } => *ball = renumber(*ball),
        }
        self
    }

    /// The wall hits of a containment of ball `ball` (of `mass`) at `time` into the step, in
    /// the arena `[-half, half]`; a resting stop is not a hit (see
    /// [`Contained::resting_impulse`]).
    pub fn walls_of(
        ball: u32,
        contained: &Contained,
        time: f64,
        half: DVec2,
        restitution: f64,
        mass: f64,
    ) -> impl Iterator<Item = Hit> {
        let position = contained.position;
        contained
            .hits
            .into_iter()
            .flatten()
            .filter(|hit| !hit.resting)
            .map(move |hit| Hit::Wall {
                ball,
                wall: hit.wall,
                time,
                point: wall_contact_point(hit.wall, position, half),
                impulse: wall_impulse(mass, restitution, hit.normal_speed),
                normal_speed: hit.normal_speed,
            })
    }
}

/// Records how the balls in `met` (by index, in index order, each with its containment) met
/// the walls of the arena `[-half, half]` at `time` into the step: each hit handed to
/// `on_hit`, and each ball's resting impulse added in turn to `resting_impulse`. A ball's mass
/// comes from its radius in `circles`.
pub fn record_walls_met(
    met: impl IntoIterator<Item = (u32, Contained)>,
    circles: &[Circle],
    (half, restitution, mass_model, time): (DVec2, f64, MassModel, f64),
    resting_impulse: &mut f64,
    mut on_hit: impl FnMut(Hit),
) {
    for (index, contained) in met {
        let mass = mass_model.mass(circles[index as usize].radius);
        *resting_impulse += contained.resting_impulse(mass);
        for hit in Hit::walls_of(index, &contained, time, half, restitution, mass) {
            on_hit(hit);
        }
    }
}

/// A point where two balls touched this step, and the normal there: what the overlay draws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    pub point: DVec2,
    /// Unit vector from the first ball towards the second.
    pub normal: DVec2,
}

/// What happened in this step, recorded by the stages in the order it happened and emptied
/// by the report stage.
#[derive(Resource, Debug, Default)]
pub struct StepLog {
    pub hits: HitLog,
    /// Discrete mode: every touching pair found; continuous mode: every ball–ball impact.
    /// Kept unless [`HitReports`] is off ([`note_contact`](Self::note_contact)).
    pub contacts: Vec<ContactPoint>,
    /// The contact points noted this step, kept or not.
    pub contact_count: u64,
    drop_contacts: bool,
    /// A continuous step stopped handling impacts for some ball (see
    /// [`hit_limit`](super::continuous::hit_limit)).
    pub cut_short: bool,
    /// The walls' impulse on resting balls (stops, the resting solver's contacts, sleeping
    /// balls' weight): no hits, but part of the pressure. Mass x pixels per second.
    pub resting_wall_impulse: f64,
}

impl StepLog {
    /// Whether this step keeps its ball hits and contact points, rather than only counting
    /// them.
    pub fn keeps_ball_hits(&self) -> bool {
        !self.hits.drop_ball_hits
    }

    /// Counts `count` ball hits, and their contact points, that this step drops.
    pub fn count_dropped_ball_hits(&mut self, count: u64) {
        debug_assert!(self.hits.drop_ball_hits || count == 0);
        self.contact_count += count;
        self.hits.ball_hits_not_kept += count;
    }

    /// Counts a contact point, and keeps it if this step's [`HitReports`] asks for them.
    pub fn note_contact(&mut self, contact: ContactPoint) {
        self.note_contacts(1, [contact]);
    }

    /// Counts `count` contact points, and keeps `points`, the same ones, if this step's
    /// [`HitReports`] asks for them: a step that drops them never reads them.
    pub fn note_contacts(&mut self, count: u64, points: impl IntoIterator<Item = ContactPoint>) {
        self.contact_count += count;
        if !self.drop_contacts {
            self.contacts.extend(points);
        }
    }
}

/// The step's hits as the stages record them: every one if this step's [`HitReports`] asks
/// for messages; otherwise the wall hits only (their impulses, summed in order, make the
/// pressure), the ball hits counted.
#[derive(Debug, Default)]
pub struct HitLog {
    /// The hits kept, in the order recorded.
    pub kept: Vec<Hit>,
    /// Ball hits counted but not kept.
    pub ball_hits_not_kept: u64,
    drop_ball_hits: bool,
}

impl HitLog {
    /// Records `hit`: kept, or only counted if it is a ball hit this step drops.
    pub fn push(&mut self, hit: Hit) {
        if !self.drop_ball_hits || matches!(hit, Hit::Wall { .. }) {
            self.kept.push(hit);
        } else {
            self.ball_hits_not_kept += 1;
        }
    }

    /// Counts `count` ball hits that this step drops, as [`push`](Self::push) would.
    pub fn count_dropped(&mut self, count: u64) {
        debug_assert!(self.drop_ball_hits || count == 0);
        self.ball_hits_not_kept += count;
    }

    /// Records each of `hits` as [`push`](Self::push) does.
    pub fn extend(&mut self, hits: impl IntoIterator<Item = Hit>) {
        for hit in hits {
            self.push(hit);
        }
    }
}

/// Before the stages: what this step's log keeps, as [`HitReports`] says.
pub fn start_log(reports: Res<HitReports>, mut log: ResMut<StepLog>) {
    log.hits.drop_ball_hits = !reports.enabled;
    log.drop_contacts = !reports.enabled;
}

/// The last step's contact points, for the overlay.
#[derive(Resource, Debug, Default)]
pub struct ContactPoints(pub Vec<ContactPoint>);

/// Whether the report stage hands every hit on as a [`BallCollision`] or [`WallCollision`]
/// message and keeps the step's [`ContactPoints`]: on unless turned off. The counters in
/// [`SimStats`] are kept either way. The headless commands, which read only the counters,
/// turn it off: at a million balls the messages and points are about 50 MB and a few
/// milliseconds a step. (Box2D's hit events are likewise asked for, not given by default.)
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq)]
pub struct HitReports {
    pub enabled: bool,
}

impl Default for HitReports {
    fn default() -> Self {
        Self { enabled: true }
    }
}

/// Turns the step's log into counters and, if [`HitReports`] asks for them, messages and
/// contact points.
pub fn report_step(
    clock: Res<SimClock>,
    snapshot: Res<BallSnapshot>,
    reports: Res<HitReports>,
    mut log: ResMut<StepLog>,
    mut stats: ResMut<SimStats>,
    mut contact_points: ResMut<ContactPoints>,
    mut ball_hits: MessageWriter<BallCollision>,
    mut wall_hits: MessageWriter<WallCollision>,
) {
    let step_start = clock.elapsed;
    let entities = &snapshot.entities;
    stats.contact_points += std::mem::take(&mut log.contact_count);
    stats.ball_collisions += std::mem::take(&mut log.hits.ball_hits_not_kept);
    for hit in log.hits.kept.drain(..) {
        match hit {
            Hit::Ball {
                a,
                b,
                time,
                point,
                normal,
                impulse,
                closing_speed,
            } => {
                stats.ball_collisions += 1;
                if reports.enabled {
                    ball_hits.write(BallCollision {
                        a: entities[a as usize],
                        b: entities[b as usize],
                        time: step_start + time,
                        point,
                        normal,
                        impulse,
                        normal_speed: closing_speed,
                    });
                }
            }
            Hit::Wall {
                ball,
                wall,
                time,
                point,
                impulse,
                normal_speed,
            } => {
                stats.wall_collisions += 1;
                stats.wall_impulse += impulse;
                if reports.enabled {
                    wall_hits.write(WallCollision {
                        ball: entities[ball as usize],
                        wall,
                        time: step_start + time,
                        point,
                        impulse,
                        normal_speed,
                    });
                }
            }
        }
    }
    stats.wall_impulse += std::mem::take(&mut log.resting_wall_impulse);
    if std::mem::take(&mut log.cut_short) {
        stats.cut_short_steps += 1;
    }
    if reports.enabled {
        // Hand the buffer over rather than copy it; the log gets the old one back, emptied.
        std::mem::swap(&mut contact_points.0, &mut log.contacts);
    } else {
        contact_points.0.clear();
    }
    log.contacts.clear();
}

#[cfg(debug_assertions)]
pub(super) fn assert_state_is_finite(balls: Query<(&Position, &Velocity), With<Ball>>) {
    for (position, velocity) in &balls {
        assert!(
            position.is_finite() && velocity.is_finite(),
            "non-finite ball state: position {:?}, velocity {:?}",
            position.0,
            velocity.0
        );
    }
}
