//! Scene files: RON descriptions of an arena and its balls, written by hand or generated.
//!
//! [`SceneFile`] is the file as written; [`SceneFile::build`] validates it and draws the
//! generated balls, giving a [`SceneSetup`]; [`SceneSetup::apply`] loads that into a world
//! (replacing any balls there). Pure data until `apply`; nothing here runs in a schedule.
//!
//! ```ron
//! (
//!   arena: (width: 800.0, height: 600.0),        // centred on the origin, x right, y up
//!   gravity: (0.0, 0.0), restitution: 1.0, mass_model: Radius,   // optional
//!   collisions: Continuous,                        // optional: or Discrete
//!   balls: [ (position: (-100.0, 0.0), velocity: (5.0, 0.0), radius: 10.0) ],  // optional
//!   generate: Some((count: 1000, radius: (5.0, 15.0), speed: (0.0, 500.0),
//!                   area_fraction: 0.30, seed: 1)),   // optional
//! )
//! ```

use std::path::Path;

use bevy::math::DVec2;
use bevy::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ron::extensions::Extensions;
use serde::{Deserialize, Serialize};

use super::ball::{Ball, BallState, NextBallId, ball_bundle};
use super::collision::narrow_phase::Circle;
use super::params::{
    ARENA_SIDE_RANGE, CollisionMode, DAMPING_RANGE, MAX_BALLS, MAX_GRAVITY, MAX_SPEED, MassModel,
    RADIUS_RANGE, RESTITUTION_RANGE, SimParams,
};
use super::placement::PlacementGrid;
use super::stats::SimStats;

/// Largest scene file read, bytes (a million hand-written balls fit in about 80 MB).
pub const MAX_SCENE_BYTES: u64 = 128 * 1024 * 1024;
/// Densest packing of equal discs in the plane, `pi / (2 sqrt 3)`; no scene can beat it.
pub const DENSEST_PACKING: f64 = 0.906_899_682;
/// Arena used when a scene gives neither `arena` nor `area_fraction`, pixels.
pub const DEFAULT_ARENA: DVec2 = DVec2::new(800.0, 600.0);
/// Random placement gives up on a ball after this many overlapping tries in a row.
const PLACEMENT_TRIES_PER_BALL: u32 = 2_000;

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<SimRng>().init_resource::<NextBallId>();
}

/// The simulation's random numbers: seeded, so the same seed gives the same scene.
#[derive(Resource, Debug, Clone, PartialEq)]
pub struct SimRng(pub ChaCha8Rng);

impl Default for SimRng {
    fn default() -> Self {
        SimRng(ChaCha8Rng::seed_from_u64(0))
    }
}

/// A scene file as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Arena size; when absent it comes from `generate.area_fraction`, else 800 x 600.
    #[serde(default)]
    pub arena: Option<ArenaSpec>,
    /// Pixels per second squared, (x, y).
    #[serde(default)]
    pub gravity: (f64, f64),
    #[serde(default = "perfectly_elastic")]
    pub restitution: f64,
    #[serde(default)]
    pub mass_model: MassModel,
    /// Per second.
    #[serde(default)]
    pub linear_damping: f64,
    /// `Continuous` or `Discrete`; when absent, loading the scene keeps the mode in use.
    #[serde(default)]
    pub collisions: Option<CollisionMode>,
    /// Balls placed by hand.
    #[serde(default)]
    pub balls: Vec<BallSpec>,
    /// Random balls added after the hand-placed ones.
    #[serde(default)]
    pub generate: Option<Generate>,
}

fn perfectly_elastic() -> f64 {
    1.0
}

/// Arena size, pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArenaSpec {
    pub width: f64,
    pub height: f64,
}

/// One hand-placed ball: pixels and pixels per second.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallSpec {
    pub position: (f64, f64),
    #[serde(default)]
    pub velocity: (f64, f64),
    pub radius: f64,
}

/// Random balls: radius and speed uniform in their ranges, direction uniform, no overlaps.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Generate {
    pub count: usize,
    /// (min, max) pixels.
    pub radius: (f64, f64),
    /// (min, max) pixels per second.
    pub speed: (f64, f64),
    /// With no `arena`: the arena is the square in which all balls cover this fraction.
    #[serde(default)]
    pub area_fraction: Option<f64>,
    #[serde(default)]
    pub seed: u64,
}

