//! The command line: `ballpit` plays (a window; with the default `gui` feature only),
//! `ballpit run` steps a scene headless and reports, `ballpit bench` times the standard gas,
//! `ballpit soak` runs random scenes long with checks. Exit codes: 0 success, 1 runtime error
//! (bad scene, unwritable file, a failed soak scene, no window in a headless build; the
//! message names the file and the line and column or the ball), 2 usage error (from clap).

use std::error::Error;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::commands::bench::{BenchCase, BenchRow, format_table, run_case};
use crate::commands::mixed::{format_mixed_table, run_mixed};
use crate::commands::observe::dump::StateDump;
use crate::commands::observe::{ObserveRequest, Observers};
use crate::commands::pile::{format_pile_table, run_pile};
use crate::commands::progress::{Progress, print_out};
use crate::commands::run::run_scene_showing;
use crate::commands::soak::soak;
use crate::headless::DEFAULT_DT;
use crate::sim::params::MAX_BALLS;
use crate::sim::{BroadPhase, CollisionMode, SceneFile};

/// Largest step count accepted by `run`.
const MAX_STEPS: u64 = 100_000_000;
/// Most threads at work on a step accepted.
const MAX_THREADS: u64 = 256;
/// Largest ball count the bench accepts.
const MAX_BENCH_BALLS: u64 = MAX_BALLS as u64;

#[derive(Debug, Parser)]
#[command(
    name = "ballpit",
    version,
    about = "Circles colliding in a box: a toy and a simulator",
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    #[command(flatten)]
    pub play: PlayArgs,
}

/// With no subcommand, `ballpit` opens a window and plays.
#[derive(Debug, clap::Args)]
pub struct PlayArgs {
    /// Scene file (RON) to play; the built-in demo when absent.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Save a PNG of the window after `--frames` frames, then exit.
    #[arg(long, value_name = "OUT.png")]
    pub screenshot: Option<PathBuf>,
    /// Record `--frames` frames of the window (25 a second of game time) as an animated
    /// GIF, then exit.
    #[arg(long, value_name = "OUT.gif", conflicts_with = "screenshot")]
    pub record: Option<PathBuf>,
    /// Override the scene's `generate.count`.
    #[arg(long)]
    pub balls: Option<usize>,
    /// Override the scene's `generate.seed`.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Frames to run before the screenshot, or to record.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: u32,
    /// Collision mode, overriding the scene's.
    #[arg(long, value_enum)]
    pub collisions: Option<CollisionMode>,
    /// Start paused (Space runs it).
    #[arg(long)]
    pub paused: bool,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene headless (no window, no GPU) for a number of fixed steps and report.
    Run(RunArgs),
    /// Time the standard gas at several sizes, on one core and on all, against all pairs.
    Bench(BenchArgs),
    /// Random scenes across the panel's ranges, each run long with checks after every step.
    Soak(SoakArgs),
    /// One bench case in this process, printed as JSON (what `bench` runs in its children).
    #[command(hide = true)]
    BenchOne(BenchOneArgs),
}

