//! The rest of each ball's path during a continuous step, as the circle it sweeps until the
//! step ends, kept in the grid in place of the ball's first circle, by slot (the grid's cell
//! order), so that a ball redirected by an impact finds every ball whose path may cross its
//! new one by reading the grid's cells around it: one pass over contiguous memory, whether
//! those balls flew straight or were redirected.
//!
//! A redirected ball stays in the cell of its first path; its new circle may reach further
//! from that cell, and [`Paths::reach`] grows to cover it. A path reaching too far (or a big
//! ball's, which has no cell) is kept apart in a short list instead.

use bevy::math::DVec2;

use crate::sim::geometry::Circle;
use crate::sim::geometry::circle::within_reach;
use crate::sim::geometry::grid::UniformGrid;

/// How far each ball's current path reaches, and the paths kept apart. The current paths of
/// the balls in cells are the grid's circles: each ball's first path's until an impact
/// redirects it; one that touches nothing while the ball's path is kept in `far`, or once it
/// takes no more impacts this step ([`end`](Self::end)).
#[derive(Debug, Default)]
pub struct Paths {
    /// How far, along either axis, a current circle reaches from its ball's cell: a query
    /// grown by this finds every circle it touches. It only grows during a step, at most to
    /// `far_limit`.
    reach: f64,
    /// A redirected circle reaching further than this goes to `far`.
    far_limit: f64,
    /// The paths kept apart: big balls' and far-reaching ones. Stale entries stay until the
    /// step ends (skipped by their hit count); a ball takes at most
    /// [`hit_limit`](super::state::hit_limit) paths a step, and few reach far.
    far: Vec<FarPath>,
}

#[derive(Clone, Copy, Debug)]
struct FarPath {
    slot: u32,
    /// The ball's hits when it took this path: the entry is current while they still are.
    hits: u32,
    swept: Circle,
}

/// A circle no other touches: the place of a path kept in `far`.
const NOWHERE: Circle = Circle {
    center: DVec2::splat(f64::NAN),
    radius: f64::NAN,
};

impl Paths {
    /// Every ball on its first path: the circles `grid` holds.
    pub fn reset(&mut self, grid: &UniformGrid) {
        self.reach = grid.small_reach();
        self.far_limit = grid.big_limit();
        self.far.clear();
    }

    /// How far, along either axis, any path so far reaches from its ball's cell.
    pub fn reach(&self) -> f64 {
        self.reach
    }

    /// Whether some path is kept apart (a big ball's or a far-reaching one).
    pub fn keeps_some_apart(&self) -> bool {
        !self.far.is_empty()
    }

    /// Ball `slot`, which now has `hits` hits, takes a new path that sweeps `swept`.
    pub fn redirect(&mut self, grid: &mut UniformGrid, slot: u32, hits: u32, swept: Circle) {
        let slot_index = slot as usize;
        if slot_index < grid.small_count() {
            let reach = grid.reach_from_cell(slot_index, swept);
            if reach <= self.far_limit {
                grid.replace_circle_in_slot(slot_index, swept);
                self.reach = self.reach.max(reach);
                return;
            }
            grid.replace_circle_in_slot(slot_index, NOWHERE);
        }
        self.far.push(FarPath { slot, hits, swept });
    }

    /// Ball `slot`'s current path is over: no path of it is found any more, until it takes a
    /// new one ([`redirect`](Self::redirect)) if it has hits left this step.
    pub fn end(&mut self, grid: &mut UniformGrid, slot: u32) {
        if (slot as usize) < grid.small_count() {
            grid.replace_circle_in_slot(slot as usize, NOWHERE);
        }
    }

    /// Calls `visit(slot)` for every ball whose current path's circle touches `swept`, once
    /// each. `hits_of(slot)` gives a ball's hits now.
    pub fn for_each_that_may_touch(
        &self,
        grid: &UniformGrid,
        swept: Circle,
        hits_of: impl Fn(u32) -> u32,
        mut visit: impl FnMut(u32),
    ) {
        self.for_each_that_may_touch_any(grid, [swept], hits_of, |_, slot| visit(slot));
    }

