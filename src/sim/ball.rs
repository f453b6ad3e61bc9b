//! The ball components, the simulation's state, one entity per ball; and the
//! [`BallSnapshot`], the same balls in contiguous arrays for the stages to work on, filled
//! from the components and written back to them table by table, in parallel for many balls.
//!
//! Positions and velocities are `f64`: the collision maths (and the continuous mode's time of
//! impact) keep energy to 1e-6 only with that precision. Rendering converts to `f32`.

use bevy::ecs::change_detection::{ContiguousComponentTicksMut, ContiguousMut};
use bevy::math::DVec2;
use bevy::prelude::*;

use super::geometry::Circle;
use super::geometry::circle::RadiusRange;
use super::parallel::{BALLS_PER_PIECE, in_pieces, piece_ranges, take_front, worth_splitting};

/// Marks a simulated ball; spawning it brings the state components along.
#[derive(Component, Debug, Default, Clone, Copy)]
#[require(BallId, Position, Velocity, Radius, Rest)]
pub struct Ball;

/// A ball's stable number, in spawn order: what reports and dumps call it.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct BallId(pub u32);

/// Centre of the ball, pixels, arena coordinates (origin at the arena's centre, y up).
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct Position(pub DVec2);

/// The centre at the start of the latest fixed step, for drawing between steps. The render
/// plugin gives it to every ball; a headless run, which draws nothing, does without (at a
/// million balls it is 24 MB), and the movement stage keeps it only where it is.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct PreviousPosition(pub DVec2);

/// Pixels per second.
#[derive(Component, Debug, Default, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct Velocity(pub DVec2);

/// Pixels. Mass follows from it through the [`MassModel`](super::MassModel).
#[derive(Component, Debug, Clone, Copy, PartialEq, Deref, DerefMut)]
pub struct Radius(pub f64);

impl Default for Radius {
    fn default() -> Self {
        Radius(10.0)
    }
}

/// Whether a ball flies, rests on others in the contact solver, or sleeps (see
/// [`resting`](super::resting)). Free balls move in their mode's stages; resting and
/// sleeping ones hold still there (an impact can free them) and only the resting stage
/// moves resting ones.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq)]
pub struct Rest {
    pub state: RestState,
    /// Seconds it has stayed slower than the sleep speed while resting.
    pub still_for: f64,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RestState {
    /// In free flight: the mode's stages move it.
    #[default]
    Free,
    /// Touching others or a wall, slow: the resting solver moves it.
    Resting,
    /// Asleep with the rest of its island of touching balls: nothing moves it.
    Asleep { island: u32 },
}

impl Rest {
    /// Whether the mode's stages hold it still (resting or asleep).
    pub fn is_held(&self) -> bool {
        self.state != RestState::Free
    }

    pub fn is_asleep(&self) -> bool {
        matches!(self.state, RestState::Asleep { .. })
    }
}

/// One ball's state as plain values: what scene files describe and dumps record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BallState {
    pub position: DVec2,
    pub velocity: DVec2,
    pub radius: f64,
}

/// Hands out [`BallId`]s in spawn order.
#[derive(Resource, Debug, Default)]
pub struct NextBallId(pub u32);

impl NextBallId {
    pub fn take(&mut self) -> BallId {
        let id = BallId(self.0);
        self.0 += 1;
        id
    }
}

/// The components that make `state` a simulated ball with number `id`.
pub fn ball_bundle(id: BallId, state: BallState) -> (Ball, BallId, Position, Velocity, Radius) {
    (
        Ball,
        id,
        Position(state.position),
        Velocity(state.velocity),
        Radius(state.radius),
    )
}

