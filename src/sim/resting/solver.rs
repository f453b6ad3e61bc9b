//! The resting-contact solver: Box2D v3's soft step over plain arrays. Pure: bodies and
//! contacts in, new velocities, positions and contact impulses out.
//!
//! `Work` gathers the bodies the contacts touch into slots and each contact into a `Link`;
//! the substeps run in `wide.rs`, four contacts at a time, each the same short
//! list of passes as Box2D's `solver.c` (velocities, warm start, a solve with a soft bias
//! that pushes overlaps out at a capped speed, positions, and a relax without it); then,
//! once per step, `apply_restitution` bounces the contacts that closed at the resting speed
//! or faster (the resting rule: slower ones do not bounce) and did not begin the step deep
//! in an overlap.
//!
//! Soft contacts (a spring of `hertz` with damping ratio `damping_ratio`, Box2D's
//! `b2MakeSoft`) and warm starting are what let a deep pile hold still with a few
//! iterations: each contact carries the weight it held last step from the start.

use bevy::math::DVec2;

pub use super::constraint::{Body, Other, RestingContact};
use super::wide::{Link, Motion, Softness, WideStep};

/// The soft step's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftStep {
    /// Seconds.
    pub dt: f64,
    pub substeps: u32,
    /// Pixels per second squared.
    pub gravity: DVec2,
    /// Per second: velocity decays as `exp(-damping t)`.
    pub damping: f64,
    /// Contact stiffness as a frequency, hertz.
    pub hertz: f64,
    pub damping_ratio: f64,
    /// The fastest an overlap is pushed out, pixels per second.
    pub max_push_speed: f64,
    pub restitution: f64,
    /// Contacts closing slower than this at the start of the step do not bounce.
    pub rest_speed: f64,
}

/// The solver's working memory, kept from step to step: filled anew each step, but never
/// given back, so a step allocates nothing (a pile of 1,000 balls stepped 18% slower when
/// its half a megabyte of arrays went back to the system after every step).
#[derive(Debug, Default)]
pub struct SolverMemory {
    work: Work,
    wide: WideStep,
}

/// One soft step of `bodies` held by `contacts`, in `memory`. Bodies with inverse mass 0
/// stay put.
pub fn soft_step(
    bodies: &mut [Body],
    contacts: &mut [RestingContact],
    step: SoftStep,
    memory: &mut SolverMemory,
) {
    let substeps = step.substeps.max(1);
    let h = step.dt / f64::from(substeps);
    let softness = Softness::new(step.hertz, step.damping_ratio, h);
    let decay = (-step.damping * h).exp();
    let SolverMemory { work, wide } = memory;
    work.fill(bodies, contacts);
    for (contact, link) in contacts.iter_mut().zip(&work.links) {
        contact.bounced = false;
        contact.closing_velocity = work.speed_at_contact(link, step.gravity);
    }
    wide.fill(&work.motion, &work.inverse_mass, &work.links);
    let bias = (softness, step.max_push_speed);
    wide.run(substeps, h, step.gravity * h, decay, bias);
    wide.finish(&mut work.motion, &mut work.links);
    for (contact, link) in contacts.iter_mut().zip(&work.links) {
        contact.step_impulse = link.step_impulse;
    }
    work.apply_restitution(contacts, step.restitution, step.rest_speed);
    for (contact, link) in contacts.iter_mut().zip(&work.links) {
        contact.impulse = link.impulse;
    }
    for (body, &slot) in bodies.iter_mut().zip(&work.slot_of) {
        if slot != NO_SLOT {
            let motion = work.motion[slot as usize];
            (body.velocity, body.shift) = (motion.velocity, motion.shift);
        }
    }
}

/// Gauss–Seidel passes over the bounces when more than one contact bounces in a step.
const RESTITUTION_PASSES: usize = 8;

/// A body the solver has no slot for: an anchor no contact touches.
const NO_SLOT: u32 = u32::MAX;

