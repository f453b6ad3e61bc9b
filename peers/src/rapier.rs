//! rapier2d 0.35, set up as a user of it would: its default integration parameters (4 solver
//! iterations), single-threaded (no `parallel` feature), frictionless colliders with the
//! scene's restitution (`Max` combine, so a pair gets it whatever the other says) and the
//! mass set directly. A gas: nothing asleep; a pile: rapier's own sleep. rapier has no
//! restitution threshold.

use bevy::math::DVec2;
use rapier2d::prelude::*;

use crate::Engine;
use crate::scene::{Ball, Scene, metres, pixels};

pub struct Rapier {
    world: PhysicsWorld,
    bodies: Vec<RigidBodyHandle>,
    radii: Vec<f64>,
}

/// A frictionless collider with restitution `restitution`.
fn material(collider: ColliderBuilder, restitution: f64) -> ColliderBuilder {
    collider
        .friction(0.0)
        .friction_combine_rule(CoefficientCombineRule::Min)
        .restitution(restitution as f32)
        .restitution_combine_rule(CoefficientCombineRule::Max)
}

impl Rapier {
    pub fn new(scene: &Scene) -> Rapier {
        let gravity = Vector::new(metres(scene.gravity.x), metres(scene.gravity.y));
        let mut world = PhysicsWorld {
            gravity,
            ..PhysicsWorld::default()
        };
        world.integration_parameters.dt = scene.dt as f32;
        for (centre, half) in scene.walls() {
            world.insert(
                RigidBodyBuilder::fixed()
                    .translation(Vector::new(metres(centre.x), metres(centre.y))),
                material(
                    ColliderBuilder::cuboid(metres(half.x), metres(half.y)),
                    scene.restitution,
                ),
            );
        }
        let bodies = (scene.balls.iter())
            .map(|ball| {
                let body = RigidBodyBuilder::dynamic()
                    .translation(Vector::new(
                        metres(ball.position.x),
                        metres(ball.position.y),
                    ))
                    .linvel(Vector::new(
                        metres(ball.velocity.x),
                        metres(ball.velocity.y),
                    ))
                    .can_sleep(scene.is_pile());
                let collider = material(
                    ColliderBuilder::ball(metres(ball.radius)),
                    scene.restitution,
                )
                .mass(scene.engine_mass(ball));
                world.insert(body, collider).0
            })
            .collect();
        Rapier {
            world,
            bodies,
            radii: scene.balls.iter().map(|ball| ball.radius).collect(),
        }
    }
}

impl Engine for Rapier {
    fn step(&mut self) {
        self.world.step();
    }

    fn balls(&mut self) -> Vec<Ball> {
        (self.bodies.iter().zip(&self.radii))
            .map(|(&handle, &radius)| {
                let body = &self.world.bodies[handle];
                let (p, v) = (body.translation(), body.linvel());
                Ball {
                    position: DVec2::new(pixels(p.x), pixels(p.y)),
                    velocity: DVec2::new(pixels(v.x), pixels(v.y)),
                    radius,
                }
            })
            .collect()
    }
}
