//! The toy's view state, shared by its parts: what the view shows ([`ViewSettings`]), how the
//! arena maps onto the window ([`PlayArea`], [`fit_window`]), the ball being aimed
//! ([`AimGuide`]), whether the panel shows, and the UI's own random numbers. The UI writes it,
//! rendering reads it; nothing here touches the simulation.

use bevy::math::DVec2;
use bevy::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::sim::params::ARENA_SIDE_RANGE;

/// The side panel's width, logical pixels.
pub const PANEL_WIDTH: f32 = 290.0;
/// Largest window the toy opens or resizes to, logical pixels.
const MAX_WINDOW: Vec2 = Vec2::new(1600.0, 1000.0);
/// Smallest window the toy resizes to for a scene, logical pixels.
const MIN_WINDOW: Vec2 = Vec2::new(640.0, 400.0);

/// How balls are coloured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColourMode {
    /// A distinct colour per ball.
    #[default]
    ByBall,
    /// Small balls cool, large balls warm.
    BySize,
    /// Slow balls cool, fast balls hot.
    BySpeed,
}

/// What the view shows; the panel tunes it.
#[derive(Resource, Clone, Debug, PartialEq)]
pub struct ViewSettings {
    pub colour_mode: ColourMode,
    pub show_aabbs: bool,
    pub show_contacts: bool,
    pub show_velocities: bool,
    pub show_bursts: bool,
    /// Draw sleeping balls dimmed.
    pub dim_sleeping: bool,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings {
            colour_mode: ColourMode::ByBall,
            show_aabbs: false,
            show_contacts: false,
            show_velocities: false,
            show_bursts: true,
            dim_sleeping: true,
        }
    }
}

/// How the arena maps onto the window: the side panel covers a strip on the left and the
/// rest shows the arena, `zoom` arena pixels to a window pixel (more than 1 for arenas larger
/// than any window).
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct PlayArea {
    /// Logical pixels.
    pub panel_width: f32,
    /// Arena pixels per window pixel, at least 1.
    pub zoom: f32,
}

impl Default for PlayArea {
    fn default() -> Self {
        PlayArea {
            panel_width: 0.0,
            zoom: 1.0,
        }
    }
}

impl PlayArea {
    /// The arena the window of `window_size` logical pixels shows; `None` when it shows none
    /// (minimised, or no wider than the panel), bounded by the accepted arena sides.
    pub fn arena_for_window(&self, window_size: Vec2) -> Option<Vec2> {
        let arena = (window_size - Vec2::new(self.panel_width, 0.0)) * self.zoom;
        let (smallest, largest) = (*ARENA_SIDE_RANGE.start(), *ARENA_SIDE_RANGE.end());
        (arena.is_finite() && arena.min_element() as f64 >= smallest)
            .then(|| arena.min(Vec2::splat(largest as f32)))
    }
}

/// The ball being aimed and the velocity it would be flung with; set by the input handling.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq)]
pub struct AimGuide(pub Option<Aim>);

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aim {
    pub ball: Entity,
    /// Pixels per second.
    pub velocity: DVec2,
}

/// Whether the panel is shown (H toggles it).
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq)]
pub struct PanelVisible(pub bool);

impl Default for PanelVisible {
    fn default() -> Self {
        PanelVisible(true)
    }
}

/// The UI's random numbers (a clicked ball's radius, a new seed): apart from the
/// simulation's [`SimRng`](crate::sim::SimRng), so playing never changes what a seed gives.
#[derive(Resource, Debug, Clone)]
pub struct UiRng(pub ChaCha8Rng);

impl Default for UiRng {
    fn default() -> Self {
        UiRng(ChaCha8Rng::seed_from_u64(0x0ba1_1b17))
    }
}

/// The window size and zoom that show `arena` beside a panel `panel` pixels wide: the arena at
/// one pixel per pixel if that fits the largest window, else zoomed out until it does.
pub fn fit_window(arena: Vec2, panel: f32) -> (Vec2, f32) {
    let room = MAX_WINDOW - Vec2::new(panel, 0.0);
    let zoom = (arena / room).max_element().max(1.0);
    let window = (arena / zoom + Vec2::new(panel, 0.0)).clamp(MIN_WINDOW, MAX_WINDOW);
    (window, zoom)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_arenas_show_one_to_one_and_large_ones_zoom_out() {
        let (window, zoom) = fit_window(Vec2::new(800.0, 600.0), 300.0);
        assert_eq!((window, zoom), (Vec2::new(1100.0, 600.0), 1.0));
        let (window, zoom) = fit_window(Vec2::new(3000.0, 3000.0), 300.0);
        assert_eq!(zoom, 3.0);
        assert_eq!(window, Vec2::new(1300.0, 1000.0));
    }

    #[test]
    fn the_arena_is_the_window_right_of_the_panel_times_the_zoom() {
        let area = PlayArea {
            panel_width: 200.0,
            zoom: 2.0,
        };
        assert_eq!(
            area.arena_for_window(Vec2::new(1000.0, 600.0)),
            Some(Vec2::new(1600.0, 1200.0))
        );
        // Minimised, or no wider than the panel: no arena.
        assert_eq!(area.arena_for_window(Vec2::ZERO), None);
        assert_eq!(area.arena_for_window(Vec2::new(200.0, 600.0)), None);
        assert_eq!(area.arena_for_window(Vec2::new(1000.0, 0.0)), None);
    }
}