    /// [`for_each_that_may_touch`](Self::for_each_that_may_touch) for each of the circles
    /// `swept` in one pass over the cells around them all: calls `visit(k, slot)` for every
    /// ball whose current path's circle touches `swept[k]`.
    pub fn for_each_that_may_touch_any<const N: usize>(
        &self,
        grid: &UniformGrid,
        swept: [Circle; N],
        hits_of: impl Fn(u32) -> u32,
        mut visit: impl FnMut(usize, u32),
    ) {
        let box_of = |probe: &Circle| {
            let near = DVec2::splat(probe.radius + self.reach);
            (probe.center - near, probe.center + near)
        };
        let (min, max) = swept.iter().map(box_of).fold(
            (DVec2::INFINITY, DVec2::NEG_INFINITY),
            |(min, max), (low, high)| (min.min(low), max.max(high)),
        );
        let current = grid.circles_by_slot();
        let probes = Probes::new(&swept);
        grid.for_each_cell_run_in_box(min, max, |cells| {
            let slots = grid.slots_of(cells);
            let first = slots.start;
            for (offset, &circle) in current[slots].iter().enumerate() {
                probes.visit_touched_by(circle, (first + offset) as u32, &mut visit);
            }
        });
        // Big balls on their first path, through their own grid; then the paths kept apart.
        for (k, &probe) in swept.iter().enumerate() {
            grid.for_each_big_that_may_touch(probe, |slot, circle| {
                if within_reach(probe, circle) && hits_of(slot) == 0 {
                    visit(k, slot);
                }
            });
        }
        for path in &self.far {
            if hits_of(path.slot) == path.hits {
                probes.visit_touched_by(path.swept, path.slot, &mut visit);
            }
        }
    }
}

/// The circles a search looks around, coordinate by coordinate, so that a candidate is
/// tested against all of them at once: a collision's two new paths take one operation a
/// step of the test, each in one lane of the processor's two-double registers.
struct Probes<const N: usize> {
    x: [f64; N],
    y: [f64; N],
    radius: [f64; N],
}

impl<const N: usize> Probes<N> {
    fn new(swept: &[Circle; N]) -> Self {
        Self {
            x: swept.map(|probe| probe.center.x),
            y: swept.map(|probe| probe.center.y),
            radius: swept.map(|probe| probe.radius),
        }
    }

