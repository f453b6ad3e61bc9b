//! Where the pointer is and what is under it, as pure functions the input systems share:
//! the pointer in arena coordinates, the ball under a point, the velocity a drag gives.

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::sim::geometry::Circle;
use crate::sim::params::MAX_FLING_SPEED;

/// Fling speed per pixel of drag, per second: a 100 px drag flings at 300 px/s.
pub const FLING_GAIN: f64 = 3.0;

/// The velocity a drag from `from` to `pointer` gives a ball: along the drag,
/// [`FLING_GAIN`] per pixel, at most [`MAX_FLING_SPEED`].
pub fn fling_velocity(from: DVec2, pointer: DVec2) -> DVec2 {
    ((pointer - from) * FLING_GAIN).clamp_length_max(MAX_FLING_SPEED)
}

/// The ball under `point`: the one whose circle contains it, nearest centre first.
pub fn ball_under<T: Copy>(
    point: DVec2,
    balls: impl IntoIterator<Item = (T, Circle)>,
) -> Option<T> {
    balls
        .into_iter()
        .filter(|(_, circle)| {
            circle.center.distance_squared(point) <= circle.radius * circle.radius
        })
        .min_by(|(_, a), (_, b)| {
            a.center
                .distance_squared(point)
                .total_cmp(&b.center.distance_squared(point))
        })
        .map(|(id, _)| id)
}

/// The pointer in arena coordinates, if it is over the window.
pub fn pointer_in_arena(window: &Window, camera: (&Camera, &GlobalTransform)) -> Option<DVec2> {
    let cursor = window.cursor_position()?;
    camera
        .0
        .viewport_to_world_2d(camera.1, cursor)
        .ok()
        .map(|p| p.as_dvec2())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fling_follows_the_drag_and_is_capped() {
        let v = fling_velocity(DVec2::new(10.0, 10.0), DVec2::new(110.0, 10.0));
        assert_eq!(v, DVec2::new(300.0, 0.0));
        let v = fling_velocity(DVec2::ZERO, DVec2::new(0.0, -1e6));
        assert!((v.length() - MAX_FLING_SPEED).abs() < 1e-9);
        assert!(v.y < 0.0);
        assert_eq!(fling_velocity(DVec2::ONE, DVec2::ONE), DVec2::ZERO);
    }

    #[test]
    fn ball_under_picks_the_containing_ball_nearest_its_centre() {
        let balls = [
            (1, Circle::new(DVec2::new(0.0, 0.0), 10.0)),
            (2, Circle::new(DVec2::new(12.0, 0.0), 10.0)),
        ];
        assert_eq!(ball_under(DVec2::new(7.0, 0.0), balls), Some(2));
        assert_eq!(ball_under(DVec2::new(-5.0, 0.0), balls), Some(1));
        assert_eq!(ball_under(DVec2::new(0.0, 30.0), balls), None);
    }
}
