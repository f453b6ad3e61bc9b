//! Free flight under uniform acceleration, exactly: a parabola, `p + v·t + ½·a·t²`. Balls in
//! free flight all feel the same gravity, so two of them move in a straight line relative to
//! each other and their time of impact is the straight-line one. A ball resting on a
//! support (a wall or a ball that does not move this step) slides with gravity's push into
//! it taken away, and a ball that does not move has no acceleration: against those the
//! relative path is a parabola and [`time_to_touch`] finds its first contact.

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

/// Subdivisions [`time_to_touch`] makes at most before it takes the start of the interval it
/// has narrowed the contact to: 2⁻⁵⁰ of the horizon.
const MAX_SUBDIVISIONS: u32 = 50;

/// The first time in `[0, horizon]` at which a point at `offset` from a circle's centre,
/// moving at `velocity` and accelerating at `accel` relative to it, comes within `reach` of
/// the centre while approaching; `None` if it does not.
///
/// `|offset + v·t + ½·a·t²|² − reach²` is a quartic in `t`. Written in Bernstein form over
/// the interval, its coefficients bound it, so halving the interval (earlier half first)
/// isolates the first root robustly; the answer errs early, never late, by at most 2⁻⁵⁰ of
/// the horizon, so a contact found this way never overlaps.
pub fn time_to_touch(
    offset: DVec2,
    velocity: DVec2,
    accel: DVec2,
    reach: f64,
    horizon: f64,
) -> Option<f64> {
    let half_accel = accel * 0.5;
    let distance = offset.length();
    // Too far to close the gap at the fastest it could close within the horizon.
    let fastest = velocity.length() + accel.length() * horizon;
    if distance - reach > fastest * horizon {
        return None;
    }
    // Monomial coefficients in t, the constant one without cancellation near contact.
    let c = [
        (distance - reach) * (distance + reach),
        2.0 * offset.dot(velocity),
        velocity.length_squared() + 2.0 * offset.dot(half_accel),
        2.0 * velocity.dot(half_accel),
        half_accel.length_squared(),
    ];
    // Closing now, or at rest relative to it and pushed in.
    let approaching = |t: f64| {
        let relative = offset + velocity * t + half_accel * (t * t);
        let moving = velocity + accel * t;
        let closing = relative.dot(moving);
        closing < 0.0 || (closing == 0.0 && relative.dot(accel) + moving.length_squared() < 0.0)
    };
    if c[0] <= 0.0 {
        return approaching(0.0).then_some(0.0);
    }
    // Over s = t / horizon in [0, 1], then in the Bernstein basis of degree 4.
    let mut scale = 1.0;
    let b = c.map(|coefficient| {
        let scaled = coefficient * scale;
        scale *= horizon;
        scaled
    });
    let bernstein = [
        b[0],
        b[0] + b[1] / 4.0,
        b[0] + b[1] / 2.0 + b[2] / 6.0,
        b[0] + 0.75 * b[1] + b[2] / 2.0 + b[3] / 4.0,
        b[0] + b[1] + b[2] + b[3] + b[4],
    ];
    let start = first_root(bernstein, 0.0, 1.0, 0)? * horizon;
    approaching(start).then_some(start)
}

/// The start of the earliest subinterval of `[low, high]` where the polynomial with
/// Bernstein coefficients `coefficients` (over that interval) may reach zero, narrowed
/// [`MAX_SUBDIVISIONS`] times; `None` where they prove it positive throughout.
fn first_root(coefficients: [f64; 5], low: f64, high: f64, depth: u32) -> Option<f64> {
    if coefficients.iter().all(|&c| c > 0.0) {
        return None;
    }
    if coefficients[0] <= 0.0 || depth == MAX_SUBDIVISIONS {
        return Some(low);
    }
    let (left, right) = split_in_half(coefficients);
    let middle = 0.5 * (low + high);
    first_root(left, low, middle, depth + 1).or_else(|| first_root(right, middle, high, depth + 1))
}

/// De Casteljau's halving: the Bernstein coefficients of the same polynomial over each half.
fn split_in_half(mut c: [f64; 5]) -> ([f64; 5], [f64; 5]) {
    let mut left = [0.0; 5];
    let mut right = [0.0; 5];
    for level in 0..5 {
        left[level] = c[0];
        right[4 - level] = c[4 - level];
        for i in 0..4 - level {
            c[i] = 0.5 * (c[i] + c[i + 1]);
        }
    }
    (left, right)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first sampled time the point is within `reach`: a brute-force reference.
    fn sampled_touch(offset: DVec2, v: DVec2, a: DVec2, reach: f64, horizon: f64) -> Option<f64> {
        (0..=200_000)
            .map(|k| horizon * k as f64 / 200_000.0)
            .find(|&t| (offset + v * t + a * (0.5 * t * t)).length() <= reach)
    }

    #[test]
    fn a_falling_ball_touches_a_resting_one_when_sampling_says() {
        let horizon = 1.0 / 60.0;
        for (offset, velocity, accel) in [
            // Dropped from 1 px above onto a ball below.
            (DVec2::new(0.0, 21.0), DVec2::ZERO, DVec2::new(0.0, -3000.0)),
            // Thrown sideways past it, falling onto its shoulder.
            (
                DVec2::new(-24.0, 8.0),
                DVec2::new(600.0, 0.0),
                DVec2::new(0.0, -500.0),
            ),
            // Rising, then falling back, passing just clear on the way up.
            (
                DVec2::new(18.0, -12.0),
                DVec2::new(0.0, 900.0),
                DVec2::new(0.0, -50_000.0),
            ),
        ] {
            let found = time_to_touch(offset, velocity, accel, 20.0, horizon);
            let sampled = sampled_touch(offset, velocity, accel, 20.0, horizon);
            match (found, sampled) {
                (Some(t), Some(s)) => {
                    assert!(t <= s && s - t < 2.0 * horizon / 200_000.0, "{t} vs {s}")
                }
                (None, None) => {}
                other => panic!("{offset} {velocity} {accel}: {other:?}"),
            }
        }
    }

    #[test]
    fn contact_time_errs_early_never_late_and_misses_are_misses() {
        // Head-on at 100 px/s from 10 px: t = 0.1 s exactly, without acceleration.
        let t = time_to_touch(
            DVec2::new(30.0, 0.0),
            DVec2::new(-100.0, 0.0),
            DVec2::ZERO,
            20.0,
            1.0,
        )
        .unwrap();
        assert!(t <= 0.1 && 0.1 - t < 1e-14, "{t}");
        // Moving away, or passing wide: never.
        assert_eq!(
            time_to_touch(
                DVec2::new(30.0, 0.0),
                DVec2::new(100.0, 0.0),
                DVec2::ZERO,
                20.0,
                1.0
            ),
            None
        );
        assert_eq!(
            time_to_touch(
                DVec2::new(30.0, 25.0),
                DVec2::new(-100.0, 0.0),
                DVec2::ZERO,
                20.0,
                1.0
            ),
            None
        );
        // Touching and pushed in: now; touching and pulled away: not.
        let touching = DVec2::new(0.0, 20.0);
        assert_eq!(
            time_to_touch(touching, DVec2::ZERO, DVec2::new(0.0, -1.0), 20.0, 1.0),
            Some(0.0)
        );
        assert_eq!(
            time_to_touch(touching, DVec2::new(0.0, 1.0), DVec2::ZERO, 20.0, 1.0),
            None
        );
    }

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
