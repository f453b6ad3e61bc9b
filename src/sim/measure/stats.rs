//! [`SimStats`]: running totals since the scene was loaded, kept by the report stage from
//! what each step recorded.

use bevy::math::DVec2;
use bevy::prelude::*;

/// Running totals since the scene was loaded. The steps and simulated time are in
/// [`SimClock`](crate::sim::SimClock).
#[derive(Resource, Debug, Default, Clone, PartialEq)]
pub struct SimStats {
    pub ball_collisions: u64,
    pub wall_collisions: u64,
    /// Sum of the walls' normal impulses on the balls, mass x pixels per second.
    pub wall_impulse: f64,
    /// Continuous steps that reached their hit budget and finished without handling every
    /// impact (see [`hit_limit`](crate::sim::continuous::hit_limit)).
    pub cut_short_steps: u64,
    /// Contact points recorded (discrete mode: touching pairs found; continuous mode:
    /// ball–ball impacts), summed over the steps.
    pub contact_points: u64,
}

impl SimStats {
    /// Mean force per unit length of wall over `elapsed` simulated seconds: total wall impulse
    /// / (perimeter x time). The 2-D pressure, in mass / second squared; zero before any time
    /// has passed.
    pub fn pressure(&self, arena_size: DVec2, elapsed: f64) -> f64 {
        wall_pressure(self.wall_impulse, arena_size, elapsed)
    }
}

/// The pressure that `wall_impulse` over `seconds` on the walls of an arena of `arena_size`
/// makes: impulse / (perimeter x time); zero for no time or no perimeter.
pub fn wall_pressure(wall_impulse: f64, arena_size: DVec2, seconds: f64) -> f64 {
    let perimeter = 2.0 * (arena_size.x + arena_size.y);
    if seconds > 0.0 && perimeter > 0.0 {
        wall_impulse / (perimeter * seconds)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pressure_is_impulse_per_perimeter_and_time() {
        let stats = SimStats {
            wall_impulse: 80.0,
            ..default()
        };
        assert_eq!(stats.pressure(DVec2::new(6.0, 4.0), 2.0), 2.0);
        assert_eq!(SimStats::default().pressure(DVec2::new(6.0, 4.0), 0.0), 0.0);
    }
}
