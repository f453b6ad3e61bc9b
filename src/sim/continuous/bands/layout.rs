//! Where the bands' edges go: a survey of the balls (their largest and mean radius, how many
//! of every fourth start at each height; in pieces on the compute pool for many balls) and
//! edges that give every band about as many balls (on the calling thread).

use crate::sim::geometry::Circle;
use crate::sim::geometry::grid::Extent;
use crate::sim::parallel::{in_pieces, piece_ranges, worth_splitting};

/// The arena's height is cut into this many bins to place the bands' edges.
const BINS: usize = 1024;

/// What the bands' layout needs of the balls: the largest radius and the mean, and how many
/// of every [`BINNED_EVERY`]th ball start in each of [`BINS`] bins of the arena's height.
pub struct Survey {
    pub largest: f64,
    mean: f64,
    bins: Vec<usize>,
    /// Half the arena's height; the bins cover `[-half_height, half_height]`.
    half_height: f64,
}

impl Survey {
    /// The balls in `circles`, in the arena's height `[-half_height, half_height]`; in pieces
    /// on the compute pool for many balls.
    pub fn of(circles: &[Circle], half_height: f64) -> Self {
        let bins_per_px = 1.0 / bin_height(half_height);
        let bin_of = |y: f64| (((y + half_height) * bins_per_px).max(0.0) as usize).min(BINS - 1);
        let pieces = in_pieces(
            piece_ranges(circles.len()),
            worth_splitting(circles.len()),
            |balls| {
                let mut bins = vec![0usize; BINS];
                for circle in circles[balls.clone()].iter().step_by(BINNED_EVERY) {
                    bins[bin_of(circle.center.y)] += 1;
                }
                let radii = Extent::of(&circles[balls]);
                (radii.radius_sum, radii.largest_radius, bins)
            },
        );
        let mut survey = Survey {
            largest: 0.0,
            mean: 0.0,
            bins: vec![0; BINS],
            half_height,
        };
        for (sum, largest, bins) in pieces {
            survey.mean += sum;
            survey.largest = survey.largest.max(largest);
            survey
                .bins
                .iter_mut()
                .zip(bins)
                .for_each(|(total, count)| *total += count);
        }
        survey.mean /= circles.len().max(1) as f64;
        survey
    }

    /// Whether some ball may be big enough for the grid to keep it apart: a big ball's paths
    /// reach across bands.
    pub fn may_have_big_balls(&self) -> bool {
        self.largest > 2.0 * self.mean
    }

    /// The edges of `count` bands of about as many balls each over the arena's height, the
    /// outer ones open (`-inf`, `+inf`); `None` if some band would be no taller than `halo`.
    pub fn edges(&self, count: usize, halo: f64) -> Option<Vec<f64>> {
        if count < 2 {
            return None;
        }
        let (half_height, bin_height) = (self.half_height, bin_height(self.half_height));
        let balls: usize = self.bins.iter().sum();
        let mut edges = vec![f64::NEG_INFINITY];
        let mut below = 0;
        for (bin, &in_bin) in self.bins.iter().enumerate() {
            below += in_bin;
            let band = edges.len();
            if band < count && below * count >= band * balls {
                edges.push(-half_height + (bin + 1) as f64 * bin_height);
            }
        }
        if edges.len() != count {
            return None;
        }
        edges.push(f64::INFINITY);
        // Each band taller than the halo, so a halo reaches only into the bands beside it.
        let inner = &edges[1..count];
        let tall = inner.windows(2).all(|pair| pair[1] - pair[0] > halo)
            && inner[0] + half_height > halo
            && half_height - inner[inner.len() - 1] > halo;
        tall.then_some(edges)
    }
}

/// Only one ball in this many goes into the bins: the edges need the balls' spread, not every
/// ball. The survey is a pass over every ball on the calling thread's share of the step, and
/// binning them all took most of it (100,000 balls on two threads: 0.23 ms, 0.14 with every
/// fourth and the radii in four lanes, [`Extent::of`]).
const BINNED_EVERY: usize = 4;

/// The height of each of [`BINS`] bins over `[-half_height, half_height]`.
fn bin_height(half_height: f64) -> f64 {
    2.0 * half_height / BINS as f64
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;

    use super::*;

    #[test]
    fn edges_share_the_balls_out_evenly_and_keep_each_band_taller_than_the_halo() {
        // 10,000 balls evenly over a height of 1,000 px, and 3,000 more in its top tenth.
        let even = (0..10_000).map(|k| -500.0 + k as f64 * 0.1);
        let crowded = (0..3_000).map(|k| 400.0 + k as f64 / 30.0);
        let circles: Vec<Circle> = even
            .chain(crowded)
            .map(|y| Circle::new(DVec2::new(0.0, y), 2.0))
            .collect();
        let survey = Survey::of(&circles, 500.0);
        assert_eq!((survey.largest, survey.may_have_big_balls()), (2.0, false));
        let edges = survey.edges(4, 50.0).unwrap();
        assert_eq!(edges.len(), 5);
        assert_eq!((edges[0], edges[4]), (f64::NEG_INFINITY, f64::INFINITY));
        for band in edges.windows(2) {
            let inside = circles
                .iter()
                .filter(|c| (band[0]..band[1]).contains(&c.center.y));
            let share = inside.count() as f64 / circles.len() as f64;
            assert!((share - 0.25).abs() < 0.01, "{band:?}: {share}");
        }
        // The top band is the crowded tenth, too thin for a halo of 100 px.
        assert!(edges[3] > 400.0);
        assert_eq!(survey.edges(4, 100.0), None);
    }
}
