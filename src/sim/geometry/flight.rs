//! Free flight under uniform gravity, exactly: a parabola, `p + v·t + ½·g·t²`. Every ball
//! feels the same gravity, so two balls move in a straight line relative to each other and
//! their time of impact is the straight-line one; only the walls see the parabola.

use bevy::math::DVec2;

/// Where a ball at `position` moving at `velocity` is after `seconds` of flight under
/// `gravity` (pixels, pixels per second, pixels per second squared).
#[inline]
pub fn position_after(position: DVec2, velocity: DVec2, gravity: DVec2, seconds: f64) -> DVec2 {
    position + velocity * seconds + gravity * (0.5 * seconds * seconds)
}

/// Its velocity then.
#[inline]
pub fn velocity_after(velocity: DVec2, gravity: DVec2, seconds: f64) -> DVec2 {
    velocity + gravity * seconds
}

/// The first time, at least zero, at which a point `gap` pixels short of a wall, moving
/// towards it at `speed` and accelerating towards it at `accel`, reaches it; `None` if it
/// never does (or only at speeds below `min_speed`, which count as resting). A point on or
/// past the wall that moves into it, or rests against it while pushed into it, reaches it
/// now.
pub fn time_to_reach(gap: f64, speed: f64, accel: f64, min_speed: f64) -> Option<f64> {
    if accel == 0.0 {
        // Straight flight.
        return (speed > min_speed).then(|| (gap / speed).max(0.0));
    }
    if gap <= 0.0 {
        let pushed_in = speed > min_speed || (speed >= -min_speed && accel > 0.0);
        return pushed_in.then_some(0.0);
    }
    // ½·accel·t² + speed·t − gap = 0, in the form that cannot cancel: q = −½(b + sign(b)·√d).
    let (a, b, c) = (0.5 * accel, speed, -gap);
    let discriminant = b * b - 4.0 * a * c;
    if discriminant < 0.0 {
        return None; // turns back first
    }
    let q = -0.5 * (b + b.signum() * discriminant.sqrt());
    [q / a, c / q]
        .into_iter()
        .filter(|t| t.is_finite() && *t >= 0.0)
        .min_by(f64::total_cmp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_parabola_and_its_velocity() {
        let (p, v, g) = (
            DVec2::new(1.0, 2.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(0.0, -10.0),
        );
        assert_eq!(position_after(p, v, g, 0.5), DVec2::new(6.0, 0.75));
        assert_eq!(velocity_after(v, g, 0.5), DVec2::new(10.0, -5.0));
    }

    #[test]
    fn dropped_thrown_and_resting_points_reach_the_wall_when_they_should() {
        // Dropped 80 px under 10 px/s²: sqrt(2·80/10) = 4 s.
        assert_eq!(time_to_reach(80.0, 0.0, 10.0, 1e-9), Some(4.0));
        // Thrown away from the wall at 20 px/s, 0 px short: back after 2·20/10 = 4 s.
        assert_eq!(
            time_to_reach(1e-300, -20.0, 10.0, 1e-9).map(|t| t.round()),
            Some(4.0)
        );
        // Thrown towards it but too slow against a pull away: never.
        assert_eq!(time_to_reach(100.0, 10.0, -1.0, 1e-9), None);
        // Against the pull, fast enough: the first crossing, 10 s here.
        let t = time_to_reach(50.0, 10.0, -0.1, 1e-9).unwrap();
        assert!(
            (10.0 * t - 0.05 * t * t - 50.0).abs() < 1e-9 && t < 10.0 + 1e-6,
            "{t}"
        );
        // Resting on the wall and pushed into it: now; moving away: not now.
        assert_eq!(time_to_reach(0.0, 0.0, 10.0, 1e-9), Some(0.0));
        assert_eq!(time_to_reach(0.0, -5.0, 10.0, 1e-9), None);
        // Without acceleration: the straight-line time.
        assert_eq!(time_to_reach(90.0, 30.0, 0.0, 1e-9), Some(3.0));
        assert_eq!(time_to_reach(90.0, 0.0, 0.0, 1e-9), None);
    }

    #[test]
    fn a_tiny_gap_at_high_speed_keeps_its_precision() {
        let t = time_to_reach(1e-9, 1e4, 500.0, 1e-9).unwrap();
        assert!((t - 1e-13).abs() < 1e-17, "{t}");
    }
}
