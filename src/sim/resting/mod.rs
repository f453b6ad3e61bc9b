//! Resting contacts and sleep, for both modes: what makes a pile under gravity hold still.
//!
//! **The resting rule** ([`rest_speed`]): with restitution below 1, an impact closing slower
//! than twice the speed gravity adds in a step does not bounce (a ball resting on the floor
//! meets it at up to one step's gain; twice leaves room for the solver's give). With
//! restitution 1, or without gravity, every impact bounces and nothing here runs. A ball
//! dropped with restitution `e` so bounces with apex heights shrinking by `e²` until its
//! impact speed falls below the resting speed, then stays on the floor.
//!
//! **The stage** ([`rest_and_sleep`], in [`SimSystems::Resting`](super::SimSystems), after
//! the mode's response and before the report) runs these named steps on the snapshot:
//!
//! 1. `wake`: every sleeping island whose ball a hit set flying, that an intent asked for, or
//!    all of them if a parameter that shapes the motion changed (gravity, restitution, mass
//!    model, arena, mode), every ball then put back inside the arena;
//! 2. near pairs (`contacts.rs`): the grid's pairs, and each ball's walls, that touch within
//!    a small margin or could within the step; an awake ball touching a sleeping island wakes
//!    it;
//! 3. `solve`: the balls that rested through the mode's stages (held still there) take one
//!    soft step of [`solver`] with their contacts (balls that are not resting are
//!    immovable anchors for it); the walls' impulses count towards the pressure, and the
//!    bounces it applies are hits; a ball it carried past a wall is put back and stopped
//!    there, and `energy.rs`'s guard takes back any mechanical energy the step gained beyond
//!    what its overlaps could release;
//! 4. `classify`: who rests next step, by mode (its comment says how);
//! 5. `fall_asleep`: islands of touching resting balls, each ball slower than
//!    [`SLEEP_SPEED`] for [`TIME_TO_SLEEP`] and none touching a flying ball, sleep (velocity
//!    exactly zero) until woken; the weight they put on the walls keeps counting.
//!
//! The mode's stages hold resting and sleeping balls still ([`Rest::is_held`]), so a
//! resting ball moves only here, and a sleeping one not at all: its state is bit-identical
//! from step to step.

mod constraint;
mod contacts;
mod energy;
mod islands;
mod sleep;
pub mod solver;
mod state;
mod wide;

use std::mem::take;

use bevy::math::DVec2;
use bevy::prelude::*;

use self::energy::keep_energy;
pub use self::islands::Islands;
pub use self::sleep::{SLEEP_SPEED, TIME_TO_SLEEP};
use self::solver::{Body, Other, RestingContact, SoftStep, soft_step};
use self::state::MotionKey;
pub use self::state::RestingState;
use super::ball::{Ball, BallSnapshot, Position, Rest, RestState, Velocity};
use super::clock::SimClock;
use super::geometry::circle::collision_point;
use super::geometry::wall::wall_contact_point;
use super::params::{CollisionMode, MAX_SPEED, SimParams, Solver};
use super::report::{Hit, StepLog};

/// The resting solver's contact stiffness for a step of `dt` seconds, hertz: an overlap of
/// `δ` between balls of effective mass `m` stores `½·m·(2π·hertz)²·δ²` like a spring.
pub fn contact_hertz(dt: f64) -> f64 {
    CONTACT_STIFFNESS * f64::from(SUBSTEPS) / dt
}

/// The resting speed is this many times the speed gravity adds in a step.
pub const REST_SPEED_STEPS: f64 = 2.0;
/// A ball in contact rests (the solver moves it, without sweeping its path) only while a
/// step takes it no further than this fraction of its radius; faster, it flies (the mode's
/// stages move it, the continuous one without tunnelling).
pub const HOLD_REACH: f64 = 0.25;
/// Substeps of the resting solver's soft step. Box2D's default is 4; 6 costs little more
/// and, with the stiffness its substeps allow, halves the overlaps in a pile (1,000 balls at
/// 10 s: largest 0.04 of a radius against 0.12 with 4).
const SUBSTEPS: u32 = 6;
/// Contact stiffness as a fraction of the substep rate: a quarter, as stiff as Box2D lets a
/// soft contact be (90 Hz at 60 steps a second).
const CONTACT_STIFFNESS: f64 = 0.25;
/// Box2D's contact damping ratio.
const CONTACT_DAMPING_RATIO: f64 = 10.0;
/// The fastest the solver pushes an overlap out, pixels per second.
const MAX_PUSH_SPEED: f64 = 100.0;

