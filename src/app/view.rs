//! The toy's view state, shared by its parts: what the view shows ([`ViewSettings`]), how the
//! arena maps onto the window ([`PlayArea`], [`fit_window`]), what the player's hands are
//! doing ([`AimGuide`], [`NewBallGuide`]), whether the panel shows, and the UI's own random
//! numbers. The UI writes it,
//! rendering reads it; nothing here touches the simulation.

use bevy::math::DVec2;
use bevy::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::sim::BallState;

/// The side panel's width, logical pixels.
pub const PANEL_WIDTH: f32 = 290.0;
/// Largest window the toy opens or resizes to, logical pixels.
const MAX_WINDOW: Vec2 = Vec2::new(1600.0, 1000.0);
/// Smallest window the toy opens, logical pixels: the whole panel fits in it.
const MIN_WINDOW: Vec2 = Vec2::new(1280.0, 720.0);

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

/// Speed shown as the hottest colour in [`ColourMode::BySpeed`], pixels per second.
pub const HOT_SPEED: f64 = 600.0;
/// Radius range spanned by the colours of [`ColourMode::BySize`], pixels.
pub const SIZE_COLOUR_RANGE: (f64, f64) = (5.0, 50.0);

/// A colour from cool (0) to hot (1): the scale of the size and speed colourings (drawn by
/// the renderer, shown as a legend by the panel).
pub fn heat_colour(heat: f64) -> Color {
    let heat = heat.clamp(0.0, 1.0) as f32;
    Color::hsl(240.0 * (1.0 - heat), 0.75, 0.55)
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

/// How the arena maps onto the window: a camera over the arena, `zoom` arena pixels to a
/// window pixel, with the arena point `center` at the window's centre. The side panel covers
/// a strip on the left. The view fits the arena (centred right of the panel, the whole arena
/// showing) when a scene loads or on `F`, and keeps fitting it as the window or the arena
/// changes size until the player zooms or pans. Showing or hiding the panel moves nothing:
/// balls stay where they are on screen.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct PlayArea {
    /// Logical pixels.
    pub panel_width: f32,
    /// Arena pixels per window pixel, within [`ZOOM_RANGE`].
    pub zoom: f32,
    /// The arena point at the window's centre, arena pixels.
    pub center: Vec2,
    /// Whether the view keeps fitting the arena.
    pub follow_fit: bool,
    /// The (arena, window) sizes the view was last fitted to.
    pub fitted_sizes: Option<(Vec2, Vec2)>,
}

/// Window pixels left free around a fitted arena.
pub const FIT_MARGIN: f32 = 12.0;
/// Arena pixels per window pixel: from 16 window pixels per arena pixel to 4096 arena pixels
/// per window pixel (a million-pixel arena fits a 250-pixel window).
pub const ZOOM_RANGE: std::ops::RangeInclusive<f32> = (1.0 / 16.0)..=4096.0;

impl Default for PlayArea {
    fn default() -> Self {
        PlayArea {
            panel_width: 0.0,
            zoom: 1.0,
            center: Vec2::ZERO,
            follow_fit: true,
            fitted_sizes: None,
        }
    }
}

impl PlayArea {
    /// Fits the view to the arena now and keeps fitting it (a loaded scene, `F`).
    pub fn request_fit(&mut self) {
        self.follow_fit = true;
        self.fitted_sizes = None;
    }

    /// Fits the view to an `arena` (arena pixels, centred on the origin) shown in a window of
    /// `window` logical pixels, if it follows the fit and either size changed since. A window
    /// with no room beside the panel (minimised) leaves the view as it was.
    pub fn keep_fitted(&mut self, arena: Vec2, window: Vec2) {
        let sizes = Some((arena, window));
        if !self.follow_fit || self.fitted_sizes == sizes {
            return;
        }
        let room = window - Vec2::new(self.panel_width, 0.0) - Vec2::splat(2.0 * FIT_MARGIN);
        if !(room.min_element() >= 1.0 && arena.is_finite()) {
            return;
        }
        self.zoom = (arena / room)
            .max_element()
            .clamp(*ZOOM_RANGE.start(), *ZOOM_RANGE.end());
        // The window's centre sits half a panel left of the play area's centre.
        self.center = Vec2::new(-self.panel_width / 2.0 * self.zoom, 0.0);
        self.fitted_sizes = sizes;
    }

