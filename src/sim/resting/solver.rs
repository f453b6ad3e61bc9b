//! The resting-contact solver: Box2D v3's soft step over plain arrays. Pure: bodies and
//! contacts in, new velocities, positions and contact impulses out.
//!
//! A step is split into substeps; each substep is the same short list of named passes as
//! Box2D's `solver.c`: [`integrate_velocities`] (gravity, damping), [`warm_start`] (the
//! impulses the contacts carried last substep), [`solve_contacts`] with a soft bias that
//! pushes overlaps out at a capped speed, [`integrate_positions`], and [`relax_contacts`]
//! (the same solve without the bias, so the push-out leaves no velocity behind); then, once
//! per step, [`apply_restitution`] to the contacts that closed faster than the resting speed
//! when the step began (the resting rule: slower ones do not bounce).
//!
//! Soft contacts (a spring of `hertz` with damping ratio `damping_ratio`, Box2D's
//! `b2MakeSoft`) and warm starting are what let a deep pile hold still with a few
//! iterations: each contact carries the weight it held last step from the start.

use bevy::math::DVec2;

use crate::sim::geometry::Wall;

/// A body the solver moves, or an anchor it does not (`inverse_mass` 0): a ball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Pixels, at the start of the step; unchanged by the solver (see `shift`).
    pub position: DVec2,
    /// Pixels per second.
    pub velocity: DVec2,
    /// 1 / mass; 0 for an anchor.
    pub inverse_mass: f64,
    /// How far the solver has moved it this step, pixels.
    pub shift: DVec2,
}

impl Body {
    pub fn new(position: DVec2, velocity: DVec2, inverse_mass: f64) -> Self {
        Self {
            position,
            velocity,
            inverse_mass,
            shift: DVec2::ZERO,
        }
    }
}

/// What a contact's second side is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Other {
    /// Another body, by index.
    Body(u32),
    /// A wall, which never moves.
    Wall(Wall),
}

/// A contact between body `a` and `other`, along `normal` (unit, from `a` towards `other`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestingContact {
    pub a: u32,
    pub other: Other,
    pub normal: DVec2,
    /// Gap at the start of the step, pixels: negative when overlapping.
    pub separation: f64,
    /// Normal impulse of the last substep (the warm start), mass x pixels per second, ≥ 0.
    pub impulse: f64,
    /// Normal impulse over the whole step so far: what a wall carried, for the pressure.
    pub step_impulse: f64,
    /// Normal speed at the start of the step, negative when closing, pixels per second:
    /// what restitution reverses.
    pub closing_velocity: f64,
    /// Whether an overlap is pushed out. Against a ball the solver does not move (one in
    /// flight), no: the mode's stages separate those, and a push against an immovable
    /// neighbour only squeezes the ball against its other contacts.
    pub push_out: bool,
    /// It bounced this step: a hit, not a resting contact.
    pub bounced: bool,
}

impl RestingContact {
    pub fn new(a: u32, other: Other, normal: DVec2, separation: f64, warm: f64) -> Self {
        Self {
            a,
            other,
            normal,
            separation,
            impulse: warm,
            step_impulse: 0.0,
            closing_velocity: 0.0,
            push_out: true,
            bounced: false,
        }
    }
}

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

/// A soft constraint's coefficients for a substep (Box2D's `b2Softness`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Softness {
    bias_rate: f64,
    mass_scale: f64,
    impulse_scale: f64,
}

