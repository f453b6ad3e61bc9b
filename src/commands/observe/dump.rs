//! `--dump OUT.json`: every ball's state, in id order; the last frame of a trajectory is the
//! same state.

use bevy::prelude::*;
use serde::Serialize;

use crate::sim::{Ball, BallId, Position, Radius, SimParams, Velocity};

/// One ball in a `--dump` file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DumpedBall {
    pub id: u32,
    pub x: f64,
    pub y: f64,
    pub vx: f64,
    pub vy: f64,
    pub r: f64,
    pub m: f64,
}

/// The `--dump` file: every ball's final state, in id order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StateDump {
    pub balls: Vec<DumpedBall>,
}

impl StateDump {
    pub fn capture(world: &mut World) -> StateDump {
        let mass_model = world.resource::<SimParams>().mass_model;
        let mut balls: Vec<DumpedBall> = world
            .query_filtered::<(&BallId, &Position, &Velocity, &Radius), With<Ball>>()
            .iter(world)
            .map(|(id, position, velocity, radius)| DumpedBall {
                id: id.0,
                x: position.x,
                y: position.y,
                vx: velocity.x,
                vy: velocity.y,
                r: radius.0,
                m: mass_model.mass(radius.0),
            })
            .collect();
        balls.sort_by_key(|ball| ball.id);
        StateDump { balls }
    }
}
