//! Impulses: the momentum a hit exchanges along the contact normal, between two balls or
//! between a ball and a wall, and the separation of an overlapping pair shared by inverse
//! mass; and [`resolve_overlaps`], the discrete response over a list of pairs on plain arrays.
//! Pure functions over plain values.
//!
//! Both modes' responses (the continuous one falls back on `resolve_overlaps` when a step is
//! cut short), the aiming guide and the property tests call these, so the impulse is written
//! once.

use bevy::math::DVec2;

use super::circle::{Circle, ContactGeometry, circle_contact};
use super::pairs::IndexedContact;
use crate::sim::cache::{FAR_PREFETCH_MIN_BALLS, PREFETCH_MIN_BALLS, prefetch, prefetch_whole};
use crate::sim::params::MassModel;

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

/// The discrete mode's response on plain arrays: for each pair `(a, b)` of indices, in order, that
/// still touches where the earlier pairs left it, the exchange along the normal (if the balls
/// approach; `on_exchange` hears of it) and then separation shared by inverse mass. Both
/// collision modes use it: discrete for every contact, continuous for a step it cut short.
///
/// The resting rule: a pair closing slower than `rest_speed` does not bounce (restitution 0)
/// and is not an exchange anyone hears of; a `held` ball (resting or asleep) then counts as
/// immovable, for the exchange and the separation alike. A faster hit on a held ball is an
/// ordinary exchange, and sets it moving: its `held` is cleared. Pairs of held balls are the
/// resting solver's, and skipped.
pub fn resolve_overlaps(
    pairs: impl IntoIterator<Item = (u32, u32)>,
    circles: &mut [Circle],
    velocities: &mut [DVec2],
    held: &mut [bool],
    constants: (MassModel, f64, f64),
    on_exchange: impl FnMut(u32, u32, ContactGeometry, Exchange),
) {
    let pairs = pairs.into_iter().map(|(a, b)| (a, b, None, None));
    resolve_known_overlaps(pairs, circles, velocities, held, constants, on_exchange);
}

/// [`resolve_overlaps`] for `contacts` as [`find_contacts`](super::pairs::find_contacts) found
/// them, marking in `touched` the balls of each as it is taken. A contact neither of whose
/// balls an earlier one touched is still where it was found, so its geometry is used as found:
/// the same result, without working it out again. Contacts found in bands are taken band after
/// band, one call each, with the same `touched` throughout: a ball an earlier band's contact
/// moved is worked out again in a later band's. For many balls, each contact's balls are
/// loaded a few contacts ahead ([`prefetch`]): they lie anywhere in the arrays.
pub fn resolve_found_contacts(
    contacts: &[IndexedContact],
    touched: &mut [bool],
    (circles, velocities, held): (&mut [Circle], &mut [DVec2], &mut [bool]),
    constants: (MassModel, f64, f64),
    on_exchange: impl FnMut(u32, u32, ContactGeometry, Exchange),
) {
    let every = (0, |_: &IndexedContact, _| true);
    let arrays = (circles, velocities, held);
    resolve_found_contacts_in_part(contacts, every, touched, arrays, constants, on_exchange);
}

/// [`resolve_found_contacts`] on a part of the arrays, which hold the balls numbered from
/// `first` on: of `contacts`, only those that `take` keeps are taken. `take` hears of each
/// contact, in order, with its balls numbered within the part (an index below `first` wraps
/// around to a large number); `touched` and `on_exchange` number the balls so too.
pub fn resolve_found_contacts_in_part(
    contacts: &[IndexedContact],
    (first, mut take): (u32, impl FnMut(&IndexedContact, (u32, u32)) -> bool),
    touched: &mut [bool],
    (circles, velocities, held): (&mut [Circle], &mut [DVec2], &mut [bool]),
    constants: (MassModel, f64, f64),
    on_exchange: impl FnMut(u32, u32, ContactGeometry, Exchange),
) {
    // Below it the loads cost 1–2% of the discrete step at 1,000 and 10,000 balls.
    let loading_ahead = circles.len() >= PREFETCH_MIN_BALLS;
    let in_part =
        |contact: &IndexedContact| (contact.a.wrapping_sub(first), contact.b.wrapping_sub(first));
    let pairs = contacts.iter().enumerate().filter_map(|(k, contact)| {
        let (a, b) = in_part(contact);
        if !take(contact, (a, b)) {
            return None;
        }
        let (ia, ib) = (a as usize, b as usize);
        let untouched = !touched[ia] && !touched[ib];
        (touched[ia], touched[ib]) = (true, true);
        let coming = contacts
            .get(k + PREFETCH_DISTANCE)
            .filter(|_| loading_ahead)
            .map(in_part);
        let known = untouched.then_some(contact.geometry);
        Some((a, b, known, coming))
    });
    resolve_known_overlaps(pairs, circles, velocities, held, constants, on_exchange);
}

