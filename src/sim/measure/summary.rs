//! [`StateSummary`]: figures over the whole current state, measured on demand from the ball
//! components: energy, momentum, temperature, the speed histogram, escapes, how many balls
//! move and sleep and, when asked, the overlaps. The headless report, the soak, the panel and the tests use the same
//! summary.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::gas::{SPEED_BINS, SpeedHistogram};
use crate::sim::ball::{Ball, Position, Radius, Rest, Velocity};
use crate::sim::geometry::Circle;
use crate::sim::geometry::pairs::contacts_among;
use crate::sim::params::SimParams;

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

/// A ball faster than this, pixels per second, counts as moving.
pub const MOVING_SPEED: f64 = 1.0;

/// Figures over the whole current state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StateSummary {
    pub ball_count: usize,
    pub kinetic_energy: f64,
    /// Kinetic plus gravitational potential energy.
    pub mechanical_energy: f64,
    pub momentum: DVec2,
    /// Largest overlap between two balls, divided by the smaller radius (measured by
    /// [`measure`](Self::measure) only: it searches for pairs).
    pub max_overlap_rel: f64,
    /// Mean of the same over the overlapping pairs (by [`measure`](Self::measure) only).
    pub mean_overlap_rel: f64,
    /// Balls faster than [`MOVING_SPEED`].
    pub moving: usize,
    /// Root mean square of the speeds, pixels per second.
    pub rms_speed: f64,
    /// Balls asleep (by [`measure`](Self::measure) only: it reads their [`Rest`]).
    pub sleeping: usize,
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

    /// Everything but the overlap, over `balls` as (position, velocity, radius), in an
    /// arena of `params`. `speeds` is scratch space for the histogram's input.
    pub fn of_balls(
        balls: impl IntoIterator<Item = (DVec2, DVec2, f64)>,
        params: &SimParams,
        speeds: &mut Vec<(f64, f64)>,
    ) -> Self {
        let half = params.half_extents();
        let mut summary = StateSummary::default();
        speeds.clear();
        for (position, velocity, radius) in balls {
            let mass = params.mass_model.mass(radius);
            summary.ball_count += 1;
            summary.kinetic_energy += kinetic_energy(mass, velocity);
            summary.mechanical_energy +=
                kinetic_energy(mass, velocity) + potential_energy(mass, position, params.gravity);
            summary.momentum += velocity * mass;
            if position.x.abs() > half.x || position.y.abs() > half.y {
                summary.escaped += 1;
            }
            speeds.push((mass, velocity.length()));
            summary.moving += usize::from(velocity.length() > MOVING_SPEED);
            summary.rms_speed += velocity.length_squared();
        }
        if summary.ball_count > 0 {
            summary.rms_speed = (summary.rms_speed / summary.ball_count as f64).sqrt();
        }
        summary.speed_histogram = SpeedHistogram::measure(speeds, SPEED_BINS);
        summary
    }

    /// Measures every ball in `world`, the largest overlap included.
    pub fn measure(world: &mut World) -> Self {
        let params = world.resource::<SimParams>().clone();
        let mut balls = world.query_filtered::<(&Position, &Velocity, &Radius), With<Ball>>();
        let states: Vec<(DVec2, DVec2, f64)> = balls
            .iter(world)
            .map(|(position, velocity, radius)| (position.0, velocity.0, radius.0))
            .collect();
        let mut summary = Self::of_balls(states.iter().copied(), &params, &mut Vec::new());
        let circles: Vec<Circle> = states
            .iter()
            .map(|&(position, _, radius)| Circle::new(position, radius))
            .collect();
        (summary.max_overlap_rel, summary.mean_overlap_rel) = overlaps_rel(&circles);
        let mut rests = world.query_filtered::<&Rest, With<Ball>>();
        summary.sleeping = rests.iter(world).filter(|rest| rest.is_asleep()).count();
        summary
    }
}

/// The largest overlap among `circles`, divided by the smaller radius of its pair.
pub fn max_overlap_rel(circles: &[Circle]) -> f64 {
    overlaps_rel(circles).0
}

/// The largest overlap among `circles`, and the mean over the overlapping pairs, each
/// divided by the smaller radius of its pair.
pub fn overlaps_rel(circles: &[Circle]) -> (f64, f64) {
    let contacts = contacts_among(circles);
    let (mut largest, mut sum, mut count) = (0.0_f64, 0.0, 0_usize);
    for contact in contacts.iter().filter(|c| c.geometry.depth > 0.0) {
        let smaller = circles[contact.a as usize]
            .radius
            .min(circles[contact.b as usize].radius);
        let overlap = contact.geometry.depth / smaller;
        largest = largest.max(overlap);
        sum += overlap;
        count += 1;
    }
    (largest, if count == 0 { 0.0 } else { sum / count as f64 })
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
}
