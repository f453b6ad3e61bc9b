//! The soft step's substeps four contacts at a time ([`WideStep`]): Box2D v3's wide
//! constraints. The contacts are coloured so that no two of a colour share a movable body,
//! then packed four to a [`WideLink`] whose lanes the passes solve together in `f32` SIMD
//! lanes (`Vec4`): one colour's links never wait on each other, and a ball's velocity and
//! shift, side by side in one `Vec4`, load and store at once. The solver hands its bodies and
//! links over before the substeps and takes them back after, in `f64`.

use std::ops::Range;

use bevy::math::{BVec4A, DVec2, Vec4};

/// A soft constraint's coefficients for a substep (Box2D's `b2Softness`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Softness {
    pub bias_rate: f64,
    pub mass_scale: f64,
    pub impulse_scale: f64,
}

impl Softness {
    pub fn new(hertz: f64, damping_ratio: f64, h: f64) -> Self {
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

/// A body's velocity and how far it has moved, side by side: what every contact reads.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Motion {
    pub velocity: DVec2,
    pub shift: DVec2,
}

/// What a pass reads of a contact, packed: its two slots, their inverse masses and its
/// effective mass (0 if neither side moves), normal, starting gap and impulse.
#[derive(Debug)]
pub(super) struct Link {
    pub a: u32,
    pub b: u32,
    pub inverse_mass_a: f64,
    pub inverse_mass_b: f64,
    pub mass: f64,
    pub normal: DVec2,
    pub separation: f64,
    pub impulse: f64,
    /// The impulse summed over the step's substeps.
    pub step_impulse: f64,
    pub push_out: bool,
}

/// Lanes in a wide link.
const LANES: usize = 4;
/// Colours tried before a link goes into a group of its own.
const COLOURS: u32 = 24;

/// Four links solved together: lane `k` is link `link[k]` between slots `a[k]` and
/// `b[k]`. A lane with no link points at the anchor with zero mass and does nothing.
#[derive(Clone, Copy, Debug)]
pub struct WideLink {
    a: [u32; LANES],
    b: [u32; LANES],
    inverse_mass_a: Vec4,
    inverse_mass_b: Vec4,
    mass: Vec4,
    normal_x: Vec4,
    normal_y: Vec4,
    separation: Vec4,
    impulse: Vec4,
    step_impulse: Vec4,
    push_out: BVec4A,
    /// Each lane's link, or `u32::MAX`.
    link: [u32; LANES],
}

/// The substeps' state: each slot's `[vx, vy, shift x, shift y]` and whether it moves, and
/// the links in wide groups, colour after colour; with the colouring's scratch arrays, kept
/// for the next step.
#[derive(Debug, Default)]
pub struct WideStep {
    states: Vec<Vec4>,
    movable: Vec<bool>,
    links: Vec<WideLink>,
    colouring: Colouring,
}

impl WideStep {
    /// Fills the state for the slots' `motion` and `inverse_mass` (the last slot is the
    /// anchor) and the `links` between them.
    pub fn fill(&mut self, motion: &[Motion], inverse_mass: &[f64], links: &[Link]) {
        let anchor = (motion.len() - 1) as u32;
        self.states.clear();
        self.states.extend(motion.iter().map(|m| {
            Vec4::new(
                m.velocity.x as f32,
                m.velocity.y as f32,
                m.shift.x as f32,
                m.shift.y as f32,
            )
        }));
        self.movable.clear();
        self.movable.extend(inverse_mass.iter().map(|&im| im > 0.0));
        let colouring = &mut self.colouring;
        colouring.solvable.clear();
        colouring
            .solvable
            .extend((0..links.len() as u32).filter(|&index| links[index as usize].mass > 0.0));
        colouring.group(links, anchor, motion.len());
        self.links.clear();
        (self.links).extend(
            (colouring.groups.iter())
                .map(|group| pack(&colouring.order[group.clone()], links, anchor)),
        );
    }

