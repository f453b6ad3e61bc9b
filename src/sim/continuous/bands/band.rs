//! One band of the step: its balls (own and halo) gathered from the step's arrays, its
//! timeline run (each on one thread of the compute pool, not split within), and the check,
//! on the calling thread, that two bands ended their shared balls alike.

use bevy::math::DVec2;

use crate::sim::continuous::state::{StepSpec, Timeline};
use crate::sim::geometry::Circle;
use crate::sim::report::Hit;

/// One band: its own balls start at `low <= y < high`.
#[derive(Debug, Default)]
pub(super) struct Band {
    pub(super) low: f64,
    pub(super) high: f64,
    pub(super) timeline: Timeline,
    /// Its balls (own and halo) by their index in the step's input, in increasing order, so
    /// ties between impacts fall as they do in the single timeline.
    pub(super) balls: Vec<u32>,
    pub(super) own: Vec<bool>,
    pub(super) own_count: usize,
    pub(super) circles: Vec<Circle>,
    pub(super) velocities: Vec<DVec2>,
    pub(super) held: Vec<bool>,
    pub(super) stopped: Vec<bool>,
    /// How many hits each of its balls took.
    pub(super) hit_counts: Vec<u32>,
    /// The hits whose first ball (the lower index, or the one at a wall) is its own, by
    /// input index.
    pub(super) hits: Vec<Hit>,
    /// Its own balls' ball hits, when only counted.
    pub(super) ball_hits_counted: u64,
}

impl Band {
    /// Its balls, own and halo (a halo `halo` px wide on each side), gathered from the step's
    /// arrays, and their impacts predicted.
    pub(super) fn predict(
        &mut self,
        (circles, velocities, held): (&[Circle], &[DVec2], &[bool]),
        halo: f64,
        spec: StepSpec,
    ) {
        self.gather(circles, velocities, held, halo);
        self.timeline
            .predict(&self.circles, &self.velocities, &self.held, spec);
    }

    /// Its balls, own and halo, from the step's arrays.
    fn gather(&mut self, circles: &[Circle], velocities: &[DVec2], held: &[bool], halo: f64) {
        let (low, high) = (self.low, self.high);
        self.balls.clear();
        self.own.clear();
        self.own_count = 0;
        for (index, circle) in circles.iter().enumerate() {
            let y = circle.center.y;
            if y >= low - halo && y < high + halo {
                let own = y >= low && y < high;
                self.balls.push(index as u32);
                self.own.push(own);
                self.own_count += usize::from(own);
            }
        }
        let balls = &self.balls;
        self.circles.clear();
        self.circles
            .extend(balls.iter().map(|&index| circles[index as usize]));
        self.velocities.clear();
        self.velocities
            .extend(balls.iter().map(|&index| velocities[index as usize]));
        self.held.clear();
        self.held
            .extend(balls.iter().map(|&index| held[index as usize]));
    }

    /// Its impacts, each of its own balls' hits kept (ball hits only counted unless
    /// `keep_ball_hits`).
    pub(super) fn run(&mut self, spec: StepSpec, keep_ball_hits: bool) {
        self.stopped.clear();
        self.stopped.resize(self.balls.len(), false);
        self.hits.clear();
        self.ball_hits_counted = 0;
        let (balls, own) = (&self.balls, &self.own);
        let (hits, counted) = (&mut self.hits, &mut self.ball_hits_counted);
        let mut record = |hit: Hit| {
            let (first, is_ball_hit) = match hit {
                Hit::Ball { a, .. } => (a, true),
                Hit::Wall { ball, .. } => (ball, false),
            };
            if !own[first as usize] {
                return; // the band that owns it records it
            }
            if is_ball_hit && !keep_ball_hits {
                *counted += 1;
            } else {
                hits.push(hit.renumbered(|local| balls[local as usize]));
            }
        };
        let arrays = (&mut self.held[..], &mut self.stopped[..]);
        self.timeline.run_impacts(
            &mut self.circles,
            &mut self.velocities,
            arrays,
            spec,
            &mut record,
        );
        self.timeline.hits_by_index(&mut self.hit_counts);
    }
}

/// Whether `below` and `above` ended the step alike, to the bit, for every ball of both
/// whose index is `near`.
pub(super) fn alike_where(below: &Band, above: &Band, near: impl Fn(u32) -> bool) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < below.balls.len() && j < above.balls.len() {
        let (index_below, index_above) = (below.balls[i], above.balls[j]);
        if index_below < index_above {
            i += 1;
        } else if index_above < index_below {
            j += 1;
        } else {
            if near(index_below) && !same_end(below, i, above, j) {
                return false;
            }
            i += 1;
            j += 1;
        }
    }
    true
}

/// Whether ball `i` of `one` and ball `j` of `other` took as many hits and ended the step
/// alike, to the bit.
fn same_end(one: &Band, i: usize, other: &Band, j: usize) -> bool {
    let bits = |v: DVec2| (v.x.to_bits(), v.y.to_bits());
    one.hit_counts[i] == other.hit_counts[j]
        && bits(one.circles[i].center) == bits(other.circles[j].center)
        && bits(one.velocities[i]) == bits(other.velocities[j])
        && one.held[i] == other.held[j]
        && one.stopped[i] == other.stopped[j]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_bands_are_alike_only_if_every_ball_near_their_edge_ended_alike_to_the_bit() {
        let band = |balls: Vec<u32>, x: &[f64], vx: &[f64]| Band {
            balls,
            circles: x
                .iter()
                .map(|&x| Circle::new(DVec2::new(x, 0.0), 1.0))
                .collect(),
            velocities: vx.iter().map(|&vx| DVec2::new(vx, 0.0)).collect(),
            held: vec![false; x.len()],
            stopped: vec![false; x.len()],
            hit_counts: vec![1; x.len()],
            ..Band::default()
        };
        // Balls 2 and 4 are in both; 4 ended elsewhere, 2 with -0 for 0 px/s.
        let below = band(
            vec![1, 2, 4, 7],
            &[1.0, 2.0, 4.0, 7.0],
            &[0.0, 0.0, 1.0, 0.0],
        );
        let above = band(
            vec![2, 3, 4, 9],
            &[2.0, 3.0, 4.5, 9.0],
            &[-0.0, 0.0, 1.0, 0.0],
        );
        assert!(alike_where(&below, &above, |index| index == 3 || index == 7));
        assert!(!alike_where(&below, &above, |index| index == 4));
        assert!(!alike_where(&below, &above, |index| index == 2));
        let mut same_ends = band(vec![2, 4], &[2.0, 4.0], &[0.0, 1.0]);
        assert!(alike_where(&below, &same_ends, |_| true));
        same_ends.hit_counts[0] = 2;
        assert!(!alike_where(&below, &same_ends, |_| true));
        same_ends.hit_counts[0] = 1;
        same_ends.stopped[1] = true;
        assert!(!alike_where(&below, &same_ends, |_| true));
    }
}
