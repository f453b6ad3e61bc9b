//! The headless simulation. Every plugin in this module works without rendering: it touches
//! no window, asset, render or egui resource, so it runs under `MinimalPlugins` in tests, on
//! the command line and in benchmarks exactly as it does in the game.
//!
//! **The pipeline.** One fixed step is one run of the simulation's own schedule,
//! [`SimSchedule`], which the host's `FixedUpdate` runs in the [`SimulationStep`] set after
//! applying the [`Intent`]s sent since the last step. Its stages, chained once in
//! [`SimPlugin`], and the system that fills each in each [`CollisionMode`] (the table in
//! `SimPlugin::build`):
//!
//! | stage | discrete | continuous |
//! |---|---|---|
//! | [`SimSystems::Movement`] | [`move_and_contain`](movement::move_and_contain): velocity, position, walls | [`damp_velocities`](movement::damp_velocities): damping only |
//! | [`SimSystems::Collision`] | [`detect_contacts`](discrete::detect::detect_contacts): grid, AABB, distance → [`Contacts`](discrete::detect::Contacts) | [`predict_impacts`](continuous::predict_impacts): every time of impact within the step |
//! | [`SimSystems::Response`] | [`resolve_contacts`](discrete::resolve::resolve_contacts): exchange, separation, walls | [`run_timeline`](continuous::run_timeline): the impacts in time order |
//! | [`SimSystems::Resting`] | [`rest_and_sleep`](resting::rest_and_sleep): the resting solver, who rests next step, sleep | the same |
//! | [`SimSystems::Report`] | [`report_step`](report::report_step): counters; messages and contact points unless [`HitReports`] is off | the same |
//! | around the stages | the clock's `start_step`, [`start_log`](report::start_log) (what the step's log keeps) and [`steer_carried`](carry::steer_carried) (the player's hand) before, `take_pending_step` and `end_step` in `Report`; a finiteness assertion in debug builds | the same |
//!
//! **Data flows one way**: components → [`BallSnapshot`](ball::BallSnapshot) (movement) →
//! contacts or predicted impacts (collision) → components (response), each stage recording
//! what happened in the [`StepLog`](report::StepLog); the report stage turns that into the
//! [`SimStats`] counters and, unless [`HitReports`] is off, the outward [`BallCollision`] /
//! [`WallCollision`] messages. Every
//! stage that needs the step's `dt` or the simulated time reads it from the [`SimClock`].
//!
//! **Where things live**: [`geometry`] the pure maths (circles, walls, impulses, the grid);
//! [`discrete`] and [`continuous`] one folder per mode; [`measure`] what reads the state
//! without changing it; [`scene`] scene files; [`params`] the parameters by owner.
//!
//! **Gravity and piles**: exact ballistic flight is pure maths in [`geometry::flight`], used
//! by the continuous timeline's `Mover`, its swept circles and the wall time of impact.
//! Balls that rest on others, and islands of them that sleep, are [`resting`]'s: both modes
//! hold them still (their [`Rest`] says so), and the resting stage alone moves
//! the resting ones, with a soft contact solver.

pub mod aim;
pub mod ball;
pub mod cache;
pub mod carry;
pub mod clock;
pub mod continuous;
pub mod discrete;
pub mod geometry;
pub mod intents;
pub mod measure;
pub mod messages;
pub mod movement;
pub mod parallel;
pub mod params;
#[cfg(test)]
mod properties;
pub mod report;
pub mod resting;
pub mod scene;
pub mod spawn;

use bevy::ecs::schedule::{
    IntoScheduleConfigs, ScheduleConfigs, ScheduleLabel, SingleThreadedExecutor,
};
use bevy::ecs::system::ScheduleSystem;
use bevy::prelude::*;

pub use ball::{
    Ball, BallId, BallState, Position, PreviousPosition, Radius, Rest, RestState, Velocity,
};
pub use carry::Carried;
pub use clock::SimClock;
pub use intents::{BallCountOutcome, Intent};
pub use measure::{SimStats, StateSummary};
pub use messages::{BallCollision, Wall, WallCollision};
pub use params::{BroadPhase, CollisionMode, MassModel, RunControl, SimParams, Solver};
pub use report::{ContactPoints, HitReports};
pub use scene::{SceneError, SceneFile, SceneSetup, SimRng};
pub use spawn::SpawnSettings;

/// The simulation's own schedule: one fixed step. The host runs it from `FixedUpdate`; its
/// executor is the simulation's business (one thread: the stages are chained, and each uses
/// the compute pool inside itself where that pays).
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct SimSchedule;