/// Every ball after this step's movement, in query order, in contiguous arrays. The movement
/// stage copies the balls into it and moves them there, the collision stage searches it and
/// the response works on it by index before writing every ball back to its components.
#[derive(Resource, Debug, Default)]
pub struct BallSnapshot {
    pub entities: Vec<Entity>,
    pub circles: Vec<Circle>,
    /// Pixels per second.
    pub velocities: Vec<DVec2>,
    /// Whether the ball is held still in the mode's stages (resting or asleep). The
    /// response clears it for a ball an impact sets moving.
    pub held: Vec<bool>,
    /// Whether the response stopped the ball against a held one, to join the resting
    /// solver at the next step (the continuous mode's impacts on a pile).
    pub stopped: Vec<bool>,
    /// How many balls were held when the movement stage filled the snapshot, as their
    /// [`Rest`] said: the count the response's releases do not change.
    pub held_when_filled: usize,
    /// The smallest and largest radius among the balls, as filled.
    pub radii: RadiusRange,
}

impl BallSnapshot {
    /// Whether every ball is held still: the mode's stages then have nothing to do.
    pub fn all_held(&self) -> bool {
        self.held.iter().all(|&held| held)
    }

    /// Copies every ball into the snapshot, in query order, table by table and in pieces on
    /// the compute pool for many balls; then `then(first, piece)` on each piece of balls just
    /// copied, while it is in the cache (`first` is the index of its first ball). Returns what
    /// `then` gave, in the balls' order.
    pub fn fill_then<R: Send + 'static>(
        &mut self,
        balls: &SnapshotBalls,
        then: impl Fn(usize, Piece) -> R + Sync,
    ) -> Vec<R> {
        let count = balls.iter().len();
        // Sized first and then written in place.
        let mut rest = self.columns_for(count);
        let Ok(tables) = balls.contiguous_iter() else {
            // Not stored in tables: one ball at a time, then all as one piece.
            let (mut held, mut radii) = (0, RadiusRange::NONE);
            for (entity, position, velocity, radius, rest_state) in balls {
                let ball = ([entity], [*position], [*velocity], [*radius], [*rest_state]);
                held += rest.take_front(1).copy_from(ball).0;
                radii = radii.with(radius.0);
            }
            (self.held_when_filled, self.radii) = (held, radii);
            let all = (
                &mut self.circles[..],
                &mut self.velocities[..],
                &mut self.held[..],
            );
            return vec![then(0, all)];
        };
        let parallel = worth_splitting(count);
        let mut results = Vec::new();
        let mut first = 0;
        // Each table fills the next part of the columns, piece by piece.
        for table in tables {
            let len = table.0.len();
            let pieces = rest.take_front(len).into_pieces().zip(piece_ranges(len));
            results.extend(in_pieces(pieces, parallel, |(mut into, balls)| {
                let (entities, positions, velocities, radii, rests) = table;
                let filled = into.copy_from((
                    &entities[balls.clone()],
                    &positions[balls.clone()],
                    &velocities[balls.clone()],
                    &radii[balls.clone()],
                    &rests[balls.clone()],
                ));
                let piece = (into.circles, into.velocities, into.held);
                (filled, then(first + balls.start, piece))
            }));
            first += len;
        }
        self.held_when_filled = results.iter().map(|((held, _), _)| held).sum();
        self.radii = (results.iter().map(|&((_, radii), _)| radii))
            .fold(RadiusRange::NONE, RadiusRange::joined);
        results.into_iter().map(|(_, result)| result).collect()
    }

    /// The columns sized for `count` balls (what they held is overwritten; `stopped` is
    /// cleared).
    fn columns_for(&mut self, count: usize) -> Columns<'_> {
        self.entities.resize(count, Entity::PLACEHOLDER);
        self.circles.resize(count, Circle::new(DVec2::ZERO, 0.0));
        self.velocities.resize(count, DVec2::ZERO);
        self.held.resize(count, false);
        self.stopped.clear();
        self.stopped.resize(count, false);
        Columns {
            entities: &mut self.entities,
            circles: &mut self.circles,
            velocities: &mut self.velocities,
            held: &mut self.held,
        }
    }
}

