//! `--series OUT.csv`: one CSV row per record of the whole system: energies, momentum,
//! temperature, the pressure over the row's interval, the collisions so far, the largest
//! overlap and the balls asleep. The header ([`COLUMNS`]) is the contract; the README gives
//! the units.

use std::fs::File;
use std::path::{Path, PathBuf};

use bevy::prelude::*;

use crate::sim::measure::stats::wall_pressure;
use crate::sim::{SimClock, SimParams, SimStats, StateSummary};

/// The series' columns, in order.
pub const COLUMNS: [&str; 12] = [
    "step",
    "time_s",
    "kinetic_energy",
    "mechanical_energy",
    "momentum_x",
    "momentum_y",
    "temperature",
    "pressure",
    "ball_collisions",
    "wall_collisions",
    "max_overlap_rel",
    "sleeping",
];

/// An open series file. A write that fails is kept and reported by [`finish`](Self::finish);
/// the run itself goes on.
pub struct Series {
    writer: csv::Writer<File>,
    path: PathBuf,
    /// The wall impulse and simulated time at the last row, for the next row's pressure.
    last: Option<(f64, f64)>,
    error: Option<String>,
}

fn cannot_write(path: &Path, error: &dyn std::fmt::Display) -> String {
    format!("{}: cannot write the series: {error}", path.display())
}

impl Series {
    /// Creates `path` and writes the header.
    pub fn create(path: &Path) -> Result<Self, String> {
        let file = File::create(path).map_err(|e| cannot_write(path, &e))?;
        let mut writer = csv::Writer::from_writer(file);
        writer
            .write_record(COLUMNS)
            .map_err(|e| cannot_write(path, &e))?;
        Ok(Series {
            writer,
            path: path.to_path_buf(),
            last: None,
            error: None,
        })
    }

    /// Writes the row for the world's state now. The first row's pressure, over no time,
    /// is `NaN`.
    pub fn record(&mut self, world: &mut World) {
        if self.error.is_some() {
            return;
        }
        let summary = StateSummary::measure(world);
        let stats = world.resource::<SimStats>().clone();
        let clock = *world.resource::<SimClock>();
        let arena = world.resource::<SimParams>().arena_size;
        let pressure = self.last.map_or(f64::NAN, |(impulse, time)| {
            wall_pressure(stats.wall_impulse - impulse, arena, clock.elapsed - time)
        });
        self.last = Some((stats.wall_impulse, clock.elapsed));
        let row = [
            clock.steps.to_string(),
            clock.elapsed.to_string(),
            summary.kinetic_energy.to_string(),
            summary.mechanical_energy.to_string(),
            summary.momentum.x.to_string(),
            summary.momentum.y.to_string(),
            summary.temperature().to_string(),
            pressure.to_string(),
            stats.ball_collisions.to_string(),
            stats.wall_collisions.to_string(),
            summary.max_overlap_rel.to_string(),
            summary.sleeping.to_string(),
        ];
        if let Err(e) = self.writer.write_record(row) {
            self.error = Some(e.to_string());
        }
    }

    /// Flushes the file; the first write that failed, if any, naming the file.
    pub fn finish(mut self) -> Result<(), String> {
        let flushed = self.writer.flush().map_err(|e| e.to_string());
        match self.error.take().map_or(flushed, Err) {
            Ok(()) => Ok(()),
            Err(e) => Err(cannot_write(&self.path, &e)),
        }
    }
}