/// The stages of [`SimSchedule`], run in this order every step.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SimSystems {
    /// Integrate motion (and, in discrete mode, keep balls inside the arena); fill the
    /// snapshot.
    Movement,
    /// Find touching pairs (discrete) or predict the step's impacts (continuous).
    Collision,
    /// Exchange momentum along contact normals and separate overlapping pairs (discrete), or
    /// handle the impacts in time order (continuous).
    Response,
    /// Move the balls that rest on others with the contact solver; decide who rests next
    /// step; put still islands to sleep and wake disturbed ones.
    Resting,
    /// Turn what the step recorded into messages and counters; advance the clock; check
    /// invariants in debug builds.
    Report,
}

/// The simulation's place in the host's `FixedUpdate`: the player's intents applied, then
/// one step of [`SimSchedule`] unless paused. Order anything that reads the step's messages
/// after it.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SimulationStep;

/// Adds the simulation: its resources, messages and schedule, run from `FixedUpdate`.
pub struct SimPlugin;

impl Plugin for SimPlugin {
    fn build(&self, app: &mut App) {
        use CollisionMode::{Continuous, Discrete};
        use SimSystems::{Collision, Movement, Report, Response, Resting};
        add_resources_and_messages(app);
        let mut schedule = Schedule::new(SimSchedule);
        schedule.set_executor(SingleThreadedExecutor::default());
        app.add_schedule(schedule)
            .configure_sets(
                SimSchedule,
                (Movement, Collision, Response, Resting, Report).chain(),
            )
            .add_systems(
                SimSchedule,
                (
                    (clock::start_step, report::start_log, carry::steer_carried)
                        .chain()
                        .before(Movement),
                    // The pipeline: each stage, the system of each mode.
                    stage(Movement, Discrete, movement::move_and_contain),
                    stage(Movement, Continuous, movement::damp_velocities),
                    stage(Collision, Discrete, discrete::detect::detect_contacts),
                    stage(Collision, Continuous, continuous::predict_impacts),
                    stage(Response, Discrete, discrete::resolve::resolve_contacts),
                    stage(Response, Continuous, continuous::run_timeline),
                    resting::rest_and_sleep.in_set(Resting),
                    (report::report_step, take_pending_step, clock::end_step)
                        .chain()
                        .in_set(Report),
                ),
            );
        #[cfg(debug_assertions)]
        app.add_systems(SimSchedule, report::assert_state_is_finite.in_set(Report));
        app.add_systems(
            FixedUpdate,
            (intents::apply_intents, run_step.run_if(simulation_running))
                .chain()
                .in_set(SimulationStep),
        );
    }
}

fn add_resources_and_messages(app: &mut App) {
    app.init_resource::<SimParams>()
        .init_resource::<Solver>()
        .init_resource::<RunControl>()
        .init_resource::<SimClock>()
        .init_resource::<SimStats>()
        .init_resource::<SimRng>()
        .init_resource::<ball::NextBallId>()
        .init_resource::<ball::BallSnapshot>()
        .init_resource::<report::StepLog>()
        .init_resource::<ContactPoints>()
        .init_resource::<HitReports>()
        .init_resource::<discrete::detect::Contacts>()
        .init_resource::<discrete::detect::DetectionGrid>()
        .init_resource::<continuous::Timeline>()
        .init_resource::<continuous::Bands>()
        .init_resource::<resting::RestingState>()
        .init_resource::<SpawnSettings>()
        .init_resource::<BallCountOutcome>()
        .add_message::<Intent>()
        .add_message::<BallCollision>()
        .add_message::<WallCollision>();
}

/// `system` in stage `set`, run only in collision mode `mode`.
fn stage<M>(
    set: SimSystems,
    mode: CollisionMode,
    system: impl IntoScheduleConfigs<ScheduleSystem, M>,
) -> ScheduleConfigs<ScheduleSystem> {
    system.in_set(set).run_if(in_mode(mode))
}

/// A run condition: the simulation is in collision mode `mode`.
pub fn in_mode(mode: CollisionMode) -> impl FnMut(Res<Solver>) -> bool + Clone {
    move |solver: Res<Solver>| solver.collisions == mode
}

/// Steps run unless paused (a pending single step runs anyway) or the arena has no room (a
/// minimised window): the balls then wait where they are.
fn simulation_running(params: Res<SimParams>, run: Res<RunControl>) -> bool {
    run.wants_step() && params.has_room()
}

/// One fixed step: one run of [`SimSchedule`].
fn run_step(world: &mut World) {
    world.run_schedule(SimSchedule);
}

fn take_pending_step(mut run: ResMut<RunControl>) {
    if run.paused {
        run.pending_steps = run.pending_steps.saturating_sub(1);
    }
}