/// The snapshot's columns that [`BallSnapshot::fill_then`] writes, or a part of them.
struct Columns<'a> {
    entities: &'a mut [Entity],
    circles: &'a mut [Circle],
    velocities: &'a mut [DVec2],
    held: &'a mut [bool],
}

impl<'a> Columns<'a> {
    /// The first `len` balls' columns; these keep the rest.
    fn take_front(&mut self, len: usize) -> Columns<'a> {
        Columns {
            entities: take_front(&mut self.entities, len),
            circles: take_front(&mut self.circles, len),
            velocities: take_front(&mut self.velocities, len),
            held: take_front(&mut self.held, len),
        }
    }

    /// In pieces of [`BALLS_PER_PIECE`] balls, as [`piece_ranges`] cuts them.
    fn into_pieces(mut self) -> impl Iterator<Item = Columns<'a>> {
        std::iter::from_fn(move || {
            let len = self.entities.len().min(BALLS_PER_PIECE);
            (len > 0).then(|| self.take_front(len))
        })
    }

    /// Copies in the same number of balls from a table's columns; returns how many are held,
    /// and their radii's range.
    fn copy_from(
        &mut self,
        (entities, positions, velocities, radii, rests): (
            impl AsRef<[Entity]>,
            impl AsRef<[Position]>,
            impl AsRef<[Velocity]>,
            impl AsRef<[Radius]>,
            impl AsRef<[Rest]>,
        ),
    ) -> (usize, RadiusRange) {
        self.entities.copy_from_slice(entities.as_ref());
        let places = self
            .circles
            .iter_mut()
            .zip(positions.as_ref())
            .zip(radii.as_ref());
        for ((circle, position), radius) in places {
            *circle = Circle::new(position.0, radius.0);
        }
        for (velocity, from) in self.velocities.iter_mut().zip(velocities.as_ref()) {
            *velocity = from.0;
        }
        let mut held_count = 0;
        for (held, rest) in self.held.iter_mut().zip(rests.as_ref()) {
            *held = rest.is_held();
            held_count += usize::from(*held);
        }
        (
            held_count,
            RadiusRange::of_each(radii.as_ref(), |radius| radius.0),
        )
    }
}

/// Part of the snapshot's balls, as [`BallSnapshot::fill_then`] hands it on.
pub type Piece<'a> = (&'a mut [Circle], &'a mut [DVec2], &'a mut [bool]);

/// The balls as the movement stage copies them into the snapshot.
pub type SnapshotBalls<'w, 's> = Query<
    'w,
    's,
    (
        Entity,
        &'static Position,
        &'static Velocity,
        &'static Radius,
        &'static Rest,
    ),
    With<Ball>,
>;

/// The balls as the stages write them back.
pub type WrittenBalls<'w, 's> =
    Query<'w, 's, (Entity, &'static mut Position, &'static mut Velocity), With<Ball>>;

/// Writes every ball's position and velocity from `circles` and `velocities`, where its
/// place in `entities` is its index. The query visits the balls in the snapshot's order
/// (nothing spawns or despawns within a step), table by table: each table's balls are written
/// from their part of the arrays, in pieces on the compute pool for many balls. Should the
/// order ever not match, the rest are looked up by entity.
pub fn write_back(
    entities: &[Entity],
    (circles, velocities): (&mut [Circle], &mut [DVec2]),
    balls: &mut WrittenBalls,
) {
    write_back_after(entities, (circles, velocities), balls, |_, _| ());
}

