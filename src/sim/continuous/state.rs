//! The continuous mode's working state: the [`Timeline`] resource, every ball on it as a
//! `Mover`, and what a step needs of the parameters ([`StepSpec`]). `predict.rs` (stage 2)
//! and `timeline.rs` (stage 3) each implement their half of `Timeline` on it.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use bevy::math::DVec2;
use bevy::prelude::*;

use super::impact::{Impact, Prediction};
use super::rerouted::Rerouted;
use crate::sim::geometry::Circle;
use crate::sim::geometry::flight::{position_after, velocity_after};
use crate::sim::geometry::grid::UniformGrid;
use crate::sim::geometry::pairs::IndexedContact;
use crate::sim::params::{MassModel, SimParams};

/// A ball takes at most this many hits in one step. Only an inelastic collapse (a pile
/// pressed together by gravity, restitution below 1) comes near it; the step then ends for
/// that ball without further impacts, and the overlaps left at the end get the discrete
/// mode's response. [`SimStats::cut_short_steps`](crate::sim::SimStats::cut_short_steps)
/// counts such steps.
pub const MAX_HITS_PER_BALL: u32 = 16;

/// What a step's timeline needs of the simulation's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSpec {
    /// Seconds.
    pub dt: f64,
    /// Half the arena size, pixels.
    pub half: DVec2,
    pub restitution: f64,
    pub mass_model: MassModel,
    /// Pixels per second squared, the same for every ball: each one's path is a parabola.
    pub gravity: DVec2,
}

impl StepSpec {
    pub fn new(params: &SimParams, dt: f64) -> Self {
        Self {
            dt,
            half: params.half_extents(),
            restitution: params.restitution,
            mass_model: params.mass_model,
            gravity: params.gravity,
        }
    }
}

/// A ball on the step's timeline: where it is `clock` seconds into the step, and how many hits
/// it has taken.
#[derive(Clone, Copy, Debug)]
pub(super) struct Mover {
    pub center: DVec2,
    pub velocity: DVec2,
    pub radius: f64,
    pub clock: f64,
    pub hits: u32,
}

impl Mover {
    pub fn circle(&self) -> Circle {
        Circle::new(self.center, self.radius)
    }

    /// Where the ball is `time` seconds into the step, in free flight under `gravity`.
    #[inline]
    pub fn center_at(&self, time: f64, gravity: DVec2) -> DVec2 {
        position_after(self.center, self.velocity, gravity, time - self.clock)
    }

    /// Its velocity then.
    #[inline]
    pub fn velocity_at(&self, time: f64, gravity: DVec2) -> DVec2 {
        velocity_after(self.velocity, gravity, time - self.clock)
    }

    pub fn advance(&mut self, time: f64, gravity: DVec2) {
        self.center = self.center_at(time, gravity);
        self.velocity = self.velocity_at(time, gravity);
        self.clock = time;
    }
}

/// The continuous mode's working state, kept between steps to reuse its buffers.
#[derive(Resource, Debug, Default)]
pub struct Timeline {
    /// Each ball's circle swept over the whole step, sorted into cells.
    pub(super) grid: UniformGrid,
    pub(super) swept: Vec<Circle>,
    /// Largest radius in `swept`.
    pub(super) grid_reach: f64,
    pub(super) predictions: Vec<Prediction>,
    pub(super) queue: BinaryHeap<Reverse<Impact>>,
    pub(super) overlapping: Vec<(u32, u32)>,
    /// Every ball on this step's timeline, by index: all a prediction reads of one ball in
    /// one cache line.
    pub(super) movers: Vec<Mover>,
    pub(super) rerouted: Rerouted,
    /// Contacts for the discrete response of a step cut short.
    pub(super) fallback: Vec<IndexedContact>,
    /// Whether some ball in the last run reached [`MAX_HITS_PER_BALL`].
    pub cut_short: bool,
}
