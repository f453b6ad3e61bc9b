//! Stage 3, response: for each contact, the elastic exchange along the line of centres, then
//! separation so nothing sticks; finally the walls again for the separated balls, since
//! separation may push a ball into a wall.
//!
//! Runs in [`SimSystems::Response`](super::SimSystems::Response), reading [`Contacts`] in
//! their stable order (Gauss–Seidel: each contact sees the velocities the earlier ones left).
//! Works on the contiguous [`BallSnapshot`] by index, then writes the balls that changed back
//! to their components in one pass. Writes a [`BallCollision`] per exchange.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{Ball, BallSnapshot, Position, Velocity};
use super::collision::Contacts;
use super::collision::narrow_phase::{Circle, ContactGeometry, circle_contact};
use super::continuous::in_mode;
use super::messages::{BallCollision, WallCollision};
use super::movement::{contain_in_arena, wall_collisions};
use super::params::{CollisionMode, MassModel, SimParams};
use super::stats::SimStats;
use super::{SimSystems, step_seconds};

pub(super) fn plugin(app: &mut App) {
    app.add_systems(
        FixedUpdate,
        resolve_contacts
            .in_set(SimSystems::Response)
            .run_if(in_mode(CollisionMode::Discrete)),
    );
}

/// The result of [`normal_exchange`]: the new velocities and what the hit carried.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exchange {
    pub velocity_a: DVec2,
    pub velocity_b: DVec2,
    /// Magnitude of the impulse along the normal (b receives `+impulse * normal`).
    pub impulse: f64,
    /// Speed at which the balls were closing along the normal before the hit.
    pub closing_speed: f64,
}

/// The 1-D collision along `normal` (unit, from a to b) between bodies of inverse masses
/// `inverse_mass_a` and `inverse_mass_b`, with coefficient of restitution `restitution`.
///
/// Only the velocity components along the normal change; the tangential ones are untouched,
/// so a grazing hit deflects a little and a head-on one exchanges everything. Returns `None`
/// when the balls are not approaching (touching but separating pairs are left alone).
///
/// With masses `m1`, `m2` and normal speeds `u1`, `u2` this is the textbook
/// `v1 = (m1*u1 + m2*u2 - m2*e*(u1 - u2)) / (m1 + m2)` and its twin for `v2`.
#[inline]
pub fn normal_exchange(
    velocity_a: DVec2,
    velocity_b: DVec2,
    inverse_mass_a: f64,
    inverse_mass_b: f64,
    normal: DVec2,
    restitution: f64,
) -> Option<Exchange> {
    let closing_speed = (velocity_a - velocity_b).dot(normal);
    let inverse_mass_sum = inverse_mass_a + inverse_mass_b;
    if closing_speed <= 0.0 || inverse_mass_sum <= 0.0 {
        return None;
    }
    let impulse = (1.0 + restitution) * closing_speed / inverse_mass_sum;
    Some(Exchange {
        velocity_a: velocity_a - normal * (impulse * inverse_mass_a),
        velocity_b: velocity_b + normal * (impulse * inverse_mass_b),
        impulse,
        closing_speed,
    })
}

/// How far each ball moves along the normal to remove an overlap of `depth` pixels, shared by
/// inverse mass (the lighter ball moves more): `(a moves back, b moves forward)`.
#[inline]
pub fn separation_shares(depth: f64, inverse_mass_a: f64, inverse_mass_b: f64) -> (f64, f64) {
    let inverse_mass_sum = inverse_mass_a + inverse_mass_b;
    if depth <= 0.0 || inverse_mass_sum <= 0.0 {
        return (0.0, 0.0);
    }
    (
        depth * inverse_mass_a / inverse_mass_sum,
        depth * inverse_mass_b / inverse_mass_sum,
    )
}

/// The discrete response on plain arrays: for each pair `(a, b)` of indices, in order, that
/// still touches where the earlier pairs left it, the exchange along the normal (if the balls
/// approach; `on_exchange` hears of it) and then separation shared by inverse mass. Both
/// collision modes use it: discrete for every contact, continuous for a step it cut short.
pub fn resolve_overlaps(
    pairs: impl IntoIterator<Item = (u32, u32)>,
    circles: &mut [Circle],
    velocities: &mut [DVec2],
    mass_model: MassModel,
    restitution: f64,
    mut on_exchange: impl FnMut(u32, u32, ContactGeometry, Exchange),
) {
    for (a, b) in pairs {
        let (ia, ib) = (a as usize, b as usize);
        // Earlier pairs may have moved either ball: work from where they are now.
        let Some(geometry) = circle_contact(circles[ia], circles[ib]) else {
            continue;
        };
        let inverse_mass_a = mass_model.inverse_mass(circles[ia].radius);
        let inverse_mass_b = mass_model.inverse_mass(circles[ib].radius);
        if let Some(exchange) = normal_exchange(
            velocities[ia],
            velocities[ib],
            inverse_mass_a,
            inverse_mass_b,
            geometry.normal,
            restitution,
        ) {
            velocities[ia] = exchange.velocity_a;
            velocities[ib] = exchange.velocity_b;
            on_exchange(a, b, geometry, exchange);
        }
        separate(
            circles,
            (ia, ib),
            geometry,
            (inverse_mass_a, inverse_mass_b),
        );
    }
}