/// [`write_back`], with `before(first, piece)` done to each piece of balls just before it is
/// written (`first` is the index of its first ball); the results in the balls' order.
pub fn write_back_after<R: Send + 'static>(
    entities: &[Entity],
    (circles, velocities): (&mut [Circle], &mut [DVec2]),
    balls: &mut WrittenBalls,
    before: impl Fn(usize, (&mut [Circle], &mut [DVec2])) -> R + Sync,
) -> Vec<R> {
    let parallel = worth_splitting(entities.len());
    let mut results = Vec::new();
    let mut written = 0;
    let (mut rest_circles, mut rest_velocities) = (&mut circles[..], &mut velocities[..]);
    if let Ok(tables) = balls.contiguous_iter_mut() {
        for (table_entities, positions, table_velocities) in tables {
            let places = written..written + table_entities.len();
            if entities.get(places.clone()) != Some(table_entities) {
                break;
            }
            let (positions, mut position_ticks) = in_place(positions);
            let (table_velocities, mut velocity_ticks) = in_place(table_velocities);
            let now = (position_ticks.this_run(), velocity_ticks.this_run());
            let pieces = positions
                .chunks_mut(BALLS_PER_PIECE)
                .zip(table_velocities.chunks_mut(BALLS_PER_PIECE))
                .zip(position_ticks.changed_mut().chunks_mut(BALLS_PER_PIECE))
                .zip(velocity_ticks.changed_mut().chunks_mut(BALLS_PER_PIECE))
                .zip(take_front(&mut rest_circles, places.len()).chunks_mut(BALLS_PER_PIECE))
                .zip(take_front(&mut rest_velocities, places.len()).chunks_mut(BALLS_PER_PIECE));
            results.extend(in_pieces(pieces.enumerate(), parallel, |(k, balls)| {
                let (
                    ((((positions, ball_velocities), position_ticks), velocity_ticks), circles),
                    velocities,
                ) = balls;
                let result = before(places.start + k * BALLS_PER_PIECE, (circles, velocities));
                for (position, circle) in positions.iter_mut().zip(circles.iter()) {
                    position.0 = circle.center;
                }
                for (velocity, &new) in ball_velocities.iter_mut().zip(velocities.iter()) {
                    velocity.0 = new;
                }
                position_ticks.fill(now.0);
                velocity_ticks.fill(now.1);
                result
            }));
            mark_changed_by(&mut position_ticks);
            mark_changed_by(&mut velocity_ticks);
            written = places.end;
        }
    }
    if written < entities.len() {
        results.push(before(written, (rest_circles, rest_velocities)));
        for (index, &entity) in entities.iter().enumerate().skip(written) {
            if let Ok((_, mut position, mut velocity)) = balls.get_mut(entity) {
                (position.0, velocity.0) = (circles[index].center, velocities[index]);
            }
        }
    }
    results
}

/// A table's column as its values and its change ticks, for pieces that each write their
/// values and mark their ticks changed: bevy's `DerefMut` would mark the whole column at
/// once, on the calling thread (at 100,000 balls, work that kept the second thread idle).
fn in_place<T>(column: ContiguousMut<'_, T>) -> (&mut [T], ContiguousComponentTicksMut<'_>) {
    ContiguousMut::bypass_change_detection_split(column)
}

/// Where a column's values were changed, for builds that track it (bevy's `track_location`;
/// nothing otherwise), as bevy's `DerefMut` records it.
fn mark_changed_by(ticks: &mut ContiguousComponentTicksMut) {
    let at = std::panic::Location::caller();
    ticks.changed_by_mut().map(|changed_by| changed_by.fill(at));
}

#[cfg(test)]
mod tests {
    use bevy::ecs::system::SystemState;

    use super::*;

