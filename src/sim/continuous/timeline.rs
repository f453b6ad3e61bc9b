//! Stage 3, continuous: the step as a timeline. Take the earliest predicted impact, move just
//! its balls to that moment, exchange momentum along the line of centres (or bounce off the
//! wall), predict anew for those balls, and repeat until the step is over; then move every
//! ball to the end of the step.
//!
//! [`Timeline::run`] reads as those steps. Balls move lazily: each `Mover` remembers where it
//! was at the moment of its last hit. An impact remembers how many hits each of its balls had
//! when it was predicted; if either has been hit since, the prediction is stale and skipped.
//!
//! The resting rule: an impact closing slower than the resting speed does not bounce. A ball
//! stopping against a wall slides along it, gravity's push into the wall taken away (the
//! wall carries it: the impulse counts towards the pressure, not as a hit); one stopping on a
//! ball that holds still holds still itself until the step ends; two flying balls meeting
//! that slowly move on together (restitution 0). None of these is a hit.

use bevy::math::DVec2;

use super::impact::{Impact, Prediction};
use super::state::{Mover, StepSpec, Timeline};
use crate::sim::geometry::circle::{Circle, circle_contact, collision_point, contact_normal};
use crate::sim::geometry::contain::{contain_all, lies_inside};
use crate::sim::geometry::impulse::{normal_exchange, resolve_overlaps, separate};
use crate::sim::geometry::pairs::find_contacts;
use crate::sim::geometry::wall::{Wall, bounce_off_wall};
use crate::sim::parallel::{BALLS_PER_PIECE, in_pieces, worth_splitting};
use crate::sim::params::BroadPhase;
use crate::sim::report::{Hit, record_walls_met};

impl Timeline {
    /// The response stage's part: handles the predicted impacts in time order, predicting
    /// anew for every ball hit, then moves every ball to the end of the step. `circles`,
    /// `velocities` and `held` must be what [`predict`](Self::predict) was given; they are
    /// updated in place (a held ball a hit sets flying is no longer held), and `stopped`
    /// says which balls stopped against a held one. Calls `on_hit` for each hit, in the
    /// order handled.
    pub fn run(
        &mut self,
        circles: &mut [Circle],
        velocities: &mut [DVec2],
        (held, stopped): (&mut [bool], &mut [bool]),
        spec: StepSpec,
        mut on_hit: impl FnMut(Hit),
    ) {
        self.run_impacts(circles, velocities, (held, stopped), spec, &mut on_hit);
        if self.cut_short {
            self.resolve_what_was_cut_short(circles, velocities, held, spec, &mut on_hit);
        }
        self.push_apart_overlaps(circles, held, spec);
        // Every ball inside, and none moved since: the walls have nothing to do.
        if !self.ends_inside || self.cut_short || !self.overlapping.is_empty() {
            self.resting_wall_impulse += contain_at_the_end(circles, velocities, spec, &mut on_hit);
        }
    }

    /// The impacts in time order, then every ball to the end of the step: [`run`](Self::run)
    /// but the fallback for balls cut short, the overlaps and the walls at the end.
    pub(super) fn run_impacts(
        &mut self,
        circles: &mut [Circle],
        velocities: &mut [DVec2],
        (held, stopped): (&mut [bool], &mut [bool]),
        spec: StepSpec,
        on_hit: &mut impl FnMut(Hit),
    ) {
        self.start(spec.dt);
        let mut last = None;
        let prefetching = self.worth_prefetching();
        while let Some(impact) = self.take_next(prefetching, spec.dt) {
            if !self.is_current(&impact, spec.hit_limit) {
                continue;
            }
            // An impact predicted for the very moment of the one that redirected its ball can
            // come before that one in the impacts' order.
            self.out_of_order |= last.is_some_and(|last| impact < last);
            last = Some(impact);
            match impact.wall() {
                Some(wall) => self.bounce_off(impact, wall, spec, on_hit),
                None => self.collide(impact, spec, on_hit),
            }
        }
        self.move_to_the_end(circles, velocities, (held, stopped), spec);
    }

