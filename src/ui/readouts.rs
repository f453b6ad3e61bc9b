//! The panel's readouts, gathered every frame in `Update`: the [`StateSummary`] the headless
//! report uses (energy, momentum, temperature, the speed histogram), collisions per second and
//! the pressure over the last simulated second, and the history the energy plot draws.

use std::collections::VecDeque;

use bevy::prelude::*;

use crate::app::scenes::SceneLoaded;
use crate::sim::measure::stats::wall_pressure;
use crate::sim::{Ball, Position, Radius, SimClock, SimParams, SimStats, StateSummary, Velocity};

/// Simulated seconds of kinetic energy the plot shows.
const PLOT_SECONDS: f64 = 10.0;
/// Simulated seconds between plot samples.
const PLOT_SAMPLE_SECONDS: f64 = 0.05;
/// Simulated seconds over which collisions per second are counted.
const RATE_WINDOW_SECONDS: f64 = 1.0;

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<Readouts>()
        .add_systems(Update, update_readouts);
}

/// Figures the panel shows, gathered every frame.
#[derive(Resource, Debug, Default)]
pub struct Readouts {
    /// The same summary the headless report uses (all but the overlap).
    pub summary: StateSummary,
    pub collisions_per_second: f64,
    /// Wall impulse per unit length and time over the last simulated second.
    pub pressure: f64,
    /// (simulated seconds, kinetic energy) over the last 10 simulated seconds.
    pub energy_history: VecDeque<[f64; 2]>,
    /// Counters at moments within the last [`RATE_WINDOW_SECONDS`].
    samples: VecDeque<CounterSample>,
    /// The histogram's input, kept to reuse its memory.
    speeds: Vec<(f64, f64)>,
}

/// [`SimStats`] counters at one moment, for rates over a window.
#[derive(Clone, Copy, Debug)]
struct CounterSample {
    sim_time: f64,
    ball_collisions: u64,
    wall_impulse: f64,
}

fn update_readouts(
    params: Res<SimParams>,
    clock: Res<SimClock>,
    stats: Res<SimStats>,
    balls: Query<(&Position, &Velocity, &Radius), With<Ball>>,
    mut loaded: MessageReader<SceneLoaded>,
    mut readouts: ResMut<Readouts>,
) {
    let readouts = &mut *readouts;
    let states = balls.iter().map(|(p, v, r)| (p.0, v.0, r.0));
    readouts.summary = StateSummary::of_balls(states, &params, &mut readouts.speeds);
    if loaded.read().count() > 0 {
        readouts.samples.clear();
        readouts.energy_history.clear();
    }
    let now = clock.elapsed;
    if readouts.samples.back().is_none_or(|s| s.sim_time < now) {
        readouts.samples.push_back(CounterSample {
            sim_time: now,
            ball_collisions: stats.ball_collisions,
            wall_impulse: stats.wall_impulse,
        });
    }
    while readouts.samples.len() > 2 && readouts.samples[1].sim_time <= now - RATE_WINDOW_SECONDS {
        readouts.samples.pop_front();
    }
    (readouts.collisions_per_second, readouts.pressure) =
        match (readouts.samples.front(), readouts.samples.back()) {
            (Some(first), Some(last)) if last.sim_time > first.sim_time => {
                let elapsed = last.sim_time - first.sim_time;
                (
                    (last.ball_collisions - first.ball_collisions) as f64 / elapsed,
                    wall_pressure(
                        last.wall_impulse - first.wall_impulse,
                        params.arena_size,
                        elapsed,
                    ),
                )
            }
            _ => (0.0, 0.0),
        };
    let energy = readouts.summary.kinetic_energy;
    if readouts
        .energy_history
        .back()
        .is_none_or(|&[t, _]| now - t >= PLOT_SAMPLE_SECONDS)
    {
        readouts.energy_history.push_back([now, energy]);
    }
    while readouts
        .energy_history
        .front()
        .is_some_and(|&[t, _]| t < now - PLOT_SECONDS)
    {
        readouts.energy_history.pop_front();
    }
}