    #[test]
    fn the_snapshot_counts_the_balls_held_when_it_was_filled() {
        let mut world = World::new();
        // Enough balls for the pool's pieces (`PARALLEL_MIN_BALLS`).
        let held = |k: u32| k % 7 == 3;
        for k in 0..24_000 {
            let state = BallState {
                position: DVec2::new(k as f64, 0.0),
                velocity: DVec2::X,
                radius: 1.0,
            };
            let rest = Rest {
                state: if held(k) {
                    RestState::Resting
                } else {
                    RestState::Free
                },
                still_for: 0.0,
            };
            world.spawn((ball_bundle(BallId(k), state), rest));
        }
        let mut state: SystemState<SnapshotBalls> = SystemState::new(&mut world);
        let balls = state.get(&world).expect("the balls' query");
        let mut snapshot = BallSnapshot::default();
        snapshot.fill_then(&balls, |_, _| ());
        let expected = (0..24_000).filter(|&k| held(k)).count();
        assert_eq!(snapshot.held_when_filled, expected);
        assert_eq!(snapshot.held.iter().filter(|&&h| h).count(), expected);
        // Filled again with nobody held, the count follows.
        let free = Rest::default();
        for mut rest in world.query::<&mut Rest>().iter_mut(&mut world) {
            *rest = free;
        }
        let balls = state.get(&world).expect("the balls' query");
        snapshot.fill_then(&balls, |_, _| ());
        assert_eq!(snapshot.held_when_filled, 0);
    }

    #[test]
    fn every_ball_written_back_is_marked_changed() {
        let mut world = World::new();
        // Enough balls for the pool's pieces (`PARALLEL_MIN_BALLS`), each marking its own.
        let count = 24_000;
        let entities: Vec<Entity> = (0..count)
            .map(|k| {
                let state = BallState {
                    position: DVec2::new(k as f64, 0.0),
                    velocity: DVec2::ZERO,
                    radius: 1.0,
                };
                world.spawn(ball_bundle(BallId(k), state)).id()
            })
            .collect();
        let mut watcher: SystemState<(Query<(), Changed<Position>>, Query<(), Changed<Velocity>>)> =
            SystemState::new(&mut world);
        let mut changed = |world: &World| {
            let (positions, velocities) = watcher.get(world).expect("the watcher's queries");
            (positions.iter().count(), velocities.iter().count())
        };
        assert_eq!(changed(&world), (count as usize, count as usize), "spawned");
        assert_eq!(changed(&world), (0, 0), "nothing since");
        let mut circles: Vec<Circle> = (0..count)
            .map(|k| Circle::new(DVec2::new(k as f64, 5.0), 1.0))
            .collect();
        let mut velocities = vec![DVec2::X; count as usize];
        let mut state: SystemState<WrittenBalls> = SystemState::new(&mut world);
        let mut balls = state.get_mut(&mut world).expect("the balls' query");
        write_back(&entities, (&mut circles, &mut velocities), &mut balls);
        assert_eq!(changed(&world), (count as usize, count as usize), "written");
        assert_eq!(world.get::<Position>(entities[23_999]).unwrap().0.y, 5.0);
    }

    #[test]
    fn balls_written_back_in_another_order_than_the_query_s_are_found_by_entity() {
        let mut world = World::new();
        let at_rest = |k: u32| BallState {
            position: DVec2::new(-(k as f64), 0.0),
            velocity: DVec2::ZERO,
            radius: 1.0,
        };
        let spawned: Vec<Entity> = (0..5)
            .map(|k| world.spawn(ball_bundle(BallId(k), at_rest(k))).id())
            .collect();
        // The snapshot's order the reverse of the table's: nothing matches by place.
        let entities: Vec<Entity> = spawned.iter().rev().copied().collect();
        let mut circles: Vec<Circle> = (0..5)
            .map(|k| Circle::new(DVec2::new(k as f64, 10.0), 1.0))
            .collect();
        let mut velocities: Vec<DVec2> = (0..5).map(|k| DVec2::new(0.0, k as f64)).collect();
        let mut state: SystemState<WrittenBalls> = SystemState::new(&mut world);
        let mut balls = state.get_mut(&mut world).expect("the balls' query");
        write_back(&entities, (&mut circles, &mut velocities), &mut balls);
        for (index, &entity) in entities.iter().enumerate() {
            assert_eq!(
                world.get::<Position>(entity).unwrap().0,
                circles[index].center
            );
            assert_eq!(world.get::<Velocity>(entity).unwrap().0, velocities[index]);
        }
    }
}