    /// The next impact to handle, the earliest left, loading ahead what the coming ones will
    /// read if `prefetching`. The last collision's finds are timed only here
    /// (`time_what_was_found`), once the next impact has been taken and its loads started,
    /// so that their movers have had longer to arrive; should one of them come first, the
    /// one taken goes back. The impacts' order is total, so the queue gives what it would
    /// have given with them timed at once.
    fn take_next(&mut self, prefetching: bool, end: f64) -> Option<Impact> {
        loop {
            let taken = self.queue.pop();
            if prefetching {
                self.prefetch_coming();
            }
            if self.untimed.is_none() {
                return taken;
            }
            self.time_what_was_found(end);
            match taken {
                Some(impact) if self.queue.has_before(&impact) => self.queue.put_back(impact),
                None => {}
                Some(impact) => return Some(impact),
            }
        }
    }

    /// The end of a step whose impacts ran in bands that held ([`Bands`](super::bands::Bands)):
    /// no band's balls overlapped at the start or were cut short, so only the walls are left,
    /// as [`run`](Self::run) ends, and not even the walls if every band's balls ended inside.
    pub(super) fn finish_after_bands(
        &mut self,
        (circles, velocities): (&mut [Circle], &mut [DVec2]),
        ends_inside: bool,
        spec: StepSpec,
        mut on_hit: impl FnMut(Hit),
    ) {
        self.overlapping.clear();
        self.cut_short = false;
        self.resting_wall_impulse = if ends_inside {
            0.0
        } else {
            contain_at_the_end(circles, velocities, spec, &mut on_hit)
        };
    }

    /// Every ball at the start of the step (placed by [`predict`](Self::predict)), no hits
    /// yet; the predictions queued. `dt` is the step's length.
    pub(super) fn start(&mut self, dt: f64) {
        self.paths.reset(&self.grid);
        (self.first_loaded, self.later_loaded) = (None, None);
        self.queue.start(
            self.predictions
                .iter()
                .filter_map(|prediction| match *prediction {
                    Prediction::Impact(impact) => Some(impact),
                    Prediction::Overlap(..) => None,
                }),
            dt,
        );
        self.overlapping.clear();
        for prediction in &self.predictions {
            if let Prediction::Overlap(a, b) = *prediction {
                let (a, b) = (self.order[a as usize], self.order[b as usize]);
                self.overlapping.push((a.min(b), a.max(b)));
            }
        }
        self.cut_short = false;
        self.out_of_order = false;
        self.resting_wall_impulse = 0.0;
    }

    /// Whether `impact` still holds: neither ball has been hit since it was predicted, and
    /// neither has used up its `hit_limit` hits for the step (which cuts the step short).
    fn is_current(&mut self, impact: &Impact, hit_limit: u32) -> bool {
        if !self.still_holds(impact) {
            return false; // stale: a ball in it has been hit since
        }
        // Its balls' hits are still the ones it names (a wall's are 0).
        if impact.hits_a == hit_limit || impact.hits_other == hit_limit {
            self.cut_short = true;
            return false;
        }
        true
    }

    /// Whether neither ball of `impact` has been hit since it was predicted: one that has is
    /// stale, skipped when taken ([`is_current`](Self::is_current)), and the loads ahead
    /// skip what its search would read (`prefetch.rs`).
    pub(super) fn still_holds(&self, impact: &Impact) -> bool {
        let hits = |slot: u32| self.movers.get(slot as usize).map(|mover| mover.hits);
        hits(impact.a) == Some(impact.hits_a)
            && (impact.wall().is_some() || hits(impact.other) == Some(impact.hits_other))
    }

