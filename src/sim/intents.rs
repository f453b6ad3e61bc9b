//! What a player (or any driver of the simulation) asks of it: fling a ball, add one, set the
//! ball count. The UI sends [`Intent`] messages; [`apply_intents`] applies them in the fixed
//! step, before the stages, paused or not, so the stages never see a ball change mid-step and
//! the UI never writes simulation components itself. A flung ball that rests or sleeps flies,
//! and its sleeping island wakes; a new ball wakes the islands it touches (the resting stage
//! sees to that); changing the count wakes every island, since balls may have gone from
//! under others.

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{BallState, Rest, RestState, Velocity};
use super::params::{MAX_SPEED, RADIUS_RANGE};
use super::resting::RestingState;
use super::spawn::{set_ball_count, spawn_ball};

/// A request to change the simulation's balls.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub enum Intent {
    /// Give `ball` this velocity (pixels per second; clamped to the accepted speed).
    Fling { ball: Entity, velocity: DVec2 },
    /// Add this ball, with the next id.
    Spawn(BallState),
    /// Add balls at random free spots, or remove the newest, until there are this many.
    SetBallCount(usize),
}

/// The last [`Intent::SetBallCount`]: how many balls were asked for and how many there are.
/// Fewer are reached when the arena is full.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BallCountOutcome {
    pub wanted: usize,
    pub reached: usize,
}

/// Applies every intent sent since the last fixed step, in the order sent.
pub fn apply_intents(mut intents: MessageReader<Intent>, mut commands: Commands) {
    for &intent in intents.read() {
        commands.queue(move |world: &mut World| apply(world, intent));
    }
}

fn apply(world: &mut World, intent: Intent) {
    match intent {
        Intent::Fling { ball, velocity } => {
            let velocity = velocity.clamp_length_max(MAX_SPEED);
            if let Some(mut current) = world.get_mut::<Velocity>(ball)
                && velocity.is_finite()
            {
                current.0 = velocity;
                wake_and_free(world, ball);
            }
        }
        Intent::Spawn(state) => {
            // Only a ball the simulation accepts: finite, with a radius in range.
            let valid = state.position.is_finite()
                && state.velocity.is_finite()
                && RADIUS_RANGE.contains(&state.radius);
            if valid {
                spawn_ball(world, state);
            }
        }
        Intent::SetBallCount(wanted) => {
            let reached = set_ball_count(world, wanted);
            world.resource_mut::<RestingState>().wake_all = true;
            world.insert_resource(BallCountOutcome { wanted, reached });
        }
    }
}

/// Sets `ball` flying; if it slept, its island wakes at the next step.
fn wake_and_free(world: &mut World, ball: Entity) {
    let Some(mut rest) = world.get_mut::<Rest>(ball) else {
        return;
    };
    let state = std::mem::take(&mut *rest).state;
    if let RestState::Asleep { island } = state {
        world
            .resource_mut::<RestingState>()
            .wake_requests
            .push(island);
    }
}