/// Moves circles `a` and `b` apart along the contact normal by the contact's depth, shared by
/// inverse mass ([`separation_shares`]).
#[inline]
pub fn separate(
    circles: &mut [Circle],
    (a, b): (usize, usize),
    geometry: ContactGeometry,
    (inverse_mass_a, inverse_mass_b): (f64, f64),
) {
    let (back, forward) = separation_shares(geometry.depth, inverse_mass_a, inverse_mass_b);
    circles[a].center -= geometry.normal * back;
    circles[b].center += geometry.normal * forward;
}

fn resolve_contacts(
    time: Res<Time>,
    stats: Res<SimStats>,
    contacts: Res<Contacts>,
    params: Res<SimParams>,
    mut snapshot: ResMut<BallSnapshot>,
    mut balls: Query<(Entity, &mut Position, &mut Velocity), With<Ball>>,
    mut collisions: MessageWriter<BallCollision>,
    mut wall_hits: MessageWriter<WallCollision>,
    mut in_contact: Local<Vec<bool>>,
) {
    if contacts.0.is_empty() {
        return;
    }
    // Discrete mode sees a hit only at the end of the step, as an overlap.
    let step_end = stats.sim_time + step_seconds(&time, &params);
    let BallSnapshot {
        entities,
        circles,
        velocities,
    } = &mut *snapshot;
    in_contact.clear();
    in_contact.resize(entities.len(), false);
    for contact in &contacts.0 {
        (
            in_contact[contact.index_a as usize],
            in_contact[contact.index_b as usize],
        ) = (true, true);
    }
    let pairs = contacts.0.iter().map(|c| (c.index_a, c.index_b));
    let (mass_model, restitution) = (params.mass_model, params.restitution);
    resolve_overlaps(
        pairs,
        circles,
        velocities,
        mass_model,
        restitution,
        |a, b, geometry, exchange| {
            collisions.write(BallCollision {
                a: entities[a as usize],
                b: entities[b as usize],
                time: step_end,
                point: geometry.point,
                normal: geometry.normal,
                impulse: exchange.impulse,
                normal_speed: exchange.closing_speed,
            });
        },
    );
    // Separation may have pushed a ball into a wall. Only balls in a contact have moved since
    // the movement stage kept every ball inside, so only they need the walls again, and only
    // they are written back.
    let half = params.half_extents();
    let mut settle = |index: usize| {
        let circle = circles[index];
        let contained = contain_in_arena(
            circle.center,
            velocities[index],
            circle.radius,
            half,
            params.restitution,
        );
        if contained.hits != [None, None] {
            wall_hits.write_batch(wall_collisions(
                entities[index],
                &contained,
                circle.radius,
                &params,
                step_end,
            ));
        }
        (contained.position, contained.velocity)
    };
    write_back(entities, &mut balls, |index| {
        in_contact[index].then(|| settle(index))
    });
}

