//! The resting stage's contacts: every pair of balls, and every ball and wall, that touch
//! within a small margin or could within the step at the speeds they have (Box2D's
//! speculative contacts) ([`NearPairs`]), and from them the resting solver's bodies and
//! contacts, warm-started from the impulses the same contacts carried last step.

use bevy::platform::collections::HashMap;

use bevy::math::DVec2;
use bevy::prelude::*;

use super::constraint::{Body, Other, RestingContact};
use crate::sim::geometry::circle::{Circle, contact_normal};
use crate::sim::geometry::grid::UniformGrid;
use crate::sim::geometry::pairs::find_touching_pairs;
use crate::sim::geometry::wall::Wall;
use crate::sim::params::MassModel;

/// Balls within this fraction of their radii of touching count as touching: a resting ball
/// sinks about `|g|·dt²` (0.14 px at 500 px/s² and 60 steps a second) in a step before its
/// contacts push back.
pub const CONTACT_MARGIN: f64 = 0.02;

/// Two balls near each other: `a < b`, places in the snapshot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearPair {
    pub a: u32,
    pub b: u32,
    /// Pixels; negative when overlapping.
    pub gap: f64,
    /// Unit, from `a` to `b`.
    pub normal: DVec2,
    /// Within the margin of touching.
    pub touching: bool,
}

/// Whether a gap of `gap` pixels between balls (or a ball and a wall) of radii summing to
/// `radii` counts as touching.
fn within_margin(gap: f64, radii: f64) -> bool {
    gap <= CONTACT_MARGIN * radii
}

/// Whether an overlap of `-gap` pixels between balls (or a ball and a wall) of radii summing
/// to `radii` is deeper than the margin: a jam being pushed out, not an impact.
fn too_deep(gap: f64, radii: f64) -> bool {
    gap < -DEEP_OVERLAP * radii
}

/// An overlap deeper than this fraction of the radii is a jam being pushed out.
pub const DEEP_OVERLAP: f64 = 0.1;

/// Pairs and walls near touching, found anew each step.
#[derive(Debug, Default)]
pub struct NearPairs {
    /// `(a, b, gap in pixels, unit normal from a to b)`, `a < b`, in the grid's fixed order.
    pub pairs: Vec<NearPair>,
    /// `(ball, wall, gap in pixels)`.
    pub walls: Vec<(u32, Wall, f64)>,
    /// Whether each ball touches a ball or a wall (within the margin, not speculatively).
    pub touching: Vec<bool>,
    /// Whether each ball could touch a ball or a wall within the step (speculatively).
    pub near: Vec<bool>,

    /// The walls' impulse on each ball in the last solve, mass x pixels per second.
    pub wall_impulse_of: Vec<f64>,
    grid: UniformGrid,
    inflated: Vec<Circle>,
    /// The grid's pairs of `inflated` circles that touch: `(a, b)`, `a < b`.
    found: Vec<(u32, u32)>,
}

impl NearPairs {
    /// Finds the pairs and walls near touching among `circles` moving at `velocities` in the
    /// arena `[-half, half]`: within the margin, or within reach of a step of `dt` (for the
    /// walls, a step falling under `gravity` too; the balls all fall alike).
    pub fn find(
        &mut self,
        circles: &[Circle],
        velocities: &[DVec2],
        (half, gravity): (DVec2, DVec2),
        dt: f64,
    ) {
        let reach = |circle: &Circle, velocity: &DVec2| {
            circle.radius * CONTACT_MARGIN + velocity.length() * dt
        };
        let fall = gravity.length() * dt * dt;
        self.inflated.clear();
        self.inflated.extend(
            circles
                .iter()
                .zip(velocities)
                .map(|(c, v)| Circle::new(c.center, c.radius + reach(c, v))),
        );
        self.found.clear();
        find_touching_pairs(&self.inflated, &mut self.grid, &mut self.found);
        self.touching.clear();
        self.touching.resize(circles.len(), false);
        self.near.clear();
        self.near.resize(circles.len(), false);

        self.wall_impulse_of.clear();
        self.wall_impulse_of.resize(circles.len(), 0.0);
        self.pairs.clear();
        for &(index_a, index_b) in &self.found {
            let (a, b) = (circles[index_a as usize], circles[index_b as usize]);
            let offset = b.center - a.center;
            let distance = offset.length();
            let gap = distance - (a.radius + b.radius);
            let touching = within_margin(gap, a.radius + b.radius);
            self.pairs.push(NearPair {
                a: index_a,
                b: index_b,
                gap,
                normal: contact_normal(offset, distance),
                touching,
            });
            self.touching[index_a as usize] |= touching;
            self.touching[index_b as usize] |= touching;
            self.near[index_a as usize] = true;
            self.near[index_b as usize] = true;
        }
        self.walls.clear();
        for (index, (circle, velocity)) in circles.iter().zip(velocities).enumerate() {
            for wall in Wall::ALL {
                let outward = wall.outward_normal();
                let axis = usize::from(outward.y != 0.0);
                let gap = half[axis] - circle.radius - circle.center.dot(outward);
                if gap <= reach(circle, velocity) + fall {
                    self.walls.push((index as u32, wall, gap));
                    self.touching[index] |= within_margin(gap, circle.radius);
                    self.near[index] = true;
                }
            }
        }
    }

