//! The fuzzer's audit of scene text (`fuzz/`), also replayed by `cargo test` over the kept
//! regressions and the shipped scenes.

use bevy::math::DVec2;

use super::file::SceneFile;
use crate::sim::geometry::Circle;
use crate::sim::geometry::circle::overlapping;

/// Scenes with more balls than this are parsed but not built by [`audit_scene_text`]: placing
/// a million balls is correct but slow, and would starve a fuzzer of inputs.
pub const AUDIT_MAX_BUILT_BALLS: usize = 20_000;
/// Scenes up to this many balls are also checked pair by pair for overlaps.
const AUDIT_MAX_PAIRWISE_BALLS: usize = 500;

/// What the fuzzer (`fuzz/`) and its regression tests check of any text offered as a scene:
/// reading it may fail but must not panic; a scene that parses writes back to RON that parses
/// to the same scene; a scene that builds (up to [`AUDIT_MAX_BUILT_BALLS`]) has every ball
/// finite, inside its arena and, up to 500 balls, none overlapping. `Err` says which of these
/// failed.
pub fn audit_scene_text(text: &str) -> Result<(), String> {
    let Ok(scene) = SceneFile::parse(text, "audit") else {
        return Ok(());
    };
    let written = scene.to_ron();
    let reread = SceneFile::parse(&written, "audit (written back)")
        .map_err(|error| format!("a parsed scene wrote unreadable RON: {error}\n{written}"))?;
    if reread.to_ron() != written {
        return Err(format!("writing back changed the scene:\n{written}"));
    }
    let count = scene.balls.len() + scene.generate.map_or(0, |g| g.count);
    if count > AUDIT_MAX_BUILT_BALLS {
        return Ok(());
    }
    let Ok(setup) = scene.build("audit") else {
        return Ok(());
    };
    let half = setup.params.half_extents();
    if !(half.is_finite() && half.min_element() > 0.0) {
        return Err(format!("arena {}", setup.params.arena_size));
    }
    for (index, ball) in setup.balls.iter().enumerate() {
        let room = half - DVec2::splat(ball.radius);
        let inside = ball.position.abs().cmple(room * (1.0 + 1e-12)).all();
        if !(ball.position.is_finite() && ball.velocity.is_finite() && ball.radius > 0.0 && inside)
        {
            return Err(format!(
                "ball {index}: {ball:?} in arena {}",
                setup.params.arena_size
            ));
        }
    }
    if setup.balls.len() <= AUDIT_MAX_PAIRWISE_BALLS {
        for (i, a) in setup.balls.iter().enumerate() {
            for (j, b) in setup.balls.iter().enumerate().skip(i + 1) {
                if overlapping(
                    Circle::new(a.position, a.radius),
                    Circle::new(b.position, b.radius),
                ) {
                    return Err(format!("balls {i} and {j} overlap: {a:?} {b:?}"));
                }
            }
        }
    }
    Ok(())
}
