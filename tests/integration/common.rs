//! Shared builders: headless apps with given balls, and readers of their state; the
//! `ballpit` binary run with arguments.

use ballpit::prelude::*;
use bevy::math::DVec2;
use bevy::prelude::*;

/// The fixed step every test uses, seconds.
pub const DT: f64 = 1.0 / 60.0;

/// A headless app in the default (continuous) mode with `params` and these balls (ids in the
/// given order); no step run yet.
pub fn app_with(params: SimParams, balls: &[BallState]) -> App {
    app_in(CollisionMode::default(), params, balls)
}

/// [`app_with`] in collision mode `mode`.
pub fn app_in(mode: CollisionMode, params: SimParams, balls: &[BallState]) -> App {
    let mut app = headless_app(DT);
    let setup = SceneSetup {
        params,
        collisions: Some(mode),
        balls: balls.to_vec(),
        rng: ballpit::sim::SimRng::default().0,
    };
    setup.apply(app.world_mut());
    app
}

/// Pauses or resumes `app`.
pub fn set_paused(app: &mut App, paused: bool) {
    app.world_mut().resource_mut::<RunControl>().paused = paused;
}

/// Steps run since the scene was loaded.
pub fn steps_run(app: &App) -> u64 {
    app.world().resource::<SimClock>().steps
}

pub fn ball(x: f64, y: f64, vx: f64, vy: f64, radius: f64) -> BallState {
    BallState {
        position: DVec2::new(x, y),
        velocity: DVec2::new(vx, vy),
        radius,
    }
}

/// Every ball's state, in id order.
pub fn states(app: &mut App) -> Vec<BallState> {
    let world = app.world_mut();
    let mut balls: Vec<(BallId, BallState)> = world
        .query::<(&BallId, &Position, &Velocity, &Radius)>()
        .iter(world)
        .map(|(id, p, v, r)| {
            (
                *id,
                BallState {
                    position: p.0,
                    velocity: v.0,
                    radius: r.0,
                },
            )
        })
        .collect();
    balls.sort_by_key(|(id, _)| *id);
    balls.into_iter().map(|(_, state)| state).collect()
}

/// The entity of the ball with id `id`.
pub fn entity_of(app: &mut App, id: u32) -> Entity {
    let world = app.world_mut();
    world
        .query::<(Entity, &BallId)>()
        .iter(world)
        .find(|(_, ball_id)| ball_id.0 == id)
        .map(|(entity, _)| entity)
        .expect("a ball with that id")
}

/// Every ball's radius by entity, to look up the balls a collision message names.
pub fn radii_by_entity(app: &mut App) -> std::collections::HashMap<Entity, f64> {
    let world = app.world_mut();
    world
        .query::<(Entity, &Radius)>()
        .iter(world)
        .map(|(e, r)| (e, r.0))
        .collect()
}

/// Runs `steps` fixed steps.
pub fn step(app: &mut App, steps: usize) {
    for _ in 0..steps {
        app.update();
    }
}

/// Loads a shipped scene by file name.
pub fn shipped_scene(name: &str) -> SceneFile {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/scenes")
        .join(name);
    SceneFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Collects every collision message into resources, for tests that audit each hit.
#[derive(Resource, Default)]
pub struct Recorded {
    pub ball_hits: Vec<BallCollision>,
    pub wall_hits: Vec<WallCollision>,
}

pub fn record_collisions(app: &mut App) {
    fn record(
        mut recorded: ResMut<Recorded>,
        mut balls: MessageReader<BallCollision>,
        mut walls: MessageReader<WallCollision>,
    ) {
        recorded.ball_hits.extend(balls.read().copied());
        recorded.wall_hits.extend(walls.read().copied());
    }
    app.init_resource::<Recorded>()
        .add_systems(FixedUpdate, record.after(SimulationStep));
}

/// Runs the `ballpit` binary with `args` from the package's folder.
pub fn ballpit(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_ballpit"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("the ballpit binary runs")
}