    /// The substeps of the soft step, each the passes of Box2D's `solver.c`: velocities
    /// (gravity's `gain`, damping's `decay`), warm start, the biased solve, positions, and
    /// the relax (the solve without bias, so the push-out leaves no velocity behind); each
    /// substep's impulses summed.
    pub fn run(&mut self, substeps: u32, h: f64, gain: DVec2, decay: f64, bias: (Softness, f64)) {
        let gain = Vec4::new(gain.x as f32, gain.y as f32, 0.0, 0.0);
        let decay = Vec4::new(decay as f32, decay as f32, 1.0, 1.0);
        for _ in 0..substeps {
            self.integrate_velocities(gain, decay);
            self.warm_start();
            self.solve::<true>(h, bias);
            self.integrate_positions(h as f32);
            self.solve::<false>(h, bias);
            for link in &mut self.links {
                link.step_impulse += link.impulse;
            }
        }
    }

    /// Gravity's `gain` (in the velocity lanes) and damping's `decay` on every movable slot.
    fn integrate_velocities(&mut self, gain: Vec4, decay: Vec4) {
        for (state, &movable) in self.states.iter_mut().zip(&self.movable) {
            if movable {
                *state = (*state + gain) * decay;
            }
        }
    }

    /// Each movable slot's shift moves on by its velocity over the substep `h`.
    fn integrate_positions(&mut self, h: f32) {
        let moved = Vec4::new(0.0, 0.0, h, h);
        for (state, &movable) in self.states.iter_mut().zip(&self.movable) {
            if movable {
                *state += Vec4::new(state.x, state.y, state.x, state.y) * moved;
            }
        }
    }

    /// Each link's impulse from the substep before (the first substep: the step before)
    /// applied again, so a contact carries its load from the start.
    fn warm_start(&mut self) {
        for link in &self.links {
            let (mut a, mut b) = gather(&self.states, link);
            apply(&mut a, &mut b, link, link.impulse);
            scatter(&mut self.states, link, a, b);
        }
    }

    /// One pass over the links, colour by colour. `BIASED`: overlaps pushed out softly (the
    /// soft coefficients and the push-out cap in `bias`); otherwise only the approach is
    /// removed. An open gap may close within the substep but not beyond.
    fn solve<const BIASED: bool>(&mut self, h: f64, (soft, max_push_speed): (Softness, f64)) {
        let inverse_h = Vec4::splat((1.0 / h) as f32);
        let zero = Vec4::ZERO;
        let one = Vec4::ONE;
        let (bias_rate, mass_scale, impulse_scale) = (
            Vec4::splat(soft.bias_rate as f32),
            Vec4::splat(soft.mass_scale as f32),
            Vec4::splat(soft.impulse_scale as f32),
        );
        let max_push = Vec4::splat(-max_push_speed as f32);
        for link in &mut self.links {
            let (mut a, mut b) = gather(&self.states, link);
            let separation = link.separation
                + link.normal_x * (b.shift_x - a.shift_x)
                + link.normal_y * (b.shift_y - a.shift_y);
            let normal_speed = link.normal_x * (b.velocity_x - a.velocity_x)
                + link.normal_y * (b.velocity_y - a.velocity_y);
            let open = separation.cmpgt(zero);
            let soft_lanes = if BIASED {
                !open & link.push_out
            } else {
                BVec4A::FALSE
            };
            let push = Vec4::select(
                open,
                separation * inverse_h,
                Vec4::select(soft_lanes, (bias_rate * separation).max(max_push), zero),
            );
            let scale_mass = Vec4::select(soft_lanes, mass_scale, one);
            let scale_impulse = Vec4::select(soft_lanes, impulse_scale, zero);
            let change =
                -(normal_speed + push) * scale_mass * link.mass - scale_impulse * link.impulse;
            let total = (link.impulse + change).max(zero);
            let applied = total - link.impulse;
            link.impulse = total;
            apply(&mut a, &mut b, link, applied);
            scatter(&mut self.states, link, a, b);
        }
    }

