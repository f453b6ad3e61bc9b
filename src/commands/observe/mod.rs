//! What `ballpit run` writes while it runs, for analysis and for watching: the [`series`]
//! (a CSV row of the whole system's figures) and the [`trajectory`] (every ball, as extended
//! XYZ frames), each at step 0, every `--every` steps and at the last step.
//!
//! Files are created, and the trajectory's size checked, before the first step, so a bad
//! path or an impossible size fails at once; a write that fails mid-run is reported at the
//! end, naming the file.

pub mod dump;
pub mod series;
pub mod trajectory;

use std::path::Path;

use bevy::prelude::*;

use self::series::Series;
use self::trajectory::Trajectory;

/// The run's observers and how often they look.
pub struct Observers {
    /// Steps between records.
    pub every: u64,
    series: Option<Series>,
    trajectory: Option<Trajectory>,
}

/// Where and how often a run records, as the command line gives it.
#[derive(Clone, Copy, Debug)]
pub struct ObserveRequest<'a> {
    pub series: Option<&'a Path>,
    pub trajectory: Option<&'a Path>,
    pub every: u64,
    /// Balls and steps of the run, for the trajectory's size.
    pub balls: usize,
    pub steps: u64,
}

impl Observers {
    /// Nothing recorded.
    pub fn none() -> Self {
        Self {
            every: u64::MAX,
            series: None,
            trajectory: None,
        }
    }

    /// Opens the files asked for: fails, naming the file, before any step runs. A refused
    /// trajectory size creates no file, and a file that cannot be created leaves none of the
    /// others behind.
    pub fn open(request: ObserveRequest) -> Result<Self, String> {
        let every = request.every.max(1);
        let frames = records(request.steps, every);
        if let Some(path) = request.trajectory {
            trajectory::check_size(path, request.balls, frames)?;
        }
        let series = request.series.map(Series::create).transpose()?;
        let trajectory = request
            .trajectory
            .map(|path| Trajectory::create(path, request.balls, frames))
            .transpose()
            .inspect_err(|_| {
                if let Some(series) = request.series {
                    let _ = std::fs::remove_file(series);
                }
            })?;
        Ok(Self {
            every,
            series,
            trajectory,
        })
    }

    /// Whether anything is recorded.
    pub fn is_empty(&self) -> bool {
        self.series.is_none() && self.trajectory.is_none()
    }

    /// Records the world's state now.
    pub fn record(&mut self, world: &mut World) {
        if let Some(series) = &mut self.series {
            series.record(world);
        }
        if let Some(trajectory) = &mut self.trajectory {
            trajectory.record(world);
        }
    }

    /// Flushes the files; the first failed write, naming its file.
    pub fn finish(self) -> Result<(), String> {
        self.series.map(Series::finish).transpose()?;
        self.trajectory.map(Trajectory::finish).transpose()?;
        Ok(())
    }
}

/// How many records a run of `steps` makes: step 0, every `every`-th step and the last.
pub fn records(steps: u64, every: u64) -> u64 {
    1 + steps / every + u64::from(!steps.is_multiple_of(every))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_count_step_zero_every_kth_step_and_the_last() {
        assert_eq!(records(0, 1), 1);
        assert_eq!(records(10, 1), 11);
        assert_eq!(records(10, 5), 3);
        assert_eq!(records(10, 3), 5); // 0, 3, 6, 9, 10
        assert_eq!(records(10, 100), 2);
    }
}
