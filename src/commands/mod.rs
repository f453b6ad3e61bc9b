//! The headless commands, with no window or GPU: [`run`] steps a scene and reports, while
//! [`observe`] writes its time series, trajectory and final state; [`bench`](mod@bench)
//! times the standard gas at several sizes and [`pile`] the pile, [`soak`] runs random scenes
//! long with checks after every step; [`progress`] shows how far the long ones are. They
//! build on [`headless`](crate::headless) apps and never touch the toy.

pub mod bench;
pub mod mixed;
pub mod observe;
pub mod pile;
pub mod progress;
pub mod run;
pub mod soak;