impl Softness {
    fn new(hertz: f64, damping_ratio: f64, h: f64) -> Self {
        let omega = 2.0 * std::f64::consts::PI * hertz;
        let a1 = 2.0 * damping_ratio + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

/// One soft step of `bodies` held by `contacts`. Bodies with inverse mass 0 stay put.
pub fn soft_step(bodies: &mut [Body], contacts: &mut [RestingContact], step: SoftStep) {
    let substeps = step.substeps.max(1);
    let h = step.dt / f64::from(substeps);
    let softness = Softness::new(step.hertz, step.damping_ratio, h);
    let decay = (-step.damping * h).exp();
    for contact in contacts.iter_mut() {
        contact.step_impulse = 0.0;
        contact.closing_velocity = normal_velocity(bodies, contact);
        contact.bounced = false;
    }
    for _ in 0..substeps {
        integrate_velocities(bodies, step.gravity * h, decay);
        warm_start(bodies, contacts);
        solve_contacts(bodies, contacts, h, Some((softness, step.max_push_speed)));
        integrate_positions(bodies, h);
        relax_contacts(bodies, contacts, h);
        for contact in contacts.iter_mut() {
            contact.step_impulse += contact.impulse;
        }
    }
    apply_restitution(bodies, contacts, step.restitution, step.rest_speed);
}

/// Contacts that closed at `rest_speed` or faster when the step began, and that the solver
/// had to hold, bounce: their normal speed becomes `-restitution` times that closing speed.
fn apply_restitution(
    bodies: &mut [Body],
    contacts: &mut [RestingContact],
    restitution: f64,
    rest_speed: f64,
) {
    if restitution == 0.0 {
        return;
    }
    for contact in contacts.iter_mut() {
        if contact.closing_velocity > -rest_speed || contact.step_impulse == 0.0 {
            continue;
        }
        let inverse_masses = inverse_masses(bodies, contact);
        if inverse_masses <= 0.0 {
            continue;
        }
        let normal_speed = normal_velocity(bodies, contact);
        let change = -(normal_speed + restitution * contact.closing_velocity) / inverse_masses;
        let total = (contact.impulse + change).max(0.0);
        let applied = total - contact.impulse;
        contact.impulse = total;
        contact.step_impulse += applied;
        contact.bounced = true;
        apply_impulse(bodies, contact, applied);
    }
}

/// The contact's relative normal velocity, `other` minus `a`: negative when closing.
fn normal_velocity(bodies: &[Body], contact: &RestingContact) -> f64 {
    let a = &bodies[contact.a as usize];
    let other = other_body(bodies, contact.other).map_or(DVec2::ZERO, |b| b.velocity);
    (other - a.velocity).dot(contact.normal)
}

fn inverse_masses(bodies: &[Body], contact: &RestingContact) -> f64 {
    bodies[contact.a as usize].inverse_mass
        + other_body(bodies, contact.other).map_or(0.0, |b| b.inverse_mass)
}

fn integrate_velocities(bodies: &mut [Body], gain: DVec2, decay: f64) {
    for body in bodies.iter_mut().filter(|body| body.inverse_mass > 0.0) {
        body.velocity = (body.velocity + gain) * decay;
    }
}

fn warm_start(bodies: &mut [Body], contacts: &[RestingContact]) {
    for contact in contacts {
        apply_impulse(bodies, contact, contact.impulse);
    }
}

fn integrate_positions(bodies: &mut [Body], h: f64) {
    for body in bodies.iter_mut().filter(|body| body.inverse_mass > 0.0) {
        body.shift += body.velocity * h;
    }
}

fn relax_contacts(bodies: &mut [Body], contacts: &mut [RestingContact], h: f64) {
    solve_contacts(bodies, contacts, h, None);
}

/// One Gauss–Seidel pass over the contacts. With `bias` (the soft coefficients and the
/// push-out cap) an overlap is pushed out softly; without, only the approach is removed. A
/// gap still open (a speculative contact) may close within the substep but not beyond.
fn solve_contacts(
    bodies: &mut [Body],
    contacts: &mut [RestingContact],
    h: f64,
    bias: Option<(Softness, f64)>,
) {
    for contact in contacts.iter_mut() {
        let inverse_masses = inverse_masses(bodies, contact);
        if inverse_masses <= 0.0 {
            continue;
        }
        let (a, other) = (
            &bodies[contact.a as usize],
            other_body(bodies, contact.other),
        );
        let relative_shift = other.map_or(DVec2::ZERO, |b| b.shift) - a.shift;
        let separation = contact.separation + relative_shift.dot(contact.normal);
        let normal_speed = normal_velocity(bodies, contact);
        let (push, mass_scale, impulse_scale) = match bias {
            _ if separation > 0.0 => (separation / h, 1.0, 0.0),
            Some((soft, max_push_speed)) if contact.push_out => (
                (soft.bias_rate * separation).max(-max_push_speed),
                soft.mass_scale,
                soft.impulse_scale,
            ),
            _ => (0.0, 1.0, 0.0),
        };
        let change =
            -(normal_speed + push) * mass_scale / inverse_masses - impulse_scale * contact.impulse;
        let total = (contact.impulse + change).max(0.0);
        let applied = total - contact.impulse;
        contact.impulse = total;
        apply_impulse(bodies, contact, applied);
    }
}

fn other_body(bodies: &[Body], other: Other) -> Option<&Body> {
    match other {
        Other::Body(index) => Some(&bodies[index as usize]),
        Other::Wall(_) => None,
    }
}

/// Pushes the contact's sides apart along its normal with `impulse`.
#[inline]
fn apply_impulse(bodies: &mut [Body], contact: &RestingContact, impulse: f64) {
    let push = contact.normal * impulse;
    let a = &mut bodies[contact.a as usize];
    a.velocity -= push * a.inverse_mass;
    if let Other::Body(index) = contact.other {
        let b = &mut bodies[index as usize];
        b.velocity += push * b.inverse_mass;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            soft_step(bodies, contacts, STEP);
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
        soft_step(&mut bodies, &mut contacts, STEP);
        let gap = 1.0 + (bodies[0].shift - bodies[1].shift).dot(DVec2::Y);
        assert!((-1e-3..0.2).contains(&gap), "{gap}");
        assert_eq!(bodies[1].shift, DVec2::ZERO);
        // It closed at 200 px/s, faster than the resting speed: it bounces at half that.
        assert!(
            (bodies[0].velocity.y - 100.0).abs() < 1e-9,
            "{}",
            bodies[0].velocity
        );
    }
}
