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
use super::placement::{PlacementGrid, overlapping};
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
    #[serde(default, deserialize_with = "checked::gravity")]
    pub gravity: (f64, f64),
    #[serde(
        default = "perfectly_elastic",
        deserialize_with = "checked::restitution"
    )]
    pub restitution: f64,
    #[serde(default)]
    pub mass_model: MassModel,
    /// Per second.
    #[serde(default, deserialize_with = "checked::damping")]
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
    #[serde(deserialize_with = "checked::arena_width")]
    pub width: f64,
    #[serde(deserialize_with = "checked::arena_height")]
    pub height: f64,
}

/// One hand-placed ball: pixels and pixels per second.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallSpec {
    #[serde(deserialize_with = "checked::position")]
    pub position: (f64, f64),
    #[serde(default, deserialize_with = "checked::velocity")]
    pub velocity: (f64, f64),
    #[serde(deserialize_with = "checked::radius")]
    pub radius: f64,
}

/// Random balls: radius and speed uniform in their ranges, direction uniform, no overlaps.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Generate {
    #[serde(deserialize_with = "checked::count")]
    pub count: usize,
    /// (min, max) pixels.
    #[serde(deserialize_with = "checked::radius_range")]
    pub radius: (f64, f64),
    /// (min, max) pixels per second.
    #[serde(deserialize_with = "checked::speed_range")]
    pub speed: (f64, f64),
    /// With no `arena`: the arena is the square in which all balls cover this fraction.
    #[serde(default, deserialize_with = "checked::area_fraction")]
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
        check::gravity(&self.gravity)?;
        check::restitution(&self.restitution)?;
        check::damping(&self.linear_damping)?;
        Ok(SimParams {
            gravity: DVec2::from(self.gravity),
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
                check::radius(&spec.radius)
                    .and(check::position(&spec.position))
                    .and(check::velocity(&spec.velocity))
                    .map_err(|error| format!("ball {index}: {error}"))?;
                Ok(BallState {
                    position: DVec2::from(spec.position),
                    velocity: DVec2::from(spec.velocity),
                    radius: spec.radius,
                })
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
        check::arena_width(&size.x).and(check::arena_height(&size.y))?;
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
        check::radius_range(&self.radius)
            .and(check::speed_range(&self.speed))
            .and(check::area_fraction(&self.area_fraction))
            .map_err(|error| format!("generate: {error}"))?;
        let ((r_min, r_max), (s_min, s_max)) = (self.radius, self.speed);
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

/// The checks on single values, shared by parsing (which adds the line and column) and by
/// [`SceneFile::build`] (for scenes made or changed in code, which adds the ball or field).
mod check {
    use std::ops::RangeInclusive;

    use super::*;

    fn in_range(value: f64, range: &RangeInclusive<f64>) -> Result<(), String> {
        if range.contains(&value) {
            Ok(())
        } else {
            Err(format!(
                "{value} is outside [{}, {}]",
                range.start(),
                range.end()
            ))
        }
    }

    fn named(name: &str, result: Result<(), String>) -> Result<(), String> {
        result.map_err(|error| format!("{name} {error}"))
    }

    /// A (min, max) pair, each in `range`, min not above max.
    fn ordered(pair: (f64, f64), range: &RangeInclusive<f64>) -> Result<(), String> {
        named("min", in_range(pair.0, range))?;
        named("max", in_range(pair.1, &(pair.0..=*range.end())))
    }

    pub fn gravity(&(x, y): &(f64, f64)) -> Result<(), String> {
        named("gravity x", in_range(x, &(-MAX_GRAVITY..=MAX_GRAVITY)))?;
        named("gravity y", in_range(y, &(-MAX_GRAVITY..=MAX_GRAVITY)))
    }

    pub fn restitution(value: &f64) -> Result<(), String> {
        named("restitution", in_range(*value, &RESTITUTION_RANGE))
    }

    pub fn damping(value: &f64) -> Result<(), String> {
        named("linear_damping", in_range(*value, &DAMPING_RANGE))
    }

    pub fn arena_width(value: &f64) -> Result<(), String> {
        named("arena width", in_range(*value, &ARENA_SIDE_RANGE))
    }

    pub fn arena_height(value: &f64) -> Result<(), String> {
        named("arena height", in_range(*value, &ARENA_SIDE_RANGE))
    }

    pub fn radius(value: &f64) -> Result<(), String> {
        named("radius", in_range(*value, &RADIUS_RANGE))
    }

    pub fn position(&(x, y): &(f64, f64)) -> Result<(), String> {
        if x.is_finite() && y.is_finite() {
            Ok(())
        } else {
            Err(format!("position ({x}, {y}) is not finite"))
        }
    }

    pub fn velocity(&(x, y): &(f64, f64)) -> Result<(), String> {
        let speed = x.hypot(y);
        named("speed", in_range(speed, &(0.0..=MAX_SPEED)))
            .map_err(|error| format!("velocity ({x}, {y}): {error}"))
    }

    pub fn count(value: &usize) -> Result<(), String> {
        if *value <= MAX_BALLS {
            Ok(())
        } else {
            Err(format!("count {value} is over the limit of {MAX_BALLS}"))
        }
    }

    pub fn radius_range(pair: &(f64, f64)) -> Result<(), String> {
        named("radius", ordered(*pair, &RADIUS_RANGE))
    }

    pub fn speed_range(pair: &(f64, f64)) -> Result<(), String> {
        named("speed", ordered(*pair, &(0.0..=MAX_SPEED)))
    }

    pub fn area_fraction(value: &Option<f64>) -> Result<(), String> {
        match value {
            Some(fraction) => named(
                "area_fraction",
                in_range(*fraction, &(f64::MIN_POSITIVE..=DENSEST_PACKING)),
            ),
            None => Ok(()),
        }
    }
}

/// Deserializers that apply [`check`] as each value is read, so a bad value is reported at
/// its line and column.
mod checked {
    use serde::{Deserialize, Deserializer, de::Error};

    use super::check;

    fn read<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        deserializer: D,
        check: fn(&T) -> Result<(), String>,
    ) -> Result<T, D::Error> {
        let value = T::deserialize(deserializer)?;
        check(&value).map_err(D::Error::custom)?;
        Ok(value)
    }

    pub fn gravity<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::gravity)
    }
    pub fn restitution<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::restitution)
    }
    pub fn damping<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::damping)
    }
    pub fn arena_width<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::arena_width)
    }
    pub fn arena_height<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::arena_height)
    }
    pub fn position<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::position)
    }
    pub fn velocity<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::velocity)
    }
    pub fn radius<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        read(d, check::radius)
    }
    pub fn count<'de, D: Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
        read(d, check::count)
    }
    pub fn radius_range<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::radius_range)
    }
    pub fn speed_range<'de, D: Deserializer<'de>>(d: D) -> Result<(f64, f64), D::Error> {
        read(d, check::speed_range)
    }
    pub fn area_fraction<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        read(d, check::area_fraction)
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