/// Why a scene could not be loaded. Each message names the file, and the line and column or
/// the ball index where it applies.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{origin}: cannot read the scene: {source}")]
    Read {
        origin: String,
        source: std::io::Error,
    },
    #[error("{origin}:{line}:{column}: {message}")]
    Syntax {
        origin: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{origin}: {message}")]
    Invalid { origin: String, message: String },
}

/// A validated scene, ready to load into a world.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSetup {
    /// The arena and physics the scene sets; the rest keep their defaults.
    pub params: SimParams,
    /// The collision mode, if the scene sets one.
    pub collisions: Option<CollisionMode>,
    pub balls: Vec<BallState>,
    /// The random stream after generation, for anything that draws later.
    pub rng: ChaCha8Rng,
}

fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME)
}

impl SceneFile {
    /// Reads and parses the scene file at `path`.
    pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
        let origin = path.display().to_string();
        let read_error = |source| SceneError::Read {
            origin: origin.clone(),
            source,
        };
        let size = std::fs::metadata(path).map_err(read_error)?.len();
        if size > MAX_SCENE_BYTES {
            return Err(SceneError::Invalid {
                origin,
                message: format!(
                    "the file is {size} bytes; scene files are limited to {MAX_SCENE_BYTES}"
                ),
            });
        }
        let text = std::fs::read_to_string(path).map_err(read_error)?;
        SceneFile::parse(&text, &origin)
    }

    /// Parses RON text; `origin` names it in errors (usually the file path).
    pub fn parse(text: &str, origin: &str) -> Result<SceneFile, SceneError> {
        ron_options()
            .from_str(text)
            .map_err(|error| SceneError::Syntax {
                origin: origin.to_string(),
                line: error.span.start.line,
                column: error.span.start.col,
                message: error.code.to_string(),
            })
    }

    /// The scene as pretty RON that [`parse`](Self::parse) reads back to the same value.
    pub fn to_ron(&self) -> String {
        ron_options()
            .to_string_pretty(self, ron::ser::PrettyConfig::default())
            .expect("a scene holds only plain numbers, tuples and enums, which RON always writes")
    }

    /// Validates the scene and draws its random balls; `origin` names it in errors.
    pub fn build(&self, origin: &str) -> Result<SceneSetup, SceneError> {
        let invalid = |message: String| SceneError::Invalid {
            origin: origin.to_string(),
            message,
        };
        let params = self.physics().map_err(invalid)?;
        let hand_placed = self.hand_placed_balls().map_err(invalid)?;
        let seed = self.generate.map_or(0, |g| g.seed);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let drawn = match &self.generate {
            Some(generate) => generate
                .draw(hand_placed.len(), &mut rng)
                .map_err(invalid)?,
            None => Vec::new(),
        };
        let arena_size = self.arena_size(&hand_placed, &drawn).map_err(invalid)?;
        let balls = place_balls(hand_placed, drawn, arena_size, &mut rng).map_err(invalid)?;
        Ok(SceneSetup {
            params: SimParams {
                arena_size,
                ..params
            },
            collisions: self.collisions,
            balls,
            rng,
        })
    }

    fn physics(&self) -> Result<SimParams, String> {
        let gravity = DVec2::from(self.gravity);
        if !(gravity.is_finite() && gravity.abs().max_element() <= MAX_GRAVITY) {
            return Err(format!(
                "gravity {gravity} must be finite, each component within ±{MAX_GRAVITY}"
            ));
        }
        check_range("restitution", self.restitution, &RESTITUTION_RANGE)?;
        check_range("linear_damping", self.linear_damping, &DAMPING_RANGE)?;
        Ok(SimParams {
            gravity,
            restitution: self.restitution,
            mass_model: self.mass_model,
            linear_damping: self.linear_damping,
            ..default()
        })
    }

    fn hand_placed_balls(&self) -> Result<Vec<BallState>, String> {
        if self.balls.len() > MAX_BALLS {
            return Err(format!(
                "{} balls listed; the limit is {MAX_BALLS}",
                self.balls.len()
            ));
        }
        self.balls
            .iter()
            .enumerate()
            .map(|(index, spec)| {
                let ball = BallState {
                    position: DVec2::from(spec.position),
                    velocity: DVec2::from(spec.velocity),
                    radius: spec.radius,
                };
                check_range(&format!("ball {index}: radius"), ball.radius, &RADIUS_RANGE)?;
                if !ball.position.is_finite() {
                    return Err(format!(
                        "ball {index}: position {} is not finite",
                        ball.position
                    ));
                }
                if !(ball.velocity.is_finite() && ball.velocity.length() <= MAX_SPEED) {
                    return Err(format!(
                        "ball {index}: velocity {} must be finite with speed at most {MAX_SPEED}",
                        ball.velocity
                    ));
                }
                Ok(ball)
            })
            .collect()
    }

    fn arena_size(&self, hand_placed: &[BallState], drawn: &[DrawnBall]) -> Result<DVec2, String> {
        let area_fraction = self.generate.and_then(|g| g.area_fraction);
        let size = match (self.arena, area_fraction) {
            (Some(_), Some(_)) => {
                return Err("give either `arena` or `generate.area_fraction`, not both".into());
            }
            (Some(arena), None) => DVec2::new(arena.width, arena.height),
            (None, Some(fraction)) => {
                DVec2::splat((total_disc_area(hand_placed, drawn) / fraction).sqrt())
            }
            (None, None) => DEFAULT_ARENA,
        };
        for (name, side) in [("width", size.x), ("height", size.y)] {
            check_range(&format!("arena {name}"), side, &ARENA_SIDE_RANGE)?;
        }
        Ok(size)
    }
}

