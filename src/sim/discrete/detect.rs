//! Stage 2, discrete: find every touching pair among the moved balls and record it as a
//! contact. The broad phase proposes candidate pairs; the AABB test and the exact
//! squared-distance test keep the touching ones.
//!
//! Runs in [`SimSystems::Collision`](crate::sim::SimSystems::Collision) in discrete mode, on
//! the contiguous [`BallSnapshot`] the movement stage wrote. Writes [`Contacts`] for the
//! response and each contact point to the [`StepLog`]; changes no ball.

use bevy::prelude::*;

use crate::sim::ball::BallSnapshot;
use crate::sim::geometry::grid::UniformGrid;
use crate::sim::geometry::pairs::{FoundInBands, IndexedContact, find_contacts};
use crate::sim::params::Solver;
use crate::sim::report::{ContactPoint, StepLog};

/// This step's touching pairs, by their places in the [`BallSnapshot`], in a stable order:
/// the response handles them in this order, band after band as the grid's search found them.
#[derive(Resource, Debug, Default)]
pub struct Contacts(pub FoundInBands<IndexedContact>);

/// The grid, kept between steps to reuse its buffers; the response reads the rows it filed
/// the balls in.
#[derive(Resource, Default)]
pub struct DetectionGrid(pub(super) UniformGrid);

pub fn detect_contacts(
    solver: Res<Solver>,
    snapshot: Res<BallSnapshot>,
    mut grid: ResMut<DetectionGrid>,
    mut contacts: ResMut<Contacts>,
    mut log: ResMut<StepLog>,
) {
    contacts.0.clear();
    if snapshot.all_held() {
        return; // nothing moved: the resting stage has every contact
    }
    find_contacts(
        &snapshot.circles,
        solver.broad_phase,
        &mut grid.0,
        &mut contacts.0,
    );
    let points = contacts.0.iter().map(|contact| ContactPoint {
        point: contact.geometry.point,
        normal: contact.geometry.normal,
    });
    log.note_contacts(contacts.0.len() as u64, points);
}
