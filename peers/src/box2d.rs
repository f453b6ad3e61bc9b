//! Box2D v3.2 (through the `boxdd` crate), set up as a user of it would: 4 substeps (its
//! documented default), one worker, frictionless shapes with the scene's restitution, mass
//! set through the density. A gas: restitution threshold 0 and no sleep, so every impact is
//! elastic; a pile: Box2D's own threshold (1 m/s) and sleep.

use bevy::math::DVec2;
use boxdd::prelude::*;

use crate::Engine;
use crate::scene::{Ball, Scene, metres, pixels};

/// Box2D's documented default (and recommended) substep count.
const SUBSTEPS: i32 = 4;

pub struct Box2d {
    world: World,
    bodies: Vec<BodyId>,
    radii: Vec<f64>,
    dt: f32,
}

impl Box2d {
    pub fn new(scene: &Scene) -> boxdd::Result<Box2d> {
        let foundation = Foundation::initialize_default()?;
        let gravity = Vec2::new(metres(scene.gravity.x), metres(scene.gravity.y));
        let mut builder = WorldBuilder::from(foundation.world_def()).gravity(gravity);
        if !scene.is_pile() {
            builder = builder.restitution_threshold(0.0).enable_sleep(false);
        }
        let mut world = foundation.create_world(builder.build()?)?;
        let material = SurfaceMaterial::new()
            .with_friction(0.0)?
            .with_restitution(scene.restitution as f32)?;
        let wall_shape = ShapeDef::builder().material(material).build()?;
        for (centre, half) in scene.walls() {
            let def = (world.body_builder())
                .body_type(BodyType::Static)
                .position(Position::new(metres(centre.x), metres(centre.y)))
                .build()?;
            let id = world.create_body(def)?;
            let shape = shapes::box_polygon(metres(half.x), metres(half.y))?;
            world.body(id)?.create_polygon(&wall_shape, &shape)?;
        }
        let mut bodies = Vec::with_capacity(scene.balls.len());
        for ball in &scene.balls {
            let def = (world.body_builder())
                .body_type(BodyType::Dynamic)
                .position(Position::new(
                    metres(ball.position.x),
                    metres(ball.position.y),
                ))
                .linear_velocity(Vec2::new(metres(ball.velocity.x), metres(ball.velocity.y)))
                .enable_sleep(scene.is_pile())
                .build()?;
            let id = world.create_body(def)?;
            // Box2D takes a density: mass = density * pi r^2.
            let radius = metres(ball.radius);
            let density = scene.engine_mass(ball) / (std::f32::consts::PI * radius * radius);
            let shape = ShapeDef::builder()
                .material(material)
                .density(density)
                .build()?;
            world
                .body(id)?
                .create_circle(&shape, &Circle::new(Vec2::new(0.0, 0.0), radius)?)?;
            bodies.push(id);
        }
        Ok(Box2d {
            world,
            bodies,
            radii: scene.balls.iter().map(|ball| ball.radius).collect(),
            dt: scene.dt as f32,
        })
    }
}

impl Engine for Box2d {
    fn step(&mut self) {
        let done = self.world.step(self.dt, SUBSTEPS).expect("box2d step");
        assert!(done.post_step_error().is_none(), "box2d post-step error");
    }

    fn balls(&mut self) -> Vec<Ball> {
        (self.bodies.iter().zip(&self.radii))
            .map(|(&id, &radius)| {
                let body = self.world.body(id).expect("live body");
                let (p, v) = (
                    body.position().expect("position"),
                    body.linear_velocity().expect("velocity"),
                );
                Ball {
                    position: DVec2::new(pixels(p.x), pixels(p.y)),
                    velocity: DVec2::new(pixels(v.x), pixels(v.y)),
                    radius,
                }
            })
            .collect()
    }
}