impl Generate {
    /// Checks the ranges, then draws each ball's radius and velocity (positions come later).
    fn draw(&self, already: usize, rng: &mut ChaCha8Rng) -> Result<Vec<DrawnBall>, String> {
        if self.count > MAX_BALLS - already {
            return Err(format!(
                "generate.count {} with {already} hand-placed balls exceeds the limit of {MAX_BALLS}",
                self.count
            ));
        }
        let (r_min, r_max) = self.radius;
        check_range("generate.radius min", r_min, &RADIUS_RANGE)?;
        check_range("generate.radius max", r_max, &(r_min..=*RADIUS_RANGE.end()))?;
        let (s_min, s_max) = self.speed;
        check_range("generate.speed min", s_min, &(0.0..=MAX_SPEED))?;
        check_range("generate.speed max", s_max, &(s_min..=MAX_SPEED))?;
        if let Some(fraction) = self.area_fraction {
            check_range(
                "generate.area_fraction",
                fraction,
                &(f64::MIN_POSITIVE..=DENSEST_PACKING),
            )?;
        }
        Ok((0..self.count)
            .map(|_| {
                let radius = rng.random_range(r_min..=r_max);
                let speed = rng.random_range(s_min..=s_max);
                let direction = rng.random_range(0.0..std::f64::consts::TAU);
                DrawnBall {
                    radius,
                    velocity: DVec2::from_angle(direction) * speed,
                }
            })
            .collect())
    }
}

/// A generated ball before it has a place.
struct DrawnBall {
    radius: f64,
    velocity: DVec2,
}

fn radii<'a>(
    hand_placed: &'a [BallState],
    drawn: &'a [DrawnBall],
) -> impl Iterator<Item = f64> + 'a {
    hand_placed
        .iter()
        .map(|b| b.radius)
        .chain(drawn.iter().map(|b| b.radius))
}

/// Total area of all the balls' discs, square pixels.
fn total_disc_area(hand_placed: &[BallState], drawn: &[DrawnBall]) -> f64 {
    radii(hand_placed, drawn)
        .map(|r| std::f64::consts::PI * r * r)
        .sum()
}

fn check_range(
    name: &str,
    value: f64,
    range: &std::ops::RangeInclusive<f64>,
) -> Result<(), String> {
    if range.contains(&value) {
        Ok(())
    } else {
        Err(format!(
            "{name} is {value}; it must lie in [{}, {}]",
            range.start(),
            range.end()
        ))
    }
}

