//! `--trajectory OUT.xyz`: the run as extended XYZ frames, the format ASE (`ase.io.read`)
//! and OVITO open as an animation. Each frame is a line with the ball count, a comment line
//! of `key=value` pairs, then a line per ball in id order:
//!
//! ```text
//! 2
//! Lattice="800 0 0 0 600 0 0 0 20" Origin="-400 -300 -10" Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:I:1 Time=0.5 step=30 pbc="F F F"
//! X -12.5 40 0 100 -3.25 0 10 10 0
//! X 30 -7 0 -100 3.25 0 10 10 1
//! ```
//!
//! The lattice is the arena (its depth twice the largest radius, so the discs fit in the
//! cell), `Origin` its lower corner, so positions are the simulation's own; `z` and the
//! third velocity are 0; `species` is `X` (ASE's and OVITO's placeholder element). Numbers
//! are written in Rust's shortest round-trip form, so the last frame reproduces `--dump`
//! exactly.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use bevy::math::DVec2;
use bevy::prelude::*;

use super::dump::StateDump;
use crate::sim::{SimClock, SimParams};

/// The largest trajectory a run may write, bytes.
pub const MAX_TRAJECTORY_BYTES: u64 = 2_000_000_000;
/// The longest a number is written, characters (see [`number`]).
pub const MAX_NUMBER: u64 = 24;
/// What a ball's line takes at most, bytes: `X`, six numbers, two zeros, a 10-digit id,
/// nine spaces and the newline.
pub const MAX_BYTES_PER_BALL: u64 = 1 + 6 * MAX_NUMBER + 2 + 10 + 9 + 1;
/// What a frame's count and comment lines take at most, bytes: eight numbers, a step count
/// and the fixed text.
pub const MAX_FRAME_HEADER: u64 = 8 * MAX_NUMBER + 20 + 200;

/// The comment line's `Properties`: the per-ball columns.
pub const PROPERTIES: &str = "species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:I:1";

/// An open trajectory file. A write that fails is kept and reported by
/// [`finish`](Self::finish); the run itself goes on.
pub struct Trajectory {
    writer: BufWriter<File>,
    path: PathBuf,
    error: Option<std::io::Error>,
}

fn cannot_write(path: &Path, error: &dyn std::fmt::Display) -> String {
    format!("{}: cannot write the trajectory: {error}", path.display())
}

/// The most a trajectory of `frames` frames of `balls` balls may take, bytes.
pub fn size_bound(balls: usize, frames: u64) -> u64 {
    let frame = (balls as u64).saturating_mul(MAX_BYTES_PER_BALL) + MAX_FRAME_HEADER;
    frames.saturating_mul(frame)
}

/// `x` in the shortest form that reads back exactly: plain (`-12.5`) unless that would take
/// more than [`MAX_NUMBER`] characters (`1e-300`, subnormals), then scientific, which never
/// does.
pub fn number(x: f64) -> String {
    let plain = x.to_string();
    if plain.len() as u64 <= MAX_NUMBER {
        plain
    } else {
        format!("{x:e}")
    }
}

/// Refuses a trajectory at `path` of `frames` frames of `balls` balls that could exceed
/// [`MAX_TRAJECTORY_BYTES`], saying how large it could grow.
pub fn check_size(path: &Path, balls: usize, frames: u64) -> Result<(), String> {
    let bound = size_bound(balls, frames);
    if bound > MAX_TRAJECTORY_BYTES {
        return Err(format!(
            "{}: a trajectory of {frames} frames of {balls} balls could reach {:.1} GB, \
                 over the {:.0} GB limit: record fewer frames (a larger --every or fewer steps)",
            path.display(),
            bound as f64 / 1e9,
            MAX_TRAJECTORY_BYTES as f64 / 1e9
        ));
    }
    Ok(())
}

impl Trajectory {
    /// Creates `path` for `frames` frames of `balls` balls, after [`check_size`].
    pub fn create(path: &Path, balls: usize, frames: u64) -> Result<Self, String> {
        check_size(path, balls, frames)?;
        let file = File::create(path).map_err(|e| cannot_write(path, &e))?;
        Ok(Trajectory {
            writer: BufWriter::new(file),
            path: path.to_path_buf(),
            error: None,
        })
    }

    /// Writes the frame for the world's state now.
    pub fn record(&mut self, world: &mut World) {
        if self.error.is_some() {
            return;
        }
        let dump = StateDump::capture(world);
        let clock = *world.resource::<SimClock>();
        let arena = world.resource::<SimParams>().arena_size;
        if let Err(e) = write_frame(&mut self.writer, &dump, arena, clock) {
            self.error = Some(e);
        }
    }