    /// Ball `impact.a` reaches `wall`: it bounces if it still moves into it, or stops
    /// against it if slower than the resting speed.
    fn bounce_off(
        &mut self,
        impact: Impact,
        wall: Wall,
        spec: StepSpec,
        on_hit: &mut impl FnMut(Hit),
    ) {
        let (a, now) = (impact.a as usize, impact.time);
        let mover = &mut self.movers[a];
        mover.advance(now);
        let mass = spec.mass_model.mass(mover.radius);
        if mover.velocity.dot(wall.outward_normal()) < spec.rest_speed {
            if let Some(impulse) = stop_against_wall(mover, wall, spec, now) {
                self.resting_wall_impulse += mass * impulse;
                mover.hits += 1;
                self.predict_for(a, now, spec);
            }
            return;
        }
        let Some(bounce) = bounce_off_wall(
            mover.circle(),
            &mut mover.velocity,
            wall,
            spec.half,
            spec.restitution,
            mass,
        ) else {
            return;
        };
        mover.center = bounce.center;
        mover.accel = spec.gravity;
        mover.hits += 1;
        on_hit(Hit::Wall {
            ball: impact.indices.0,
            wall,
            time: now,
            point: bounce.point,
            impulse: bounce.impulse,
            normal_speed: bounce.normal_speed,
        });
        self.predict_for(a, now, spec);
    }

    /// Balls `impact.a` and `impact.other` meet: they exchange momentum along the line of
    /// centres if they still approach, or come to rest on each other if slower than the
    /// resting speed.
    fn collide(&mut self, impact: Impact, spec: StepSpec, on_hit: &mut impl FnMut(Hit)) {
        // `a` is the one of lower index in the step's input, whatever their slots.
        let (a, b, now) = (impact.a as usize, impact.other as usize, impact.time);
        self.movers[a].advance(now);
        self.movers[b].advance(now);
        let (ma, mb) = (self.movers[a], self.movers[b]);
        let offset = mb.center - ma.center;
        let normal = contact_normal(offset, offset.length());
        let (velocity_a, velocity_b) = (ma.moving_velocity(), mb.moving_velocity());
        if (velocity_a - velocity_b).dot(normal) < spec.rest_speed {
            self.come_to_rest(a, b, normal, now, spec);
            return;
        }
        if spec.rest_speed > 0.0 && ma.is_still() != mb.is_still() {
            self.stop_for_the_solver(if ma.is_still() { b } else { a }, now, spec);
            return;
        }
        let Some(exchange) = normal_exchange(
            velocity_a,
            velocity_b,
            spec.mass_model.inverse_mass(ma.radius),
            spec.mass_model.inverse_mass(mb.radius),
            normal,
            spec.restitution,
        ) else {
            return;
        };
        self.movers[a].fly(exchange.velocity_a, spec.gravity);
        self.movers[b].fly(exchange.velocity_b, spec.gravity);
        self.movers[a].hits += 1;
        self.movers[b].hits += 1;
        on_hit(Hit::Ball {
            a: impact.indices.0,
            b: impact.indices.1,
            time: now,
            point: collision_point(ma.circle(), mb.circle()),
            normal,
            impulse: exchange.impulse,
            closing_speed: exchange.closing_speed,
        });
        self.predict_for_both((a, b), now, spec);
    }

    /// Balls `a` and `b` meet slower than the resting speed (`normal` from `a` to `b`): a
    /// ball meeting one that holds still stops on it and holds still too; two moving balls
    /// lose their closing speed (restitution 0) and fly on.
    fn come_to_rest(&mut self, a: usize, b: usize, normal: DVec2, now: f64, spec: StepSpec) {
        let (ma, mb) = (self.movers[a], self.movers[b]);
        match (ma.is_still(), mb.is_still()) {
            (true, true) => {}
            (false, true) => self.stop_on_support(a, normal, now, spec),
            (true, false) => self.stop_on_support(b, -normal, now, spec),
            (false, false) => {
                let Some(exchange) = normal_exchange(
                    ma.velocity,
                    mb.velocity,
                    spec.mass_model.inverse_mass(ma.radius),
                    spec.mass_model.inverse_mass(mb.radius),
                    normal,
                    0.0,
                ) else {
                    return;
                };
                self.movers[a].velocity = exchange.velocity_a;
                self.movers[b].velocity = exchange.velocity_b;
                self.movers[a].hits += 1;
                self.movers[b].hits += 1;
                self.predict_for(a, now, spec);
                self.predict_for(b, now, spec);
            }
        }
    }