/// Checks the hand-placed balls lie inside the arena without overlapping, then places the
/// drawn ones at random free spots.
fn place_balls(
    hand_placed: Vec<BallState>,
    drawn: Vec<DrawnBall>,
    arena_size: DVec2,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<BallState>, String> {
    let half = arena_size * 0.5;
    let covered = total_disc_area(&hand_placed, &drawn) / (arena_size.x * arena_size.y);
    if covered > DENSEST_PACKING {
        return Err(format!(
            "the balls would cover {:.0}% of the {} x {} arena; no packing of discs exceeds {:.1}%",
            covered * 100.0,
            arena_size.x,
            arena_size.y,
            DENSEST_PACKING * 100.0
        ));
    }
    let largest_radius = radii(&hand_placed, &drawn).fold(0.0, f64::max);
    let total = hand_placed.len() + drawn.len();
    let mut grid = PlacementGrid::new(half, largest_radius, total);
    let mut balls = Vec::with_capacity(total);
    for (index, ball) in hand_placed.into_iter().enumerate() {
        let limit = half - DVec2::splat(ball.radius);
        if ball.position.x.abs() > limit.x || ball.position.y.abs() > limit.y {
            return Err(format!(
                "ball {index} at {} with radius {} lies outside the {} x {} arena",
                ball.position, ball.radius, arena_size.x, arena_size.y
            ));
        }
        let circle = Circle::new(ball.position, ball.radius);
        if let Some(other) = grid.first_overlap(circle) {
            return Err(format!("balls {other} and {index} overlap"));
        }
        grid.insert(circle);
        balls.push(ball);
    }
    for (k, ball) in drawn.into_iter().enumerate() {
        let index = balls.len();
        let limit = half - DVec2::splat(ball.radius);
        if limit.min_element() < 0.0 {
            return Err(format!(
                "generated ball {k} (radius {}) is wider than the {} x {} arena",
                ball.radius, arena_size.x, arena_size.y
            ));
        }
        let spot = grid.random_free_spot(ball.radius, half, rng, PLACEMENT_TRIES_PER_BALL);
        let Some(position) = spot else {
            return Err(format!(
                "could not place generated ball {k} of {total} (ball {index}) without overlap after \
                 {PLACEMENT_TRIES_PER_BALL} tries: the balls cover {:.0}% of the arena, and random \
                 placement stalls near 50%; use fewer or smaller balls, or a larger arena",
                covered * 100.0
            ));
        };
        grid.insert(Circle::new(position, ball.radius));
        balls.push(BallState {
            position,
            velocity: ball.velocity,
            radius: ball.radius,
        });
    }
    Ok(balls)
}

impl SceneSetup {
    /// Replaces the world's balls with this scene's, sets its physics (keeping the pause
    /// state, time scale and broad phase already chosen), reseeds the RNG and zeroes the
    /// counters.
    pub fn apply(&self, world: &mut World) {
        let old_balls: Vec<Entity> = world
            .query_filtered::<Entity, With<Ball>>()
            .iter(world)
            .collect();
        for entity in old_balls {
            world.despawn(entity);
        }
        let mut params = world
            .get_resource::<SimParams>()
            .cloned()
            .unwrap_or_default();
        params.arena_size = self.params.arena_size;
        params.gravity = self.params.gravity;
        params.restitution = self.params.restitution;
        params.mass_model = self.params.mass_model;
        params.linear_damping = self.params.linear_damping;
        if let Some(mode) = self.collisions {
            params.collisions = mode;
        }
        world.insert_resource(params);
        world.insert_resource(SimRng(self.rng.clone()));
        world.insert_resource(SimStats::default());
        let mut next_id = NextBallId::default();
        world.spawn_batch(
            self.balls
                .iter()
                .map(|&ball| ball_bundle(next_id.take(), ball))
                .collect::<Vec<_>>(),
        );
        world.insert_resource(next_id);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_fraction_sets_a_square_arena() {
        let scene = SceneFile::parse(
            "(generate: Some((count: 100, radius: (10.0, 10.0), speed: (0.0, 0.0), area_fraction: 0.25)))",
            "test",
        )
        .unwrap();
        let setup = scene.build("test").unwrap();
        let expected_side = (100.0 * std::f64::consts::PI * 100.0 / 0.25_f64).sqrt();
        assert!((setup.params.arena_size.x - expected_side).abs() < 1e-9);
        assert_eq!(setup.params.arena_size.x, setup.params.arena_size.y);
    }
}