/// Scenes with more balls than this are parsed but not built by [`audit_scene_text`]: placing
/// a million balls is correct but slow, and would starve a fuzzer of inputs.
pub const AUDIT_MAX_BUILT_BALLS: usize = 20_000;
/// Scenes up to this many balls are also checked pair by pair for overlaps.
const AUDIT_MAX_PAIRWISE_BALLS: usize = 500;

/// What the fuzzer (`fuzz/`) and its regression tests check of any text offered as a scene:
/// reading it may fail but must not panic; a scene that parses writes back to RON that parses
/// to the same scene; a scene that builds (up to [`AUDIT_MAX_BUILT_BALLS`]) has every ball
/// finite, inside its arena and, up to 500 balls, none overlapping. `Err` says which of these
/// failed.
pub fn audit_scene_text(text: &str) -> Result<(), String> {
    let Ok(scene) = SceneFile::parse(text, "audit") else {
        return Ok(());
    };
    let written = scene.to_ron();
    let reread = SceneFile::parse(&written, "audit (written back)")
        .map_err(|error| format!("a parsed scene wrote unreadable RON: {error}\n{written}"))?;
    if reread.to_ron() != written {
        return Err(format!("writing back changed the scene:\n{written}"));
    }
    let count = scene.balls.len() + scene.generate.map_or(0, |g| g.count);
    if count > AUDIT_MAX_BUILT_BALLS {
        return Ok(());
    }
    let Ok(setup) = scene.build("audit") else {
        return Ok(());
    };
    let half = setup.params.half_extents();
    if !(half.is_finite() && half.min_element() > 0.0) {
        return Err(format!("arena {}", setup.params.arena_size));
    }
    for (index, ball) in setup.balls.iter().enumerate() {
        let room = half - DVec2::splat(ball.radius);
        let inside = ball.position.abs().cmple(room * (1.0 + 1e-12)).all();
        if !(ball.position.is_finite() && ball.velocity.is_finite() && ball.radius > 0.0 && inside)
        {
            return Err(format!(
                "ball {index}: {ball:?} in arena {}",
                setup.params.arena_size
            ));
        }
    }
    if setup.balls.len() <= AUDIT_MAX_PAIRWISE_BALLS {
        for (i, a) in setup.balls.iter().enumerate() {
            for (j, b) in setup.balls.iter().enumerate().skip(i + 1) {
                if overlapping(
                    Circle::new(a.position, a.radius),
                    Circle::new(b.position, b.radius),
                ) {
                    return Err(format!("balls {i} and {j} overlap: {a:?} {b:?}"));
                }
            }
        }
    }
    Ok(())
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