    /// Zooms by `factor` (above 1 zooms out) keeping the arena point `fixed` where it is on
    /// screen; the player has taken the view over.
    pub fn zoom_at(&mut self, fixed: Vec2, factor: f32) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let zoom = (self.zoom * factor).clamp(*ZOOM_RANGE.start(), *ZOOM_RANGE.end());
        self.center = fixed + (self.center - fixed) * (zoom / self.zoom);
        self.zoom = zoom;
        self.follow_fit = false;
    }

    /// Moves the view with a pointer that moved `window_delta` logical pixels (y down): the
    /// arena under it moves along; the player has taken the view over.
    pub fn pan_by(&mut self, window_delta: Vec2) {
        if window_delta.is_finite() {
            self.center -= Vec2::new(window_delta.x, -window_delta.y) * self.zoom;
            self.follow_fit = false;
        }
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

/// The ball a drag from empty space will add, and the velocity it will be thrown with; set by
/// the input handling, drawn as a ghost with an arrow.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq)]
pub struct NewBallGuide(pub Option<BallState>);

/// Whether the help overlay (every input) is shown: `?` and the panel's Help button toggle it.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct HelpVisible(pub bool);

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

/// The window size to open for `arena` beside a panel `panel` pixels wide: the arena at one
/// pixel per pixel with a margin around it if that fits the largest window, else the largest.
pub fn fit_window(arena: Vec2, panel: f32) -> Vec2 {
    let frame = Vec2::new(panel, 0.0) + Vec2::splat(2.0 * FIT_MARGIN);
    let zoom = (arena / (MAX_WINDOW - frame)).max_element().max(1.0);
    (arena / zoom + frame).clamp(MIN_WINDOW, MAX_WINDOW)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heat_runs_from_blue_to_red_and_clamps() {
        assert_eq!(heat_colour(-1.0), heat_colour(0.0));
        assert_eq!(heat_colour(7.0), heat_colour(1.0));
        assert_ne!(heat_colour(0.0), heat_colour(1.0));
    }

    #[test]
    fn the_window_opens_one_to_one_for_small_arenas_and_at_most_the_largest() {
        let margins = Vec2::splat(2.0 * FIT_MARGIN);
        let window = fit_window(Vec2::new(1200.0, 800.0), 300.0);
        assert_eq!(window, Vec2::new(1500.0, 800.0) + margins);
        assert_eq!(fit_window(Vec2::new(3000.0, 3000.0), 300.0).y, MAX_WINDOW.y);
        assert_eq!(fit_window(Vec2::new(10.0, 10.0), 300.0), MIN_WINDOW);
    }

    #[test]
    fn a_fitted_view_shows_the_whole_arena_right_of_the_panel() {
        let mut area = PlayArea {
            panel_width: 300.0,
            ..default()
        };
        let window = Vec2::new(1100.0, 600.0) + Vec2::splat(2.0 * FIT_MARGIN);
        area.keep_fitted(Vec2::new(800.0, 600.0), window);
        assert_eq!((area.zoom, area.center), (1.0, Vec2::new(-150.0, 0.0)));
        // A larger arena zooms out; the play area's centre stays on the arena's.
        area.keep_fitted(Vec2::new(1600.0, 1200.0), window);
        assert_eq!(area.zoom, 2.0);
        assert_eq!(area.center, Vec2::new(-300.0, 0.0));
        // No room beside the panel (minimised): the view stays.
        area.keep_fitted(Vec2::new(800.0, 600.0), Vec2::ZERO);
        assert_eq!(area.zoom, 2.0);
    }

    #[test]
    fn zooming_keeps_the_point_under_the_pointer_and_stops_following_the_fit() {
        let mut area = PlayArea::default();
        let fixed = Vec2::new(100.0, 50.0);
        let on_screen = |area: &PlayArea| (fixed - area.center) / area.zoom;
        let before = on_screen(&area);
        area.zoom_at(fixed, 0.5);
        assert_eq!(area.zoom, 0.5);
        assert!((on_screen(&area) - before).length() < 1e-4);
        assert!((area.center - Vec2::new(50.0, 25.0)).length() < 1e-4);
        assert!(!area.follow_fit);
        // Bounded, and a bad factor changes nothing.
        area.zoom_at(fixed, 1e-9);
        assert_eq!(area.zoom, *ZOOM_RANGE.start());
        let kept = area;
        area.zoom_at(fixed, f32::NAN);
        area.zoom_at(fixed, -2.0);
        assert_eq!(area, kept);
        // Fitting again follows the fit.
        area.request_fit();
        area.keep_fitted(Vec2::splat(100.0), Vec2::splat(500.0));
        assert!(area.follow_fit);
        assert!((area.zoom - 100.0 / (500.0 - 2.0 * FIT_MARGIN)).abs() < 1e-6);
    }

    #[test]
    fn panning_drags_the_arena_with_the_pointer() {
        let mut area = PlayArea {
            zoom: 2.0,
            ..default()
        };
        // The pointer moves right and down: the view's centre moves left and up.
        area.pan_by(Vec2::new(10.0, 5.0));
        assert_eq!(area.center, Vec2::new(-20.0, 10.0));
        assert!(!area.follow_fit);
    }
}
