//! The balls as a 2-D gas: a histogram of their speeds against the Maxwell–Boltzmann
//! distribution for their temperature. Pure functions over `(mass, speed)` pairs; the
//! headless report and the panel call them, nothing runs in a schedule.
//!
//! Units: temperature is the mean kinetic energy per ball (`k = 1`; two degrees of freedom,
//! so `<m v^2 / 2> = T`). A ball of mass `m` at temperature `T` then has speed density
//! `f(v) = (m v / T) exp(-m v^2 / 2T)` and `P(speed < v) = 1 - exp(-m v^2 / 2T)`. Balls of
//! different masses share the temperature, so the expected histogram is the mixture over
//! the balls' masses.

use serde::Serialize;

/// Bins in the report's and the panel's histogram.
pub const SPEED_BINS: usize = 40;
/// Mass groups the expected curve is averaged over: enough that a group's masses differ by
/// a fraction of a percent of the range, few enough to draw every frame at 100,000 balls.
const MASS_GROUPS: usize = 64;
/// The histogram reaches at least this many most-probable speeds of the lightest ball:
/// `exp(-3.5^2 / 2)`, 0.2% of those balls, lie beyond.
const TAIL_REACH: f64 = 3.5;

/// `P(speed < v)` for one ball of `mass` at `temperature` in 2-D.
#[inline]
pub fn maxwell_boltzmann_2d_cdf(speed: f64, mass: f64, temperature: f64) -> f64 {
    1.0 - (-mass * speed * speed / (2.0 * temperature)).exp()
}

/// The speed density `(m v / T) exp(-m v^2 / 2T)` for one ball of `mass` at `temperature`.
#[inline]
pub fn maxwell_boltzmann_2d(speed: f64, mass: f64, temperature: f64) -> f64 {
    let a = mass / temperature;
    a * speed * (-0.5 * a * speed * speed).exp()
}

/// Ball speeds in equal bins from zero, with the counts the Maxwell–Boltzmann distribution
/// expects at the balls' temperature.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SpeedHistogram {
    /// Pixels per second; bin `i` holds speeds in `[i, i + 1) * bin_width`.
    pub bin_width: f64,
    pub counts: Vec<u64>,
    /// Expected balls per bin at `temperature`.
    pub expected: Vec<f64>,
    /// Mean kinetic energy per ball.
    pub temperature: f64,
}

impl SpeedHistogram {
    /// Bins `balls`, given as `(mass, speed)`, into `bin_count` bins reaching past the
    /// fastest ball and far enough into the expected tail. Non-finite or non-positive values
    /// are skipped; no balls or no motion give an empty histogram.
    pub fn measure(balls: &[(f64, f64)], bin_count: usize) -> Self {
        let valid = || {
            balls
                .iter()
                .copied()
                .filter(|&(mass, speed)| mass.is_finite() && mass > 0.0 && speed.is_finite())
        };
        let (mut count, mut energy, mut fastest) = (0usize, 0.0, 0.0_f64);
        let (mut lightest, mut heaviest) = (f64::INFINITY, 0.0_f64);
        for (mass, speed) in valid() {
            count += 1;
            energy += 0.5 * mass * speed * speed;
            fastest = fastest.max(speed.abs());
            lightest = lightest.min(mass);
            heaviest = heaviest.max(mass);
        }
        if count == 0 || energy <= 0.0 || bin_count == 0 {
            return Self::default();
        }
        let temperature = energy / count as f64;
        let top = fastest.max(TAIL_REACH * (temperature / lightest).sqrt());
        let bin_width = top * (1.0 + 1e-9) / bin_count as f64;
        let mut counts = vec![0; bin_count];
        for (_, speed) in valid() {
            let bin = ((speed.abs() / bin_width) as usize).min(bin_count - 1);
            counts[bin] += 1;
        }
        // The mixture over masses, grouped: each group's ball count at its mean mass.
        let group_width = (heaviest - lightest) / MASS_GROUPS as f64;
        let mut groups = [(0.0_f64, 0.0_f64); MASS_GROUPS]; // (balls, mass sum)
        for (mass, _) in valid() {
            let group = if group_width > 0.0 {
                (((mass - lightest) / group_width) as usize).min(MASS_GROUPS - 1)
            } else {
                0
            };
            groups[group].0 += 1.0;
            groups[group].1 += mass;
        }
        let expected = (0..bin_count)
            .map(|bin| {
                let (low, high) = (bin as f64 * bin_width, (bin + 1) as f64 * bin_width);
                groups
                    .iter()
                    .filter(|(balls, _)| *balls > 0.0)
                    .map(|&(balls, mass_sum)| {
                        let mass = mass_sum / balls;
                        balls
                            * (maxwell_boltzmann_2d_cdf(high, mass, temperature)
                                - maxwell_boltzmann_2d_cdf(low, mass, temperature))
                    })
                    .sum()
            })
            .collect();
        Self {
            bin_width,
            counts,
            expected,
            temperature,
        }
    }

