//! Mouse and keys. Click empty space: a ball appears there (as large as the spawn settings
//! allow and the room permits). Drag from a ball and release: it is flung with a velocity from
//! the drag, and while dragging the aiming guide shows what it will hit. Space pauses, N steps
//! once, R resets, H hides the panel. Pointer and keys over the panel stay with the panel.
//! Balls are added and flung through [`Intent`]s, applied in the fixed step. Runs in the
//! windowed app's `Update`.

use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use bevy_egui::input::{egui_wants_any_keyboard_input, egui_wants_any_pointer_input};
use rand::RngExt;

use crate::app::scenes::SceneRequest;
use crate::app::view::{Aim, AimGuide, PanelVisible, UiRng};
use crate::sim::geometry::Circle;
use crate::sim::params::MAX_FLING_SPEED;
use crate::sim::spawn::fit_radius_at;
use crate::sim::{Ball, BallState, Intent, Position, Radius, RunControl, SimParams, SpawnSettings};

/// Fling speed per pixel of drag, per second: a 100 px drag flings at 300 px/s.
pub const FLING_GAIN: f64 = 3.0;

pub(super) fn plugin(app: &mut App) {
    app.add_systems(
        Update,
        (
            press_pointer.run_if(not(egui_wants_any_pointer_input)),
            drag_and_release,
            handle_keys.run_if(not(egui_wants_any_keyboard_input)),
        )
            .chain(),
    );
}

/// The velocity a drag from `ball_centre` to `pointer` flings a ball with: along the drag,
/// [`FLING_GAIN`] per pixel, at most [`MAX_FLING_SPEED`].
pub fn fling_velocity(ball_centre: DVec2, pointer: DVec2) -> DVec2 {
    ((pointer - ball_centre) * FLING_GAIN).clamp_length_max(MAX_FLING_SPEED)
}

/// The ball under `point`: the one whose circle contains it, nearest centre first.
pub fn ball_under<T: Copy>(
    point: DVec2,
    balls: impl IntoIterator<Item = (T, Circle)>,
) -> Option<T> {
    balls
        .into_iter()
        .filter(|(_, circle)| {
            circle.center.distance_squared(point) <= circle.radius * circle.radius
        })
        .min_by(|(_, a), (_, b)| {
            a.center
                .distance_squared(point)
                .total_cmp(&b.center.distance_squared(point))
        })
        .map(|(id, _)| id)
}

/// The pointer in arena coordinates, if it is over the window.
fn pointer_in_arena(window: &Window, camera: (&Camera, &GlobalTransform)) -> Option<DVec2> {
    let cursor = window.cursor_position()?;
    camera
        .0
        .viewport_to_world_2d(camera.1, cursor)
        .ok()
        .map(|p| p.as_dvec2())
}

fn press_pointer(
    buttons: Res<ButtonInput<MouseButton>>,
    window: Single<&Window, With<PrimaryWindow>>,
    camera: Single<(&Camera, &GlobalTransform)>,
    balls: Query<(Entity, &Position, &Radius), With<Ball>>,
    params: Res<SimParams>,
    settings: Res<SpawnSettings>,
    mut rng: ResMut<UiRng>,
    mut guide: ResMut<AimGuide>,
    mut intents: MessageWriter<Intent>,
) {
    if !buttons.just_pressed(MouseButton::Left) {
        return;
    }
    let Some(point) = pointer_in_arena(&window, *camera) else {
        return;
    };
    let circles = balls.iter().map(|(e, p, r)| (e, Circle::new(p.0, r.0)));
    if let Some(ball) = ball_under(point, circles.clone()) {
        guide.0 = Some(Aim {
            ball,
            velocity: DVec2::ZERO,
        });
        return;
    }
    let wanted = rng.0.random_range(settings.radius.0..=settings.radius.1);
    if let Some(radius) = fit_radius_at(
        point,
        wanted,
        params.half_extents(),
        circles.map(|(_, c)| c),
    ) {
        intents.write(Intent::Spawn(BallState {
            position: point,
            velocity: DVec2::ZERO,
            radius,
        }));
    }
}

fn drag_and_release(
    buttons: Res<ButtonInput<MouseButton>>,
    window: Single<&Window, With<PrimaryWindow>>,
    camera: Single<(&Camera, &GlobalTransform)>,
    balls: Query<&Position, With<Ball>>,
    mut guide: ResMut<AimGuide>,
    mut intents: MessageWriter<Intent>,
) {
    let Some(aim) = guide.0 else { return };
    let Ok(position) = balls.get(aim.ball) else {
        guide.0 = None; // the ball is gone (reset, count lowered)
        return;
    };
    let fling =
        pointer_in_arena(&window, *camera).map_or(aim.velocity, |p| fling_velocity(position.0, p));
    if buttons.pressed(MouseButton::Left) {
        guide.0 = Some(Aim {
            velocity: fling,
            ..aim
        });
    } else {
        intents.write(Intent::Fling {
            ball: aim.ball,
            velocity: fling,
        });
        guide.0 = None;
    }
}

fn handle_keys(
    keys: Res<ButtonInput<KeyCode>>,
    mut run: ResMut<RunControl>,
    mut panel: ResMut<PanelVisible>,
    mut requests: MessageWriter<SceneRequest>,
) {
    if keys.just_pressed(KeyCode::Space) {
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fling_follows_the_drag_and_is_capped() {
        let v = fling_velocity(DVec2::new(10.0, 10.0), DVec2::new(110.0, 10.0));
        assert_eq!(v, DVec2::new(300.0, 0.0));
        let v = fling_velocity(DVec2::ZERO, DVec2::new(0.0, -1e6));
        assert!((v.length() - MAX_FLING_SPEED).abs() < 1e-9);
        assert!(v.y < 0.0);
        assert_eq!(fling_velocity(DVec2::ONE, DVec2::ONE), DVec2::ZERO);
    }

    #[test]
    fn ball_under_picks_the_containing_ball_nearest_its_centre() {
        let balls = [
            (1, Circle::new(DVec2::new(0.0, 0.0), 10.0)),
            (2, Circle::new(DVec2::new(12.0, 0.0), 10.0)),
        ];
        assert_eq!(ball_under(DVec2::new(7.0, 0.0), balls), Some(2));
        assert_eq!(ball_under(DVec2::new(-5.0, 0.0), balls), Some(1));
        assert_eq!(ball_under(DVec2::new(0.0, 30.0), balls), None);
    }
}
