//! Building a scene: [`SceneFile::build`] validates it and draws and places its random balls,
//! giving a [`SceneSetup`]; [`SceneSetup::apply`] loads that into a world, replacing any balls
//! there. Pure data until `apply`.

use bevy::math::DVec2;
use bevy::prelude::*;
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::check;
use super::file::{DEFAULT_ARENA, Generate, SceneError, SceneFile};
use super::placement::PlacementGrid;
use crate::sim::ball::{Ball, BallId, BallState, NextBallId, ball_bundle};
use crate::sim::clock::SimClock;
use crate::sim::geometry::Circle;
use crate::sim::measure::SimStats;
use crate::sim::params::{CollisionMode, DENSEST_PACKING, MAX_BALLS, SimParams, Solver};

/// Random placement gives up on a ball after this many overlapping tries in a row.
const PLACEMENT_TRIES_PER_BALL: u32 = 2_000;

/// The simulation's random numbers: seeded, so the same seed gives the same scene.
#[derive(Resource, Debug, Clone, PartialEq)]
pub struct SimRng(pub ChaCha8Rng);

impl Default for SimRng {
    fn default() -> Self {
        SimRng(ChaCha8Rng::seed_from_u64(0))
    }
}

/// A validated scene, ready to load into a world.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSetup {
    /// The arena and physics the scene sets.
    pub params: SimParams,
    /// The collision mode, if the scene sets one.
    pub collisions: Option<CollisionMode>,
    pub balls: Vec<BallState>,
    /// The random stream after generation, for anything that draws later.
    pub rng: ChaCha8Rng,
}

impl SceneFile {
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
        Ok((0..self.count)
            .map(|_| {
                let (radius, velocity) = draw_ball(rng, self.radius, self.speed);
                DrawnBall { radius, velocity }
            })
            .collect())
    }
}

/// One random ball's radius and velocity: radius and speed uniform in their (min, max)
/// ranges, direction uniform. Scenes and the ball-count slider draw their balls with it.
pub fn draw_ball(rng: &mut impl Rng, radius: (f64, f64), speed: (f64, f64)) -> (f64, DVec2) {
    let radius = rng.random_range(radius.0..=radius.1);
    let speed = rng.random_range(speed.0..=speed.1);
    let direction = rng.random_range(0.0..std::f64::consts::TAU);
    (radius, DVec2::from_angle(direction) * speed)
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
    /// Replaces the world's balls with this scene's, sets its physics and (if it names one) its
    /// collision mode, reseeds the RNG and zeroes the clock and the counters. How the world is
    /// run (pause, time scale) and the broad phase stay as they were.
    pub fn apply(&self, world: &mut World) {
        let old_balls: Vec<Entity> = world
            .query_filtered::<Entity, With<Ball>>()
            .iter(world)
            .collect();
        for entity in old_balls {
            world.despawn(entity);
        }
        world.insert_resource(self.params.clone());
        let mut solver = world.get_resource::<Solver>().copied().unwrap_or_default();
        if let Some(mode) = self.collisions {
            solver.collisions = mode;
        }
        world.insert_resource(solver);
        world.insert_resource(SimRng(self.rng.clone()));
        world.insert_resource(SimStats::default());
        world.insert_resource(SimClock::default());
        world.spawn_batch(
            space_order(&self.balls)
                .into_iter()
                .map(|index| ball_bundle(BallId(index), self.balls[index as usize])),
        );
        world.insert_resource(NextBallId(self.balls.len() as u32));
    }
}

/// The order the balls are stored in: row by row of square cells a largest diameter wide, in
/// the scene's order within a cell. Balls near each other then lie near each other in every
/// per-ball array (the ECS tables, and the stages' snapshots that follow them): at a million
/// balls, a fifth of a discrete step. Each ball's id stays its place in the scene.
fn space_order(balls: &[BallState]) -> Vec<u32> {
    let (min, max) = balls
        .iter()
        .fold((DVec2::MAX, DVec2::MIN), |(min, max), ball| {
            (min.min(ball.position), max.max(ball.position))
        });
    let largest_radius = balls.iter().map(|ball| ball.radius).fold(0.0, f64::max);
    let cell = (2.0 * largest_radius).max(f64::MIN_POSITIVE);
    // Saturating casts: the balls are inside the arena, but no value can panic here.
    let columns = ((max.x - min.x) / cell) as u64 + 1;
    let cell_of = |ball: &BallState| {
        let place = (ball.position - min) / cell;
        (place.y as u64)
            .saturating_mul(columns)
            .saturating_add(place.x as u64)
    };
    // Scene files hold at most `MAX_BALLS` balls, so an index fits a `u32` (half the memory).
    let mut order: Vec<u32> = (0..balls.len() as u32).collect();
    order.sort_by_key(|&index| cell_of(&balls[index as usize]));
    order
}
