//! Adding and removing balls in a running simulation: the ball-count slider grows or shrinks
//! the population, a click puts a ball in free space. World functions that the
//! [`Intent`](super::Intent)s call in the fixed step, and the pure geometry behind them; no
//! systems of their own.

use std::ops::RangeInclusive;

use bevy::math::DVec2;
use bevy::prelude::*;

use super::ball::{Ball, BallId, BallState, NextBallId, Position, Radius, ball_bundle};
use super::geometry::Circle;
use super::params::{MAX_BALLS, MAX_SPEED, RADIUS_RANGE, RADIUS_SLIDER, SimParams};
use super::scene::placement::PlacementGrid;
use super::scene::{SimRng, draw_ball};

/// Random placement tries per added ball before the arena counts as full.
const PLACEMENT_TRIES: u32 = 200;

/// Radius and speed ranges for balls added while running (the count slider, clicks).
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq)]
#[reflect(Resource)]
pub struct SpawnSettings {
    /// (min, max) pixels.
    pub radius: (f64, f64),
    /// (min, max) pixels per second.
    pub speed: (f64, f64),
}

impl Default for SpawnSettings {
    fn default() -> Self {
        SpawnSettings {
            radius: (10.0, 40.0),
            speed: (100.0, 350.0),
        }
    }
}

impl SpawnSettings {
    /// Brings both ranges within the accepted limits, min never above max, NaN to defaults.
    pub fn clamp_to_limits(&mut self) {
        let defaults = SpawnSettings::default();
        self.radius = clamp_range(self.radius, &RADIUS_RANGE, defaults.radius);
        self.speed = clamp_range(self.speed, &(0.0..=MAX_SPEED), defaults.speed);
    }
}

fn clamp_range(
    range: (f64, f64),
    limits: &RangeInclusive<f64>,
    fallback: (f64, f64),
) -> (f64, f64) {
    if !(range.0.is_finite() && range.1.is_finite()) {
        return fallback;
    }
    let low = range.0.clamp(*limits.start(), *limits.end());
    (low, range.1.clamp(low, *limits.end()))
}

/// Spawns one ball with the next id.
pub fn spawn_ball(world: &mut World, state: BallState) -> Entity {
    let id = world.resource_mut::<NextBallId>().take();
    world.spawn(ball_bundle(id, state)).id()
}

/// Adds or removes balls until there are `target` (at most [`MAX_BALLS`]). Removes the newest
/// first; adds balls with radius and velocity drawn from [`SpawnSettings`] at random free
/// spots. Returns how many balls there are afterwards: fewer than asked when the arena is full.
pub fn set_ball_count(world: &mut World, target: usize) -> usize {
    let target = target.min(MAX_BALLS);
    let mut balls: Vec<(BallId, Entity, Circle)> = world
        .query_filtered::<(&BallId, Entity, &Position, &Radius), With<Ball>>()
        .iter(world)
        .map(|(id, entity, position, radius)| (*id, entity, Circle::new(position.0, radius.0)))
        .collect();
    if balls.len() >= target {
        balls.sort_by_key(|(id, _, _)| *id);
        for (_, entity, _) in balls.drain(target..) {
            world.despawn(entity);
        }
        return target;
    }
    let half = world.resource::<SimParams>().half_extents();
    let settings = *world.resource::<SpawnSettings>();
    let largest = balls
        .iter()
        .map(|(_, _, c)| c.radius)
        .fold(settings.radius.1, f64::max);
    let mut grid = PlacementGrid::new(half, largest, target);
    for (_, _, circle) in &balls {
        grid.insert(*circle);
    }
    let mut count = balls.len();
    let mut rng = world.resource_mut::<SimRng>().0.clone();
    while count < target {
        let (radius, velocity) = draw_ball(&mut rng, settings.radius, settings.speed);
        let Some(position) = grid.random_free_spot(radius, half, &mut rng, PLACEMENT_TRIES) else {
            break;
        };
        grid.insert(Circle::new(position, radius));
        spawn_ball(
            world,
            BallState {
                position,
                velocity,
                radius,
            },
        );
        count += 1;
    }
    world.resource_mut::<SimRng>().0 = rng;
    count
}

/// The share of an arena's free area that balls added at random free spots may fill: random
/// sequential addition of equal discs jams near 0.55, and finds spots quickly well below it.
pub const FILL_SHARE: f64 = 0.3;

