//! Scene files: RON descriptions of an arena and its balls, written by hand or generated.
//!
//! [`SceneFile`] is the file as written (`file.rs`: reading, parsing, writing back); building
//! it (`build.rs`) validates it and draws the generated balls, giving a [`SceneSetup`], which
//! `apply` loads into a world; `check.rs` holds the checks on single values, `placement.rs`
//! random placement without overlap, `audit.rs` the fuzzer's audit. This file only declares
//! and re-exports them. Pure data until `apply`; nothing here runs in a schedule.
//!
//! ```ron
//! (
//!   arena: (width: 800.0, height: 600.0),        // centred on the origin, x right, y up
//!   gravity: (0.0, 0.0), restitution: 1.0, mass_model: Radius,   // optional
//!   collisions: Continuous,                        // optional: or Discrete
//!   balls: [ (position: (-100.0, 0.0), velocity: (5.0, 0.0), radius: 10.0) ],  // optional
//!   generate: Some((count: 1000, radius: (5.0, 15.0), speed: (0.0, 500.0),
//!                   area_fraction: 0.30, seed: 1)),   // optional
//! )
//! ```

mod audit;
mod build;
mod check;
mod file;
pub mod placement;

pub use audit::{AUDIT_MAX_BUILT_BALLS, audit_scene_text};
pub use build::{SceneSetup, SimRng, draw_ball};
pub use file::{
    ArenaSpec, BallSpec, DEFAULT_ARENA, Generate, MAX_SCENE_BYTES, SceneError, SceneFile,
};
