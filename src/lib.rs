//! ballpit: circles colliding in a box.
//!
//! Headless (always built):
//! - [`sim`]: the simulation plugin, runnable under `MinimalPlugins`; its stages are
//!   movement → collision → response → report, in its own schedule run from `FixedUpdate`.
//! - [`headless`]: apps with only the simulation, one fixed step per update; the timing loop.
//! - [`commands`]: `run` (a scene stepped and reported), `bench` (the standard gas timed at
//!   several sizes), `soak` (random scenes run long with checks after every step).
//! - [`cli`]: the `ballpit` command line; [`huge_pages`]: the binary started again with the
//!   heap on huge pages (Linux with glibc), before anything else runs.
//!
//! The toy (the default `gui` feature: window, rendering, egui):
//! - `app`: the toy's shared state (scene requests, view settings);
//! - `render`: drawing the simulation (reads its state only);
//! - `ui`: the egui panel, mouse and keys (send intents);
//! - `play`: the windowed toy put together; `diagnostics`: its frame timings.

pub mod cli;
pub mod commands;
pub mod headless;
pub mod huge_pages;
pub mod sim;

#[cfg(feature = "gui")]
pub mod app;
#[cfg(feature = "gui")]
pub mod diagnostics;
#[cfg(feature = "gui")]
pub mod play;
#[cfg(feature = "gui")]
pub mod record;
#[cfg(feature = "gui")]
pub mod render;
#[cfg(feature = "gui")]
pub mod ui;

/// The types most users of the crate need.
pub mod prelude {
    pub use crate::commands::run::{RunReport, run_scene};
    pub use crate::headless::headless_app;
    pub use crate::sim::{
        Ball, BallCollision, BallId, BallState, BroadPhase, CollisionMode, Intent, MassModel,
        Position, Radius, RunControl, SceneFile, SceneSetup, SimClock, SimParams, SimPlugin,
        SimStats, SimSystems, SimulationStep, Solver, StateSummary, Velocity, Wall, WallCollision,
    };
}