/// The solver's working arrays. Each body a contact touches, and each movable one, has a
/// slot, numbered in the order the contacts first name them (neighbours in space stay
/// neighbours in memory), with its motion and inverse mass; one last slot, an anchor that
/// never moves, stands for the walls. Each contact is a [`Link`]. The substeps' passes run
/// on a `WideStep` filled from them; the restitution pass is a plain loop over them.
#[derive(Debug, Default)]
struct Work {
    motion: Vec<Motion>,
    inverse_mass: Vec<f64>,
    links: Vec<Link>,
    /// Each body's slot, or [`NO_SLOT`].
    slot_of: Vec<u32>,
    /// Each contact's two slots, the second `None` for a wall.
    ends: Vec<(u32, Option<u32>)>,
}

impl Work {
    /// Empties the arrays and fills them for `bodies` and `contacts`.
    fn fill(&mut self, bodies: &[Body], contacts: &[RestingContact]) {
        let work = self;
        work.motion.clear();
        work.inverse_mass.clear();
        work.links.clear();
        work.slot_of.clear();
        work.slot_of.resize(bodies.len(), NO_SLOT);
        let slot = |work: &mut Work, index: u32| {
            let existing = work.slot_of[index as usize];
            if existing != NO_SLOT {
                return existing;
            }
            let body = &bodies[index as usize];
            work.slot_of[index as usize] = work.motion.len() as u32;
            work.motion.push(Motion {
                velocity: body.velocity,
                shift: body.shift,
            });
            work.inverse_mass.push(body.inverse_mass);
            work.slot_of[index as usize]
        };
        let mut ends = std::mem::take(&mut work.ends);
        ends.clear();
        for contact in contacts {
            let a = slot(work, contact.a);
            let b = match contact.other {
                Other::Body(index) => Some(slot(work, index)),
                Other::Wall(_) => None,
            };
            ends.push((a, b));
        }
        for (index, body) in bodies.iter().enumerate() {
            if body.inverse_mass > 0.0 {
                slot(work, index as u32);
            }
        }
        let anchor = work.motion.len() as u32;
        work.motion.push(Motion::default());
        work.inverse_mass.push(0.0);
        for (contact, &(a, b)) in contacts.iter().zip(&ends) {
            let b = b.unwrap_or(anchor);
            let (inverse_mass_a, inverse_mass_b) =
                (work.inverse_mass[a as usize], work.inverse_mass[b as usize]);
            let inverse_masses = inverse_mass_a + inverse_mass_b;
            work.links.push(Link {
                a,
                b,
                inverse_mass_a,
                inverse_mass_b,
                mass: if inverse_masses > 0.0 {
                    1.0 / inverse_masses
                } else {
                    0.0
                },
                normal: contact.normal,
                separation: contact.separation,
                impulse: contact.impulse,
                step_impulse: 0.0,
                push_out: contact.push_out,
            });
        }
        work.ends = ends;
    }

    /// The contact's relative normal velocity, `b` minus `a`: negative when closing.
    #[inline]
    fn normal_velocity(motion: &[Motion], link: &Link) -> f64 {
        (motion[link.b as usize].velocity - motion[link.a as usize].velocity).dot(link.normal)
    }

    /// Pushes the contact's sides apart along its normal with `impulse`.
    #[inline]
    fn apply_impulse(motion: &mut [Motion], link: &Link, impulse: f64) {
        let push = link.normal * impulse;
        motion[link.a as usize].velocity -= push * link.inverse_mass_a;
        motion[link.b as usize].velocity += push * link.inverse_mass_b;
    }

    /// The normal speed at which the link's sides meet (see
    /// [`RestingContact::closing_velocity`]).
    fn speed_at_contact(&self, link: &Link, gravity: DVec2) -> f64 {
        let speed = Self::normal_velocity(&self.motion, link);
        if link.separation <= 0.0 || speed >= 0.0 {
            return speed;
        }
        let falls = |inverse_mass: f64| f64::from(u8::from(inverse_mass > 0.0));
        let accel =
            (falls(link.inverse_mass_b) - falls(link.inverse_mass_a)) * gravity.dot(link.normal);
        -(speed * speed - 2.0 * accel * link.separation)
            .max(0.0)
            .sqrt()
    }

