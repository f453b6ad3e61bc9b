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
    /// Its balls within a halo of its lower edge, and of its upper edge, by their place in
    /// `balls`: those it shares with the band below, and with the band above. Two bands
    /// that meet at an edge take the same balls around it, in the same order (by index).
    pub(super) shared_below: Vec<u32>,
    pub(super) shared_above: Vec<u32>,
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

    /// Its balls, own and halo, from the step's arrays, and which of them are shared with
    /// the band below and the band above.
    fn gather(&mut self, circles: &[Circle], velocities: &[DVec2], held: &[bool], halo: f64) {
        let (low, high) = (self.low, self.high);
        self.balls.clear();
        self.own.clear();
        self.own_count = 0;
        self.shared_below.clear();
        self.shared_above.clear();
        for (index, circle) in circles.iter().enumerate() {
            let y = circle.center.y;
            if y >= low - halo && y < high + halo {
                let (own, place) = (y >= low && y < high, self.balls.len() as u32);
                if y < low + halo {
                    self.shared_below.push(place);
                }
                if y >= high - halo {
                    self.shared_above.push(place);
                }
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
/// whose index is `near`: the balls around the edge they meet at, which both hold.
pub(super) fn alike_where(below: &Band, above: &Band, near: impl Fn(u32) -> bool) -> bool {
    below.shared_above.len() == above.shared_below.len()
        && below
            .shared_above
            .iter()
            .zip(&above.shared_below)
            .all(|(&i, &j)| {
                let (i, j) = (i as usize, j as usize);
                let index = below.balls[i];
                index == above.balls[j] && (!near(index) || same_end(below, i, above, j))
            })
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
        // `shared`: the places of the balls the band shares with its neighbour.
        let band = |balls: Vec<u32>, shared: Vec<u32>, x: &[f64], vx: &[f64]| Band {
            balls,
            shared_below: shared.clone(),
            shared_above: shared,
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
            vec![1, 2],
            &[1.0, 2.0, 4.0, 7.0],
            &[0.0, 0.0, 1.0, 0.0],
        );
        let above = band(
            vec![2, 3, 4, 9],
            vec![0, 2],
            &[2.0, 3.0, 4.5, 9.0],
            &[-0.0, 0.0, 1.0, 0.0],
        );
        assert!(alike_where(&below, &above, |index| index == 3 || index == 7));
        assert!(!alike_where(&below, &above, |index| index == 4));
        assert!(!alike_where(&below, &above, |index| index == 2));
        let mut same_ends = band(vec![2, 4], vec![0, 1], &[2.0, 4.0], &[0.0, 1.0]);
        assert!(alike_where(&below, &same_ends, |_| true));
        same_ends.hit_counts[0] = 2;
        assert!(!alike_where(&below, &same_ends, |_| true));
        same_ends.hit_counts[0] = 1;
        same_ends.stopped[1] = true;
        assert!(!alike_where(&below, &same_ends, |_| true));
        // Shared lists that do not name the same balls, or as many, are never alike.
        same_ends.stopped[1] = false;
        assert!(alike_where(&below, &same_ends, |_| true));
        same_ends.shared_below = vec![1, 0];
        assert!(!alike_where(&below, &same_ends, |_| false));
        same_ends.shared_below = vec![0];
        assert!(!alike_where(&below, &same_ends, |_| false));
    }

    #[test]
    fn two_bands_gather_the_balls_around_their_edge_alike_and_only_those_in_both() {
        // Balls on a line up the arena, some on an edge or a halo's edge exactly, a NaN among
        // them; the middle band is shorter than two halos, so some balls are in all three.
        let ys = (0..400)
            .map(|k| -100.0 + 0.5 * k as f64)
            .chain([0.0, 30.0, 10.0, f64::NAN]);
        let circles: Vec<Circle> = ys.map(|y| Circle::new(DVec2::new(0.0, y), 1.0)).collect();
        let velocities = vec![DVec2::ZERO; circles.len()];
        let held = vec![false; circles.len()];
        let edges = [f64::NEG_INFINITY, 0.0, 30.0, f64::INFINITY];
        let halo = 20.0;
        let bands: Vec<Band> = edges
            .windows(2)
            .map(|edge| {
                let mut band = Band {
                    low: edge[0],
                    high: edge[1],
                    ..Band::default()
                };
                band.gather(&circles, &velocities, &held, halo);
                band
            })
            .collect();
        let owned: usize = bands.iter().map(|band| band.own_count).sum();
        assert_eq!(
            owned,
            circles.len() - 1,
            "every ball but the NaN owned once"
        );
        let names = |band: &Band, places: &[u32]| -> Vec<u32> {
            places.iter().map(|&at| band.balls[at as usize]).collect()
        };
        for pair in bands.windows(2) {
            let (below, above) = (&pair[0], &pair[1]);
            let shared = names(below, &below.shared_above);
            assert_eq!(shared, names(above, &above.shared_below));
            let in_both: Vec<u32> = below
                .balls
                .iter()
                .copied()
                .filter(|index| above.balls.contains(index))
                .collect();
            assert_eq!(shared, in_both);
            assert!(shared.len() > 70, "{} shared", shared.len());
        }
        for band in &bands {
            for (place, &index) in band.balls.iter().enumerate() {
                let y = circles[index as usize].center.y;
                assert_eq!(band.circles[place].center.y.to_bits(), y.to_bits());
                assert_eq!(band.own[place], y >= band.low && y < band.high, "{y}");
            }
        }
    }
}
