//! Property tests (proptest) over the pure collision functions: random masses, radii,
//! positions, velocities and restitution, extremes included. Test-only; nothing here runs in
//! the game.
//!
//! Everything is `f64`, so the tolerances are relative 1e-12 for a single hit and 1e-9 for a
//! whole timeline of hits.

use bevy::math::DVec2;
use proptest::prelude::*;

use super::continuous::{MIN_HITS_PER_BALL, StepSpec, Timeline};
use super::geometry::circle::{
    Circle, circle_contact, circles_touch, collision_point, time_of_impact,
};
use super::geometry::contain::contain_in_arena;
use super::geometry::impulse::{normal_exchange, resolve_overlaps};
use super::geometry::wall::wall_time_of_impact;
use super::params::{MAX_SPEED, MassModel, RADIUS_RANGE};

/// Relative tolerance for one hit.
const ONE_HIT: f64 = 1e-12;

/// Coefficients of restitution, with both ends drawn often.
fn restitution() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), Just(1.0), 0.0..=1.0]
}

/// Masses from a thousandth to a million: log-uniform, so both light and heavy appear.
fn mass() -> impl Strategy<Value = f64> {
    (-3.0..6.0f64).prop_map(|exponent| 10f64.powf(exponent))
}

/// Radii across the accepted range, log-uniform.
fn radius() -> impl Strategy<Value = f64> {
    let (low, high) = (RADIUS_RANGE.start().ln(), RADIUS_RANGE.end().ln());
    (low..=high).prop_map(f64::exp)
}

/// Velocities up to the fastest accepted speed, the zero velocity included.
fn velocity() -> impl Strategy<Value = DVec2> {
    prop_oneof![
        1 => Just(DVec2::ZERO),
        9 => (0.0..std::f64::consts::TAU, -3.0..(MAX_SPEED.log10()))
            .prop_map(|(angle, exponent)| DVec2::from_angle(angle) * 10f64.powf(exponent)),
    ]
}

fn unit_vector() -> impl Strategy<Value = DVec2> {
    (0.0..std::f64::consts::TAU).prop_map(DVec2::from_angle)
}

fn mass_model() -> impl Strategy<Value = MassModel> {
    prop::sample::select(MassModel::ALL.to_vec())
}

/// Two circles that touch or overlap (centres possibly coincident).
fn touching_pair() -> impl Strategy<Value = (Circle, Circle)> {
    (radius(), radius(), unit_vector(), 0.0..=1.0f64).prop_map(|(ra, rb, direction, depth)| {
        let a = Circle::new(DVec2::new(3.0, -7.0), ra);
        let b = Circle::new(a.center + direction * (ra + rb) * (1.0 - depth), rb);
        (a, b)
    })
}

fn momentum(masses: [f64; 2], velocities: [DVec2; 2]) -> DVec2 {
    masses[0] * velocities[0] + masses[1] * velocities[1]
}

/// The scale momentum errors are measured against: the sum of the magnitudes, since the total
/// may be zero.
fn momentum_scale(masses: [f64; 2], velocities: [DVec2; 2]) -> f64 {
    masses[0] * velocities[0].length() + masses[1] * velocities[1].length()
}

fn kinetic_energy(masses: [f64; 2], velocities: [DVec2; 2]) -> f64 {
    0.5 * (masses[0] * velocities[0].length_squared() + masses[1] * velocities[1].length_squared())
}

