//! The aiming guide's prediction: where a ball sent off with some velocity first hits another
//! ball, and the directions both leave in. Built from the simulation's own collision functions
//! ([`time_of_impact`], [`collision_point`], [`normal_exchange`], [`wall_time_of_impact`]),
//! not a copy, so the guide shows what the simulation will do. Pure; runs in no schedule.

use bevy::math::DVec2;

use super::geometry::circle::{Circle, collision_point, contact_normal, time_of_impact};
use super::geometry::impulse::normal_exchange;
use super::geometry::wall::wall_time_of_impact;

/// Another ball the aimed ball might hit, with whatever the caller uses to name it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AimTarget<T> {
    pub id: T,
    pub circle: Circle,
    pub velocity: DVec2,
    pub inverse_mass: f64,
}

/// The first hit along the aimed ball's path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AimPrediction<T> {
    pub target: T,
    /// Seconds from now.
    pub time: f64,
    /// The aimed ball's centre at the hit.
    pub cue_center: DVec2,
    /// The target's centre at the hit.
    pub target_center: DVec2,
    /// The radius-weighted collision point.
    pub point: DVec2,
    /// Unit normal from the aimed ball to the target at the hit.
    pub normal: DVec2,
    pub cue_velocity_after: DVec2,
    pub target_velocity_after: DVec2,
}

/// The first ball that `cue` (moving at `velocity`, inverse mass `inverse_mass`) hits within
/// `horizon` seconds, everything moving in straight lines meanwhile, and how both leave.
pub fn predict_first_hit<T: Copy>(
    cue: Circle,
    velocity: DVec2,
    inverse_mass: f64,
    targets: impl IntoIterator<Item = AimTarget<T>>,
    restitution: f64,
    horizon: f64,
) -> Option<AimPrediction<T>> {
    let (target, time) = targets
        .into_iter()
        .filter_map(|target| {
            time_of_impact(cue, velocity, target.circle, target.velocity)
                .filter(|&time| time <= horizon)
                .map(|time| (target, time))
        })
        .min_by(|(_, t1), (_, t2)| t1.total_cmp(t2))?;
    let cue_at_hit = Circle::new(cue.center + velocity * time, cue.radius);
    let target_at_hit = Circle::new(
        target.circle.center + target.velocity * time,
        target.circle.radius,
    );
    let offset = target_at_hit.center - cue_at_hit.center;
    let normal = contact_normal(offset, offset.length());
    let exchange = normal_exchange(
        velocity,
        target.velocity,
        inverse_mass,
        target.inverse_mass,
        normal,
        restitution,
    );
    let (cue_velocity_after, target_velocity_after) = exchange
        .map_or((velocity, target.velocity), |e| {
            (e.velocity_a, e.velocity_b)
        });
    Some(AimPrediction {
        target: target.id,
        time,
        cue_center: cue_at_hit.center,
        target_center: target_at_hit.center,
        point: collision_point(cue_at_hit, target_at_hit),
        normal,
        cue_velocity_after,
        target_velocity_after,
    })
}

/// Seconds until a ball of `radius` at `center` moving at `velocity` touches a wall of the
/// arena `[-half, half]` along a straight path (the simulation's own [`wall_time_of_impact`]);
/// infinite when it meets none.
pub fn time_to_wall(center: DVec2, velocity: DVec2, radius: f64, half: DVec2) -> f64 {
    wall_time_of_impact(center, velocity, radius, half, DVec2::ZERO)
        .map_or(f64::INFINITY, |(time, _)| time)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn still(id: u32, x: f64, y: f64, r: f64) -> AimTarget<u32> {
        AimTarget {
            id,
            circle: Circle::new(DVec2::new(x, y), r),
            velocity: DVec2::ZERO,
            inverse_mass: 1.0 / r,
        }
    }

    #[test]
    fn predicts_the_nearest_ball_on_the_path() {
        let cue = Circle::new(DVec2::ZERO, 10.0);
        let targets = [
            still(1, 100.0, 0.0, 10.0),
            still(2, 50.0, 5.0, 10.0),
            still(3, 50.0, 80.0, 10.0),
        ];
        let hit = predict_first_hit(cue, DVec2::new(100.0, 0.0), 0.1, targets, 1.0, 10.0).unwrap();
        assert_eq!(hit.target, 2);
        let gap = 50.0 - (400.0f64 - 25.0).sqrt();
        assert!((hit.time - gap / 100.0).abs() < 1e-12);
        assert!((hit.cue_center.distance(hit.target_center) - 20.0).abs() < 1e-9);
    }

    #[test]
    fn equal_masses_leave_at_right_angles() {
        let cue = Circle::new(DVec2::ZERO, 10.0);
        let hit = predict_first_hit(
            cue,
            DVec2::new(50.0, 0.0),
            0.1,
            [still(7, 60.0, 8.0, 10.0)],
            1.0,
            10.0,
        )
        .unwrap();
        assert!(hit.cue_velocity_after.dot(hit.target_velocity_after).abs() < 1e-9);
        assert!(hit.target_velocity_after.normalize().dot(hit.normal) > 1.0 - 1e-12);
        assert!((hit.point - (hit.cue_center + hit.normal * 10.0)).length() < 1e-9);
    }

    #[test]
    fn nothing_within_the_horizon_is_none() {
        let cue = Circle::new(DVec2::ZERO, 10.0);
        assert_eq!(
            predict_first_hit(
                cue,
                DVec2::new(1.0, 0.0),
                0.1,
                [still(1, 100.0, 0.0, 10.0)],
                1.0,
                5.0
            ),
            None
        );
        assert_eq!(
            predict_first_hit(
                cue,
                DVec2::new(-1.0, 0.0),
                0.1,
                [still(1, 100.0, 0.0, 10.0)],
                1.0,
                1e9
            ),
            None
        );
    }

    #[test]
    fn time_to_wall_takes_the_nearer_wall() {
        let half = DVec2::new(100.0, 50.0);
        assert_eq!(
            time_to_wall(DVec2::ZERO, DVec2::new(10.0, 0.0), 10.0, half),
            9.0
        );
        assert_eq!(
            time_to_wall(DVec2::ZERO, DVec2::new(10.0, -20.0), 10.0, half),
            2.0
        );
        assert_eq!(
            time_to_wall(DVec2::ZERO, DVec2::ZERO, 10.0, half),
            f64::INFINITY
        );
    }
}