/// How many contacts ahead [`resolve_found_contacts`] loads a contact's balls.
const PREFETCH_DISTANCE: usize = 8;

/// [`resolve_overlaps`] for pairs `(a, b, known, coming)` that may come with their contact's
/// geometry, `known`, when neither ball has moved since it was found, and with the balls of
/// a pair to come, `coming`, whose circles and velocities are loaded into the cache.
fn resolve_known_overlaps(
    pairs: impl IntoIterator<Item = (u32, u32, Option<ContactGeometry>, Option<(u32, u32)>)>,
    circles: &mut [Circle],
    velocities: &mut [DVec2],
    held: &mut [bool],
    (mass_model, restitution, rest_speed): (MassModel, f64, f64),
    mut on_exchange: impl FnMut(u32, u32, ContactGeometry, Exchange),
) {
    for (a, b, known, coming) in pairs {
        if let Some(coming) = coming {
            load_ahead(coming, circles, velocities);
        }
        let (ia, ib) = (a as usize, b as usize);
        if held[ia] && held[ib] {
            continue;
        }
        // Earlier pairs may have moved either ball: work from where they are now.
        let Some(geometry) = known.or_else(|| circle_contact(circles[ia], circles[ib])) else {
            continue;
        };
        let resting = (velocities[ia] - velocities[ib]).dot(geometry.normal) < rest_speed;
        let inverse_mass = |index: usize| {
            if resting && held[index] {
                0.0
            } else {
                mass_model.inverse_mass(circles[index].radius)
            }
        };
        let (inverse_mass_a, inverse_mass_b) = (inverse_mass(ia), inverse_mass(ib));
        if let Some(exchange) = normal_exchange(
            velocities[ia],
            velocities[ib],
            inverse_mass_a,
            inverse_mass_b,
            geometry.normal,
            if resting { 0.0 } else { restitution },
        ) {
            velocities[ia] = exchange.velocity_a;
            velocities[ib] = exchange.velocity_b;
            if !resting {
                (held[ia], held[ib]) = (false, false);
                on_exchange(a, b, geometry, exchange);
            }
        }
        separate(
            circles,
            (ia, ib),
            geometry,
            (inverse_mass_a, inverse_mass_b),
        );
    }
}

/// Brings the circles and velocities of the pair of balls `(a, b)` into the cache. From
/// [`FAR_PREFETCH_MIN_BALLS`] balls a circle's two lines when it straddles two, which at a
/// million balls made the discrete step 2.7% quicker; at 100,000, where most are in the cache
/// anyway, the second load cost 1.4% (docs/performance.md, *The grid's passes by index loaded
/// ahead (thirty-fifth session)*).
fn load_ahead((a, b): (u32, u32), circles: &[Circle], velocities: &[DVec2]) {
    let whole = circles.len() >= FAR_PREFETCH_MIN_BALLS;
    for ball in [a as usize, b as usize] {
        if whole {
            prefetch_whole(circles.get(ball));
        } else {
            prefetch(circles.get(ball));
        }
        prefetch(velocities.get(ball));
    }
}