    /// Flushes the file; the first write that failed, if any, naming the file.
    pub fn finish(mut self) -> Result<(), String> {
        let flushed = self.writer.flush();
        match self.error.take().map_or(flushed, Err) {
            Ok(()) => Ok(()),
            Err(e) => Err(cannot_write(&self.path, &e)),
        }
    }
}

/// One frame of `dump` in an arena of `arena` at `clock`.
pub fn write_frame(
    out: &mut impl Write,
    dump: &StateDump,
    arena: DVec2,
    clock: SimClock,
) -> std::io::Result<()> {
    let largest = dump.balls.iter().map(|ball| ball.r).fold(0.0, f64::max);
    let depth = (2.0 * largest).max(1.0);
    let (width, height) = (number(arena.x), number(arena.y));
    writeln!(out, "{}", dump.balls.len())?;
    writeln!(
        out,
        "Lattice=\"{width} 0 0 0 {height} 0 0 0 {}\" Origin=\"{} {} {}\" \
         Properties={PROPERTIES} Time={} step={} pbc=\"F F F\"",
        number(depth),
        number(-arena.x / 2.0),
        number(-arena.y / 2.0),
        number(-depth / 2.0),
        number(clock.elapsed),
        clock.steps
    )?;
    for ball in &dump.balls {
        writeln!(
            out,
            "X {} {} 0 {} {} 0 {} {} {}",
            number(ball.x),
            number(ball.y),
            number(ball.vx),
            number(ball.vy),
            number(ball.r),
            number(ball.m),
            ball.id
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::observe::dump::DumpedBall;

    #[test]
    fn a_frame_is_the_count_the_comment_and_a_line_per_ball() {
        let ball = |id, x, vx| DumpedBall {
            id,
            x,
            y: 40.0,
            vx,
            vy: -3.25,
            r: 10.0,
            m: 10.0,
        };
        let dump = StateDump {
            balls: vec![ball(0, -12.5, 100.0), ball(1, 0.1, -100.0)],
        };
        let clock = SimClock {
            steps: 30,
            elapsed: 0.5,
            ..default()
        };
        let mut text = Vec::new();
        write_frame(&mut text, &dump, DVec2::new(800.0, 600.0), clock).unwrap();
        assert_eq!(
            String::from_utf8(text).unwrap(),
            "2\nLattice=\"800 0 0 0 600 0 0 0 20\" Origin=\"-400 -300 -10\" \
             Properties=species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:I:1 Time=0.5 \
             step=30 pbc=\"F F F\"\n\
             X -12.5 40 0 100 -3.25 0 10 10 0\n\
             X 0.1 40 0 -100 -3.25 0 10 10 1\n"
        );
    }

    #[test]
    fn numbers_read_back_exactly_and_lines_stay_within_the_stated_bounds() {
        let awkward = [
            -1.234_567_890_123_456_7e-10,
            f64::MIN_POSITIVE / 3.0,
            -f64::MAX,
            0.1 + 0.2,
            -12.5,
        ];
        for x in awkward {
            let written = number(x);
            assert!(written.len() as u64 <= MAX_NUMBER, "{written}");
            assert_eq!(written.parse::<f64>().unwrap(), x);
        }
        let worst = DumpedBall {
            id: u32::MAX,
            x: awkward[0],
            y: awkward[1],
            vx: awkward[2],
            vy: awkward[0],
            r: -f64::MAX,
            m: awkward[1],
        };
        let clock = SimClock {
            steps: u64::MAX,
            elapsed: awkward[0],
            ..default()
        };
        let dump = StateDump { balls: vec![worst] };
        let mut text = Vec::new();
        write_frame(&mut text, &dump, DVec2::splat(-f64::MAX), clock).unwrap();
        let text = String::from_utf8(text).unwrap();
        let lines: Vec<&str> = text.split_inclusive('\n').collect();
        assert!(
            (lines[0].len() + lines[1].len()) as u64 <= MAX_FRAME_HEADER,
            "{text}"
        );
        assert!(lines[2].len() as u64 <= MAX_BYTES_PER_BALL, "{}", lines[2]);
    }

    #[test]
    fn a_million_balls_every_step_is_refused_with_its_size() {
        let path = std::env::temp_dir().join("ballpit-never-written.xyz");
        let error = Trajectory::create(&path, 1_000_000, 201).err().unwrap();
        assert!(error.contains("could reach 33.6 GB"), "{error}");
        assert!(!path.exists());
        assert!(size_bound(1_000, 601) < MAX_TRAJECTORY_BYTES);
    }
}
