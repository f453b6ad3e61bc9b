//! Checks on single scene values, shared by parsing (through [`checked`], the serde
//! deserializers that apply them as each value is read, so an error has its line and column)
//! and by [`SceneFile::build`](super::SceneFile::build) (for scenes made or changed in code,
//! which adds the ball or field).

use std::ops::RangeInclusive;

use crate::sim::params::{
    ARENA_SIDE_RANGE, DAMPING_RANGE, DENSEST_PACKING, MAX_BALLS, MAX_GRAVITY, MAX_SPEED,
    RADIUS_RANGE, RESTITUTION_RANGE,
};

fn in_range(value: f64, range: &RangeInclusive<f64>) -> Result<(), String> {
    if range.contains(&value) {
        Ok(())
    } else {
        Err(format!(
            "{value} is outside [{}, {}]",
            range.start(),
            range.end()
        ))
    }
}

fn named(name: &str, result: Result<(), String>) -> Result<(), String> {
    result.map_err(|error| format!("{name} {error}"))
}

/// A (min, max) pair, each in `range`, min not above max.
fn ordered(pair: (f64, f64), range: &RangeInclusive<f64>) -> Result<(), String> {
    named("min", in_range(pair.0, range))?;
    named("max", in_range(pair.1, &(pair.0..=*range.end())))
}

pub fn gravity(&(x, y): &(f64, f64)) -> Result<(), String> {
    named("gravity x", in_range(x, &(-MAX_GRAVITY..=MAX_GRAVITY)))?;
    named("gravity y", in_range(y, &(-MAX_GRAVITY..=MAX_GRAVITY)))
}

pub fn restitution(value: &f64) -> Result<(), String> {
    named("restitution", in_range(*value, &RESTITUTION_RANGE))
}

pub fn damping(value: &f64) -> Result<(), String> {
    named("linear_damping", in_range(*value, &DAMPING_RANGE))
}

pub fn arena_width(value: &f64) -> Result<(), String> {
    named("arena width", in_range(*value, &ARENA_SIDE_RANGE))
}

pub fn arena_height(value: &f64) -> Result<(), String> {
    named("arena height", in_range(*value, &ARENA_SIDE_RANGE))
}

pub fn radius(value: &f64) -> Result<(), String> {
    named("radius", in_range(*value, &RADIUS_RANGE))
}

pub fn position(&(x, y): &(f64, f64)) -> Result<(), String> {
    if x.is_finite() && y.is_finite() {
        Ok(())
    } else {
        Err(format!("position ({x}, {y}) is not finite"))
    }
}

pub fn velocity(&(x, y): &(f64, f64)) -> Result<(), String> {
    let speed = x.hypot(y);
    named("speed", in_range(speed, &(0.0..=MAX_SPEED)))
        .map_err(|error| format!("velocity ({x}, {y}): {error}"))
}

pub fn count(value: &usize) -> Result<(), String> {
    if *value <= MAX_BALLS {
        Ok(())
    } else {
        Err(format!("count {value} is over the limit of {MAX_BALLS}"))
    }
}

pub fn radius_range(pair: &(f64, f64)) -> Result<(), String> {
    named("radius", ordered(*pair, &RADIUS_RANGE))
}

pub fn speed_range(pair: &(f64, f64)) -> Result<(), String> {
    named("speed", ordered(*pair, &(0.0..=MAX_SPEED)))
}

pub fn area_fraction(value: &Option<f64>) -> Result<(), String> {
    match value {
        Some(fraction) => named(
            "area_fraction",
            in_range(*fraction, &(f64::MIN_POSITIVE..=DENSEST_PACKING)),
        ),
        None => Ok(()),
    }
}

/// Deserializers that apply [`check`] as each value is read, so a bad value is reported at
/// its line and column.
pub(super) mod checked {
    use serde::{Deserialize, Deserializer, de::Error};

    use super as check;

    fn read<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        deserializer: D,
        check: fn(&T) -> Result<(), String>,
    ) -> Result<T, D::Error> {
        let value = T::deserialize(deserializer)?;
        check(&value).map_err(D::Error::custom)?;
        Ok(value)
    }

    pub fn gravity<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::gravity)
    }
    pub fn restitution<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::restitution)
    }
    pub fn damping<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::damping)
    }
    pub fn arena_width<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::arena_width)
    }
    pub fn arena_height<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::arena_height)
    }
    pub fn position<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::position)
    }
    pub fn velocity<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::velocity)
    }
    pub fn radius<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::radius)
    }
    pub fn count<'de, D: Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
        read(d, check::count)
    }
    pub fn radius_range<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::radius_range)
    }
    pub fn speed_range<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::speed_range)
    }
    pub fn area_fraction<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        read(d, check::area_fraction)
    }
}