fn all_finite(vectors: &[DVec2]) -> bool {
    vectors.iter().all(|v| v.is_finite())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2_000))]

    #[test]
    fn an_exchange_keeps_momentum_and_never_gains_energy(
        masses in [mass(), mass()],
        va in velocity(),
        vb in velocity(),
        normal in unit_vector(),
        e in restitution(),
    ) {
        let before = [va, vb];
        let Some(hit) = normal_exchange(va, vb, 1.0 / masses[0], 1.0 / masses[1], normal, e)
        else {
            // Not approaching: nothing to check but that it was right to refuse.
            prop_assert!((va - vb).dot(normal) <= 0.0);
            return Ok(());
        };
        let after = [hit.velocity_a, hit.velocity_b];
        prop_assert!(all_finite(&after) && hit.impulse.is_finite() && hit.impulse >= 0.0);
        let drift = (momentum(masses, after) - momentum(masses, before)).length();
        prop_assert!(drift <= ONE_HIT * momentum_scale(masses, before), "momentum drift {drift}");
        let (energy_before, energy_after) =
            (kinetic_energy(masses, before), kinetic_energy(masses, after));
        prop_assert!(energy_after <= energy_before * (1.0 + ONE_HIT),
            "energy {energy_before} -> {energy_after}");
        if e == 1.0 {
            prop_assert!((energy_after - energy_before).abs() <= ONE_HIT * energy_before,
                "elastic energy {energy_before} -> {energy_after}");
        }
        // The balls no longer approach, and the tangential parts are untouched.
        prop_assert!((after[0] - after[1]).dot(normal) <= ONE_HIT * (va - vb).length());
        let tangent = normal.perp();
        for (old, new) in before.iter().zip(&after) {
            prop_assert!((old.dot(tangent) - new.dot(tangent)).abs() <= ONE_HIT * (va.length() + vb.length()));
        }
    }

    #[test]
    fn swapping_the_balls_mirrors_the_exchange(
        masses in [mass(), mass()],
        va in velocity(),
        vb in velocity(),
        normal in unit_vector(),
        e in restitution(),
    ) {
        let forward = normal_exchange(va, vb, 1.0 / masses[0], 1.0 / masses[1], normal, e);
        let swapped = normal_exchange(vb, va, 1.0 / masses[1], 1.0 / masses[0], -normal, e);
        match (forward, swapped) {
            (None, None) => {}
            (Some(f), Some(s)) => {
                prop_assert_eq!(f.velocity_a, s.velocity_b);
                prop_assert_eq!(f.velocity_b, s.velocity_a);
                prop_assert_eq!(f.impulse, s.impulse);
            }
            _ => prop_assert!(false, "one order hits, the other does not"),
        }
    }

    #[test]
    fn resolving_a_pair_separates_it_keeps_momentum_and_the_centre_of_mass(
        (a, b) in touching_pair(),
        va in velocity(),
        vb in velocity(),
        model in mass_model(),
        e in restitution(),
    ) {
        let masses = [model.mass(a.radius), model.mass(b.radius)];
        let mut circles = [a, b];
        let mut velocities = [va, vb];
        resolve_overlaps([(0, 1)], &mut circles, &mut velocities, &mut [false; 2], (model, e, 0.0), |_, _, _, _| {});
        prop_assert!(all_finite(&velocities) && all_finite(&[circles[0].center, circles[1].center]));
        let drift = (momentum(masses, velocities) - momentum(masses, [va, vb])).length();
        prop_assert!(drift <= ONE_HIT * momentum_scale(masses, [va, vb]), "momentum drift {drift}");
        prop_assert!(kinetic_energy(masses, velocities) <= kinetic_energy(masses, [va, vb]) * (1.0 + ONE_HIT));
        let reach = a.radius + b.radius;
        let gap = circles[0].center.distance(circles[1].center);
        prop_assert!(gap >= reach * (1.0 - ONE_HIT), "still overlapping: {gap} < {reach}");
        let centre_of_mass = |c: &[Circle; 2]| (masses[0] * c[0].center + masses[1] * c[1].center) / (masses[0] + masses[1]);
        let shift = centre_of_mass(&circles).distance(centre_of_mass(&[a, b]));
        prop_assert!(shift <= ONE_HIT * (reach + a.center.length() + b.center.length()), "centre of mass moved {shift}");
    }

    #[test]
    fn resolving_a_swapped_pair_gives_the_mirrored_result(
        (a, b) in touching_pair(),
        va in velocity(),
        vb in velocity(),
        model in mass_model(),
        e in restitution(),
    ) {
        // Coincident centres have no line of centres; both orders then use the same fixed
        // normal, so only distinct centres mirror.
        prop_assume!(a.center != b.center);
        let mut forward = ([a, b], [va, vb]);
        let mut swapped = ([b, a], [vb, va]);
        resolve_overlaps([(0, 1)], &mut forward.0, &mut forward.1, &mut [false; 2], (model, e, 0.0), |_, _, _, _| {});
        resolve_overlaps([(0, 1)], &mut swapped.0, &mut swapped.1, &mut [false; 2], (model, e, 0.0), |_, _, _, _| {});
        let scale = va.length() + vb.length();
        for (mine, theirs) in [(0, 1), (1, 0)] {
            prop_assert!(forward.1[mine].distance(swapped.1[theirs]) <= ONE_HIT * scale);
            let moved = forward.0[mine].center.distance(swapped.0[theirs].center);
            prop_assert!(moved <= ONE_HIT * (a.radius + b.radius + a.center.length() + b.center.length()));
        }
    }

    #[test]
    fn a_separating_pair_is_left_alone(
        (a, b) in touching_pair(),
        va in velocity(),
        vb in velocity(),
        model in mass_model(),
        e in restitution(),
    ) {
        let offset = b.center - a.center;
        prop_assume!(offset != DVec2::ZERO);
        // Reflect the relative velocity if it approaches, so that the pair separates.
        let normal = offset.normalize();
        let relative = vb - va;
        let vb = va + relative - 2.0 * relative.dot(normal).min(0.0) * normal;
        prop_assume!((vb - va).dot(offset) >= 0.0);
        let mut circles = [a, b];
        let mut velocities = [va, vb];
        let mut exchanges = 0;
        resolve_overlaps([(0, 1)], &mut circles, &mut velocities, &mut [false; 2], (model, e, 0.0), |_, _, _, _| exchanges += 1);
        prop_assert_eq!(exchanges, 0);
        prop_assert_eq!(velocities, [va, vb]);
        prop_assert_eq!(time_of_impact(a, va, b, vb), None);
    }

    #[test]
    fn the_collision_point_lies_between_the_centres_and_ignores_order((a, b) in touching_pair()) {
        let point = collision_point(a, b);
        prop_assert_eq!(point, collision_point(b, a));
        prop_assert!(point.is_finite());
        let reach = a.radius + b.radius;
        prop_assert!(point.distance(a.center) <= a.radius * (1.0 + ONE_HIT) + ONE_HIT * reach);
        prop_assert!(point.distance(b.center) <= b.radius * (1.0 + ONE_HIT) + ONE_HIT * reach);
        prop_assert!(circles_touch(a, b) && circle_contact(a, b).is_some());
    }

    #[test]
    fn the_time_of_impact_is_when_the_circles_first_touch(
        ra in radius(),
        rb in radius(),
        offset in (unit_vector(), 0.0..5_000.0f64),
        va in velocity(),
        vb in velocity(),
    ) {
        let a = Circle::new(DVec2::ZERO, ra);
        let b = Circle::new(offset.0 * (ra + rb + offset.1), rb);
        let Some(time) = time_of_impact(a, va, b, vb) else {
            return Ok(());
        };
        prop_assert!(time.is_finite() && time >= 0.0);
        let gap_at = |t: f64| (b.center + vb * t).distance(a.center + va * t);
        let reach = ra + rb;
        let scale = reach + (vb - va).length() * time;
        prop_assert!((gap_at(time) - reach).abs() <= 1e-9 * scale, "gap {} vs {reach}", gap_at(time));
        prop_assert!(gap_at(time * 0.5) >= reach * (1.0 - 1e-9));
    }

    #[test]
    fn containment_keeps_a_ball_inside_without_speeding_it_up(
        position in (-5_000.0..5_000.0f64, -5_000.0..5_000.0f64),
        velocity in velocity(),
        radius in radius(),
        half in (1.0..3_000.0f64, 1.0..3_000.0f64),
        e in restitution(),
    ) {
        let half = DVec2::new(half.0, half.1);
        let contained = contain_in_arena(DVec2::from(position), velocity, radius, half, e);
        prop_assert!(contained.position.is_finite() && contained.velocity.is_finite());
        for axis in 0..2 {
            let room = (half[axis] - radius).max(0.0);
            prop_assert!(contained.position[axis].abs() <= room * (1.0 + ONE_HIT));
            prop_assert!(contained.velocity[axis].abs() <= velocity[axis].abs());
        }
        if let Some((time, _)) = wall_time_of_impact(DVec2::from(position), velocity, radius, half, DVec2::ZERO) {
            prop_assert!(time.is_finite() && time >= 0.0);
        }
    }
}

