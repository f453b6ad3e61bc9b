//! The grid's first pass over the balls: the box of their centres, the sum of their radii
//! and the largest radius ([`Extent`]), in four lanes so that no ball waits on the one before.

use bevy::math::DVec2;

use crate::sim::geometry::circle::Circle;

/// What a pass over some balls finds: the box of their centres, the sum of their radii and
/// the largest radius.
#[derive(Clone, Copy)]
pub struct Extent {
    pub min: DVec2,
    pub max: DVec2,
    pub radius_sum: f64,
    pub largest_radius: f64,
}

impl Extent {
    /// No ball yet.
    pub const NONE: Self = Self {
        min: DVec2::MAX,
        max: DVec2::MIN,
        radius_sum: 0.0,
        largest_radius: 0.0,
    };

    /// The extent of `circles`, in four lanes that do not wait on one another: the `k`th of
    /// each run of four in lane `k`, the last few in the first (the sum's rounding is fixed by
    /// the circles' order alone).
    pub fn of(circles: &[Circle]) -> Self {
        let mut lanes = [Self::NONE; 4];
        let runs = circles.chunks_exact(4);
        let rest = runs.remainder();
        for run in runs {
            for (extent, &circle) in lanes.iter_mut().zip(run) {
                *extent = extent.with(circle);
            }
        }
        for &circle in rest {
            lanes[0] = lanes[0].with(circle);
        }
        let [a, b, c, d] = lanes;
        a.joined(b).joined(c.joined(d))
    }

    /// With `circle` too.
    pub fn with(self, circle: Circle) -> Self {
        self.joined(Self {
            min: circle.center,
            max: circle.center,
            radius_sum: circle.radius,
            largest_radius: circle.radius,
        })
    }

    /// Both passes' balls, `self`'s first (the sums are added in that order).
    pub fn joined(self, other: Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
            radius_sum: self.radius_sum + other.radius_sum,
            largest_radius: self.largest_radius.max(other.largest_radius),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_lanes_find_what_one_ball_after_another_finds() {
        // Radii in multiples of 1/64: their sums are exact in any order.
        let circle_at = |k: usize| {
            let (x, y) = (
                (k * 7_919 % 1_000) as f64,
                (k * 104_729 % 977) as f64 - 400.0,
            );
            Circle::new(DVec2::new(x, y), 1.0 + (k * 31 % 700) as f64 / 64.0)
        };
        for balls in [0..0, 3..4, 0..3, 5..9, 2..9, 0..4_099, 17..4_113] {
            let circles: Vec<Circle> = balls.clone().map(circle_at).collect();
            let lanes = Extent::of(&circles);
            let one_by_one = balls
                .clone()
                .map(circle_at)
                .fold(Extent::NONE, Extent::with);
            let found = |e: Extent| (e.min, e.max, e.radius_sum, e.largest_radius);
            assert_eq!(found(lanes), found(one_by_one), "balls {balls:?}");
        }
        let some = Extent::of(&(0..100).map(circle_at).collect::<Vec<_>>());
        assert!(some.min.x < some.max.x && some.min.y < some.max.y && some.radius_sum > 100.0);
    }
}
