//! Measuring the simulation: read its state, never change it. [`stats`]: the running
//! counters the report stage keeps; [`summary`]: the figures over the whole state (energy,
//! momentum, overlap, escapes, temperature and the speed histogram) that the headless report,
//! the panel and the tests all use; [`gas`]: the speed histogram against the 2-D
//! Maxwell–Boltzmann distribution.

pub mod gas;
pub mod stats;
pub mod summary;

pub use stats::SimStats;
pub use summary::StateSummary;