/// The resting rule's speed for a step of `dt` seconds, pixels per second: impacts closing
/// slower than it do not bounce. Zero (every impact bounces) with restitution 1 or without
/// gravity.
pub fn rest_speed(params: &SimParams, dt: f64) -> f64 {
    if params.restitution < 1.0 {
        REST_SPEED_STEPS * params.gravity.length() * dt
    } else {
        0.0
    }
}

/// The resting stage: see the module's header for its steps.
pub fn rest_and_sleep(
    clock: Res<SimClock>,
    params: Res<SimParams>,
    solver: Res<Solver>,
    mut snapshot: ResMut<BallSnapshot>,
    mut balls: Query<(Entity, &mut Position, &mut Velocity, &mut Rest), With<Ball>>,
    mut state: ResMut<RestingState>,
    mut log: ResMut<StepLog>,
) {
    let (dt, rest_speed) = (clock.dt, rest_speed(&params, clock.dt));
    let state = &mut *state;
    let key = MotionKey {
        gravity: params.gravity,
        restitution: params.restitution,
        mass_model: params.mass_model,
        arena_size: params.arena_size,
        mode: solver.collisions,
    };
    let changed = state.last_key.replace(key).is_some_and(|last| last != key);
    // As the components said when the movement stage read them (nothing changes a `Rest`
    // between that stage and this one): the elastic gas then never reads a ball's `Rest` here.
    let anyone_held = snapshot.held_when_filled > 0;
    if rest_speed == 0.0 && !anyone_held {
        state.warm.clear();
        return; // the rule is off and nobody rests: the elastic paths stay untouched
    }
    // Read here, after the early return: `state.rests` is only used below it.
    read_rests(&snapshot.entities, &balls, &mut state.rests);
    state.wake_all |= changed || rest_speed == 0.0;
    let snapshot = &mut *snapshot;
    if changed {
        keep_inside(snapshot, params.half_extents());
    }
    if everyone_sleeps_undisturbed(state, &snapshot.held) {
        log.resting_wall_impulse += state.island_load.values().sum::<f64>() * dt;
        return; // sleeping costs nothing
    }
    sleep::wake(state, &snapshot.held);
    state.near.find(
        &snapshot.circles,
        &snapshot.velocities,
        (params.half_extents(), params.gravity),
        dt,
    );
    sleep::wake_touched(state);
    let load = solve(state, snapshot, &params, (dt, rest_speed), &mut log);
    log.resting_wall_impulse += load + state.island_load.values().sum::<f64>() * dt;
    classify(state, snapshot, solver.collisions, rest_speed, dt);
    sleep::fall_asleep(state, &mut snapshot.velocities, dt);
    state.asleep = state.rests.iter().filter(|rest| rest.is_asleep()).count();
    write_back(snapshot, &state.rests, &mut balls);
}

/// Puts every ball back inside the arena `[-half, half]`: after a resize the mode's stages
/// contain only the balls they move, and held ones may have been left outside.
fn keep_inside(snapshot: &mut BallSnapshot, half: DVec2) {
    for circle in &mut snapshot.circles {
        circle.center = inside_arena(circle.center, circle.radius, half);
    }
}

/// `center` moved the least so that a ball of `radius` lies inside the arena `[-half, half]`
/// (centred on an axis it is wider than).
fn inside_arena(center: DVec2, radius: f64, half: DVec2) -> DVec2 {
    let limit = (half - DVec2::splat(radius)).max(DVec2::ZERO);
    center.clamp(-limit, limit)
}

/// Whether every ball sleeps, no hit disturbed one and nothing asks to wake them.
fn everyone_sleeps_undisturbed(state: &RestingState, held: &[bool]) -> bool {
    !state.wake_all
        && state.wake_requests.is_empty()
        && held.iter().all(|&held| held)
        && state.rests.iter().all(Rest::is_asleep)
}

/// Each ball's [`Rest`], in the snapshot's order.
fn read_rests(
    entities: &[Entity],
    balls: &Query<(Entity, &mut Position, &mut Velocity, &mut Rest), With<Ball>>,
    rests: &mut Vec<Rest>,
) {
    rests.clear();
    rests.extend(
        entities
            .iter()
            .map(|&entity| balls.get(entity).map_or(Rest::default(), |ball| *ball.3)),
    );
}

