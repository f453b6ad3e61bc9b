//! [`SceneFile`]: a scene file as written, read and parsed from RON (every value checked as it
//! is read, so an error names its line and column) and written back.

use std::path::Path;

use bevy::math::DVec2;
use ron::extensions::Extensions;
use serde::{Deserialize, Serialize};

use super::check::checked;
use crate::sim::params::{CollisionMode, MassModel};

/// Largest scene file read, bytes (a million hand-written balls fit in about 80 MB).
pub const MAX_SCENE_BYTES: u64 = 128 * 1024 * 1024;
/// Arena used when a scene gives neither `arena` nor `area_fraction`, pixels.
pub const DEFAULT_ARENA: DVec2 = DVec2::new(800.0, 600.0);

/// A scene file as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Arena size; when absent it comes from `generate.area_fraction`, else 800 x 600.
    #[serde(default)]
    pub arena: Option<ArenaSpec>,
    /// Pixels per second squared, (x, y).
    #[serde(default, deserialize_with = "checked::gravity")]
    pub gravity: (f64, f64),
    #[serde(
        default = "perfectly_elastic",
        deserialize_with = "checked::restitution"
    )]
    pub restitution: f64,
    #[serde(default)]
    pub mass_model: MassModel,
    /// Per second.
    #[serde(default, deserialize_with = "checked::damping")]
    pub linear_damping: f64,
    /// `Continuous` or `Discrete`; when absent, loading the scene keeps the mode in use.
    #[serde(default)]
    pub collisions: Option<CollisionMode>,
    /// Balls placed by hand.
    #[serde(default)]
    pub balls: Vec<BallSpec>,
    /// Random balls added after the hand-placed ones.
    #[serde(default)]
    pub generate: Option<Generate>,
}

fn perfectly_elastic() -> f64 {
    1.0
}

/// Arena size, pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArenaSpec {
    #[serde(deserialize_with = "checked::arena_width")]
    pub width: f64,
    #[serde(deserialize_with = "checked::arena_height")]
    pub height: f64,
}

/// One hand-placed ball: pixels and pixels per second.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BallSpec {
    #[serde(deserialize_with = "checked::position")]
    pub position: (f64, f64),
    #[serde(default, deserialize_with = "checked::velocity")]
    pub velocity: (f64, f64),
    #[serde(deserialize_with = "checked::radius")]
    pub radius: f64,
}

/// Random balls: radius and speed uniform in their ranges, direction uniform, no overlaps.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Generate {
    #[serde(deserialize_with = "checked::count")]
    pub count: usize,
    /// (min, max) pixels.
    #[serde(deserialize_with = "checked::radius_range")]
    pub radius: (f64, f64),
    /// (min, max) pixels per second.
    #[serde(deserialize_with = "checked::speed_range")]
    pub speed: (f64, f64),
    /// With no `arena`: the arena is the square in which all balls cover this fraction.
    #[serde(default, deserialize_with = "checked::area_fraction")]
    pub area_fraction: Option<f64>,
    #[serde(default)]
    pub seed: u64,
}

/// Why a scene could not be loaded. Each message names the file, and the line and column or
/// the ball index where it applies.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{origin}: cannot read the scene: {source}")]
    Read {
        origin: String,
        source: std::io::Error,
    },
    #[error("{origin}:{line}:{column}: {message}")]
    Syntax {
        origin: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{origin}: {message}")]
    Invalid { origin: String, message: String },
}

fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME)
}

impl SceneFile {
    /// Reads and parses the scene file at `path`.
    pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
        let origin = path.display().to_string();
        let read_error = |source| SceneError::Read {
            origin: origin.clone(),
            source,
        };
        let size = std::fs::metadata(path).map_err(read_error)?.len();
        if size > MAX_SCENE_BYTES {
            return Err(SceneError::Invalid {
                origin,
                message: format!(
                    "the file is {size} bytes; scene files are limited to {MAX_SCENE_BYTES}"
                ),
            });
        }
        let text = std::fs::read_to_string(path).map_err(read_error)?;
        SceneFile::parse(&text, &origin)
    }

    /// Parses RON text; `origin` names it in errors (usually the file path).
    pub fn parse(text: &str, origin: &str) -> Result<SceneFile, SceneError> {
        ron_options()
            .from_str(text)
            .map_err(|error| SceneError::Syntax {
                origin: origin.to_string(),
                line: error.span.start.line,
                column: error.span.start.col,
                message: error.code.to_string(),
            })
    }

    /// The scene as pretty RON that [`parse`](Self::parse) reads back to the same value.
    pub fn to_ron(&self) -> String {
        ron_options()
            .to_string_pretty(self, ron::ser::PrettyConfig::default())
            .expect("a scene holds only plain numbers, tuples and enums, which RON always writes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_fraction_sets_a_square_arena() {
        let scene = SceneFile::parse(
            "(generate: Some((count: 100, radius: (10.0, 10.0), speed: (0.0, 0.0), area_fraction: 0.25)))",
            "test",
        )
        .unwrap();
        let setup = scene.build("test").unwrap();
        let expected_side = (100.0 * std::f64::consts::PI * 100.0 / 0.25_f64).sqrt();
        assert!((setup.params.arena_size.x - expected_side).abs() < 1e-9);
        assert_eq!(setup.params.arena_size.x, setup.params.arena_size.y);
    }
}
