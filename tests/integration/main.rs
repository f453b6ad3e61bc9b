//! The integration tests: one crate, so one link. Headless apps under `MinimalPlugins`, each
//! `update()` exactly one fixed step (see `common`).

mod cli;
mod common;
mod continuous;
mod game;
mod physics;
mod scenes;
mod toy;
