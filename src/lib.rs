//! ballpit: circles colliding in a box.
//!
//! - [`sim`]: the headless simulation plugin, runnable under `MinimalPlugins`; its stages are
//!   movement → collision → response, in `FixedUpdate`.
//! - [`headless`]: step a scene without a window and measure it.
//! - [`render`]: drawing the simulation in a window (reads its state only).
//! - [`ui`]: the egui panel, mouse and keys.
//! - [`play`]: the windowed toy; [`diagnostics`]: its frame and simulation timings.
//! - [`bench`]: the standard gas timed at several sizes.
//! - [`soak`]: random scenes run long with checks after every step.
//! - [`cli`]: the `ballpit` command line.

pub mod bench;
pub mod cli;
pub mod diagnostics;
pub mod headless;
pub mod play;
pub mod render;
pub mod sim;
pub mod soak;
pub mod ui;

/// The types most users of the crate need.
pub mod prelude {
    pub use crate::headless::{RunReport, headless_app, run_scene};
    pub use crate::sim::{
        Ball, BallCollision, BallId, BallState, BroadPhase, CollisionMode, MassModel, Position,
        Radius, SceneFile, SceneSetup, SimParams, SimPlugin, SimStats, SimSystems, StateSummary,
        Velocity, Wall, WallCollision,
    };
}
