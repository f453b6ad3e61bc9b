//! Stage 3, discrete: for each contact, the elastic exchange along the line of centres, then
//! separation so nothing sticks; finally the walls again for the separated balls, since
//! separation may push a ball into a wall.
//!
//! Runs in [`SimSystems::Response`](crate::sim::SimSystems::Response) in discrete mode,
//! reading [`Contacts`] in their stable order (Gauss–Seidel: each contact sees the velocities
//! the earlier ones left). Works on the contiguous [`BallSnapshot`] by index, then writes
//! every ball (the movement stage moved them in the snapshot) back to its components in one
//! pass. Records each exchange and wall
//! hit in the [`StepLog`]. The resting rule applies to pairs and walls alike (see
//! [`resolve_overlaps`]); pairs of resting balls are the resting stage's.

use bevy::prelude::*;

use super::detect::Contacts;
use crate::sim::ball::{Ball, BallSnapshot, Position, Velocity, write_back};
use crate::sim::clock::SimClock;
use crate::sim::geometry::impulse::resolve_overlaps;
use crate::sim::geometry::wall::contain_at_rest;
use crate::sim::params::SimParams;
use crate::sim::report::{Hit, StepLog};
use crate::sim::resting::rest_speed;

pub fn resolve_contacts(
    clock: Res<SimClock>,
    contacts: Res<Contacts>,
    params: Res<SimParams>,
    mut snapshot: ResMut<BallSnapshot>,
    mut balls: Query<(Entity, &mut Position, &mut Velocity), With<Ball>>,
    mut log: ResMut<StepLog>,
    mut in_contact: Local<Vec<bool>>,
) {
    if snapshot.all_held() {
        return; // nothing moved, and nothing touches
    }
    // Discrete mode sees a hit only at the end of the step, as an overlap.
    let step_end = clock.dt;
    let BallSnapshot {
        entities,
        circles,
        velocities,
        held,
        ..
    } = &mut *snapshot;
    in_contact.clear();
    in_contact.resize(entities.len(), false);
    for contact in &contacts.0 {
        (
            in_contact[contact.a as usize],
            in_contact[contact.b as usize],
        ) = (true, true);
    }
    let pairs = contacts.0.iter().map(|contact| (contact.a, contact.b));
    let (mass_model, restitution) = (params.mass_model, params.restitution);
    let rest_speed = rest_speed(&params, clock.dt);
    let log = &mut *log;
    let hits = &mut log.hits;
    resolve_overlaps(
        pairs,
        circles,
        velocities,
        held,
        (mass_model, restitution, rest_speed),
        |a, b, geometry, exchange| hits.push(Hit::ball(a, b, step_end, geometry, exchange)),
    );
    // Separation may have pushed a ball into a wall. Only balls in a contact have moved since
    // the movement stage kept every ball inside, so only they need the walls again.
    let half = params.half_extents();
    let resting_wall_impulse = &mut log.resting_wall_impulse;
    for (index, _) in in_contact.iter().enumerate().filter(|(_, touched)| **touched) {
        let circle = circles[index];
        let contained = contain_at_rest(
            circle.center,
            velocities[index],
            circle.radius,
            half,
            restitution,
            rest_speed,
        );
        if contained.hits != [None, None] {
            let mass = mass_model.mass(circle.radius);
            *resting_wall_impulse += contained.resting_impulse(mass);
            hits.extend(Hit::walls_of(
                index as u32,
                &contained,
                step_end,
                half,
                restitution,
                mass,
            ));
        }
        (circles[index].center, velocities[index]) = (contained.position, contained.velocity);
    }
    // Every ball: the movement stage moved them in the snapshot only.
    write_back(entities, &mut balls, |index| {
        Some((circles[index].center, velocities[index]))
    });
}