#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Ball counts, comma-separated.
    #[arg(long, value_delimiter = ',',
          value_parser = clap::value_parser!(u64).range(1..=MAX_BENCH_BALLS))]
    pub sizes: Option<Vec<u64>>,
    /// Timed steps per case (after a short warm-up); with `--pile`, steps from the start
    /// [default: 200, with `--pile` 600 = 10 s]
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub steps: Option<u64>,
    /// Time the pile (`assets/scenes/pile.ron`, the standard gas under gravity with
    /// restitution 0.5) in both modes instead of the gas [default sizes: 1000,10000].
    #[arg(long)]
    pub pile: bool,
    /// Time mixed sizes (`assets/scenes/mixed.ron`: small balls and three big ones) against
    /// the small balls alone, in both modes [default size: 5000 small balls; below about 1500
    /// the arena is too small for the big ones].
    #[arg(long, conflicts_with = "pile")]
    pub mixed: bool,
    /// Run the all-pairs reference for sizes up to this (it is O(N^2)).
    #[arg(long, default_value_t = 10_000)]
    pub all_pairs_max: u64,
    /// Rounds of the gas's cases, each round every case once; each case reports its median
    /// round (a single run moves by up to 10% on a busy machine).
    #[arg(long, default_value_t = 3, conflicts_with_all = ["pile", "mixed"],
          value_parser = clap::value_parser!(u64).range(1..=100))]
    pub rounds: u64,
    /// Also run each size's one-core cases on every core, one child pinned to each (cores 0,
    /// 1, ...), started together: what a perfectly split step could gain on this machine,
    /// printed beside the all-core figures ("2c") as "host".
    #[arg(long, conflicts_with_all = ["pile", "mixed"])]
    pub on_each_core: bool,
    /// Print the rows as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress bar (it is drawn on stderr only when stderr is a terminal).
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Debug, clap::Args)]
pub struct SoakArgs {
    /// Number of random scenes.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub scenes: u64,
    /// Steps per scene.
    #[arg(long, default_value_t = 100_000, value_parser = clap::value_parser!(u64).range(1..=MAX_STEPS))]
    pub steps: u64,
    /// Seed of the first scene; scene k has seed `seed + k`.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Most balls in a scene.
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u64).range(1..=MAX_BENCH_BALLS))]
    pub max_balls: u64,
    /// No progress bar (it is drawn on stderr only when stderr is a terminal).
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Debug, clap::Args)]
pub struct BenchOneArgs {
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_BENCH_BALLS))]
    pub balls: u64,
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub steps: u64,
    #[arg(long, value_enum, default_value_t = BroadPhase::Grid)]
    pub broad_phase: BroadPhase,
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_THREADS))]
    pub threads: u64,
    #[arg(long, value_enum, default_value_t = CollisionMode::Discrete)]
    pub collisions: CollisionMode,
}

#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Scene file (RON), e.g. assets/scenes/gas.ron.
    #[arg(long)]
    pub scene: PathBuf,
    /// Number of fixed steps to run.
    #[arg(long, value_parser = clap::value_parser!(u64).range(..=MAX_STEPS))]
    pub steps: u64,
    /// Override the scene's `generate.count`.
    #[arg(long)]
    pub balls: Option<usize>,
    /// Override the scene's `generate.seed`.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Fixed step in seconds, in (0, 1].
    #[arg(long, default_value_t = DEFAULT_DT, value_parser = parse_step_seconds)]
    pub dt: f64,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Write the final state of every ball to this JSON file.
    #[arg(long, value_name = "OUT.json")]
    pub dump: Option<PathBuf>,
    /// Threads at work on each step: this one and `T - 1` workers for the stages' parallel
    /// parts (default: bevy's compute pool for this machine's cores, and this thread).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_THREADS))]
    pub threads: Option<u64>,
    /// Collision mode, overriding the scene's (default: continuous).
    #[arg(long, value_enum)]
    pub collisions: Option<CollisionMode>,
    /// No progress bar (it is drawn on stderr only when stderr is a terminal).
    #[arg(long)]
    pub quiet: bool,
    /// Write the time series to this CSV file: a row at step 0, every `--every` steps and at
    /// the last step (the README lists the columns).
    #[arg(long, value_name = "OUT.csv")]
    pub series: Option<PathBuf>,
    /// Write the balls' motion to this extended XYZ file (ASE, OVITO): a frame at step 0,
    /// every `--every` steps and at the last step.
    #[arg(long, value_name = "OUT.xyz")]
    pub trajectory: Option<PathBuf>,
    /// Steps between the series' rows and the trajectory's frames, at least 1.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub every: u64,
}

fn parse_step_seconds(text: &str) -> Result<f64, String> {
    let dt: f64 = text.parse().map_err(|e| format!("not a number: {e}"))?;
    if dt > 0.0 && dt <= 1.0 {
        Ok(dt)
    } else {
        Err(format!("{dt} is outside (0, 1] seconds"))
    }
}

impl Cli {
    /// Runs the chosen command; errors are printed and give exit code 1.
    pub fn run(self) -> ExitCode {
        let outcome = match self.command {
            Some(Command::Run(args)) => run_headless(args),
            Some(Command::Bench(args)) => run_bench(args),
            Some(Command::Soak(args)) => run_soak(args),
            Some(Command::BenchOne(args)) => run_bench_one(args),
            None => run_window(self.play),
        };
        match outcome {
            Ok(()) => ExitCode::SUCCESS,
            Err(error) => {
                eprintln!("error: {error}");
                ExitCode::FAILURE
            }
        }
    }
}

