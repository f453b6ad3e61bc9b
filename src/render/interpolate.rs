//! Where to draw a ball between two fixed steps: its last two positions blended by
//! `Time<Fixed>::overstep_fraction`, so motion is smooth at any display rate. Used by the
//! sprites and the overlays.

use bevy::prelude::*;

use crate::sim::{Position, PreviousPosition, RunControl};

/// How far between the previous and the latest fixed step to draw: 1 (the latest state)
/// while paused, since no step is under way.
pub fn interpolation_fraction(fixed: &Time<Fixed>, run: &RunControl) -> f64 {
    if run.paused {
        1.0
    } else {
        fixed.overstep_fraction_f64().clamp(0.0, 1.0)
    }
}

/// Where to draw a ball this frame.
pub fn drawn_position(previous: &PreviousPosition, position: &Position, fraction: f64) -> Vec2 {
    previous.0.lerp(position.0, fraction).as_vec2()
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::*;

    #[test]
    fn drawn_position_interpolates_between_steps() {
        let previous = PreviousPosition(DVec2::new(0.0, 0.0));
        let position = Position(DVec2::new(10.0, -4.0));
        assert_eq!(
            drawn_position(&previous, &position, 0.25),
            Vec2::new(2.5, -1.0)
        );
        assert_eq!(
            drawn_position(&previous, &position, 1.0),
            Vec2::new(10.0, -4.0)
        );
    }
}
