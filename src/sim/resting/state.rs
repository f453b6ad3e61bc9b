//! The resting stage's state between steps: [`RestingState`].

use std::collections::BTreeMap;

use bevy::platform::collections::HashMap;

use bevy::math::DVec2;
use bevy::prelude::*;

use super::contacts::NearPairs;
use super::solver::{Body, RestingContact, SolverMemory};
use crate::sim::ball::Rest;
use crate::sim::params::{CollisionMode, MassModel};

/// What the parameters were when balls last fell asleep: a change wakes them all.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MotionKey {
    pub gravity: DVec2,
    pub restitution: f64,
    pub mass_model: MassModel,
    pub arena_size: DVec2,
    pub mode: CollisionMode,
}

/// The resting stage's state, kept between steps.
#[derive(Resource, Debug, Default)]
pub struct RestingState {
    /// How many balls sleep now.
    pub asleep: usize,
    /// Sleeping islands to wake at the next step (an intent touched them).
    pub wake_requests: Vec<u32>,
    /// Wake every sleeping ball at the next step.
    pub wake_all: bool,
    pub(super) last_key: Option<MotionKey>,
    /// Each contact's last impulse, for the warm start: keyed by the two sides.
    pub(super) warm: HashMap<(u64, u64), f64>,
    /// Each sleeping island's weight on the walls, mass x pixels per second squared.
    pub(super) island_load: BTreeMap<u32, f64>,
    pub(super) next_island: u32,
    pub(super) near: NearPairs,
    pub(super) rests: Vec<Rest>,
    /// The solver's input and working memory, kept between steps so a step allocates
    /// nothing: its bodies, its contacts, each body's velocity when the step began.
    pub(super) bodies: Vec<Body>,
    pub(super) contacts: Vec<RestingContact>,
    pub(super) start: Vec<DVec2>,
    pub(super) memory: SolverMemory,
}