/// Writes each ball's new `(position, velocity)` from `new_state(index)`, where `index` is
/// its place in the snapshot's `entities`; `None` leaves the ball as it is. The query visits
/// the balls in the snapshot's order (nothing spawns or despawns within a step); should that
/// ever not hold, the rest are looked up by entity.
pub(super) fn write_back(
    entities: &[Entity],
    balls: &mut Query<(Entity, &mut Position, &mut Velocity), With<Ball>>,
    mut new_state: impl FnMut(usize) -> Option<(DVec2, DVec2)>,
) {
    let mut matched = 0;
    for (index, (entity, mut position, mut velocity)) in balls.iter_mut().enumerate() {
        if entities.get(index) != Some(&entity) {
            break;
        }
        matched = index + 1;
        if let Some(state) = new_state(index) {
            (position.0, velocity.0) = state;
        }
    }
    for (index, &entity) in entities.iter().enumerate().skip(matched) {
        if let Ok((_, mut position, mut velocity)) = balls.get_mut(entity)
            && let Some(state) = new_state(index)
        {
            (position.0, velocity.0) = state;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinetic_energy(velocity: DVec2, inverse_mass: f64) -> f64 {
        0.5 * velocity.length_squared() / inverse_mass
    }

    #[test]
    fn tutorial_worked_example_equal_masses_swap_velocities() {
        let ex = normal_exchange(
            DVec2::new(5.0, 0.0),
            DVec2::new(-1.0, 0.0),
            0.1,
            0.1,
            DVec2::X,
            1.0,
        )
        .unwrap();
        assert_eq!(ex.velocity_a, DVec2::new(-1.0, 0.0));
        assert_eq!(ex.velocity_b, DVec2::new(5.0, 0.0));
        assert_eq!(ex.closing_speed, 6.0);
        assert!((ex.impulse - 60.0).abs() < 1e-12);
    }

    #[test]
    fn unequal_masses_head_on_match_the_textbook_formulas() {
        let (m1, m2, u1, u2) = (3.0, 7.0, 4.0, -2.0);
        for e in [0.0, 0.25, 1.0] {
            let ex = normal_exchange(
                DVec2::new(u1, 0.0),
                DVec2::new(u2, 0.0),
                1.0 / m1,
                1.0 / m2,
                DVec2::X,
                e,
            )
            .unwrap();
            let v1 = (m1 * u1 + m2 * u2 - m2 * e * (u1 - u2)) / (m1 + m2);
            let v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2);
            assert!((ex.velocity_a.x - v1).abs() < 1e-12, "e = {e}");
            assert!((ex.velocity_b.x - v2).abs() < 1e-12, "e = {e}");
        }
    }

    #[test]
    fn only_the_normal_component_is_exchanged() {
        let normal = DVec2::new(0.6, 0.8);
        let tangent = normal.perp();
        let (va, vb) = (DVec2::new(3.0, 1.0), DVec2::new(-2.0, 0.5));
        let ex = normal_exchange(va, vb, 0.5, 0.25, normal, 1.0).unwrap();
        assert!((ex.velocity_a.dot(tangent) - va.dot(tangent)).abs() < 1e-12);
        assert!((ex.velocity_b.dot(tangent) - vb.dot(tangent)).abs() < 1e-12);
    }

    #[test]
    fn momentum_is_kept_and_energy_scales_with_restitution() {
        let normal = DVec2::new(1.0, 1.0).normalize();
        let (va, vb, ia, ib) = (
            DVec2::new(7.0, -1.0),
            DVec2::new(-3.0, 2.0),
            1.0 / 4.0,
            1.0 / 9.0,
        );
        let reduced_mass = 1.0 / (ia + ib);
        let closing = (va - vb).dot(normal);
        let energy_before = kinetic_energy(va, ia) + kinetic_energy(vb, ib);
        for e in [0.0, 0.5, 0.9, 1.0] {
            let ex = normal_exchange(va, vb, ia, ib, normal, e).unwrap();
            let momentum_before = va / ia + vb / ib;
            let momentum_after = ex.velocity_a / ia + ex.velocity_b / ib;
            assert!((momentum_after - momentum_before).length() < 1e-12);
            let energy_after =
                kinetic_energy(ex.velocity_a, ia) + kinetic_energy(ex.velocity_b, ib);
            let expected_loss = 0.5 * (1.0 - e * e) * reduced_mass * closing * closing;
            assert!(
                (energy_before - energy_after - expected_loss).abs() < 1e-10,
                "e = {e}"
            );
        }
    }

    #[test]
    fn separating_pairs_are_left_alone() {
        assert_eq!(
            normal_exchange(
                DVec2::new(-1.0, 0.0),
                DVec2::new(1.0, 0.0),
                1.0,
                1.0,
                DVec2::X,
                1.0
            ),
            None
        );
        assert_eq!(
            normal_exchange(
                DVec2::new(0.0, 3.0),
                DVec2::new(0.0, 3.0),
                1.0,
                1.0,
                DVec2::X,
                1.0
            ),
            None
        );
    }

    #[test]
    fn separation_is_shared_by_inverse_mass() {
        assert_eq!(separation_shares(3.0, 1.0, 2.0), (1.0, 2.0));
        assert_eq!(separation_shares(-1.0, 1.0, 1.0), (0.0, 0.0));
        assert_eq!(separation_shares(1.0, 0.0, 0.0), (0.0, 0.0));
    }
}