    /// The flying ball in `slot` meets a still one faster than the resting speed: the still one
    /// rests in a pile the contact solver holds, where an impact is a simultaneous problem
    /// (every contact of the pile at once, as Box2D solves it), not a chain of pairwise
    /// exchanges. So the flying ball stops at the contact, keeping its velocity, and joins
    /// the solver at the next step, whose restitution pass bounces it off the pile.
    fn stop_for_the_solver(&mut self, slot: usize, now: f64, spec: StepSpec) {
        let mover = &mut self.movers[slot];
        mover.hold_still();
        mover.hits += 1;
        self.predict_for(slot, now, spec);
    }

    /// The ball in `slot` stops on a support that holds still (towards `into`, unit): it keeps only
    /// its velocity along the support's surface, for the end of the step, and holds still.
    fn stop_on_support(&mut self, slot: usize, into: DVec2, now: f64, spec: StepSpec) {
        let mover = &mut self.movers[slot];
        mover.velocity -= into * mover.velocity.dot(into).max(0.0);
        mover.hold_still();
        mover.hits += 1;
        self.predict_for(slot, now, spec);
    }

    /// Every ball where the end of the step finds it. A held ball stays held if nothing hit
    /// it; a ball still now that was not held all along stopped against a held one. With none
    /// held (a gas), only the balls still now have their flags written, `stopped` cleared first.
    fn move_to_the_end(
        &mut self,
        circles: &mut [Circle],
        velocities: &mut [DVec2],
        (held, stopped): (&mut [bool], &mut [bool]),
        spec: StepSpec,
    ) {
        // On more than one thread the movers move in pieces at once, then are written; on one,
        // each is moved as it is written, in one pass.
        let parallel = worth_splitting(self.movers.len());
        if parallel {
            in_pieces(self.movers.chunks_mut(BALLS_PER_PIECE), true, |movers| {
                movers.iter_mut().for_each(|mover| mover.advance(spec.dt));
            });
        }
        // Every flag read, without stopping at the first held one: LLVM then reads them 16
        // at a time (`contains` reads one at a time, and in a gas none is held).
        let none_held = !held.iter().fold(false, |any, &held| any | held);
        if none_held {
            stopped.fill(false);
        }
        let mut inside = true;
        for (&ball, mover) in self.order.iter().zip(&self.movers) {
            let index = ball as usize;
            let (center, velocity) = if parallel {
                (mover.center, mover.velocity)
            } else {
                mover.state_at(spec.dt)
            };
            (circles[index].center, velocities[index]) = (center, velocity);
            if mover.is_still() || !none_held {
                held[index] &= mover.is_still() && mover.hits == 0;
                stopped[index] = mover.is_still() && !held[index];
            }
            inside &= lies_inside(center, mover.radius, spec.half);
        }
        self.ends_inside = inside;
    }

    /// Some balls stopped taking hits: whatever overlaps now gets the discrete response.
    fn resolve_what_was_cut_short(
        &mut self,
        circles: &mut [Circle],
        velocities: &mut [DVec2],
        held: &mut [bool],
        spec: StepSpec,
        on_hit: &mut impl FnMut(Hit),
    ) {
        find_contacts(
            circles,
            BroadPhase::Grid,
            &mut self.grid,
            &mut self.fallback,
        );
        let pairs = self.fallback.iter().map(|contact| (contact.a, contact.b));
        resolve_overlaps(
            pairs,
            circles,
            velocities,
            held,
            (spec.mass_model, spec.restitution, spec.rest_speed),
            |a, b, geometry, exchange| on_hit(Hit::ball(a, b, spec.dt, geometry, exchange)),
        );
    }

    /// Pushes apart, shared by inverse mass, the pairs that overlapped at the start of the step
    /// and still do; a held ball does not move, and two held ones are the resting stage's.
    fn push_apart_overlaps(&self, circles: &mut [Circle], held: &[bool], spec: StepSpec) {
        for &(a, b) in &self.overlapping {
            let (a, b) = (a as usize, b as usize);
            if held[a] && held[b] {
                continue;
            }
            let Some(geometry) = circle_contact(circles[a], circles[b]) else {
                continue;
            };
            let inverse_mass = |index: usize| {
                if held[index] {
                    0.0
                } else {
                    spec.mass_model.inverse_mass(circles[index].radius)
                }
            };
            let inverse_masses = (inverse_mass(a), inverse_mass(b));
            separate(circles, (a, b), geometry, inverse_masses);
        }
    }
}

