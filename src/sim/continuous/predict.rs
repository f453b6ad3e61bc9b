//! Stage 2, continuous: predicting impacts. At the start of the step the circles swept along
//! each ball's straight path go into the grid; their AABBs and distances cut the candidate
//! pairs, and the exact time of impact gives each approaching pair's moment of contact within
//! the step, and each ball's first wall contact. During the timeline, a ball redirected by an
//! impact is predicted for again against the balls near the rest of its path.

use std::cmp::Reverse;

use bevy::math::DVec2;

use super::impact::{Impact, Prediction, approach_time, swept_circle};
use super::state::{MAX_HITS_PER_BALL, StepSpec, Timeline};
use crate::sim::geometry::circle::{Circle, circles_touch, overlapping};
use crate::sim::geometry::pairs::search_in_bands;
use crate::sim::geometry::wall::wall_time_of_impact;

/// Pixels added to a redirected ball's swept circle, so rounding can never make the swept
/// circles' test reject a pair that touches at the very edge of the step.
const SWEPT_MARGIN: f64 = 1e-6;

impl Timeline {
    /// The collision stage's part: every impact of the coming step that the balls' current
    /// paths lead to. `circles` are the balls at the start of the step, `velocities` their
    /// velocities for the whole step.
    pub fn predict(&mut self, circles: &[Circle], velocities: &[DVec2], spec: StepSpec) {
        let dt = spec.dt;
        self.swept.clear();
        self.swept.extend(
            circles
                .iter()
                .zip(velocities)
                .map(|(circle, velocity)| swept_circle(*circle, *velocity, spec.gravity, dt)),
        );
        self.grid_reach = self.swept.iter().map(|s| s.radius).fold(0.0, f64::max);
        self.grid.rebuild(&self.swept);
        self.predictions.clear();
        search_in_bands(&self.grid, &mut self.predictions, |grid, rows, found| {
            grid.for_each_candidate_pair_in_rows(rows, |i, j, swept_i, swept_j| {
                // The swept circles bound the paths: if they do not touch, the balls cannot.
                if !circles_touch(swept_i, swept_j) {
                    return;
                }
                let (a, b) = (i.min(j), i.max(j));
                let (ca, cb) = (circles[a as usize], circles[b as usize]);
                let (va, vb) = (velocities[a as usize], velocities[b as usize]);
                if overlapping(ca, cb) {
                    found.push(Prediction::Overlap(a, b));
                }
                if let Some(time) = approach_time(ca, va, cb, vb).filter(|&t| t <= dt) {
                    let impact = Impact::between(time, (a as usize, 0), (b as usize, 0));
                    found.push(Prediction::Impact(impact));
                }
            });
        });
        for (index, (circle, velocity)) in circles.iter().zip(velocities).enumerate() {
            if let Some((time, wall)) = wall_time_of_impact(
                circle.center,
                *velocity,
                circle.radius,
                spec.half,
                spec.gravity,
            ) && time <= dt
            {
                let impact = Impact::with_wall(time, index, 0, wall);
                self.predictions.push(Prediction::Impact(impact));
            }
        }
    }

    /// Queues ball `index`'s next wall and ball impacts after its velocity changed at `now`.
    pub(super) fn predict_for(&mut self, index: usize, now: f64, spec: StepSpec) {
        let mover = self.movers[index];
        if mover.hits == MAX_HITS_PER_BALL {
            // No more impacts for this ball this step: the end-of-step fallback takes over.
            self.cut_short = true;
            return;
        }
        let (circle, velocity) = (mover.circle(), mover.velocity);
        let queue = &mut self.queue;
        if let Some((time, wall)) = wall_time_of_impact(
            circle.center,
            velocity,
            circle.radius,
            spec.half,
            spec.gravity,
        ) && now + time <= spec.dt
        {
            queue.push(Reverse(Impact::with_wall(
                now + time,
                index,
                mover.hits,
                wall,
            )));
        }
        let rest = spec.dt - now;
        let mut swept = swept_circle(circle, velocity, spec.gravity, rest);
        swept.radius += SWEPT_MARGIN;
        self.rerouted.insert(
            self.grid.cell_index(swept.center),
            index as u32,
            mover.hits,
            swept,
        );
        let movers = &self.movers;
        let mut consider = |other: u32| {
            let other_index = other as usize;
            if other_index == index {
                return;
            }
            let other_mover = &movers[other_index];
            let other_circle =
                Circle::new(other_mover.center_at(now, spec.gravity), other_mover.radius);
            let other_velocity = other_mover.velocity_at(now, spec.gravity);
            let Some(time) = approach_time(circle, velocity, other_circle, other_velocity)
                .map(|t| now + t)
                .filter(|&t| t <= spec.dt)
            else {
                return;
            };
            queue.push(Reverse(Impact::between(
                time,
                (index, mover.hits),
                (other_index, other_mover.hits),
            )));
        };
        // Balls on their first path of the step are filed in the grid by the circle that path
        // sweeps; the ones that changed course since, in `rerouted`. Both filters are the
        // swept circles: if they do not touch, neither can the balls.
        let near = DVec2::splat(swept.radius + self.grid_reach);
        self.grid.for_each_near(
            swept.center - near,
            swept.center + near,
            |other, other_swept| {
                if movers[other as usize].hits == 0 && circles_touch(swept, other_swept) {
                    consider(other);
                }
            },
        );
        let near = DVec2::splat(swept.radius + self.rerouted.reach);
        let rerouted = &self.rerouted;
        self.grid
            .for_each_cell_run_in_box(swept.center - near, swept.center + near, |cells| {
                let hits_of = |ball: u32| movers[ball as usize].hits;
                rerouted.for_each_in_cells(cells, hits_of, |other, other_swept| {
                    if circles_touch(swept, other_swept) {
                        consider(other);
                    }
                });
            });
    }
}