/// The impulse a wall gives a ball of `mass` arriving at `normal_speed` with restitution
/// `restitution`: its normal momentum reversed and scaled, `m (1 + e) v_n`.
#[inline]
pub fn wall_impulse(mass: f64, restitution: f64, normal_speed: f64) -> f64 {
    mass * (1.0 + restitution) * normal_speed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::geometry::pairs::{FoundInBands, contacts_among};

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

    #[test]
    fn contacts_found_in_bands_resolve_exactly_as_one_list_worked_out_again() {
        use crate::sim::parallel::{PARALLEL_MIN_BALLS, threads_at_work};
        // A crowded lattice, large enough to be searched in bands: a ball's neighbours overlap it,
        // so contacts across a band's edge move balls another band's contacts take later.
        let side = 160;
        let count = side * 150;
        assert!(count >= PARALLEL_MIN_BALLS);
        let circles: Vec<Circle> = (0..count)
            .map(|k| {
                let (x, y) = ((k % side) as f64 * 4.0, (k / side) as f64 * 4.0);
                let jitter = ((k * 7919) % 11) as f64 * 0.05;
                Circle::new(DVec2::new(x + jitter, y - jitter), 2.0 + jitter)
            })
            .collect();
        let velocities = jumbled_velocities(count);
        let held: Vec<bool> = (0..count).map(|k| k % 17 == 0).collect();
        let contacts = contacts_among(&circles);
        if threads_at_work() > 1 {
            assert!(contacts.bands().count() > 1, "searched in bands");
        }
        assert!(contacts.len() > count, "{} contacts", contacts.len());
        let balls = (&circles[..], &velocities[..], &held[..]);
        let by_bands = resolved(&contacts, balls, true);
        assert!(
            by_bands.3.len() > count / 2,
            "{} exchanges",
            by_bands.3.len()
        );
        assert!(by_bands == resolved(&contacts, balls, false));
    }

    #[test]
    fn contacts_taken_as_found_resolve_exactly_as_worked_out_again() {
        // A crowded jumble: most balls in several contacts, so many are moved before their turn.
        let circles: Vec<Circle> = (0..600)
            .map(|k| {
                let (x, y) = ((k * 37 % 101) as f64 * 2.2, (k * 53 % 97) as f64 * 2.0);
                Circle::new(DVec2::new(x, y), 2.0 + (k % 5) as f64 * 0.7)
            })
            .collect();
        let velocities = jumbled_velocities(600);
        let held: Vec<bool> = (0..600).map(|k| k % 11 == 0).collect();
        let contacts = contacts_among(&circles);
        assert!(contacts.len() > 500, "{} contacts", contacts.len());
        let balls = (&circles[..], &velocities[..], &held[..]);
        assert_eq!(
            resolved(&contacts, balls, true),
            resolved(&contacts, balls, false)
        );
    }

    fn jumbled_velocities(count: usize) -> Vec<DVec2> {
        (0..count)
            .map(|k| DVec2::new((k % 13) as f64 - 6.0, (k % 7) as f64 - 3.0) * 40.0)
            .collect()
    }

    /// The balls after `contacts` and each exchange (as text), the contacts taken as found band
    /// after band (`as_found`) or worked out again as one list.
    fn resolved(
        contacts: &FoundInBands<IndexedContact>,
        (circles, velocities, held): (&[Circle], &[DVec2], &[bool]),
        as_found: bool,
    ) -> (Vec<Circle>, Vec<DVec2>, Vec<bool>, Vec<String>) {
        let constants = (MassModel::Radius, 0.8, 5.0);
        let (mut c, mut v, mut h) = (circles.to_vec(), velocities.to_vec(), held.to_vec());
        let mut exchanges = Vec::new();
        let mut record = |a, b, geometry, exchange: Exchange| {
            exchanges.push(format!("{a} {b} {geometry:?} {exchange:?}"));
        };
        if as_found {
            let mut touched = vec![false; circles.len()];
            for band in contacts.bands() {
                let arrays = (&mut c[..], &mut v[..], &mut h[..]);
                resolve_found_contacts(band, &mut touched, arrays, constants, &mut record);
            }
        } else {
            let pairs = contacts.iter().map(|contact| (contact.a, contact.b));
            resolve_overlaps(pairs, &mut c, &mut v, &mut h, constants, record);
        }
        (c, v, h, exchanges)
    }
}
