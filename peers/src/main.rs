//! peers: runs a ballpit scene file in Box2D v3 and rapier, each set up as its users would
//! (`box2d.rs`, `rapier.rs` say how), and prints what `ballpit run --json` prints of the
//! same run: ms per step, energy, momentum, overlaps, balls escaped and still moving. Not
//! built by `cargo test` or CI: `cargo run --release -p peers -- --scene FILE`.

mod box2d;
mod calendar;
mod edmd;
mod ours;
mod rapier;
mod scene;

use std::time::Instant;

use ballpit::commands::observe::dump::{DumpedBall, StateDump};
use ballpit::headless::{mean, median};
use ballpit::sim::geometry::circle::Circle;
use ballpit::sim::measure::summary::overlaps_rel;
use ballpit::sim::{SimParams, StateSummary};
use clap::{Parser, ValueEnum};
use serde::Serialize;

use scene::{Ball, Scene};

/// What the harness needs of an engine; pixels and pixels per second across it.
pub trait Engine {
    /// One step of the scene's `dt`.
    fn step(&mut self);
    /// The balls now, in the scene's order.
    fn balls(&mut self) -> Vec<Ball>;
}

#[derive(Clone, Copy, Debug, PartialEq, ValueEnum)]
enum Engines {
    Box2d,
    Rapier,
    /// The persistent event-driven reference (`edmd.rs`): an experiment, not in `all`.
    Edmd,
    All,
}

#[derive(Parser)]
#[command(about = "Runs a ballpit scene file in Box2D v3 and rapier")]
struct Cli {
    /// The scene file (RON), as `ballpit run --scene` reads it.
    #[arg(long)]
    scene: String,
    /// Override the scene's generated ball count.
    #[arg(long)]
    balls: Option<usize>,
    /// Override the scene's generation seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Steps to run (of the scene's 1/60 s).
    #[arg(long, default_value_t = 600)]
    steps: u64,
    /// Untimed steps at the start (still run).
    #[arg(long, default_value_t = 0)]
    warmup: u64,
    #[arg(long, value_enum, default_value = "all")]
    engine: Engines,
    /// One JSON object per engine and line instead of a table.
    #[arg(long)]
    json: bool,
    /// Write each engine's final state to `DIR/ENGINE.json` in the format of `ballpit run
    /// --dump` (ids in the scene's order).
    #[arg(long, value_name = "DIR")]
    dump: Option<std::path::PathBuf>,
    /// Run ballpit too, in this process (one thread, the scene's collision mode), and step
    /// the engines in turns of two steps, timing the second of each: every engine then meets
    /// the same spells of a busy host. Half the steps are timed.
    #[arg(long)]
    interleave: bool,
}

/// The fields `ballpit run --json` reports that an engine can: the same names, the same
/// meanings.
#[derive(Serialize)]
struct Report {
    engine: &'static str,
    balls: usize,
    arena: [f64; 2],
    steps: u64,
    dt_s: f64,
    sim_time_s: f64,
    ms_per_step_median: f64,
    ms_per_step_mean: f64,
    kinetic_energy_start: f64,
    kinetic_energy_end: f64,
    kinetic_energy_change_rel: f64,
    mechanical_energy_start: f64,
    mechanical_energy_end: f64,
    mechanical_energy_change_rel: f64,
    momentum_start: [f64; 2],
    momentum_end: [f64; 2],
    max_overlap_rel: f64,
    mean_overlap_rel: f64,
    moving: usize,
    rms_speed: f64,
    escaped: usize,
}

