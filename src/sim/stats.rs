//! Measuring the simulation: [`SimStats`], counters updated at the end of every fixed step
//! from the collision messages, and [`StateSummary`], the whole-state figures (energy,
//! momentum, overlap, escapes) that reports and tests compute on demand.
//!
//! The counters run in [`SimSystems::Bookkeeping`](super::SimSystems::Bookkeeping), after the
//! response. In debug builds that set also asserts that every position and velocity is finite.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{Ball, Position, Radius, Velocity};
use super::collision::broad_phase::UniformGrid;
use super::collision::narrow_phase::Circle;
use super::collision::{IndexedContact, find_contacts};
use super::gas::{SPEED_BINS, SpeedHistogram};
use super::messages::{BallCollision, WallCollision};
use super::params::{BroadPhase, SimParams};
use super::{SimSystems, step_seconds};

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<SimStats>()
        .add_systems(FixedUpdate, count_step.in_set(SimSystems::Bookkeeping));
    #[cfg(debug_assertions)]
    app.add_systems(
        FixedUpdate,
        assert_state_is_finite.in_set(SimSystems::Bookkeeping),
    );
}

/// Running totals since the scene was loaded.
#[derive(Resource, Debug, Default, Clone, PartialEq)]
pub struct SimStats {
    pub steps: u64,
    /// Simulated seconds.
    pub sim_time: f64,
    pub ball_collisions: u64,
    pub wall_collisions: u64,
    /// Sum of the walls' normal impulses on the balls, mass x pixels per second.
    pub wall_impulse: f64,
    /// Continuous steps that reached their hit budget and finished without handling every
    /// impact (see [`MAX_HITS_PER_BALL`](super::continuous::MAX_HITS_PER_BALL)).
    pub cut_short_steps: u64,
}

impl SimStats {
    /// Mean force per unit length of wall: total wall impulse / (perimeter x simulated time).
    /// The 2-D pressure, in mass / second squared; zero before any time has passed.
    pub fn pressure(&self, arena_size: DVec2) -> f64 {
        let perimeter = 2.0 * (arena_size.x + arena_size.y);
        if self.sim_time > 0.0 && perimeter > 0.0 {
            self.wall_impulse / (perimeter * self.sim_time)
        } else {
            0.0
        }
    }
}

fn count_step(
    time: Res<Time>,
    params: Res<SimParams>,
    mut stats: ResMut<SimStats>,
    mut ball_hits: MessageReader<BallCollision>,
    mut wall_hits: MessageReader<WallCollision>,
) {
    stats.steps += 1;
    stats.sim_time += step_seconds(&time, &params);
    stats.ball_collisions += ball_hits.read().count() as u64;
    for hit in wall_hits.read() {
        stats.wall_collisions += 1;
        stats.wall_impulse += hit.impulse;
    }
}

#[cfg(debug_assertions)]
fn assert_state_is_finite(balls: Query<(&Position, &Velocity), With<Ball>>) {
    for (position, velocity) in &balls {
        assert!(
            position.is_finite() && velocity.is_finite(),
            "non-finite ball state: position {:?}, velocity {:?}",
            position.0,
            velocity.0
        );
    }
}

/// Kinetic energy `m v^2 / 2` of one ball.
#[inline]
pub fn kinetic_energy(mass: f64, velocity: DVec2) -> f64 {
    0.5 * mass * velocity.length_squared()
}

/// Potential energy of one ball in uniform `gravity`, zero at the origin: `-m g . p`.
#[inline]
pub fn potential_energy(mass: f64, position: DVec2, gravity: DVec2) -> f64 {
    -mass * gravity.dot(position)
}

/// Figures over the whole current state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StateSummary {
    pub ball_count: usize,
    pub kinetic_energy: f64,
    /// Kinetic plus gravitational potential energy.
    pub mechanical_energy: f64,
    pub momentum: DVec2,
    /// Largest overlap between two balls, divided by the smaller radius.
    pub max_overlap_rel: f64,
    /// Balls whose centre lies outside the arena.
    pub escaped: usize,
    /// Ball speeds against the Maxwell–Boltzmann curve for their temperature.
    pub speed_histogram: SpeedHistogram,
}

impl StateSummary {
    /// Mean kinetic energy per ball: the 2-D gas's temperature, in energy units.
    pub fn temperature(&self) -> f64 {
        if self.ball_count == 0 {
            0.0
        } else {
            self.kinetic_energy / self.ball_count as f64
        }
    }

    /// Measures every ball in `world`.
    pub fn measure(world: &mut World) -> Self {
        let params = world.resource::<SimParams>().clone();
        let half = params.half_extents();
        let mut summary = StateSummary::default();
        let mut circles = Vec::new();
        let mut speeds = Vec::new();
        let mut balls = world.query_filtered::<(&Position, &Velocity, &Radius), With<Ball>>();
        for (position, velocity, radius) in balls.iter(world) {
            let mass = params.mass_model.mass(radius.0);
            summary.ball_count += 1;
            summary.kinetic_energy += kinetic_energy(mass, velocity.0);
            summary.mechanical_energy += kinetic_energy(mass, velocity.0)
                + potential_energy(mass, position.0, params.gravity);
            summary.momentum += velocity.0 * mass;
            if position.x.abs() > half.x || position.y.abs() > half.y {
                summary.escaped += 1;
            }
            circles.push(Circle::new(position.0, radius.0));
            speeds.push((mass, velocity.length()));
        }
        summary.speed_histogram = SpeedHistogram::measure(&speeds, SPEED_BINS);
        let mut contacts: Vec<IndexedContact> = Vec::new();
        find_contacts(
            &circles,
            BroadPhase::Grid,
            &mut UniformGrid::default(),
            &mut contacts,
        );
        summary.max_overlap_rel = contacts
            .iter()
            .map(|c| {
                let smaller = circles[c.a as usize]
                    .radius
                    .min(circles[c.b as usize].radius);
                c.geometry.depth / smaller
            })
            .fold(0.0, f64::max);
        summary
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn energy_formulas() {
        assert_eq!(kinetic_energy(2.0, DVec2::new(3.0, 4.0)), 25.0);
        assert_eq!(
            potential_energy(2.0, DVec2::new(0.0, 10.0), DVec2::new(0.0, -9.0)),
            180.0
        );
    }

    #[test]
    fn pressure_is_impulse_per_perimeter_and_time() {
        let stats = SimStats {
            sim_time: 2.0,
            wall_impulse: 80.0,
            ..default()
        };
        assert_eq!(stats.pressure(DVec2::new(6.0, 4.0)), 2.0);
        assert_eq!(SimStats::default().pressure(DVec2::new(6.0, 4.0)), 0.0);
    }
}
