//! The integration tests: one crate, so one link. Headless apps under `MinimalPlugins`, each
//! `update()` exactly one fixed step (see `common`); `game` builds the whole toy without a
//! window (with the default `gui` feature only).

mod cli;
mod common;
mod continuous;
#[cfg(feature = "gui")]
mod game;
mod hands;
mod headless;
mod house;
mod observe;
mod physics;
mod piles;
mod scenes;
mod toy;