/// Applies `--collisions`, then `--balls` and `--seed` to the scene's `generate`, which must
/// exist for those two.
fn override_scene(
    scene: &mut SceneFile,
    origin: &str,
    collisions: Option<CollisionMode>,
    balls: Option<usize>,
    seed: Option<u64>,
) -> Result<(), Box<dyn Error>> {
    if let Some(mode) = collisions {
        scene.collisions = Some(mode);
    }
    if balls.is_none() && seed.is_none() {
        return Ok(());
    }
    let Some(generate) = scene.generate.as_mut() else {
        return Err(format!(
            "{origin}: --balls and --seed override `generate`, which this scene lacks"
        )
        .into());
    };
    generate.count = balls.unwrap_or(generate.count);
    generate.seed = seed.unwrap_or(generate.seed);
    Ok(())
}

/// The scene played when no `--scene` is given, built in so it works from any directory.
#[cfg(feature = "gui")]
const DEMO_SCENE: &str = include_str!("../assets/scenes/demo.ron");

#[cfg(feature = "gui")]
fn run_window(args: PlayArgs) -> Result<(), Box<dyn Error>> {
    use crate::app::scenes::CurrentScene;
    use crate::play::{PlayOptions, play};
    let (mut file, origin) = match &args.scene {
        Some(path) => (SceneFile::load(path)?, path.display().to_string()),
        None => (
            SceneFile::parse(DEMO_SCENE, "demo.ron")?,
            "demo.ron".to_string(),
        ),
    };
    override_scene(&mut file, &origin, args.collisions, args.balls, args.seed)?;
    // Refuse a bad scene here, with exit code 1, rather than in the window.
    let arena = file.build(&origin)?.params.arena_size.as_vec2();
    let screenshot = args.screenshot.map(|path| (path, args.frames));
    if let Some(path) = &args.record {
        use crate::record::MAX_RECORD_FRAMES;
        if args.frames > MAX_RECORD_FRAMES {
            return Err(format!(
                "a recording keeps its frames in memory: at most {MAX_RECORD_FRAMES} (30 s), \
                 not {}",
                args.frames
            )
            .into());
        }
        // An unwritable recording fails now, not after the frames are played (and an
        // existing file stays as it is until the new one is written).
        std::fs::OpenOptions::new()
            .append(true)
            .create(true)
            .open(path)
            .map_err(|e| format!("{}: cannot write the recording: {e}", path.display()))?;
    }
    let record = args.record.map(|path| (path, args.frames));
    match play(PlayOptions {
        scene: CurrentScene { file, origin },
        arena,
        screenshot,
        record,
        paused: args.paused,
    }) {
        bevy::app::AppExit::Success => Ok(()),
        bevy::app::AppExit::Error(code) => Err(format!("the game exited with code {code}").into()),
    }
}

/// What a build without the `gui` feature says when asked to play.
#[cfg(any(test, not(feature = "gui")))]
const NO_WINDOW: &str = "this ballpit was built without the `gui` feature, so it cannot open a \
     window; `ballpit run`, `bench` and `soak` work headless";

/// A build without the `gui` feature has no window to play in.
#[cfg(not(feature = "gui"))]
fn run_window(_args: PlayArgs) -> Result<(), Box<dyn Error>> {
    Err(NO_WINDOW.into())
}

fn run_headless(args: RunArgs) -> Result<(), Box<dyn Error>> {
    let origin = args.scene.display().to_string();
    let mut scene = SceneFile::load(&args.scene)?;
    override_scene(&mut scene, &origin, args.collisions, args.balls, args.seed)?;
    let setup = scene.build(&origin)?;
    let threads = args.threads.map(|n| n as usize);
    // A file that cannot be written, or a trajectory too large, fails now, before any step.
    let mut observers = Observers::open(ObserveRequest {
        series: args.series.as_deref(),
        trajectory: args.trajectory.as_deref(),
        every: args.every,
        balls: setup.balls.len(),
        steps: args.steps,
    })?;
    let progress = Progress::new(args.steps, "steps", args.quiet);
    let (mut app, report) = run_scene_showing(
        &setup,
        args.steps,
        args.dt,
        threads,
        &progress,
        &mut observers,
    );
    drop(progress);
    // The report and the dump come first: a series that failed mid-run loses neither.
    let printed = if args.json {
        print_out(&format!("{}\n", serde_json::to_string(&report)?))
    } else {
        print_out(&report.to_text())
    };
    if let Some(path) = args.dump {
        let dump = StateDump::capture(app.world_mut());
        let text = serde_json::to_string(&dump)?;
        std::fs::write(&path, text)
            .map_err(|e| format!("{}: cannot write the dump: {e}", path.display()))?;
    }
    observers.finish()?;
    Ok(printed?)
}

