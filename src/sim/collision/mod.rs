//! Stage 2, collision: find every touching pair and record it as a [`Contact`].
//!
//! Runs in [`SimSystems::Collision`](super::SimSystems::Collision), after movement and before
//! response. The broad phase proposes candidate pairs, the narrow phase's AABB test and exact
//! squared-distance test keep the touching ones. Writes [`Contacts`]; changes no ball.

pub mod broad_phase;
pub mod narrow_phase;

use bevy::prelude::*;

use super::SimSystems;
use super::ball::{Ball, Position, Radius};
use super::params::{BroadPhase, SimParams};
use broad_phase::{UniformGrid, for_each_pair};
use narrow_phase::{Circle, ContactGeometry, circle_contact};

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<Contacts>()
        .init_resource::<CollisionScratch>()
        .add_systems(FixedUpdate, detect_contacts.in_set(SimSystems::Collision));
}

/// Two balls that touch or overlap after this step's movement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    pub a: Entity,
    pub b: Entity,
    /// Unit vector from `a`'s centre towards `b`'s.
    pub normal: bevy::math::DVec2,
    /// Overlap along the normal, pixels.
    pub depth: f64,
    /// The radius-weighted collision point, pixels.
    pub point: bevy::math::DVec2,
}

/// This step's contacts, in a stable order: the response processes them in this order.
#[derive(Resource, Debug, Default)]
pub struct Contacts(pub Vec<Contact>);

/// A contact between balls `a < b`, numbered by their position in the input slice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndexedContact {
    pub a: u32,
    pub b: u32,
    pub geometry: ContactGeometry,
}

/// Finds every touching pair among `circles` and appends it to `found`, each pair once with
/// `a < b` and the normal from `a` to `b`. The order is fixed by the input and the method.
pub fn find_contacts(
    circles: &[Circle],
    method: BroadPhase,
    grid: &mut UniformGrid,
    found: &mut Vec<IndexedContact>,
) {
    let keep_touching = |i: u32, j: u32, ci: Circle, cj: Circle| {
        let (a, b, ca, cb) = if i < j {
            (i, j, ci, cj)
        } else {
            (j, i, cj, ci)
        };
        if let Some(geometry) = circle_contact(ca, cb) {
            found.push(IndexedContact { a, b, geometry });
        }
    };
    match method {
        BroadPhase::Grid => {
            grid.rebuild(circles);
            grid.for_each_candidate_pair(keep_touching);
        }
        BroadPhase::AllPairs => for_each_pair(circles, keep_touching),
    }
}

/// Buffers the collision stage keeps between steps.
#[derive(Resource, Default)]
struct CollisionScratch {
    entities: Vec<Entity>,
    circles: Vec<Circle>,
    grid: UniformGrid,
    found: Vec<IndexedContact>,
}

fn detect_contacts(
    balls: Query<(Entity, &Position, &Radius), With<Ball>>,
    params: Res<SimParams>,
    mut scratch: ResMut<CollisionScratch>,
    mut contacts: ResMut<Contacts>,
) {
    let CollisionScratch {
        entities,
        circles,
        grid,
        found,
    } = &mut *scratch;
    entities.clear();
    circles.clear();
    for (entity, position, radius) in &balls {
        entities.push(entity);
        circles.push(Circle::new(position.0, radius.0));
    }
    found.clear();
    find_contacts(circles, params.broad_phase, grid, found);
    contacts.0.clear();
    contacts.0.extend(found.iter().map(|contact| Contact {
        a: entities[contact.a as usize],
        b: entities[contact.b as usize],
        normal: contact.geometry.normal,
        depth: contact.geometry.depth,
        point: contact.geometry.point,
    }));
}
