//! The headless simulation. Every plugin in this module works without rendering: it touches
//! no window, asset, render or egui resource, so it runs under `MinimalPlugins` in tests, on
//! the command line and in benchmarks exactly as it does in the game.
//!
//! One fixed step, in `FixedUpdate`, is four ordered sets (chained once, below).
//! [`SimParams::collisions`] chooses the systems of stages 2 and 3:
//!
//! 1. [`SimSystems::Movement`]: integrate velocity (and, in discrete mode, position and the
//!    walls); copy every ball into the contiguous [`BallSnapshot`](ball::BallSnapshot).
//! 2. [`SimSystems::Collision`]: discrete, broad phase (grid), AABB test, exact distance test →
//!    [`Contacts`] (`collision`); continuous, the exact time of impact of every approaching
//!    pair and wall within the step (`continuous`).
//! 3. [`SimSystems::Response`]: discrete, exchange along each contact normal, separation, walls
//!    (`response`); continuous, the impacts in time order, predicting anew after each
//!    (`continuous`). Either writes the balls back.
//! 4. [`SimSystems::Bookkeeping`]: counters from the collision messages; debug invariants.
//!
//! Data flows one way: components → snapshot → contacts or impacts → components, and outward
//! as [`BallCollision`] / [`WallCollision`] messages.

pub mod aim;
pub mod ball;
pub mod collision;
pub mod continuous;
pub mod gas;
pub mod messages;
pub mod movement;
pub mod params;
pub mod placement;
#[cfg(test)]
mod properties;
pub mod response;
pub mod scene;
pub mod spawn;
pub mod stats;

use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;

pub use ball::{Ball, BallId, BallState, Position, PreviousPosition, Radius, Velocity};
pub use collision::{Contact, Contacts};
pub use messages::{BallCollision, Wall, WallCollision};
pub use params::{BroadPhase, CollisionMode, MassModel, SimParams};
pub use scene::{SceneError, SceneFile, SceneSetup, SimRng};
pub use spawn::SpawnSettings;
pub use stats::{SimStats, StateSummary};

/// The simulation's stages, run in this order every fixed step.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimSystems {
    /// Integrate motion and keep balls inside the arena.
    Movement,
    /// Find touching pairs (discrete) or predict the step's impacts (continuous).
    Collision,
    /// Exchange momentum along contact normals and separate overlapping pairs (discrete), or
    /// handle the impacts in time order (continuous).
    Response,
    /// Count steps and collisions; check invariants in debug builds.
    Bookkeeping,
}

/// Adds the simulation: its resources, messages and the four ordered stages.
pub struct SimPlugin;

impl Plugin for SimPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SimParams>()
            .init_resource::<PendingSteps>()
            .add_message::<BallCollision>()
            .add_message::<WallCollision>()
            .configure_sets(
                FixedUpdate,
                (
                    SimSystems::Movement,
                    SimSystems::Collision,
                    SimSystems::Response,
                    SimSystems::Bookkeeping,
                )
                    .chain()
                    .run_if(simulation_running),
            )
            .add_plugins((
                movement::plugin,
                collision::plugin,
                continuous::plugin,
                response::plugin,
                stats::plugin,
                scene::plugin,
                spawn::plugin,
            ))
            .add_systems(
                FixedUpdate,
                take_pending_step.in_set(SimSystems::Bookkeeping),
            )
            // The stages are chained, so no two of them could run at once; each uses the
            // compute pool inside itself where that pays. One thread saves the wake-ups.
            .edit_schedule(FixedUpdate, |schedule| {
                schedule.set_executor(SingleThreadedExecutor::default());
            });
    }
}

/// Steps to run although the simulation is paused: the panel's and the N key's single step.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct PendingSteps(pub u32);

/// Steps run unless paused (a pending single step runs anyway) or the arena has no room (a
/// minimised window): the balls then wait where they are.
fn simulation_running(params: Res<SimParams>, pending: Res<PendingSteps>) -> bool {
    (!params.paused || pending.0 > 0) && params.has_room()
}

fn take_pending_step(params: Res<SimParams>, mut pending: ResMut<PendingSteps>) {
    if params.paused {
        pending.0 = pending.0.saturating_sub(1);
    }
}

/// Simulated seconds in this fixed step: the fixed timestep scaled by `time_scale`.
pub fn step_seconds(time: &Time, params: &SimParams) -> f64 {
    time.delta_secs_f64() * params.time_scale
}
