//! What the resting solver works on: bodies (balls, movable or anchored) and the contacts
//! between them and with the walls, as plain values. [`solver`](super::solver) steps them;
//! [`contacts`](super::contacts) builds them from the balls.

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
    /// Normal speed at contact, negative when closing, pixels per second: what restitution
    /// reverses. The speed at the start of the step, and for a gap still open the speed the
    /// sides would meet at in free flight across it (gravity pulls a ball onto a wall, not
    /// onto a ball that falls with it). Never the speed other contacts' push-outs give it: a
    /// pushed pile would bounce forever.
    pub closing_velocity: f64,
    /// Whether an overlap is pushed out. Against a ball the solver does not move (one in
    /// flight), no: the mode's stages separate those, and a push against an immovable
    /// neighbour only squeezes the ball against its other contacts.
    pub push_out: bool,
    /// It bounced this step: a hit, not a resting contact.
    pub bounced: bool,
    /// Whether it may bounce: not when it began the step deep in an overlap, where its
    /// closing speed is the push-out's own (bouncing that back pumps energy into a jam).
    pub may_bounce: bool,
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
            may_bounce: true,
        }
    }
}
