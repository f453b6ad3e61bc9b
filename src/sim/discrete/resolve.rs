//! Stage 3, discrete: for each contact, the elastic exchange along the line of centres, then
//! separation so nothing sticks; finally the walls again for the separated balls, since
//! separation may push a ball into a wall.
//!
//! Runs in [`SimSystems::Response`](crate::sim::SimSystems::Response) in discrete mode,
//! reading [`Contacts`] in their stable order (Gauss–Seidel: each contact sees the velocities
//! the earlier ones left); for many balls on more than one thread, in a step that only counts
//! its ball hits, in [`parts`](super::parts) of the arrays at once with the same result, by
//! the rows of the [`DetectionGrid`]. Works on the contiguous [`BallSnapshot`] by index,
//! then contains the balls in a contact in the arena again and writes every ball (the
//! movement stage moved them in the snapshot) back to its components, both in pieces on the
//! compute pool for many balls. Records each exchange and wall hit in the [`StepLog`]. The
//! resting rule applies to pairs and walls alike (see
//! [`resolve_overlaps`](crate::sim::geometry::impulse::resolve_overlaps)); pairs of resting
//! balls are the resting stage's.

use bevy::prelude::*;

use super::detect::{Contacts, DetectionGrid};
use super::parts::ExchangesInParts;
use crate::sim::ball::{BallSnapshot, WrittenBalls, write_back_after};
use crate::sim::clock::SimClock;
use crate::sim::geometry::impulse::resolve_found_contacts;
use crate::sim::movement::Arena;
use crate::sim::parallel::{threads_at_work, worth_splitting};
use crate::sim::params::SimParams;
use crate::sim::report::{Hit, StepLog};

pub fn resolve_contacts(
    clock: Res<SimClock>,
    contacts: Res<Contacts>,
    params: Res<SimParams>,
    mut snapshot: ResMut<BallSnapshot>,
    mut balls: WrittenBalls,
    mut log: ResMut<StepLog>,
    grid: Res<DetectionGrid>,
    mut in_contact: Local<Vec<bool>>,
    mut in_parts: Local<ExchangesInParts>,
) {
    if snapshot.all_held() {
        return; // nothing moved, and nothing touches
    }
    let BallSnapshot {
        entities,
        circles,
        velocities,
        held,
        ..
    } = &mut *snapshot;
    in_contact.clear();
    in_contact.resize(entities.len(), false);
    let arena = Arena::new(&params, clock.dt);
    let constants = (params.mass_model, params.restitution, arena.rest_speed);
    // Discrete mode sees a hit only at the end of the step, as an overlap.
    let step_end = clock.dt;
    let log = &mut *log;
    // Each contact's balls marked as it is taken, while they are in the cache.
    if worth_splitting(entities.len()) && !log.keeps_ball_hits() {
        // In parts of the arrays at once, with the same result; the hits only counted.
        let arrays = (&mut circles[..], &mut velocities[..], &mut held[..]);
        let found = (&contacts.0, &grid.0);
        let parts = threads_at_work();
        let exchanges = in_parts.resolve(found, parts, &mut in_contact, arrays, constants);
        log.hits.count_dropped(exchanges);
    } else {
        // Band after band, as the search found them, each hit recorded as it happens.
        let hits = &mut log.hits;
        let mut record =
            |a, b, geometry, exchange| hits.push(Hit::ball(a, b, step_end, geometry, exchange));
        for band in contacts.0.bands() {
            let arrays = (&mut circles[..], &mut velocities[..], &mut held[..]);
            resolve_found_contacts(band, &mut in_contact, arrays, constants, &mut record);
        }
    }
    // Every ball written back (the movement stage moved them in the snapshot only), each piece
    // after the walls again for its balls in a contact: separation may have pushed them into a
    // wall, and only they have moved since the movement stage kept every ball inside.
    let in_contact = &*in_contact;
    let met = write_back_after(
        entities,
        (circles, velocities),
        &mut balls,
        |first, piece| {
            let touched = |index: usize| in_contact[index];
            arena.contain_piece(first, piece, touched, None)
        },
    );
    arena.record(met.into_iter().flatten(), circles, log);
}
