//! The resting stage's energy guard ([`keep_energy`]): with restitution below 1 the solved
//! balls' mechanical energy never grows by more than their overlaps could release.
//!
//! The soft step's passes are Gauss–Seidel, one relax pass a substep: under an extreme load
//! (a wedge of balls pressed into a wall by 3,000 px/s² sideways) a pass can end with a
//! contact still pushing while its sides separate, and that does work (the soak's seed 115:
//! 1.7e-6 of the energy in a step). The guard compares the solved balls' energy after the
//! step with what they began with, allows what the overlaps' springs and the lifts out of
//! them may add, and takes any excess out of their kinetic energy.

use bevy::math::DVec2;

use super::constraint::{Body, Other, RestingContact};
use crate::sim::measure::summary::{kinetic_energy, potential_energy};

/// What pushing out the overlaps the `contacts` began the step with may add to the bodies'
/// mechanical energy: each overlap's spring energy (stiffness `omega`, radians per second,
/// carried by the heavier movable side) and each movable body's weight times its overlaps
/// (the height a push-out may lift it).
fn overlap_allowance(
    bodies: &[Body],
    contacts: &[RestingContact],
    gravity: DVec2,
    omega: f64,
) -> f64 {
    let mass = |index: u32| {
        let inverse_mass = bodies[index as usize].inverse_mass;
        if inverse_mass > 0.0 {
            1.0 / inverse_mass
        } else {
            0.0
        }
    };
    let mut allowance = 0.0;
    for contact in contacts.iter().filter(|contact| contact.separation < 0.0) {
        let depth = -contact.separation;
        let (mass_a, mass_b) = match contact.other {
            Other::Body(b) => (mass(contact.a), mass(b)),
            Other::Wall(_) => (mass(contact.a), 0.0),
        };
        allowance += 0.5 * mass_a.max(mass_b) * (omega * depth).powi(2)
            + (mass_a + mass_b) * gravity.length() * depth;
    }
    allowance
}

/// Takes out of the movable `bodies`' kinetic energy (all their velocities scaled alike)
/// what their mechanical energy gained over the step beyond the allowance of the overlaps
/// the `contacts` began with. `start` is each body's velocity when the step began; `bodies`
/// hold where the step ends (`position + shift`) and their velocity then; `hertz` is the
/// contacts' stiffness. Returns the energy taken (0 when the step gained none).
pub fn keep_energy(
    bodies: &mut [Body],
    start: &[DVec2],
    contacts: &[RestingContact],
    gravity: DVec2,
    hertz: f64,
) -> f64 {
    let mechanical = |mass: f64, velocity: DVec2, position: DVec2| {
        kinetic_energy(mass, velocity) + potential_energy(mass, position, gravity)
    };
    let (mut before, mut after) = (0.0, 0.0);
    for (body, &velocity) in bodies.iter().zip(start) {
        if body.inverse_mass > 0.0 {
            let mass = 1.0 / body.inverse_mass;
            before += mechanical(mass, velocity, body.position);
            after += mechanical(mass, body.velocity, body.position + body.shift);
        }
    }
    let omega = 2.0 * std::f64::consts::PI * hertz;
    let excess = after - before - overlap_allowance(bodies, contacts, gravity, omega);
    if excess <= 0.0 {
        return 0.0;
    }
    let kinetic: f64 = (bodies.iter())
        .filter(|body| body.inverse_mass > 0.0)
        .map(|body| 0.5 * body.velocity.length_squared() / body.inverse_mass)
        .sum();
    let scale = (1.0 - excess / kinetic).max(0.0).sqrt();
    for body in bodies.iter_mut().filter(|body| body.inverse_mass > 0.0) {
        body.velocity *= scale;
    }
    excess.min(kinetic)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::geometry::Wall;

    const GRAVITY: DVec2 = DVec2::new(0.0, -500.0);

    #[test]
    fn a_step_that_loses_energy_is_left_alone() {
        // Fell 1 px and sped up by less than the fall gives: energy lost.
        let mut bodies = vec![Body {
            shift: DVec2::new(0.0, -1.0),
            ..Body::new(DVec2::ZERO, DVec2::new(0.0, -30.0), 0.1)
        }];
        let start = [DVec2::new(0.0, -10.0)];
        assert_eq!(keep_energy(&mut bodies, &start, &[], GRAVITY, 90.0), 0.0);
        assert_eq!(bodies[0].velocity, DVec2::new(0.0, -30.0));
    }

    #[test]
    fn a_gain_beyond_the_overlaps_is_taken_back_out_of_the_speed() {
        // Mass 10, no overlap, unmoved, sped up from 10 to 20 px/s: 1,500 gained, all taken.
        let mut bodies = vec![Body::new(DVec2::ZERO, DVec2::new(20.0, 0.0), 0.1)];
        let start = [DVec2::new(10.0, 0.0)];
        let taken = keep_energy(&mut bodies, &start, &[], GRAVITY, 90.0);
        assert!((taken - 1500.0).abs() < 1e-9, "{taken}");
        assert!(
            (bodies[0].velocity.x - 10.0).abs() < 1e-12,
            "{}",
            bodies[0].velocity
        );
    }

    #[test]
    fn an_overlap_may_pay_for_its_push_out() {
        // 0.1 px into the floor, pushed out and left at 5 px/s: its spring (½·10·(2π·90·0.1)²
        // = 1,599) and lift (10·500·0.1 = 500) pay for the 125 + 500 gained.
        let floor = RestingContact::new(0, Other::Wall(Wall::Bottom), DVec2::NEG_Y, -0.1, 0.0);
        let mut bodies = vec![Body {
            shift: DVec2::new(0.0, 0.1),
            ..Body::new(DVec2::ZERO, DVec2::new(0.0, 5.0), 0.1)
        }];
        let taken = keep_energy(&mut bodies, &[DVec2::ZERO], &[floor], GRAVITY, 90.0);
        assert_eq!(taken, 0.0);
        assert_eq!(bodies[0].velocity, DVec2::new(0.0, 5.0));
    }
}
