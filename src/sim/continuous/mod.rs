//! The continuous mode: each fixed step as a timeline of impacts, handled in time order, so
//! nothing tunnels or overlaps and, with restitution 1, energy is kept to rounding.
//!
//! The movement stage only damps velocities, so every free ball's path over the step is a
//! parabola under gravity (a straight segment without): exact free flight. Resting and
//! sleeping balls hold still on the timeline until an impact sets them flying; impacts
//! slower than the resting speed do not bounce (`timeline.rs` says what they do). All balls feel the same
//! gravity, so two balls approach in a straight line and their time of impact is the
//! straight-line one; a wall's is the first root of a quadratic. Then:
//!
//! - stage 2, [`predict_impacts`] ([`predict`]): every approaching pair's and every ball's
//!   wall time of impact within the step, found through the grid of swept circles
//!   ([`impact`] holds what a prediction is; `timing.rs` times the pairs, a batch at a time);
//! - stage 3, [`run_timeline`] ([`timeline`]): the impacts in time order, predicting anew for
//!   the balls each one redirects (`repredict.rs`; `paths.rs` keeps every ball's current path
//!   by slot), then every ball to the end of the step, and the balls written back.
//!
//! From 20,000 to 400,000 balls with more than one thread, both stages take the step in
//! horizontal bands of the arena, one timeline each, at once (`bands/`): the balls near each
//! edge must end alike in the two bands beside it, so the result is the single timeline's to
//! the bit, or the step is run again as one (and the next few are, backing off). Held balls,
//! the resting rule and big balls keep the single timeline.
//!
//! [`state`] holds the [`Timeline`] resource both halves work on; the [`Bands`] resource
//! holds the bands' own timelines.
//!
//! The [`Timeline`] works on plain arrays, so it is tested without an app.

mod bands;
pub mod impact;
mod paths;
pub mod predict;
mod prefetch;
mod queue;
mod repredict;
pub mod state;
pub mod timeline;
mod timing;

use bevy::prelude::*;

use crate::sim::ball::{BallSnapshot, WrittenBalls, write_back};
use crate::sim::clock::SimClock;
use crate::sim::params::SimParams;
use crate::sim::report::{ContactPoint, Hit, StepLog};
pub use bands::Bands;
pub use state::{MAX_HITS_PER_BALL, MIN_HITS_PER_BALL, StepSpec, Timeline, hit_limit};

/// Stage 2: every impact of the coming step that the balls' paths lead to.
pub fn predict_impacts(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    snapshot: Res<BallSnapshot>,
    mut timeline: ResMut<Timeline>,
    mut bands: ResMut<Bands>,
) {
    if snapshot.all_held() {
        return; // nothing flies: `run_timeline` has nothing to do either
    }
    let spec = StepSpec::new(&params, clock.dt, snapshot.radii);
    bands.predict_step(
        &mut timeline,
        &snapshot.circles,
        &snapshot.velocities,
        &snapshot.held,
        spec,
    );
}

/// Stage 3: the impacts in time order; the balls written back at the end of the step.
pub fn run_timeline(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    mut timeline: ResMut<Timeline>,
    mut bands: ResMut<Bands>,
    mut snapshot: ResMut<BallSnapshot>,
    mut balls: WrittenBalls,
    mut log: ResMut<StepLog>,
) {
    if snapshot.all_held() {
        return;
    }
    let spec = StepSpec::new(&params, clock.dt, snapshot.radii);
    let BallSnapshot {
        entities,
        circles,
        velocities,
        held,
        stopped,
        ..
    } = &mut *snapshot;
    let log = &mut *log;
    let keep_ball_hits = log.keeps_ball_hits();
    let (arrays, flags) = (
        (&mut **circles, &mut **velocities),
        (&mut **held, &mut **stopped),
    );
    let timeline = &mut *timeline;
    let counted = bands.run_step(timeline, arrays, flags, spec, keep_ball_hits, |hit| {
        if let Hit::Ball { point, normal, .. } = hit {
            log.note_contact(ContactPoint { point, normal });
        }
        log.hits.push(hit);
    });
    log.count_dropped_ball_hits(counted);
    log.cut_short = timeline.cut_short;
    log.resting_wall_impulse += timeline.resting_wall_impulse;
    write_back(entities, (circles, velocities), &mut balls);
}
