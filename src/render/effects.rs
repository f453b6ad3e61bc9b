//! Collision effects: a short burst of particles at each ball–ball collision point, read from
//! the [`BallCollision`] messages and sized by the impulse. Bursts per frame and live
//! particles are capped, so thousands of collisions per second cost little. Runs in the
//! windowed app's `Update`.

use bevy::prelude::*;

use crate::app::view::ViewSettings;
use crate::sim::BallCollision;

/// Live particles at most.
const MAX_PARTICLES: usize = 1_500;
/// New bursts per frame at most (the strongest are kept).
const MAX_BURSTS_PER_FRAME: usize = 24;
/// Particles per burst.
const PARTICLES_PER_BURST: usize = 6;
/// Seconds a particle lives.
const PARTICLE_LIFE: f32 = 0.3;
/// Impulse that gives a full-size burst, mass x pixels per second.
const FULL_BURST_IMPULSE: f64 = 5_000.0;
/// Speed of a full-size burst's particles, pixels per second.
const FULL_BURST_SPEED: f32 = 160.0;

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<Particles>()
        .add_systems(Update, (spawn_bursts, age_and_draw_particles).chain());
}

#[derive(Clone, Copy, Debug)]
struct Particle {
    position: Vec2,
    velocity: Vec2,
    age: f32,
    size: f32,
}

#[derive(Resource, Default)]
struct Particles(Vec<Particle>);

/// Burst strength in [0.2, 1] from a collision's impulse.
pub fn burst_strength(impulse: f64) -> f32 {
    (impulse / FULL_BURST_IMPULSE).sqrt().clamp(0.2, 1.0) as f32
}

fn spawn_bursts(
    view: Res<ViewSettings>,
    mut collisions: MessageReader<BallCollision>,
    mut particles: ResMut<Particles>,
    mut strongest: Local<Vec<(f64, Vec2)>>,
) {
    strongest.clear();
    strongest.extend(
        collisions
            .read()
            .map(|hit| (hit.impulse, hit.point.as_vec2())),
    );
    if !view.show_bursts {
        return;
    }
    if strongest.len() > MAX_BURSTS_PER_FRAME {
        strongest.select_nth_unstable_by(MAX_BURSTS_PER_FRAME, |a, b| b.0.total_cmp(&a.0));
        strongest.truncate(MAX_BURSTS_PER_FRAME);
    }
    for &(impulse, point) in strongest.iter() {
        let strength = burst_strength(impulse);
        for k in 0..PARTICLES_PER_BURST {
            if particles.0.len() >= MAX_PARTICLES {
                return;
            }
            let angle =
                (k as f32 + 0.5) / PARTICLES_PER_BURST as f32 * std::f32::consts::TAU + point.x;
            particles.0.push(Particle {
                position: point,
                velocity: Vec2::from_angle(angle) * FULL_BURST_SPEED * strength,
                age: 0.0,
                size: 1.0 + 2.5 * strength,
            });
        }
    }
}

fn age_and_draw_particles(time: Res<Time>, mut particles: ResMut<Particles>, mut gizmos: Gizmos) {
    let dt = time.delta_secs();
    particles.0.retain_mut(|particle| {
        particle.age += dt;
        particle.position += particle.velocity * dt;
        particle.age < PARTICLE_LIFE
    });
    for particle in &particles.0 {
        let fade = 1.0 - particle.age / PARTICLE_LIFE;
        gizmos
            .circle_2d(
                particle.position,
                particle.size * fade.max(0.3),
                Color::srgba(1.0, 0.85, 0.4, fade),
            )
            .resolution(8);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn burst_strength_grows_with_impulse_and_is_bounded() {
        assert_eq!(burst_strength(0.0), 0.2);
        assert!(burst_strength(1_000.0) < burst_strength(4_000.0));
        assert_eq!(burst_strength(1e12), 1.0);
    }
}