fn run_bench(args: BenchArgs) -> Result<(), Box<dyn Error>> {
    if args.pile {
        return run_pile_bench(&args);
    }
    if args.mixed {
        return run_mixed_bench(&args);
    }
    let sizes = args.sizes.clone().unwrap_or(vec![1_000, 10_000, 100_000]);
    let steps = args.steps.unwrap_or(200);
    let rounds = args.rounds as usize;
    let progress = Progress::new(
        (rounds * sizes.len()) as u64,
        "size-rounds",
        args.quiet || args.json,
    );
    // Round after round, each size's cases once in each.
    let mut by_size: Vec<Vec<BenchRow>> = vec![Vec::new(); sizes.len()];
    for _ in 0..rounds {
        for (&balls, rows) in sizes.iter().zip(&mut by_size) {
            rows.push(BenchRow::measure(
                balls as usize,
                steps,
                args.all_pairs_max,
                args.on_each_core,
            )?);
            progress.advance(1);
        }
    }
    let rows: Vec<BenchRow> = by_size
        .into_iter()
        .filter_map(BenchRow::median_of_rounds)
        .collect();
    drop(progress);
    if args.json {
        print_out(&format!("{}\n", serde_json::to_string(&rows)?))?;
    } else {
        print_out(&format_table(&rows))?;
    }
    Ok(())
}

fn run_pile_bench(args: &BenchArgs) -> Result<(), Box<dyn Error>> {
    let mut rows = Vec::new();
    let sizes = args.sizes.clone().unwrap_or(vec![1_000, 10_000]);
    let progress = Progress::new(2 * sizes.len() as u64, "cases", args.quiet || args.json);
    for balls in sizes {
        for mode in [CollisionMode::Continuous, CollisionMode::Discrete] {
            rows.push(run_pile(balls as usize, mode, args.steps.unwrap_or(600))?);
            progress.advance(1);
        }
    }
    drop(progress);
    if args.json {
        print_out(&format!("{}\n", serde_json::to_string(&rows)?))?;
    } else {
        print_out(&format_pile_table(&rows))?;
    }
    Ok(())
}

fn run_mixed_bench(args: &BenchArgs) -> Result<(), Box<dyn Error>> {
    let mut rows = Vec::new();
    for small in args.sizes.clone().unwrap_or(vec![5_000]) {
        for mode in [CollisionMode::Continuous, CollisionMode::Discrete] {
            rows.push(run_mixed(small as usize, mode, args.steps.unwrap_or(200))?);
        }
    }
    if args.json {
        print_out(&format!("{}\n", serde_json::to_string(&rows)?))?;
    } else {
        print_out(&format_mixed_table(&rows))?;
    }
    Ok(())
}

fn run_soak(args: SoakArgs) -> Result<(), Box<dyn Error>> {
    let failed = soak(
        args.seed,
        args.scenes,
        args.steps,
        args.max_balls as usize,
        args.quiet,
    );
    if failed > 0 {
        return Err(format!("{failed} of {} scenes failed", args.scenes).into());
    }
    print_out(&format!("all {} scenes passed\n", args.scenes))?;
    Ok(())
}

fn run_bench_one(args: BenchOneArgs) -> Result<(), Box<dyn Error>> {
    let case = BenchCase {
        balls: args.balls as usize,
        steps: args.steps,
        broad_phase: args.broad_phase,
        collisions: args.collisions,
    };
    let row = serde_json::to_string(&run_case(case, args.threads as usize)?)?;
    print_out(&format!("{row}\n"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_headless_build_says_plainly_why_it_cannot_play() {
        assert!(NO_WINDOW.contains("without the `gui` feature, so it cannot open a window;"));
        assert!(!NO_WINDOW.contains("  "), "{NO_WINDOW}");
    }
}
