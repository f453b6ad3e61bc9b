//! Circles: the exact circle–circle tests (AABB, squared distance, contact, collision point,
//! time of impact), as pure functions over plain values.
//!
//! Both modes' collision stages call them for every candidate pair the grid proposes; the
//! aiming guide, scene placement and the measurements call the same ones, so every prediction
//! matches the simulation exactly.

use bevy::math::DVec2;

/// A circle in arena coordinates (pixels). Plain numbers (`bytemuck::Pod`), so a buffer of
/// other plain numbers may hold circles for a while.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Circle {
    pub center: DVec2,
    /// Pixels; always positive for a valid ball.
    pub radius: f64,
}

impl Circle {
    pub const fn new(center: DVec2, radius: f64) -> Self {
        Self { center, radius }
    }
}

/// The smallest and largest radius among some circles (`NONE` for none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiusRange {
    pub smallest: f64,
    pub largest: f64,
}

impl Default for RadiusRange {
    fn default() -> Self {
        Self::NONE
    }
}

impl RadiusRange {
    pub const NONE: Self = Self {
        smallest: f64::INFINITY,
        largest: f64::NEG_INFINITY,
    };

    /// The range of the radii `radius(item)` of `items`, in four lanes that do not wait on
    /// one another.
    pub fn of_each<T>(items: &[T], radius: impl Fn(&T) -> f64) -> Self {
        let mut lanes = [Self::NONE; 4];
        let fours = items.chunks_exact(4);
        for item in fours.remainder() {
            lanes[0] = lanes[0].with(radius(item));
        }
        for four in fours {
            for (lane, item) in lanes.iter_mut().zip(four) {
                *lane = lane.with(radius(item));
            }
        }
        let [a, b, c, d] = lanes;
        a.joined(b).joined(c.joined(d))
    }

    /// With a circle of `radius` too (a NaN changes nothing: comparisons, one instruction
    /// each, where `f64::min` takes several to pass NaNs over).
    #[inline]
    pub fn with(self, radius: f64) -> Self {
        Self {
            smallest: if radius < self.smallest {
                radius
            } else {
                self.smallest
            },
            largest: if radius > self.largest {
                radius
            } else {
                self.largest
            },
        }
    }

    /// The circles of both.
    pub fn joined(self, other: Self) -> Self {
        Self {
            smallest: self.with(other.smallest).smallest,
            largest: self.with(other.largest).largest,
        }
    }
}

/// Where and how deeply two circles touch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactGeometry {
    /// Unit vector from the first circle's centre towards the second's.
    pub normal: DVec2,
    /// Overlap along the normal, pixels (`r1 + r2 - distance`); zero when just touching.
    pub depth: f64,
    /// The radius-weighted collision point `(p1*r2 + p2*r1) / (r1 + r2)`.
    pub point: DVec2,
}

/// The cheap pre-check: do the circles' axis-aligned bounding boxes overlap (or touch)?
#[inline]
pub fn aabbs_overlap(a: Circle, b: Circle) -> bool {
    let reach = a.radius + b.radius;
    let d = (b.center - a.center).abs();
    d.x <= reach && d.y <= reach
}

/// The tutorial's collision point, weighted by radius: `(p1*r2 + p2*r1) / (r1 + r2)`.
///
/// For two touching circles it is the point where they touch; for overlapping ones it lies on
/// the line of centres, inside the lens, closer to the smaller circle's centre.
#[inline]
pub fn collision_point(a: Circle, b: Circle) -> DVec2 {
    (a.center * b.radius + b.center * a.radius) / (a.radius + b.radius)
}

/// The unit normal used when two centres coincide and the line of centres is undefined.
///
/// Any fixed direction keeps the result finite and deterministic; separation then pushes the
/// pair apart along it.
pub const COINCIDENT_NORMAL: DVec2 = DVec2::X;