    /// Hands the substeps' results back: each link's impulse and step impulse, each slot's
    /// velocity and shift.
    pub fn finish(&self, motion: &mut [Motion], links: &mut [Link]) {
        for (slot, state) in motion.iter_mut().zip(&self.states) {
            slot.velocity = DVec2::new(f64::from(state.x), f64::from(state.y));
            slot.shift = DVec2::new(f64::from(state.z), f64::from(state.w));
        }
        for wide in &self.links {
            for lane in 0..LANES {
                if let Some(link) = links.get_mut(wide.link[lane] as usize) {
                    link.impulse = f64::from(wide.impulse[lane]);
                    link.step_impulse = f64::from(wide.step_impulse[lane]);
                }
            }
        }
    }
}

/// One side of four lanes: velocities and shifts, lane by lane.
struct Sides {
    velocity_x: Vec4,
    velocity_y: Vec4,
    shift_x: Vec4,
    shift_y: Vec4,
}

fn gather_side(states: &[Vec4], slots: &[u32; LANES]) -> Sides {
    let [s0, s1, s2, s3] = slots.map(|slot| states[slot as usize]);
    Sides {
        velocity_x: Vec4::new(s0.x, s1.x, s2.x, s3.x),
        velocity_y: Vec4::new(s0.y, s1.y, s2.y, s3.y),
        shift_x: Vec4::new(s0.z, s1.z, s2.z, s3.z),
        shift_y: Vec4::new(s0.w, s1.w, s2.w, s3.w),
    }
}

fn gather(states: &[Vec4], link: &WideLink) -> (Sides, Sides) {
    (gather_side(states, &link.a), gather_side(states, &link.b))
}

/// Writes the lanes' velocities back (the shifts are unchanged by a pass). Lanes of one wide
/// link never share a movable slot; the anchor they may share never changes.
fn scatter(states: &mut [Vec4], link: &WideLink, a: Sides, b: Sides) {
    for (slots, side) in [(&link.a, &a), (&link.b, &b)] {
        for lane in 0..LANES {
            let state = &mut states[slots[lane] as usize];
            state.x = side.velocity_x[lane];
            state.y = side.velocity_y[lane];
        }
    }
}

/// Pushes each lane's sides apart along its normal with `impulse`.
fn apply(a: &mut Sides, b: &mut Sides, link: &WideLink, impulse: Vec4) {
    let (push_x, push_y) = (link.normal_x * impulse, link.normal_y * impulse);
    a.velocity_x -= push_x * link.inverse_mass_a;
    a.velocity_y -= push_y * link.inverse_mass_a;
    b.velocity_x += push_x * link.inverse_mass_b;
    b.velocity_y += push_y * link.inverse_mass_b;
}

/// The colouring's arrays: the links to colour (`solvable`, indices into the links) in,
/// `order` and `groups` out.
#[derive(Debug, Default)]
struct Colouring {
    solvable: Vec<u32>,
    /// Each slot's colours taken, a bit each.
    used: Vec<u32>,
    colours: Vec<u32>,
    order: Vec<u32>,
    groups: Vec<Range<usize>>,
}

impl Colouring {
    /// Puts the `solvable` links in groups of at most four, colour after colour: `order`
    /// lists them, and each group is a range of it. Within a group no two links share a
    /// movable slot (the `anchor`, which never moves, may be shared). Greedy colouring, each
    /// link the lowest colour neither of its slots has; a link whose slots have all
    /// [`COLOURS`] goes in a group of its own, last.
    fn group(&mut self, links: &[Link], anchor: u32, slots: usize) {
        self.used.clear();
        self.used.resize(slots, 0);
        let mut count = [0usize; COLOURS as usize + 1];
        self.colours.clear();
        for &index in &self.solvable {
            let link = &links[index as usize];
            let movable_b = link.b != anchor;
            let used = &mut self.used;
            let taken = used[link.a as usize] | if movable_b { used[link.b as usize] } else { 0 };
            let colour = taken.trailing_ones().min(COLOURS);
            if colour < COLOURS {
                used[link.a as usize] |= 1 << colour;
                if movable_b {
                    used[link.b as usize] |= 1 << colour;
                }
            }
            count[colour as usize] += 1;
            self.colours.push(colour);
        }
        let mut start = [0usize; COLOURS as usize + 2];
        for colour in 0..=COLOURS as usize {
            start[colour + 1] = start[colour] + count[colour];
        }
        let mut next = start;
        self.order.clear();
        self.order.resize(self.solvable.len(), 0);
        for (&index, &colour) in self.solvable.iter().zip(&self.colours) {
            self.order[next[colour as usize]] = index;
            next[colour as usize] += 1;
        }
        self.groups.clear();
        for colour in 0..COLOURS as usize {
            let (first, end) = (start[colour], start[colour + 1]);
            (self.groups).extend(
                (first..end)
                    .step_by(LANES)
                    .map(|at| at..(at + LANES).min(end)),
            );
        }
        let overflow = start[COLOURS as usize]..start[COLOURS as usize + 1];
        self.groups.extend(overflow.map(|at| at..at + 1));
    }
}

/// A group's links packed into lanes, the empty lanes pointing at the `anchor` with no mass.
fn pack(group: &[u32], links: &[Link], anchor: u32) -> WideLink {
    let lane = |k: usize| group.get(k).map(|&index| &links[index as usize]);
    let value = |pick: fn(&Link) -> f64| {
        Vec4::from_array(std::array::from_fn(|k| {
            lane(k).map_or(0.0, |l| pick(l) as f32)
        }))
    };
    WideLink {
        a: std::array::from_fn(|k| lane(k).map_or(anchor, |l| l.a)),
        b: std::array::from_fn(|k| lane(k).map_or(anchor, |l| l.b)),
        inverse_mass_a: value(|l| l.inverse_mass_a),
        inverse_mass_b: value(|l| l.inverse_mass_b),
        mass: value(|l| l.mass),
        normal_x: value(|l| l.normal.x),
        normal_y: value(|l| l.normal.y),
        separation: value(|l| l.separation),
        impulse: value(|l| l.impulse),
        step_impulse: Vec4::ZERO,
        push_out: BVec4A::new(
            lane(0).is_some_and(|l| l.push_out),
            lane(1).is_some_and(|l| l.push_out),
            lane(2).is_some_and(|l| l.push_out),
            lane(3).is_some_and(|l| l.push_out),
        ),
        link: std::array::from_fn(|k| group.get(k).copied().unwrap_or(u32::MAX)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::prelude::default;

    fn link(a: u32, b: u32) -> Link {
        Link {
            a,
            b,
            inverse_mass_a: 1.0,
            inverse_mass_b: 1.0,
            mass: 0.5,
            normal: DVec2::X,
            separation: 0.0,
            impulse: 0.0,
            step_impulse: 0.0,
            push_out: true,
        }
    }

    #[test]
    fn a_group_never_shares_a_movable_slot_and_every_link_is_in_one_group() {
        // A chain 0-1-2-…-29, every ball on the floor (the anchor, slot 30), and a star on 0.
        let anchor = 30;
        let mut links: Vec<Link> = (0..29).map(|k| link(k, k + 1)).collect();
        links.extend((0..30).map(|k| link(k, anchor)));
        links.extend((2..30).map(|k| link(0, k)));
        let all: Vec<u32> = (0..links.len() as u32).collect();
        let mut colouring = Colouring {
            solvable: all.clone(),
            ..default()
        };
        colouring.group(&links, anchor, 31);
        let order = &colouring.order;
        let groups: Vec<&[u32]> = (colouring.groups.iter())
            .map(|range| &order[range.clone()])
            .collect();
        let mut seen: Vec<u32> = groups.iter().copied().flatten().copied().collect();
        seen.sort_unstable();
        assert_eq!(seen, all);
        for group in &groups {
            assert!((1..=LANES).contains(&group.len()));
            let mut slots: Vec<u32> = group
                .iter()
                .flat_map(|&index| [links[index as usize].a, links[index as usize].b])
                .filter(|&slot| slot != anchor)
                .collect();
            let count = slots.len();
            slots.sort_unstable();
            slots.dedup();
            assert_eq!(slots.len(), count, "{group:?} shares a slot");
        }
        // Ball 0 has 30 links: past the 24 colours the rest go one to a group.
        assert!(groups.iter().filter(|group| group.len() == 1).count() >= 30 - 24);
    }
}