/// The radius of `more` equal balls that fill [`FILL_SHARE`] of the area an arena of `arena`
/// pixels has free beside balls covering `covered` square pixels; `None` when that is
/// smaller than the smallest ball a player adds, or no area is free.
pub fn radius_to_fit(arena: DVec2, covered: f64, more: usize) -> Option<f64> {
    let free = arena.x * arena.y - covered;
    let radius = (FILL_SHARE * free / (std::f64::consts::PI * more.max(1) as f64)).sqrt();
    let largest = *RADIUS_SLIDER.end();
    (radius >= *RADIUS_SLIDER.start()).then_some(radius.min(largest))
}

/// The radius [`radius_to_fit`] gives `more` balls added beside the balls in `world`, in its
/// arena.
pub fn radius_to_fit_beside(world: &mut World, more: usize) -> Option<f64> {
    let covered: f64 = world
        .query_filtered::<&Radius, With<Ball>>()
        .iter(world)
        .map(|radius| std::f64::consts::PI * radius.0 * radius.0)
        .sum();
    radius_to_fit(world.resource::<SimParams>().arena_size, covered, more)
}

/// Adds balls until there are `target` as [`set_ball_count`] does, drawing the added balls'
/// radius as [`radius_to_fit_beside`] gives (and keeping it in the [`SpawnSettings`]), so that
/// they fit beside the balls already there. Returns the count reached.
pub fn add_smaller_balls(world: &mut World, target: usize) -> usize {
    let present = world.query_filtered::<(), With<Ball>>().iter(world).count();
    let more = target.min(MAX_BALLS).saturating_sub(present);
    if let Some(radius) = radius_to_fit_beside(world, more) {
        world.resource_mut::<SpawnSettings>().radius = (radius, radius);
    }
    set_ball_count(world, target)
}

/// The radius of a ball centred at `point` that fits in the arena `[-half, half]` without
/// overlapping any of `nearby`: `wanted` when there is room, smaller when not, `None` when
/// not even the smallest ball a player adds (the radius sliders' least) fits.
pub fn fit_radius_at(
    point: DVec2,
    wanted: f64,
    half: DVec2,
    nearby: impl IntoIterator<Item = Circle>,
) -> Option<f64> {
    let to_walls = (half - point.abs()).min_element();
    let room = nearby
        .into_iter()
        .map(|circle| circle.center.distance(point) - circle.radius)
        .fold(to_walls, f64::min);
    let radius = wanted.min(room);
    (radius >= *RADIUS_SLIDER.start()).then_some(radius)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_radius_to_fit_fills_a_share_of_the_free_area() {
        let arena = DVec2::new(800.0, 600.0);
        let covered = 80_000.0;
        let radius = radius_to_fit(arena, covered, 2_000).unwrap();
        let filled = 2_000.0 * std::f64::consts::PI * radius * radius;
        assert!((filled / (480_000.0 - covered) - FILL_SHARE).abs() < 1e-12);
        // Too many for the smallest ball, or no room: none.
        assert_eq!(radius_to_fit(arena, covered, 100_000), None);
        assert_eq!(radius_to_fit(arena, 480_000.0, 1), None);
        // A few balls in a large arena: no larger than the sliders reach.
        assert_eq!(radius_to_fit(arena, 0.0, 1), Some(*RADIUS_SLIDER.end()));
    }

    #[test]
    fn fit_radius_shrinks_to_the_room_available() {
        let half = DVec2::splat(100.0);
        let others = [Circle::new(DVec2::new(30.0, 0.0), 10.0)];
        assert_eq!(fit_radius_at(DVec2::ZERO, 15.0, half, others), Some(15.0));
        assert_eq!(fit_radius_at(DVec2::ZERO, 25.0, half, others), Some(20.0));
        assert_eq!(
            fit_radius_at(DVec2::new(95.0, 0.0), 25.0, half, []),
            Some(5.0)
        );
        // Room for less than the smallest ball a player adds: none.
        assert_eq!(fit_radius_at(DVec2::new(98.0, 0.0), 25.0, half, []), None);
        assert_eq!(
            fit_radius_at(DVec2::new(25.0, 0.0), 25.0, half, others),
            None
        );
        assert_eq!(fit_radius_at(DVec2::new(300.0, 0.0), 5.0, half, []), None);
    }

    #[test]
    fn clamped_ranges_are_ordered_and_finite() {
        let mut settings = SpawnSettings {
            radius: (50.0, 2.0),
            speed: (f64::NAN, 3.0),
        };
        settings.clamp_to_limits();
        assert_eq!(settings.radius, (50.0, 50.0));
        assert_eq!(settings.speed, SpawnSettings::default().speed);
        let mut settings = SpawnSettings {
            radius: (0.0, 1e9),
            speed: (-5.0, 1e12),
        };
        settings.clamp_to_limits();
        assert_eq!(settings.radius, (0.5, 1000.0));
        assert_eq!(settings.speed, (0.0, MAX_SPEED));
    }
}