/// Ball `mover`, at a wall and closing slower than the resting speed, stops against it: its
/// velocity into the wall goes, and so does gravity's push into it for the rest of the step,
/// so it slides along the wall. Returns the impulse per unit mass the wall gives it over the
/// step (the stop and the push it carries), or `None` if it neither moves nor is pushed.
fn stop_against_wall(mover: &mut Mover, wall: Wall, spec: StepSpec, now: f64) -> Option<f64> {
    let outward = wall.outward_normal();
    let (speed_in, pushed_in) = (
        mover.velocity.dot(outward).max(0.0),
        mover.accel.dot(outward).max(0.0),
    );
    if speed_in == 0.0 && pushed_in == 0.0 {
        return None;
    }
    mover.velocity -= outward * speed_in;
    mover.accel -= outward * pushed_in;
    let axis = usize::from(outward.y != 0.0);
    mover.center[axis] = outward[axis] * (spec.half[axis] - mover.radius);
    Some(speed_in + pushed_in * (spec.dt - now))
}

/// Rounding can leave a ball a hair past a wall, and pushing overlaps apart can push one into
/// it: the same containment as the discrete mode puts it back. Returns the walls' impulse on
/// the balls it stopped there by the resting rule.
fn contain_at_the_end(
    circles: &mut [Circle],
    velocities: &mut [DVec2],
    spec: StepSpec,
    on_hit: &mut impl FnMut(Hit),
) -> f64 {
    let arena = (spec.half, spec.restitution, spec.rest_speed);
    let met = contain_all((circles, velocities), arena);
    let mut resting_impulse = 0.0;
    let recording = (spec.half, spec.restitution, spec.mass_model, spec.dt);
    record_walls_met(met, circles, recording, &mut resting_impulse, on_hit);
    resting_impulse
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::continuous::MIN_HITS_PER_BALL;
    use crate::sim::params::MassModel;

    #[test]
    fn a_timeline_on_plain_arrays_bounces_a_fast_pair_and_keeps_energy() {
        let spec = StepSpec {
            dt: 1.0,
            half: DVec2::new(1_000.0, 1_000.0),
            restitution: 1.0,
            mass_model: MassModel::Radius,
            gravity: DVec2::ZERO,
            rest_speed: 0.0,
            hit_limit: MIN_HITS_PER_BALL,
        };
        let mut circles = vec![
            Circle::new(DVec2::new(-100.0, 0.0), 5.0),
            Circle::new(DVec2::new(100.0, 3.0), 10.0),
        ];
        let mut velocities = vec![DVec2::new(300.0, 0.0), DVec2::new(-300.0, 0.0)];
        let energy = |v: &[DVec2], c: &[Circle]| -> f64 {
            v.iter()
                .zip(c)
                .map(|(v, c)| 0.5 * c.radius * v.length_squared())
                .sum()
        };
        let before = energy(&velocities, &circles);
        let mut timeline = Timeline::default();
        let (mut held, mut stopped) = (vec![false; 2], vec![false; 2]);
        timeline.predict(&circles, &velocities, &held, spec);
        let mut hits = Vec::new();
        timeline.run(
            &mut circles,
            &mut velocities,
            (&mut held, &mut stopped),
            spec,
            |hit| hits.push(hit),
        );
        assert_eq!(hits.len(), 1);
        let Hit::Ball { time, point, .. } = hits[0] else {
            panic!("a ball hit")
        };
        // Closing 600 px/s over 200 - sqrt(15^2 - 3^2) px.
        let expected = (200.0 - (15.0f64 * 15.0 - 9.0).sqrt()) / 600.0;
        assert!((time - expected).abs() < 1e-12, "{time} vs {expected}");
        assert!(point.x.abs() < 15.0);
        assert!((energy(&velocities, &circles) - before).abs() < 1e-9 * before);
        assert!(circles[0].center.distance(circles[1].center) >= 15.0 - 1e-9);
        assert!(velocities[0].x < 0.0 && velocities[1].x > 0.0);
    }
}
