//! The command line: `ballpit` plays (a window), `ballpit run` steps a scene headless and
//! reports. Exit codes: 0 success, 1 runtime error (bad scene, unwritable file), 2 usage
//! error (from clap).

use std::error::Error;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::headless::{DEFAULT_DT, StateDump, run_scene};
use crate::play::{CurrentScene, PlayOptions, play};
use crate::sim::SceneFile;

/// The scene played when no `--scene` is given, built in so it works from any directory.
const DEMO_SCENE: &str = include_str!("../assets/scenes/demo.ron");

/// Largest step count accepted by `run`.
const MAX_STEPS: u64 = 100_000_000;

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
    /// Frames to run before the screenshot.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: u32,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scene headless (no window, no GPU) for a number of fixed steps and report.
    Run(RunArgs),
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

fn run_window(args: PlayArgs) -> Result<(), Box<dyn Error>> {
    let (file, origin) = match &args.scene {
        Some(path) => (SceneFile::load(path)?, path.display().to_string()),
        None => (
            SceneFile::parse(DEMO_SCENE, "demo.ron")?,
            "demo.ron".to_string(),
        ),
    };
    // Refuse a bad scene here, with exit code 1, rather than in the window.
    file.build(&origin)?;
    let screenshot = args.screenshot.map(|path| (path, args.frames));
    match play(PlayOptions {
        scene: CurrentScene { file, origin },
        screenshot,
    }) {
        bevy::app::AppExit::Success => Ok(()),
        bevy::app::AppExit::Error(code) => Err(format!("the game exited with code {code}").into()),
    }
}

fn run_headless(args: RunArgs) -> Result<(), Box<dyn Error>> {
    let origin = args.scene.display().to_string();
    let mut scene = SceneFile::load(&args.scene)?;
    if args.balls.is_some() || args.seed.is_some() {
        let Some(generate) = scene.generate.as_mut() else {
            return Err(format!(
                "{origin}: --balls and --seed override `generate`, which this scene lacks"
            )
            .into());
        };
        generate.count = args.balls.unwrap_or(generate.count);
        generate.seed = args.seed.unwrap_or(generate.seed);
    }
    let setup = scene.build(&origin)?;
    let (mut app, report) = run_scene(&setup, args.steps, args.dt);
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print!("{}", report.to_text());
    }
    if let Some(path) = args.dump {
        let dump = StateDump::capture(app.world_mut());
        let text = serde_json::to_string(&dump)?;
        std::fs::write(&path, text)
            .map_err(|e| format!("{}: cannot write the dump: {e}", path.display()))?;
    }
    Ok(())
}