/// Step 3: one soft step for the balls that rested through the step. Returns the walls'
/// impulse on them.
fn solve(
    state: &mut RestingState,
    snapshot: &mut BallSnapshot,
    params: &SimParams,
    (dt, rest_speed): (f64, f64),
    log: &mut StepLog,
) -> f64 {
    let solved =
        |index: usize| state.rests[index].state == RestState::Resting && snapshot.held[index];
    let (mut bodies, mut contacts) = (take(&mut state.bodies), take(&mut state.contacts));
    state.near.solver_input(
        (&snapshot.circles, &snapshot.velocities, &snapshot.entities),
        solved,
        params.mass_model,
        &state.warm,
        (&mut bodies, &mut contacts),
    );
    let load = if contacts.is_empty() && bodies.iter().all(|body| body.inverse_mass == 0.0) {
        0.0
    } else {
        solve_bodies(
            state,
            snapshot,
            params,
            (dt, rest_speed),
            (&mut bodies, &mut contacts),
            log,
        )
    };
    (state.bodies, state.contacts) = (bodies, contacts);
    load
}

/// Step 3 proper: the soft step of `bodies` held by `contacts` (the solver's input), written
/// back to the snapshot. Returns the walls' impulse on them.
fn solve_bodies(
    state: &mut RestingState,
    snapshot: &mut BallSnapshot,
    params: &SimParams,
    (dt, rest_speed): (f64, f64),
    (bodies, contacts): (&mut Vec<Body>, &mut Vec<RestingContact>),
    log: &mut StepLog,
) -> f64 {
    let step = SoftStep {
        dt,
        substeps: SUBSTEPS,
        gravity: params.gravity,
        damping: params.linear_damping,
        hertz: contact_hertz(dt),
        damping_ratio: CONTACT_DAMPING_RATIO,
        max_push_speed: MAX_PUSH_SPEED,
        restitution: params.restitution,
        rest_speed,
    };
    state.start.clear();
    state.start.extend(bodies.iter().map(|body| body.velocity));
    soft_step(bodies, contacts, step, &mut state.memory);
    log_bounces(contacts, snapshot, params, dt, log);
    // Refilled in place, like the solver's memory.
    state.warm.clear();
    (state.warm).extend(state.near.warm_starts(contacts, &snapshot.entities));
    let half = params.half_extents();
    let mut stop_impulse = 0.0;
    for (body, circle) in bodies.iter_mut().zip(&snapshot.circles) {
        if body.inverse_mass == 0.0 {
            continue;
        }
        let (center, velocity) = stop_at_walls(
            body.position + body.shift,
            body.velocity,
            circle.radius,
            half,
        );
        stop_impulse += (body.velocity - velocity).length() / body.inverse_mass;
        (body.shift, body.velocity) = (center - body.position, velocity);
    }
    keep_energy(bodies, &state.start, contacts, params.gravity, step.hertz);
    for (index, body) in bodies.iter().enumerate() {
        if body.inverse_mass > 0.0 {
            snapshot.circles[index].center = body.position + body.shift;
            // A safety net: no velocity leaves the solver faster than any ball may go.
            snapshot.velocities[index] = body.velocity.clamp_length_max(MAX_SPEED);
        }
    }
    state.near.total_wall_impulse() + stop_impulse
}

/// A solved ball's `center` put back inside the arena `[-half, half]` and its `velocity`
/// into each wall it was put back from stopped, as the wall would have stopped it: the
/// solver sees only the walls found near at the start of the step.
fn stop_at_walls(center: DVec2, velocity: DVec2, radius: f64, half: DVec2) -> (DVec2, DVec2) {
    let inside = inside_arena(center, radius, half);
    let pushed = inside - center;
    let into_a_wall = (pushed * velocity).cmplt(DVec2::ZERO);
    let stopped = DVec2::select(into_a_wall, DVec2::ZERO, velocity);
    (inside, stopped)
}

