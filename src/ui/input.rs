//! Mouse and keys. The pointer on the balls is [`hands`]'s; here are the wheel and the keys.
//! The wheel zooms at the pointer; `F` fits the arena; `Delete` (or `Backspace`) removes the
//! ball under the pointer; `?` (or F1) shows every input; Space pauses (on release, unless the
//! view was dragged with it held); N steps once; R resets; H hides the panel. Pointer and keys
//! over the panel stay with the panel. Runs in the windowed app's `Update`.

use bevy::input::mouse::{MouseScrollUnit, MouseWheel};
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::input::{egui_wants_any_keyboard_input, egui_wants_any_pointer_input};

use super::hands::{self, Hand, PannedWithSpace};
use super::pointer::{ball_under, pointer_in_arena};
use crate::app::scenes::SceneRequest;
use crate::app::view::{HelpVisible, PanelVisible, PlayArea};
use crate::sim::geometry::Circle;
use crate::sim::{Ball, Intent, Position, Radius, RunControl};

/// Zoom per wheel notch: each notch shows 15 % more or less of the arena.
const ZOOM_PER_NOTCH: f32 = 1.15;
/// Pixels of a touchpad's scroll that count as one wheel notch.
const PIXELS_PER_NOTCH: f32 = 40.0;

pub(super) fn plugin(app: &mut App) {
    app.init_resource::<Hand>()
        .init_resource::<PannedWithSpace>()
        .add_systems(
            Update,
            (
                hands::press.run_if(not(egui_wants_any_pointer_input)),
                hands::drag_and_release,
                zoom_with_wheel.run_if(not(egui_wants_any_pointer_input)),
                handle_keys.run_if(not(egui_wants_any_keyboard_input)),
            )
                .chain(),
        );
}

/// The zoom factor for a wheel turned `notches` (positive away from the player, which
/// zooms in).
pub fn wheel_zoom_factor(notches: f32) -> f32 {
    ZOOM_PER_NOTCH.powf(-notches)
}

fn zoom_with_wheel(
    mut wheel: MessageReader<MouseWheel>,
    window: Single<&Window, With<PrimaryWindow>>,
    camera: Single<(&Camera, &GlobalTransform)>,
    mut play_area: ResMut<PlayArea>,
) {
    let notches: f32 = wheel
        .read()
        .map(|event| match event.unit {
            MouseScrollUnit::Line => event.y,
            MouseScrollUnit::Pixel => event.y / PIXELS_PER_NOTCH,
        })
        .sum();
    if notches == 0.0 {
        return;
    }
    if let Some(pointer) = pointer_in_arena(&window, *camera) {
        play_area.zoom_at(pointer.as_vec2(), wheel_zoom_factor(notches));
    }
}

fn handle_keys(
    keys: Res<ButtonInput<KeyCode>>,
    window: Option<Single<&Window, With<PrimaryWindow>>>,
    camera: Option<Single<(&Camera, &GlobalTransform)>>,
    balls: Query<(Entity, &Position, &Radius), With<Ball>>,
    mut run: ResMut<RunControl>,
    mut panel: ResMut<PanelVisible>,
    mut help: ResMut<HelpVisible>,
    mut play_area: ResMut<PlayArea>,
    mut panned: ResMut<PannedWithSpace>,
    mut requests: MessageWriter<SceneRequest>,
    mut intents: MessageWriter<Intent>,
) {
    if keys.just_pressed(KeyCode::Space) {
        panned.0 = false;
    }
    if keys.just_released(KeyCode::Space) && !std::mem::take(&mut panned.0) {
        run.paused = !run.paused;
    }
    if keys.just_pressed(KeyCode::KeyN) {
        run.step_once();
    }
    if keys.just_pressed(KeyCode::KeyR) {
        requests.write(SceneRequest::Reset);
    }
    if keys.just_pressed(KeyCode::KeyH) {
        panel.0 = !panel.0;
    }
    if keys.any_just_pressed([KeyCode::Slash, KeyCode::F1]) {
        help.0 = !help.0;
    }
    if keys.just_pressed(KeyCode::KeyF) {
        play_area.request_fit();
    }
    let delete = keys.any_just_pressed([KeyCode::Delete, KeyCode::Backspace]);
    if let (true, Some(window), Some(camera)) = (delete, window, camera)
        && let Some(pointer) = pointer_in_arena(&window, *camera)
    {
        let circles = balls.iter().map(|(e, p, r)| (e, Circle::new(p.0, r.0)));
        if let Some(ball) = ball_under(pointer, circles) {
            intents.write(Intent::Remove(ball));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wheel_zooms_in_away_from_the_player_and_out_towards() {
        assert!(wheel_zoom_factor(1.0) < 1.0);
        assert!(wheel_zoom_factor(-1.0) > 1.0);
        assert!((wheel_zoom_factor(2.0) * wheel_zoom_factor(-2.0) - 1.0).abs() < 1e-6);
        assert_eq!(wheel_zoom_factor(0.0), 1.0);
    }
}