/// Two circles overlap when they interpenetrate by more than this fraction of their radii
/// sum: less is rounding. So hand-written decimals that touch (Newton's cradle) are accepted,
/// and a pair left touching by a time of impact is not pushed apart again.
pub const OVERLAP_TOLERANCE: f64 = 1e-9;

/// Whether two circles overlap by more than rounding ([`OVERLAP_TOLERANCE`]).
#[inline]
pub fn overlapping(a: Circle, b: Circle) -> bool {
    let reach = (a.radius + b.radius) * (1.0 - OVERLAP_TOLERANCE);
    a.center.distance_squared(b.center) < reach * reach
}

/// The unit normal along `offset`, the vector from one centre to the other, whose length is
/// `distance`: [`COINCIDENT_NORMAL`] when the centres coincide.
#[inline]
pub fn contact_normal(offset: DVec2, distance: f64) -> DVec2 {
    if distance > 0.0 {
        offset / distance
    } else {
        COINCIDENT_NORMAL
    }
}

/// Both tests at once, without an early exit: the AABB test and the squared-distance test are
/// each a few flops, and in a hot loop where about half the candidates pass the AABB test a
/// branch on it mispredicts often. True when the circles touch or overlap.
#[inline]
pub fn circles_touch(a: Circle, b: Circle) -> bool {
    let reach = a.radius + b.radius;
    let delta = b.center - a.center;
    let aabb = (delta.x.abs() <= reach) & (delta.y.abs() <= reach);
    aabb & (delta.length_squared() <= reach * reach)
}

/// Whether the circles touch or overlap, by the squared-distance test alone: what
/// [`circles_touch`] decides, but for centres the sum of the radii apart to the last bit
/// (the AABB test may then say no where the distance says yes). For bounding circles, whose
/// every candidate is tested whole without a branch: the continuous mode's swept circles,
/// where a pair passing at the very edge costs only its exact time of impact, and the AABB
/// test beside the distance only added work (a fifth of the first search's instructions).
#[inline]
pub fn within_reach(a: Circle, b: Circle) -> bool {
    let reach = a.radius + b.radius;
    (b.center - a.center).length_squared() <= reach * reach
}

/// The exact test: AABB first, then squared distance against `(r1 + r2)^2` (no square root
/// unless the circles really touch). Returns `None` for circles that neither touch nor overlap.
#[inline]
pub fn circle_contact(a: Circle, b: Circle) -> Option<ContactGeometry> {
    if !aabbs_overlap(a, b) {
        return None;
    }
    let delta = b.center - a.center;
    let reach = a.radius + b.radius;
    let distance_squared = delta.length_squared();
    if distance_squared > reach * reach {
        return None;
    }
    let distance = distance_squared.sqrt();
    Some(ContactGeometry {
        normal: contact_normal(delta, distance),
        depth: reach - distance,
        point: collision_point(a, b),
    })
}

/// Pairs (and balls and walls) closing more slowly than this, pixels per second, count as
/// resting, not approaching. Without it, rounding after a perfectly inelastic hit could
/// schedule the same impact again and again at the same instant.
pub const MIN_APPROACH_SPEED: f64 = 1e-9;