    /// Contacts that closed at `rest_speed` or faster when the step began, and that the
    /// solver had to hold, bounce: their normal speed becomes `-restitution` times that
    /// closing speed. A ball struck on two sides at once shares its bounces: the passes
    /// converge on impulses that meet every contact's target together (each bounce impulse
    /// non-negative), where one pass would let the last contact's push add to the first's and
    /// gain energy.
    fn apply_restitution(
        &mut self,
        contacts: &mut [RestingContact],
        restitution: f64,
        rest_speed: f64,
    ) {
        if restitution == 0.0 {
            return;
        }
        let bouncing: Vec<usize> = (contacts.iter().zip(&self.links).enumerate())
            .filter(|(_, (contact, link))| {
                contact.may_bounce
                    && contact.closing_velocity <= -rest_speed
                    && contact.step_impulse != 0.0
                    && link.mass != 0.0
            })
            .map(|(index, _)| index)
            .collect();
        let mut bounce = vec![0.0; bouncing.len()];
        let passes = if bouncing.len() > 1 {
            RESTITUTION_PASSES
        } else {
            1
        };
        for _ in 0..passes {
            for (bounce, &index) in bounce.iter_mut().zip(&bouncing) {
                let link = &mut self.links[index];
                let normal_speed = Self::normal_velocity(&self.motion, link);
                let target = -restitution * contacts[index].closing_velocity;
                let total = (*bounce - (normal_speed - target) * link.mass).max(0.0);
                let applied = total - *bounce;
                *bounce = total;
                link.impulse += applied;
                Self::apply_impulse(&mut self.motion, link, applied);
            }
        }
        for (bounce, &index) in bounce.iter().zip(&bouncing) {
            contacts[index].step_impulse += bounce;
            contacts[index].bounced = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::geometry::Wall;

    fn other_body(bodies: &[Body], other: Other) -> Option<&Body> {
        match other {
            Other::Body(index) => Some(&bodies[index as usize]),
            Other::Wall(_) => None,
        }
    }

    const STEP: SoftStep = SoftStep {
        dt: 1.0 / 60.0,
        substeps: 4,
        gravity: DVec2::new(0.0, -500.0),
        damping: 0.0,
        hertz: 60.0,
        damping_ratio: 10.0,
        max_push_speed: 100.0,
        restitution: 0.5,
        rest_speed: 16.0,
    };

    /// A column of `count` balls of radius 10 and mass 10 standing on a floor at y = 0.
    fn column(count: usize) -> (Vec<Body>, Vec<RestingContact>) {
        let bodies = (0..count)
            .map(|k| Body::new(DVec2::new(0.0, 10.0 + 20.0 * k as f64), DVec2::ZERO, 0.1))
            .collect();
        let mut contacts = vec![RestingContact::new(
            0,
            Other::Wall(Wall::Bottom),
            DVec2::NEG_Y,
            0.0,
            0.0,
        )];
        contacts.extend(
            (1..count).map(|k| {
                RestingContact::new(k as u32 - 1, Other::Body(k as u32), DVec2::Y, 0.0, 0.0)
            }),
        );
        (bodies, contacts)
    }

    /// Runs `steps` soft steps, moving the bodies to where each step leaves them.
    fn run(bodies: &mut [Body], contacts: &mut [RestingContact], steps: usize) {
        for _ in 0..steps {
            soft_step(bodies, contacts, STEP, &mut SolverMemory::default());
            for contact in contacts.iter_mut() {
                let a = bodies[contact.a as usize].shift;
                let other = other_body(bodies, contact.other).map_or(DVec2::ZERO, |b| b.shift);
                contact.separation += (other - a).dot(contact.normal);
            }
            for body in bodies.iter_mut() {
                body.position += std::mem::take(&mut body.shift);
            }
        }
    }

    #[test]
    fn a_column_stands_still_and_the_floor_carries_its_weight() {
        let (mut bodies, mut contacts) = column(10);
        run(&mut bodies, &mut contacts, 120);
        // A soft contact gives like a stiff spring, in proportion to its load: the floor's,
        // carrying ten balls, 0.035 px; the whole column 0.35 px (7 px per 400 of height).
        for (k, body) in bodies.iter().enumerate() {
            let sunk = 10.0 + 20.0 * k as f64 - body.position.y;
            assert!((0.0..0.4).contains(&sunk), "ball {k} sank {sunk} px");
            assert!(body.velocity.length() < 0.01, "ball {k}: {}", body.velocity);
        }
        // Ten balls of mass 10 under 500 px/s² for one step of 1/60 s.
        let weight_impulse = 10.0 * 10.0 * 500.0 / 60.0;
        let floor = contacts[0].step_impulse;
        assert!(
            (floor - weight_impulse).abs() < 1e-3 * weight_impulse,
            "{floor}"
        );
    }

    #[test]
    fn an_overlap_is_pushed_out_without_leaving_speed() {
        let (mut bodies, mut contacts) = column(2);
        bodies[1].position.y -= 2.0;
        contacts[1].separation = -2.0;
        run(&mut bodies, &mut contacts, 60);
        assert!(contacts[1].separation > -0.05, "{}", contacts[1].separation);
        assert!(bodies[1].velocity.length() < 0.01, "{}", bodies[1].velocity);
    }

    #[test]
    fn a_speculative_gap_closes_but_never_overshoots_and_anchors_stay_put() {
        let mut bodies = vec![
            Body::new(DVec2::new(0.0, 30.0), DVec2::new(0.0, -200.0), 0.1),
            Body::new(DVec2::new(0.0, 0.0), DVec2::ZERO, 0.0),
        ];
        // 1 px apart, closing at 200 px/s: 3.3 px a step would overshoot by 2.3 px.
        let mut contacts = vec![RestingContact::new(1, Other::Body(0), DVec2::Y, 1.0, 0.0)];
        soft_step(
            &mut bodies,
            &mut contacts,
            STEP,
            &mut SolverMemory::default(),
        );
        let gap = 1.0 + (bodies[0].shift - bodies[1].shift).dot(DVec2::Y);
        assert!((-1e-3..0.2).contains(&gap), "{gap}");
        assert_eq!(bodies[1].shift, DVec2::ZERO);
        // It closed at 200 px/s and a little more as it fell to the contact (500 px/s² for
        // a substep or two): faster than the resting speed, it bounces at half that.
        let bounce = bodies[0].velocity.y;
        assert!(
            (100.0..100.0 + 500.0 / 60.0 / 4.0).contains(&bounce),
            "{bounce}"
        );
    }

    #[test]
    fn a_jam_being_pushed_out_does_not_bounce() {
        // A ball 3 px deep in the floor, moving into it at 200 px/s: as a fresh impact it
        // would bounce at 100 px/s; as a jam (it may not bounce) it only stops.
        let run = |may_bounce: bool| {
            let mut bodies = vec![Body::new(
                DVec2::new(0.0, 7.0),
                DVec2::new(0.0, -200.0),
                0.1,
            )];
            let mut contact =
                RestingContact::new(0, Other::Wall(Wall::Bottom), DVec2::NEG_Y, -3.0, 0.0);
            contact.may_bounce = may_bounce;
            let mut contacts = vec![contact];
            soft_step(
                &mut bodies,
                &mut contacts,
                STEP,
                &mut SolverMemory::default(),
            );
            (bodies[0].velocity.y, contacts[0].bounced)
        };
        let (bounced_speed, bounced) = run(true);
        assert!(bounced && bounced_speed > 90.0, "{bounced_speed}");
        let (jammed_speed, bounced) = run(false);
        assert!(!bounced && jammed_speed < 20.0, "{jammed_speed}");
    }
}
