//! A ballpit scene file as the engines get it: balls in pixels and pixels per second, the
//! arena's corner at the origin, and the physics the scene sets. Loaded and drawn by
//! ballpit's own code, so every engine starts from the state `ballpit run` starts from.

use ballpit::sim::{MassModel, SceneFile, SceneSetup};
use bevy::math::DVec2;

/// Pixels per metre when handing the scene to an engine: radii 5–15 px become 0.05–0.15 m,
/// the sizes both engines are tuned for.
pub const PX_PER_M: f64 = 100.0;
/// Half the thickness of the four static boxes around the arena, pixels.
pub const WALL_HALF: f64 = 100.0;

/// One ball, pixels and pixels per second, the arena's lower left corner at the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    pub position: DVec2,
    pub velocity: DVec2,
    pub radius: f64,
}

/// The scene: its balls, the arena `[0, size]`, gravity, restitution, mass model and step.
#[derive(Clone, Debug)]
pub struct Scene {
    pub balls: Vec<Ball>,
    pub size: DVec2,
    pub gravity: DVec2,
    pub restitution: f64,
    pub mass_model: MassModel,
    /// Seconds.
    pub dt: f64,
    /// The scene as ballpit loads it, for `--interleave`'s ballpit engine.
    pub setup: SceneSetup,
}

impl Scene {
    /// Reads the scene file at `path`; `balls` and `seed` override its `generate` block as
    /// `ballpit run --balls --seed` do.
    pub fn load(path: &str, balls: Option<usize>, seed: Option<u64>) -> Result<Scene, String> {
        let text = std::fs::read_to_string(path).map_err(|error| format!("{path}: {error}"))?;
        let mut file = SceneFile::parse(&text, path).map_err(|error| error.to_string())?;
        if let Some(generate) = file.generate.as_mut() {
            generate.count = balls.unwrap_or(generate.count);
            generate.seed = seed.unwrap_or(generate.seed);
        } else if balls.is_some() || seed.is_some() {
            return Err(format!(
                "{path} generates no balls: --balls and --seed need it to"
            ));
        }
        let setup = file.build(path).map_err(|error| error.to_string())?;
        let half = setup.params.half_extents();
        Ok(Scene {
            balls: (setup.balls.iter())
                .map(|ball| Ball {
                    position: ball.position + half,
                    velocity: ball.velocity,
                    radius: ball.radius,
                })
                .collect(),
            size: setup.params.arena_size,
            gravity: setup.params.gravity,
            restitution: setup.params.restitution,
            mass_model: setup.params.mass_model,
            dt: ballpit::headless::DEFAULT_DT,
            setup,
        })
    }

    /// Whether the scene is a pile (gravity on): then each engine runs with its own defaults
    /// for resting contacts (restitution threshold, sleep), as a user would have them; a gas
    /// runs with every impact elastic and nothing asleep.
    pub fn is_pile(&self) -> bool {
        self.gravity != DVec2::ZERO
    }

    /// Each ball's mass under the scene's mass model, as the engines get it: one
    /// [`PX_PER_M`]th of it in kilograms (under the radius model a ball's mass in kilograms
    /// is its radius in metres). Scaling every mass alike changes no motion.
    pub fn engine_mass(&self, ball: &Ball) -> f32 {
        (self.mass_model.mass(ball.radius) / PX_PER_M) as f32
    }

    /// The four static boxes just outside `[0, w] x [0, h]`, as (centre, half extents),
    /// their ends overlapping so the corners are closed.
    pub fn walls(&self) -> [(DVec2, DVec2); 4] {
        let (w, h, t) = (self.size.x, self.size.y, WALL_HALF);
        [
            (DVec2::new(w / 2.0, -t), DVec2::new(w / 2.0 + 2.0 * t, t)),
            (DVec2::new(w / 2.0, h + t), DVec2::new(w / 2.0 + 2.0 * t, t)),
            (DVec2::new(-t, h / 2.0), DVec2::new(t, h / 2.0 + 2.0 * t)),
            (DVec2::new(w + t, h / 2.0), DVec2::new(t, h / 2.0 + 2.0 * t)),
        ]
    }
}

/// Pixels to metres, as the engines take them.
pub fn metres(px: f64) -> f32 {
    (px / PX_PER_M) as f32
}

/// Metres to pixels.
pub fn pixels(m: f32) -> f64 {
    f64::from(m) * PX_PER_M
}