fn main() {
    let cli = Cli::parse();
    let scene = match Scene::load(&cli.scene, cli.balls, cli.seed) {
        Ok(scene) => scene,
        Err(error) => {
            eprintln!("peers: {error}");
            std::process::exit(1);
        }
    };
    let kinds: &[&'static str] = match cli.engine {
        Engines::Box2d => &["box2d"],
        Engines::Rapier => &["rapier"],
        Engines::Edmd => &["edmd"],
        Engines::All => &["box2d", "rapier"],
    };
    if !cli.json {
        println!(
            "engine    balls  steps  ms/step mean  median  energy change  overlap max / mean  moving  escaped"
        );
    }
    let mut engines: Vec<(&'static str, Box<dyn Engine>)> = Vec::new();
    if cli.interleave {
        // First: the first app of the process sets bevy's task pools (one thread).
        engines.push((
            "ballpit",
            Box::new(ours::Ballpit::new(&scene, &scene.setup)),
        ));
    }
    for &kind in kinds {
        let engine: Box<dyn Engine> = match kind {
            "box2d" => Box::new(box2d::Box2d::new(&scene).expect("box2d world")),
            "edmd" => match edmd::Edmd::new(&scene) {
                Ok(edmd) => Box::new(edmd),
                Err(error) => {
                    eprintln!("peers: {error}");
                    std::process::exit(1);
                }
            },
            _ => Box::new(rapier::Rapier::new(&scene)),
        };
        engines.push((kind, engine));
    }
    let times = if cli.interleave {
        time_in_turn(&mut engines, cli.steps, cli.warmup)
    } else {
        (engines.iter_mut())
            .map(|(_, engine)| time_steps(engine.as_mut(), cli.steps, cli.warmup))
            .collect()
    };
    for ((kind, engine), mut times) in engines.iter_mut().zip(times) {
        let kind: &'static str = kind;
        let report = report(kind, engine.as_mut(), &scene, cli.steps, &mut times);
        if let Some(dir) = &cli.dump {
            let path = dir.join(format!("{kind}.json"));
            let written = std::fs::create_dir_all(dir)
                .and_then(|()| std::fs::write(&path, dump(&scene, &engine.balls())));
            if let Err(error) = written {
                eprintln!("peers: {}: {error}", path.display());
                std::process::exit(1);
            }
        }
        if cli.json {
            println!(
                "{}",
                serde_json::to_string(&report).expect("a report serialises")
            );
        } else {
            println!(
                "{:<8} {:>6} {:>6}  {:>12.3}  {:>6.3}  {:>13.3e}  {:>8.3} / {:<7.4}  {:>6}  {:>7}",
                report.engine,
                report.balls,
                report.steps,
                report.ms_per_step_mean,
                report.ms_per_step_median,
                report.mechanical_energy_change_rel,
                report.max_overlap_rel,
                report.mean_overlap_rel,
                report.moving,
                report.escaped
            );
        }
    }
}

/// Runs `steps` steps of `engine`, and returns how long each after the first `warmup` took,
/// milliseconds.
fn time_steps(engine: &mut dyn Engine, steps: u64, warmup: u64) -> Vec<f64> {
    let mut times = Vec::with_capacity(steps as usize);
    for step in 0..steps {
        let started = Instant::now();
        engine.step();
        if step >= warmup {
            times.push(started.elapsed().as_secs_f64() * 1e3);
        }
    }
    times
}

/// [`time_steps`] for every engine at once, in turns of two steps: each engine takes two
/// steps in turn, and only the second is timed. The first brings the engine's own data back
/// into the cache after the others' turns, so the timed step starts as it would in a program
/// that runs only that engine (ballpit's 100,000-ball gas took 21–25 ms a step timed
/// straight after Box2D's, against 16–21 alone). Returns each engine's timed steps (every
/// second step, from step `warmup` on), milliseconds.
fn time_in_turn(
    engines: &mut [(&'static str, Box<dyn Engine>)],
    steps: u64,
    warmup: u64,
) -> Vec<Vec<f64>> {
    let mut times = vec![Vec::with_capacity(steps as usize / 2); engines.len()];
    for turn in (0..steps).step_by(TURN as usize) {
        for ((_, engine), times) in engines.iter_mut().zip(&mut times) {
            for step in turn..(turn + TURN).min(steps) {
                let timed = step == turn + TURN - 1 && step >= warmup;
                times.extend(time_steps(engine.as_mut(), 1, u64::from(!timed)));
            }
        }
    }
    times
}

/// The steps of an engine's turn in [`time_in_turn`].
const TURN: u64 = 2;

/// The report of `engine` after `steps` steps that took `times` (the timed ones), the start
/// and the end measured as ballpit measures them (its own code, in its coordinates).
fn report(
    name: &'static str,
    engine: &mut dyn Engine,
    scene: &Scene,
    steps: u64,
    times: &mut [f64],
) -> Report {
    let start = measure(scene, &scene.balls);
    let balls = engine.balls();
    let end = measure(scene, &balls);
    let circles: Vec<Circle> = balls
        .iter()
        .map(|ball| Circle::new(ball.position, ball.radius))
        .collect();
    let (max_overlap_rel, mean_overlap_rel) = overlaps_rel(&circles);
    let change = |start: f64, end: f64| (end - start) / start.abs();
    Report {
        engine: name,
        balls: balls.len(),
        arena: scene.size.to_array(),
        steps,
        dt_s: scene.dt,
        sim_time_s: scene.dt * steps as f64,
        ms_per_step_median: median(times),
        ms_per_step_mean: mean(times),
        kinetic_energy_start: start.kinetic_energy,
        kinetic_energy_end: end.kinetic_energy,
        kinetic_energy_change_rel: change(start.kinetic_energy, end.kinetic_energy),
        mechanical_energy_start: start.mechanical_energy,
        mechanical_energy_end: end.mechanical_energy,
        mechanical_energy_change_rel: change(start.mechanical_energy, end.mechanical_energy),
        momentum_start: start.momentum.to_array(),
        momentum_end: end.momentum.to_array(),
        max_overlap_rel,
        mean_overlap_rel,
        moving: end.moving,
        rms_speed: end.rms_speed,
        escaped: end.escaped,
    }
}

/// `balls` as `ballpit run --dump` writes them: ids in the scene's order, ballpit's centred
/// coordinates.
fn dump(scene: &Scene, balls: &[Ball]) -> String {
    let half = scene.size / 2.0;
    let dump = StateDump {
        balls: (balls.iter().enumerate())
            .map(|(id, ball)| DumpedBall {
                id: id as u32,
                x: ball.position.x - half.x,
                y: ball.position.y - half.y,
                vx: ball.velocity.x,
                vy: ball.velocity.y,
                r: ball.radius,
                m: scene.mass_model.mass(ball.radius),
            })
            .collect(),
    };
    serde_json::to_string_pretty(&dump).expect("a dump serialises")
}

/// ballpit's summary of `balls`, moved back into its centred arena.
fn measure(scene: &Scene, balls: &[Ball]) -> StateSummary {
    let params = SimParams {
        arena_size: scene.size,
        gravity: scene.gravity,
        mass_model: scene.mass_model,
        ..SimParams::default()
    };
    let half = scene.size / 2.0;
    let centred = balls
        .iter()
        .map(|ball| (ball.position - half, ball.velocity, ball.radius));
    StateSummary::of_balls(centred, &params, &mut Vec::new())
}