    /// Fills `bodies` with the solver's bodies (the `solved` balls movable, every other an
    /// anchor that stands still for it: the mode's stages move those) and `contacts` with
    /// the contacts that involve a solved ball, warm-started from `warm`.
    pub fn solver_input(
        &mut self,
        (circles, velocities, entities): (&[Circle], &[DVec2], &[Entity]),
        solved: impl Fn(usize) -> bool,
        mass_model: MassModel,
        warm: &HashMap<(u64, u64), f64>,
        (bodies, contacts): (&mut Vec<Body>, &mut Vec<RestingContact>),
    ) {
        bodies.clear();
        bodies.extend(circles.iter().zip(velocities).enumerate().map(
            |(index, (circle, velocity))| {
                if solved(index) {
                    Body::new(
                        circle.center,
                        *velocity,
                        mass_model.inverse_mass(circle.radius),
                    )
                } else {
                    Body::new(circle.center, DVec2::ZERO, 0.0)
                }
            },
        ));
        contacts.clear();
        for &NearPair {
            a, b, gap, normal, ..
        } in &self.pairs
        {
            if solved(a as usize) || solved(b as usize) {
                let warm_start = warm.get(&key(entities, a, Some(b))).copied();
                let mut contact =
                    RestingContact::new(a, Other::Body(b), normal, gap, warm_start.unwrap_or(0.0));
                contact.push_out = solved(a as usize) && solved(b as usize);
                let radii = circles[a as usize].radius + circles[b as usize].radius;
                contact.may_bounce = !too_deep(gap, radii);
                contacts.push(contact);
            }
        }
        for &(ball, wall, gap) in &self.walls {
            if solved(ball as usize) {
                let warm_start = warm.get(&wall_key(entities, ball, wall)).copied();
                let mut contact = RestingContact::new(
                    ball,
                    Other::Wall(wall),
                    wall.outward_normal(),
                    gap,
                    warm_start.unwrap_or(0.0),
                );
                contact.may_bounce = !too_deep(gap, circles[ball as usize].radius);
                contacts.push(contact);
            }
        }
    }

    /// Each solved contact's impulse under its key, for the next step's warm start; and the
    /// walls' impulse on each ball recorded in `wall_impulse_of`.
    pub fn warm_starts<'a>(
        &'a mut self,
        contacts: &'a [RestingContact],
        entities: &'a [Entity],
    ) -> impl Iterator<Item = ((u64, u64), f64)> + 'a {
        for contact in contacts {
            if let Other::Wall(_) = contact.other {
                self.wall_impulse_of[contact.a as usize] += contact.step_impulse;
            }
        }
        contacts.iter().map(move |contact| {
            let key = match contact.other {
                Other::Body(b) => key(entities, contact.a, Some(b)),
                Other::Wall(wall) => wall_key(entities, contact.a, wall),
            };
            (key, contact.impulse)
        })
    }

    /// The walls' impulse on all balls in the last solve.
    pub fn total_wall_impulse(&self) -> f64 {
        self.wall_impulse_of.iter().sum()
    }
}

/// A pair's key, the same whichever ball comes first.
fn key(entities: &[Entity], a: u32, b: Option<u32>) -> (u64, u64) {
    let a = entities[a as usize].to_bits();
    let b = b.map_or(u64::MAX, |b| entities[b as usize].to_bits());
    (a.min(b), a.max(b))
}

/// A ball and wall's key.
fn wall_key(entities: &[Entity], ball: u32, wall: Wall) -> (u64, u64) {
    (entities[ball as usize].to_bits(), u64::MAX - wall as u64)
}