/// A handful of balls in a small box, placed without overlap.
fn crowd() -> impl Strategy<Value = (Vec<Circle>, Vec<DVec2>)> {
    prop::collection::vec((radius_small(), unit_vector(), 0.0..2_000.0f64), 2..12).prop_map(
        |balls| {
            // Lay them out on a row of slots so none overlap, then give each its velocity.
            let mut circles = Vec::new();
            let mut velocities = Vec::new();
            let mut x = -190.0;
            for (radius, direction, speed) in balls {
                let y = direction.y * (40.0 - radius);
                circles.push(Circle::new(DVec2::new(x + radius, y), radius));
                velocities.push(direction * speed);
                x += 2.0 * radius + 1.0;
            }
            (circles, velocities)
        },
    )
}

fn radius_small() -> impl Strategy<Value = f64> {
    0.5..=15.0f64
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn a_timeline_keeps_energy_and_leaves_no_overlap(
        (mut circles, mut velocities) in crowd(),
        model in mass_model(),
        e in restitution(),
        dt in prop_oneof![Just(1.0 / 60.0), 0.001..0.2f64],
    ) {
        let spec = StepSpec { dt, half: DVec2::new(200.0, 50.0), restitution: e, mass_model: model, gravity: DVec2::ZERO, rest_speed: 0.0, hit_limit: MIN_HITS_PER_BALL };
        let energy = |c: &[Circle], v: &[DVec2]| -> f64 {
            c.iter().zip(v).map(|(c, v)| 0.5 * model.mass(c.radius) * v.length_squared()).sum()
        };
        let start = energy(&circles, &velocities);
        let mut timeline = Timeline::default();
        // A step cut short (an inelastic squeeze into a corner) may leave overlaps that later
        // steps push apart gradually: only until then must every pair be apart.
        let mut any_cut_short = false;
        for _ in 0..20 {
            let before = energy(&circles, &velocities);
            let (mut held, mut stopped) = (vec![false; circles.len()], vec![false; circles.len()]);
            timeline.predict(&circles, &velocities, &held, spec);
            timeline.run(&mut circles, &mut velocities, (&mut held, &mut stopped), spec, |_| {});
            let after = energy(&circles, &velocities);
            prop_assert!(all_finite(&velocities));
            prop_assert!(after <= before * (1.0 + 1e-9) + 1e-9, "energy grew {before} -> {after}");
            for c in &circles {
                prop_assert!(c.center.is_finite());
                prop_assert!(c.center.x.abs() + c.radius <= spec.half.x * (1.0 + 1e-9));
                prop_assert!(c.center.y.abs() + c.radius <= spec.half.y * (1.0 + 1e-9));
            }
            any_cut_short |= timeline.cut_short;
            if !any_cut_short {
                for (i, a) in circles.iter().enumerate() {
                    for b in &circles[i + 1..] {
                        let reach = a.radius + b.radius;
                        prop_assert!(a.center.distance(b.center) >= reach * (1.0 - 1e-9));
                    }
                }
            }
        }
        if e == 1.0 {
            let end = energy(&circles, &velocities);
            prop_assert!((end - start).abs() <= 1e-9 * start, "elastic energy {start} -> {end}");
        }
    }
}