    /// Calls `visit(k, slot)` for each of the circles `swept[k]` that `circle`, the current
    /// path of the ball in `slot`, touches by [`within_reach`] (the same sums and products,
    /// so the same answer to the bit).
    #[inline]
    fn visit_touched_by(&self, circle: Circle, slot: u32, visit: &mut impl FnMut(usize, u32)) {
        let mut touched = 0_u32;
        for k in 0..N {
            let (dx, dy) = (circle.center.x - self.x[k], circle.center.y - self.y[k]);
            let reach = self.radius[k] + circle.radius;
            touched |= u32::from(dx * dx + dy * dy <= reach * reach) << k;
        }
        if touched != 0 {
            for k in 0..N {
                if touched >> k & 1 != 0 {
                    visit(k, slot);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slots whose current path touches `probe`, sorted.
    fn found(paths: &Paths, grid: &UniformGrid, probe: Circle, hits: &[u32]) -> Vec<u32> {
        let mut slots = Vec::new();
        paths.for_each_that_may_touch(
            grid,
            probe,
            |slot| hits[slot as usize],
            |slot| slots.push(slot),
        );
        slots.sort_unstable();
        slots
    }

    #[test]
    fn probes_find_what_within_reach_finds_to_the_bit() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let random_circle = |rng: &mut rand_chacha::ChaCha8Rng| {
            let center = DVec2::new(rng.random_range(-40.0..40.0), rng.random_range(-40.0..40.0));
            Circle::new(center, rng.random_range(0.5..20.0))
        };
        let (mut touching, mut edge) = (0, 0);
        for case in 0..20_000 {
            let swept = [random_circle(&mut rng), random_circle(&mut rng)];
            let mut circle = match case % 4 {
                0 => NOWHERE,
                _ => random_circle(&mut rng),
            };
            if case % 4 == 1 {
                // Exactly the sum of the radii apart along an axis: the test's very edge.
                circle.center = swept[1].center + DVec2::X * (swept[1].radius + circle.radius);
                edge += usize::from(within_reach(swept[1], circle));
            }
            let expected: Vec<(usize, u32)> = (0..2)
                .filter(|&k| within_reach(swept[k], circle))
                .map(|k| (k, 7))
                .collect();
            let mut visited = Vec::new();
            Probes::new(&swept).visit_touched_by(circle, 7, &mut |k, slot| visited.push((k, slot)));
            assert_eq!(visited, expected, "case {case}");
            let mut alone = Vec::new();
            Probes::new(&[swept[1]])
                .visit_touched_by(circle, 7, &mut |k, slot| alone.push((k, slot)));
            assert_eq!(
                alone.len(),
                usize::from(within_reach(swept[1], circle)),
                "case {case}"
            );
            touching += visited.len();
        }
        assert!(
            touching > 2_000 && edge > 1_000,
            "{touching} touching, {edge} at the edge"
        );
    }

    /// `circles` in a grid numbered by slot (with the slot order) and every ball on its first
    /// path.
    fn first_paths(circles: &[Circle]) -> (UniformGrid, Vec<u32>, Paths) {
        let mut grid = UniformGrid::default();
        grid.rebuild(circles);
        let mut order = Vec::new();
        grid.renumber_by_slot(&mut order);
        let mut paths = Paths::default();
        paths.reset(&grid);
        (grid, order, paths)
    }

    #[test]
    fn a_redirected_path_is_found_where_it_goes_not_where_it_was() {
        // 20 x 20 balls of radius 2, 10 px apart: the grid's limit for big is 8 px.
        let circles: Vec<Circle> = (0..400)
            .map(|k| Circle::new(DVec2::new((k % 20) as f64, (k / 20) as f64) * 10.0, 2.0))
            .collect();
        let (mut grid, order, mut paths) = first_paths(&circles);
        let slot_at = |center: DVec2| {
            let index = circles.iter().position(|c| c.center == center).unwrap();
            order.iter().position(|&k| k as usize == index).unwrap() as u32
        };
        let (near, far) = (
            slot_at(DVec2::new(50.0, 50.0)),
            slot_at(DVec2::new(100.0, 100.0)),
        );
        let mut hits = vec![0; 400];
        // One moves 4 px (it stays in reach), the other 60 px (kept apart).
        let (near_path, far_path) = (
            Circle::new(DVec2::new(54.0, 50.0), 3.0),
            Circle::new(DVec2::new(160.0, 100.0), 3.0),
        );
        hits[near as usize] = 1;
        paths.redirect(&mut grid, near, 1, near_path);
        hits[far as usize] = 1;
        paths.redirect(&mut grid, far, 1, far_path);
        assert_eq!(paths.far.len(), 1);
        // A probe beside the new paths finds them; one at the old place of the far one does not.
        let beside_near = Circle::new(DVec2::new(57.5, 50.0), 1.0);
        assert!(found(&paths, &grid, beside_near, &hits).contains(&near));
        let beside_far = Circle::new(DVec2::new(163.5, 100.0), 1.0);
        assert!(found(&paths, &grid, beside_far, &hits).contains(&far));
        let old_place = Circle::new(DVec2::new(100.0, 100.0), 1.0);
        assert!(!found(&paths, &grid, old_place, &hits).contains(&far));
        // Another hit makes the far entry stale; a ball taking no more impacts is found nowhere.
        hits[far as usize] = 2;
        assert!(!found(&paths, &grid, beside_far, &hits).contains(&far));
        paths.end(&mut grid, near);
        assert!(!found(&paths, &grid, beside_near, &hits).contains(&near));
    }

    #[test]
    fn a_big_ball_s_path_is_kept_apart_and_found_until_it_is_hit_again() {
        let circles = crate::sim::geometry::grid::mixed_sizes();
        let (mut grid, order, mut paths) = first_paths(&circles);
        // The ball of radius 200 is big: its slot lies past the cells'.
        let big = order
            .iter()
            .position(|&k| k as usize == circles.len() - 1)
            .unwrap() as u32;
        assert!(big as usize >= grid.small_count());
        let mut hits = vec![0; circles.len()];
        hits[big as usize] = 1;
        let moved = Circle::new(DVec2::new(260.0, 300.0), 205.0);
        paths.redirect(&mut grid, big, 1, moved);
        assert_eq!(paths.far.len(), 1);
        let beside = Circle::new(DVec2::new(260.0, 507.0), 3.0);
        assert!(found(&paths, &grid, beside, &hits).contains(&big));
        // Its first path is no longer found (it has been hit), nor, after another hit, this one.
        let first_only = Circle::new(DVec2::new(210.0, 55.0), 1.0);
        assert!(!found(&paths, &grid, first_only, &hits).contains(&big));
        hits[big as usize] = 2;
        paths.end(&mut grid, big);
        assert!(!found(&paths, &grid, beside, &hits).contains(&big));
    }
}
