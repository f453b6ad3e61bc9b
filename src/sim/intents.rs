//! What a player (or any driver of the simulation) asks of it: fling, carry, release or
//! remove a ball, add one, set the ball count. The UI sends [`Intent`] messages;
//! [`apply_intents`] applies them in the fixed step, before the stages, paused or not, so the
//! stages never see a ball change mid-step and the UI never writes simulation components
//! itself. A flung ball that rests or sleeps flies, and its sleeping island wakes; a carried
//! one that sleeps wakes with its island (one that rests stays in the resting solver, see
//! [`carry`](super::carry)); a new ball wakes the islands it touches (the resting stage sees to that); removing balls
//! wakes every island, since balls may have gone from under others.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{Ball, BallState, Position, PreviousPosition, Radius, Rest, Velocity};
use super::carry::{Carried, paused_carry_stop, set_free, wake_if_asleep};
use super::geometry::Circle;
use super::params::{MAX_BALLS, MAX_SPEED, RADIUS_RANGE, RADIUS_SLIDER, RunControl, SimParams};
use super::resting::RestingState;
use super::spawn::{add_smaller_balls, radius_to_fit_beside, set_ball_count, spawn_ball};

/// A request to change the simulation's balls.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub enum Intent {
    /// Give `ball` this velocity (pixels per second; clamped to the accepted speed).
    Fling { ball: Entity, velocity: DVec2 },
    /// Add this ball, with the next id.
    Spawn(BallState),
    /// Add balls at random free spots, or remove the newest, until there are this many.
    SetBallCount(usize),
    /// As `SetBallCount`, the added balls made as small as they must be to fit
    /// ([`add_smaller_balls`]): what the panel offers when the arena is full.
    AddSmallerBalls(usize),
    /// Hold `ball` and carry it towards `target` (arena pixels); sent again as the pointer
    /// moves. Paused, it moves there at once, stopping at the first ball or wall on the way.
    Carry { ball: Entity, target: DVec2 },
    /// Let a carried ball go at this velocity (pixels per second; clamped as a fling is).
    Release { ball: Entity, velocity: DVec2 },
    /// Take this ball out of the simulation.
    Remove(Entity),
}

/// The last [`Intent::SetBallCount`] or [`Intent::AddSmallerBalls`]: how many balls were
/// asked for and how many there are (fewer when the arena is full), and the radius that
/// [`Intent::AddSmallerBalls`] would give the rest (`None`: not even the smallest fit).
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct BallCountOutcome {
    pub wanted: usize,
    pub reached: usize,
    pub smaller_radius: Option<f64>,
}

impl BallCountOutcome {
    /// What the panel says under the count slider when the count asked for was not reached:
    /// the arena is full, and what to do about it.
    pub fn note(&self) -> Option<String> {
        (self.reached < self.wanted).then(|| {
            let advice = match self.smaller_radius {
                Some(radius) => format!(
                    "“Add smaller balls” adds the rest at radius {radius:.1} px; or enlarge the \
                     arena."
                ),
                None => format!(
                    "Even balls of {:.0} px radius do not fit: enlarge the arena.",
                    RADIUS_SLIDER.start()
                ),
            };
            format!(
                "The arena is full: {} of {} balls fit. {advice}",
                self.reached, self.wanted
            )
        })
    }
}

/// Applies every intent sent since the last fixed step, in the order sent.
pub fn apply_intents(mut intents: MessageReader<Intent>, mut commands: Commands) {
    for &intent in intents.read() {
        commands.queue(move |world: &mut World| apply(world, intent));
    }
}

fn apply(world: &mut World, intent: Intent) {
    match intent {
        Intent::Fling { ball, velocity } => fling(world, ball, velocity),
        Intent::Spawn(state) => {
            // Only a ball the simulation accepts: finite, with a radius in range.
            let valid = state.position.is_finite()
                && state.velocity.is_finite()
                && RADIUS_RANGE.contains(&state.radius);
            if valid {
                spawn_ball(world, state);
            }
        }
        Intent::SetBallCount(wanted) => set_count(world, wanted, set_ball_count),
        Intent::AddSmallerBalls(wanted) => set_count(world, wanted, add_smaller_balls),
        Intent::Carry { ball, target } => carry(world, ball, target),
        Intent::Release { ball, velocity } => {
            if let Ok(mut entity) = world.get_entity_mut(ball) {
                entity.remove::<Carried>();
                fling(world, ball, velocity);
            }
        }
        Intent::Remove(ball) => {
            if world.get::<Ball>(ball).is_some() {
                world.despawn(ball);
                world.resource_mut::<RestingState>().wake_all = true;
            }
        }
    }
}

/// Sets the ball count with `set` and records the outcome; every island wakes, since balls
/// may have gone from under others.
fn set_count(world: &mut World, wanted: usize, set: fn(&mut World, usize) -> usize) {
    let reached = set(world, wanted);
    world.resource_mut::<RestingState>().wake_all = true;
    let smaller_radius = (reached < wanted)
        .then(|| radius_to_fit_beside(world, wanted.min(MAX_BALLS) - reached))
        .flatten();
    world.insert_resource(BallCountOutcome {
        wanted,
        reached,
        smaller_radius,
    });
}

/// Gives `ball` `velocity` (clamped to the accepted speed) and sets it flying.
fn fling(world: &mut World, ball: Entity, velocity: DVec2) {
    let velocity = velocity.clamp_length_max(MAX_SPEED);
    if let Some(mut current) = world.get_mut::<Velocity>(ball)
        && velocity.is_finite()
    {
        current.0 = velocity;
        change_rest(world, ball, set_free);
    }
}

/// Holds `ball` with its target at `target`; paused, moves it there at once as far as the
/// way is free, and holds it still.
fn carry(world: &mut World, ball: Entity, target: DVec2) {
    let Some(&Position(center)) = world.get::<Position>(ball) else {
        return;
    };
    let Some(&Radius(radius)) = world.get::<Radius>(ball) else {
        return;
    };
    if !target.is_finite() {
        return;
    }
    world.entity_mut(ball).insert(Carried { target });
    change_rest(world, ball, wake_if_asleep);
    if !world.resource::<RunControl>().paused {
        return;
    }
    let half = world.resource::<SimParams>().half_extents();
    let others: Vec<Circle> = world
        .query_filtered::<(Entity, &Position, &Radius), With<Ball>>()
        .iter(world)
        .filter(|(other, ..)| *other != ball)
        .map(|(_, position, radius)| Circle::new(position.0, radius.0))
        .collect();
    let stop = paused_carry_stop(Circle::new(center, radius), target, others, half);
    let mut entity = world.entity_mut(ball);
    entity.insert((
        Position(stop),
        PreviousPosition(stop),
        Velocity(DVec2::ZERO),
    ));
}

/// Applies `change` to `ball`'s [`Rest`] ([`set_free`], [`wake_if_asleep`]), with the
/// resting state it may ask to wake an island in.
fn change_rest(world: &mut World, ball: Entity, change: fn(&mut Rest, &mut RestingState)) {
    world.resource_scope(|world, mut resting: Mut<RestingState>| {
        if let Some(mut rest) = world.get_mut::<Rest>(ball) {
            change(&mut rest, &mut resting);
        }
    });
}
