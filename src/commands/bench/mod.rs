//! `ballpit bench`: the standard gas (`assets/scenes/gas.ron`: radius U[5, 15] px, speed
//! U[0, 500] px/s, area fraction 0.30, dt 1/60 s) at several sizes, with figures per size: the
//! discrete mode on one core, two cores and against all pairs, then the continuous mode
//! against the discrete one.
//!
//! Each case runs in a child process (`ballpit bench-one`), so its peak memory is its own and
//! its core count can be set: one-core cases are started under `taskset -c 0`, which Bevy's
//! task pools see as one available core. Timings are compared as ratios within one run, and
//! every case runs in several rounds, each round every case once: each case reports its
//! median round ([`BenchRow::median_of_rounds`]), so a slow spell of the machine moves a
//! figure only if it lasts through most rounds, and the ratios (two cores against one, a size
//! against the first) are taken between those medians.
//!
//! Its parts: `case.rs` runs a case, `rows.rs` makes a size's row of cases, `table.rs` prints
//! the rows.

mod case;
mod rows;
mod table;

pub use case::{BenchCase, CaseResult, run_case};
pub use rows::BenchRow;
pub use table::format_table;
