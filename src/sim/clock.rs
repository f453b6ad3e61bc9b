//! [`SimClock`]: the step's clock, the one resource every stage reads for `dt` and the
//! simulated time. Set at the start of each step from the fixed timestep and the time scale,
//! advanced by the reporting stage at its end; nothing in the simulation reads the wall clock.

use bevy::prelude::*;

use super::params::RunControl;

/// How long this step is and how much simulated time came before it.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq)]
pub struct SimClock {
    /// Simulated seconds in this step: the fixed timestep times [`RunControl::time_scale`].
    pub dt: f64,
    /// Simulated seconds since the scene was loaded, up to the start of this step (the end of
    /// the last one once a step is over).
    pub elapsed: f64,
    /// Steps run since the scene was loaded.
    pub steps: u64,
}

/// First in every step: this step's `dt`.
pub(super) fn start_step(time: Res<Time>, run: Res<RunControl>, mut clock: ResMut<SimClock>) {
    clock.dt = time.delta_secs_f64() * run.time_scale;
}

/// Last in every step: the step is over.
pub(super) fn end_step(mut clock: ResMut<SimClock>) {
    clock.steps += 1;
    clock.elapsed += clock.dt;
}