    /// Half the summed absolute difference between counts and expectation, over the ball
    /// count: 0 for a perfect match, 1 for no overlap at all (the total variation distance).
    pub fn distance_from_expected(&self) -> f64 {
        let total: u64 = self.counts.iter().sum();
        if total == 0 {
            return 0.0;
        }
        let difference: f64 = self
            .counts
            .iter()
            .zip(&self.expected)
            .map(|(&count, &expected)| (count as f64 - expected).abs())
            .sum();
        0.5 * difference / total as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_density_integrates_to_the_cdf_and_the_cdf_to_one() {
        let (mass, temperature) = (7.0, 3_500.0);
        let (mut integral, step) = (0.0, 0.01);
        let mut speed = 0.0;
        while speed < 400.0 {
            integral += maxwell_boltzmann_2d(speed + step / 2.0, mass, temperature) * step;
            speed += step;
        }
        let cdf = maxwell_boltzmann_2d_cdf(400.0, mass, temperature);
        assert!((integral - cdf).abs() < 1e-6, "{integral} vs {cdf}");
        assert!((cdf - 1.0).abs() < 1e-6);
        // Mean kinetic energy of the distribution is the temperature.
        let mut mean_energy = 0.0;
        let mut speed = 0.0;
        while speed < 400.0 {
            let v = speed + step / 2.0;
            mean_energy += 0.5 * mass * v * v * maxwell_boltzmann_2d(v, mass, temperature) * step;
            speed += step;
        }
        assert!((mean_energy - temperature).abs() < 1e-3 * temperature);
    }

    #[test]
    fn expected_counts_cover_every_ball_and_equal_speeds_sit_in_one_bin() {
        let balls: Vec<(f64, f64)> = (0..500).map(|i| (5.0 + (i % 11) as f64, 300.0)).collect();
        let histogram = SpeedHistogram::measure(&balls, SPEED_BINS);
        assert_eq!(histogram.counts.iter().sum::<u64>(), 500);
        assert_eq!(histogram.counts.iter().filter(|&&c| c > 0).count(), 1);
        let expected: f64 = histogram.expected.iter().sum();
        assert!((expected - 500.0).abs() < 2.0, "{expected}");
        assert!(histogram.distance_from_expected() > 0.5);
    }

    #[test]
    fn maxwellian_speeds_match_their_curve() {
        // Speeds at the quantiles of the distribution itself: the histogram follows it.
        let (mass, temperature, n) = (4.0, 10_000.0, 20_000);
        let balls: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let p = (i as f64 + 0.5) / n as f64;
                (mass, (-2.0 * temperature / mass * (1.0 - p).ln()).sqrt())
            })
            .collect();
        let histogram = SpeedHistogram::measure(&balls, SPEED_BINS);
        assert!((histogram.temperature - temperature).abs() < 0.01 * temperature);
        assert!(histogram.distance_from_expected() < 0.02);
    }

    #[test]
    fn no_balls_still_or_strange_values_give_an_empty_histogram() {
        assert_eq!(SpeedHistogram::measure(&[], 10), SpeedHistogram::default());
        assert_eq!(
            SpeedHistogram::measure(&[(1.0, 0.0), (2.0, 0.0)], 10),
            SpeedHistogram::default()
        );
        let histogram = SpeedHistogram::measure(&[(f64::NAN, 1.0), (1.0, f64::INFINITY)], 10);
        assert_eq!(histogram, SpeedHistogram::default());
    }
}