/// Seconds until two circles moving at constant velocities first touch, or `None` if they
/// never do. Pairs that already touch count as touching now (`Some(0.0)`) only while they
/// approach; a separating pair gives `None`.
///
/// Solves `|d + v t|^2 = (r1 + r2)^2` for the smaller root, written as `c / (-b + sqrt(disc))`
/// so the subtraction of nearly equal terms in the textbook form cannot lose precision.
#[inline]
pub fn time_of_impact(a: Circle, velocity_a: DVec2, b: Circle, velocity_b: DVec2) -> Option<f64> {
    let offset = b.center - a.center;
    let velocity = velocity_b - velocity_a;
    let reach = a.radius + b.radius;
    let half_b = offset.dot(velocity);
    if half_b >= 0.0 {
        return None; // not approaching
    }
    let c = offset.length_squared() - reach * reach;
    if c <= 0.0 {
        return Some(0.0);
    }
    let discriminant = half_b * half_b - velocity.length_squared() * c;
    if discriminant < 0.0 {
        return None; // they pass each other
    }
    Some(c / (-half_b + discriminant.sqrt()))
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    fn circle(x: f64, y: f64, r: f64) -> Circle {
        Circle::new(DVec2::new(x, y), r)
    }

    #[test]
    fn aabb_rejects_far_pairs_and_accepts_diagonal_near_misses() {
        assert!(!aabbs_overlap(circle(0.0, 0.0, 1.0), circle(3.0, 0.0, 1.0)));
        // Diagonal neighbours: boxes overlap, circles do not; the exact test must reject them.
        let (a, b) = (circle(0.0, 0.0, 1.0), circle(1.6, 1.6, 1.0));
        assert!(aabbs_overlap(a, b));
        assert_eq!(circle_contact(a, b), None);
    }

    #[test]
    fn collision_point_is_weighted_by_radius() {
        // Touching circles: the point is where they touch.
        let p = collision_point(circle(0.0, 0.0, 10.0), circle(30.0, 0.0, 20.0));
        assert_eq!(p, DVec2::new(10.0, 0.0));
        // Equal radii: the midpoint.
        let p = collision_point(circle(-2.0, 4.0, 5.0), circle(2.0, 0.0, 5.0));
        assert_eq!(p, DVec2::new(0.0, 2.0));
    }

    #[test]
    fn contact_has_unit_normal_from_a_to_b_and_the_overlap_depth() {
        let c = circle_contact(circle(0.0, 0.0, 10.0), circle(6.0, 8.0, 5.0)).unwrap();
        assert!((c.normal - DVec2::new(0.6, 0.8)).length() < 1e-15);
        assert!((c.depth - 5.0).abs() < 1e-12);
    }

    #[test]
    fn circles_touch_agrees_with_circle_contact() {
        let a = circle(0.0, 0.0, 10.0);
        for (x, y) in [
            (20.0, 0.0),
            (20.001, 0.0),
            (14.0, 14.0),
            (15.0, 15.0),
            (0.0, 0.0),
            (-3.0, 19.0),
        ] {
            let b = circle(x, y, 10.0);
            assert_eq!(
                circles_touch(a, b),
                circle_contact(a, b).is_some(),
                "({x}, {y})"
            );
        }
    }

    #[test]
    fn within_reach_decides_as_circles_touch_does_short_of_the_last_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        let (mut touching, mut tangent) = (0, 0);
        for case in 0..20_000 {
            let a = circle(
                rng.random_range(-50.0..50.0),
                rng.random_range(-50.0..50.0),
                rng.random_range(0.5..20.0),
            );
            let radius = rng.random_range(0.5..20.0);
            // Every fourth pair tangent, as near as rounding lets it be.
            let direction = DVec2::from_angle(rng.random_range(0.0..std::f64::consts::TAU));
            let distance = if case % 4 == 0 {
                a.radius + radius
            } else {
                rng.random_range(0.0..60.0)
            };
            let b = Circle::new(a.center + direction * distance, radius);
            let (by_distance, both) = (within_reach(a, b), circles_touch(a, b));
            touching += usize::from(both);
            if by_distance != both {
                // Only where the distance is the reach to rounding, and only ever more.
                assert!(by_distance, "{a:?} {b:?}");
                let apart = a.center.distance(b.center);
                assert!(
                    (apart - (a.radius + b.radius)).abs() <= 1e-12 * apart,
                    "{a:?} {b:?}"
                );
                tangent += 1;
            }
        }
        assert!(touching > 5_000, "{touching} touching");
        assert!(tangent < 100, "{tangent} decided apart by the last bit");
        assert!(within_reach(
            circle(0.0, 0.0, 10.0),
            circle(20.0, 0.0, 10.0)
        ));
        assert!(!within_reach(
            circle(0.0, 0.0, 10.0),
            circle(20.001, 0.0, 10.0)
        ));
        assert!(!within_reach(
            circle(f64::NAN, 0.0, 1.0),
            circle(0.0, 0.0, 1.0)
        ));
    }

    #[test]
    fn touching_counts_as_contact_with_zero_depth() {
        let c = circle_contact(circle(0.0, 0.0, 10.0), circle(20.0, 0.0, 10.0)).unwrap();
        assert_eq!(c.depth, 0.0);
        assert_eq!(c.point, DVec2::new(10.0, 0.0));
        assert_eq!(
            circle_contact(circle(0.0, 0.0, 10.0), circle(20.001, 0.0, 10.0)),
            None
        );
    }

    #[test]
    fn time_of_impact_head_on_and_glancing() {
        let a = circle(0.0, 0.0, 1.0);
        let b = circle(10.0, 0.0, 1.0);
        // Closing at 4 px/s over a gap of 8 px.
        let t = time_of_impact(a, DVec2::new(3.0, 0.0), b, DVec2::new(-1.0, 0.0)).unwrap();
        assert!((t - 2.0).abs() < 1e-12);
        // Offset by 1.5 (< reach 2): they touch when the x gap is sqrt(4 - 2.25).
        let b = circle(10.0, 1.5, 1.0);
        let t = time_of_impact(a, DVec2::new(1.0, 0.0), b, DVec2::ZERO).unwrap();
        assert!((t - (10.0 - 1.75f64.sqrt())).abs() < 1e-12);
        // Offset by 2.5 (> reach): a miss.
        assert_eq!(
            time_of_impact(a, DVec2::X, circle(10.0, 2.5, 1.0), DVec2::ZERO),
            None
        );
    }

    #[test]
    fn time_of_impact_of_touching_and_separating_pairs() {
        let (a, b) = (circle(0.0, 0.0, 1.0), circle(1.5, 0.0, 1.0));
        assert_eq!(time_of_impact(a, DVec2::X, b, DVec2::ZERO), Some(0.0));
        assert_eq!(time_of_impact(a, -DVec2::X, b, DVec2::ZERO), None);
        assert_eq!(time_of_impact(a, DVec2::ZERO, b, DVec2::ZERO), None);
    }

    #[test]
    fn time_of_impact_keeps_precision_for_a_tiny_gap_at_high_speed() {
        let a = circle(0.0, 0.0, 10.0);
        let b = circle(20.0 + 1e-9, 0.0, 10.0);
        let t = time_of_impact(a, DVec2::new(1.0e4, 0.0), b, DVec2::ZERO).unwrap();
        assert!((t - 1e-13).abs() < 1e-17, "{t}");
    }

    #[test]
    fn coincident_centres_give_a_finite_normal_and_full_depth() {
        let c = circle_contact(circle(3.0, 3.0, 4.0), circle(3.0, 3.0, 6.0)).unwrap();
        assert_eq!(c.normal, COINCIDENT_NORMAL);
        assert_eq!(c.depth, 10.0);
        assert!(c.point.is_finite());
    }

    #[test]
    fn a_radius_range_in_four_lanes_is_the_one_found_ball_by_ball() {
        let radii: Vec<f64> = (0..23)
            .map(|k| 1.0 + ((k * 37) % 19) as f64 / 4.0)
            .collect();
        for count in [0, 1, 3, 4, 5, 8, 23] {
            let lanes = RadiusRange::of_each(&radii[..count], |&radius| radius);
            let one_by_one = radii[..count]
                .iter()
                .fold(RadiusRange::NONE, |range, &radius| range.with(radius));
            assert_eq!(lanes, one_by_one, "{count} radii");
        }
        let all = RadiusRange::of_each(&radii, |&radius| radius);
        assert_eq!((all.smallest, all.largest), (1.0, 5.5));
        // A NaN changes nothing.
        assert_eq!(all.with(f64::NAN), all);
    }
}