/// The contacts that bounced in the solver are hits like any other, at the end of the step.
fn log_bounces(
    contacts: &[RestingContact],
    snapshot: &BallSnapshot,
    params: &SimParams,
    dt: f64,
    log: &mut StepLog,
) {
    for contact in contacts.iter().filter(|contact| contact.bounced) {
        let circle = snapshot.circles[contact.a as usize];
        let (impulse, closing_speed) = (contact.step_impulse, -contact.closing_velocity);
        log.hits.push(match contact.other {
            Other::Body(b) => Hit::Ball {
                a: contact.a,
                b,
                time: dt,
                point: collision_point(circle, snapshot.circles[b as usize]),
                normal: contact.normal,
                impulse,
                closing_speed,
            },
            Other::Wall(wall) => Hit::Wall {
                ball: contact.a,
                wall,
                time: dt,
                point: wall_contact_point(wall, circle.center, params.half_extents()),
                impulse,
                normal_speed: closing_speed,
            },
        });
    }
}

/// Step 4: who rests next step, by mode. Resting slower than the sleep speed counts towards
/// sleep.
///
/// - Continuous: a ball touching something (a ball or a wall) and slow enough to go no
///   further than [`HOLD_REACH`] of its radius in a step; any other flies, its impacts
///   exact. (Holding only balls slower than the resting speed lets the balls in a forming
///   pile collapse inelastically in flight: 1,000 balls then take 4.2 ms a step, not 0.7.)
/// - Either mode: a ball the response stopped against a held one, at any speed.
/// - Discrete: any ball that could touch something within the step, at any speed (Box2D's
///   speculative contacts: the solver stops it at the contact and bounces it there); only a
///   ball with nothing within reach flies. The tutorial's move-then-separate would melt a
///   pile.
fn classify(
    state: &mut RestingState,
    snapshot: &BallSnapshot,
    mode: CollisionMode,
    rest_speed: f64,
    dt: f64,
) {
    for (index, rest) in state.rests.iter_mut().enumerate() {
        if rest.is_asleep() {
            continue;
        }
        let speed = snapshot.velocities[index].length();
        let in_contact = match mode {
            CollisionMode::Continuous => {
                let hold_speed = rest_speed.max(HOLD_REACH * snapshot.circles[index].radius / dt);
                state.near.touching[index] && speed <= hold_speed
            }
            CollisionMode::Discrete => state.near.near[index],
        };
        let resting = rest_speed > 0.0 && (in_contact || snapshot.stopped[index]);
        rest.state = if resting {
            RestState::Resting
        } else {
            RestState::Free
        };
        rest.still_for = if resting && speed < SLEEP_SPEED {
            rest.still_for + dt
        } else {
            0.0
        };
    }
}

/// Writes each ball's position, velocity and [`Rest`] back.
fn write_back(
    snapshot: &BallSnapshot,
    rests: &[Rest],
    balls: &mut Query<(Entity, &mut Position, &mut Velocity, &mut Rest), With<Ball>>,
) {
    for (index, &entity) in snapshot.entities.iter().enumerate() {
        if let Ok((_, mut position, mut velocity, mut rest)) = balls.get_mut(entity) {
            position.set_if_neq(Position(snapshot.circles[index].center));
            velocity.set_if_neq(Velocity(snapshot.velocities[index]));
            rest.set_if_neq(rests[index]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ball_put_back_inside_stops_moving_into_that_wall_only() {
        let half = DVec2::new(100.0, 50.0);
        // Past the right wall and the floor, moving into both and along neither.
        let (center, velocity) =
            stop_at_walls(DVec2::new(95.0, -45.0), DVec2::new(30.0, -20.0), 10.0, half);
        assert_eq!((center, velocity), (DVec2::new(90.0, -40.0), DVec2::ZERO));
        // Past the floor only, sliding right: the slide is kept.
        let (center, velocity) =
            stop_at_walls(DVec2::new(0.0, -45.0), DVec2::new(30.0, -20.0), 10.0, half);
        assert_eq!(
            (center, velocity),
            (DVec2::new(0.0, -40.0), DVec2::new(30.0, 0.0))
        );
        // Put back but already leaving the wall: untouched velocity.
        let (_, velocity) = stop_at_walls(DVec2::new(0.0, -45.0), DVec2::new(0.0, 5.0), 10.0, half);
        assert_eq!(velocity, DVec2::new(0.0, 5.0));
        // Inside: nothing changes.
        let inside = (DVec2::new(1.0, 2.0), DVec2::new(-3.0, 4.0));
        assert_eq!(stop_at_walls(inside.0, inside.1, 10.0, half), inside);
    }
}
