//! The pointer on the balls, as physics sandboxes have it:
//!
//! - left drag from a ball: aim and fling (the guide shows what it will hit);
//! - right drag, or Shift + left drag, on a ball: carry it (it follows the pointer through
//!   the simulation's bounded spring and is thrown with the pointer's velocity on release);
//! - left click or drag in empty space: a new ball there, thrown along the drag;
//! - right click on a ball: remove it;
//! - middle drag, or Space + left drag: pan the view.
//!
//! Everything that changes balls is an [`Intent`], applied in the fixed step (so it works
//! paused); panning changes only the [`PlayArea`]. Runs in the windowed app's `Update`.

use std::collections::VecDeque;

use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;
use rand::RngExt;

use super::pointer::{ball_under, fling_velocity, pointer_in_arena};
use crate::app::view::{Aim, AimGuide, NewBallGuide, PlayArea, UiRng};
use crate::sim::geometry::Circle;
use crate::sim::params::MAX_FLING_SPEED;
use crate::sim::spawn::fit_radius_at;
use crate::sim::{Ball, BallState, Intent, Position, Radius, SimParams, SpawnSettings};

/// How far (window pixels) a right press may move and still be a click, not a drag.
const CLICK_SLOP: f32 = 4.0;
/// Seconds of pointer motion a carried ball's throw is measured over (at least the last two
/// frames).
const THROW_WINDOW: f64 = 0.1;

/// What the pointer is doing, between frames.
#[derive(Resource, Debug, Default, Clone, PartialEq)]
pub enum Hand {
    #[default]
    Idle,
    /// Right button down on a ball, not yet moved: a click removes it, a drag carries it.
    Pressed { ball: Entity, at: Vec2 },
    /// Carrying `ball` while `button` is down; `trail` is the pointer's recent
    /// (real seconds, arena position), for the throw.
    Carrying {
        ball: Entity,
        button: MouseButton,
        trail: VecDeque<(f64, DVec2)>,
    },
    /// Dragging the view while `button` is down, from the window position `last`.
    Panning { button: MouseButton, last: Vec2 },
    /// Aiming (the [`AimGuide`] holds the ball) or placing a new ball (the
    /// [`NewBallGuide`]) while the left button is down.
    Guiding,
}

/// Whether the view was panned with Space held since Space went down: then releasing Space
/// does not pause.
#[derive(Resource, Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct PannedWithSpace(pub bool);

/// The pointer, the ball under it and what the buttons and modifier keys say.
struct Pointer {
    window: Vec2,
    arena: DVec2,
}

/// Starts a gesture on a button press (not over the panel).
pub(super) fn press(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    window: Single<&Window, With<PrimaryWindow>>,
    camera: Single<(&Camera, &GlobalTransform)>,
    balls: Query<(Entity, &Position, &Radius), With<Ball>>,
    params: Res<SimParams>,
    settings: Res<SpawnSettings>,
    mut rng: ResMut<UiRng>,
    mut hand: ResMut<Hand>,
    mut guides: (ResMut<AimGuide>, ResMut<NewBallGuide>),
    mut space: ResMut<PannedWithSpace>,
) {
    let Some(pointer) = pointer_at(&window, *camera) else {
        return;
    };
    let circles = balls.iter().map(|(e, p, r)| (e, Circle::new(p.0, r.0)));
    let under = ball_under(pointer.arena, circles.clone());
    let shift = keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]);
    let pan = |button| Hand::Panning {
        button,
        last: pointer.window,
    };
    let carry = |ball, button| Hand::Carrying {
        ball,
        button,
        trail: VecDeque::new(),
    };
    let next = if buttons.just_pressed(MouseButton::Middle) {
        pan(MouseButton::Middle)
    } else if buttons.just_pressed(MouseButton::Right) {
        match under {
            Some(ball) => Hand::Pressed {
                ball,
                at: pointer.window,
            },
            None => return,
        }
    } else if buttons.just_pressed(MouseButton::Left) {
        if keys.pressed(KeyCode::Space) {
            space.0 = true;
            pan(MouseButton::Left)
        } else if let Some(ball) = under {
            if shift {
                carry(ball, MouseButton::Left)
            } else {
                guides.0.0 = Some(Aim {
                    ball,
                    velocity: DVec2::ZERO,
                });
                Hand::Guiding
            }
        } else {
            let wanted = rng.0.random_range(settings.radius.0..=settings.radius.1);
            let half = params.half_extents();
            let Some(radius) = fit_radius_at(pointer.arena, wanted, half, circles.map(|c| c.1))
            else {
                return;
            };
            guides.1.0 = Some(BallState {
                position: pointer.arena,
                velocity: DVec2::ZERO,
                radius,
            });
            Hand::Guiding
        }
    } else {
        return;
    };
    *hand = next;
}

/// Carries a gesture on while its button is down and finishes it on release.
pub(super) fn drag_and_release(
    buttons: Res<ButtonInput<MouseButton>>,
    window: Single<&Window, With<PrimaryWindow>>,
    camera: Single<(&Camera, &GlobalTransform)>,
    balls: Query<&Position, With<Ball>>,
    time: Res<Time<Real>>,
    mut hand: ResMut<Hand>,
    mut guides: (ResMut<AimGuide>, ResMut<NewBallGuide>),
    mut play_area: ResMut<PlayArea>,
    mut intents: MessageWriter<Intent>,
) {
    let pointer = pointer_at(&window, *camera);
    let now = time.elapsed_secs_f64();
    let done = match &mut *hand {
        Hand::Idle => false,
        Hand::Pressed { ball, at } => {
            let moved = pointer.is_some_and(|p| p.window.distance(*at) > CLICK_SLOP);
            if !buttons.pressed(MouseButton::Right) {
                intents.write(Intent::Remove(*ball));
                true
            } else if moved {
                *hand = Hand::Carrying {
                    ball: *ball,
                    button: MouseButton::Right,
                    trail: VecDeque::new(),
                };
                false
            } else {
                false
            }
        }
        Hand::Carrying {
            ball,
            button,
            trail,
        } => {
            if balls.get(*ball).is_err() {
                true // the ball is gone (reset, count lowered)
            } else if buttons.pressed(*button) {
                if let Some(pointer) = pointer {
                    follow(trail, now, pointer.arena);
                    intents.write(Intent::Carry {
                        ball: *ball,
                        target: pointer.arena,
                    });
                }
                false
            } else {
                if let Some(pointer) = pointer {
                    follow(trail, now, pointer.arena);
                }
                intents.write(Intent::Release {
                    ball: *ball,
                    velocity: throw_velocity(trail),
                });
                true
            }
        }
        Hand::Panning { button, last } => {
            if let Some(pointer) = pointer {
                play_area.pan_by(pointer.window - *last);
                *last = pointer.window;
            }
            !buttons.pressed(*button)
        }
        Hand::Guiding => {
            guide(
                buttons.pressed(MouseButton::Left),
                pointer.map(|p| p.arena),
                &balls,
                &mut guides,
                &mut intents,
            );
            guides.0.0.is_none() && guides.1.0.is_none()
        }
    };
    if done {
        *hand = Hand::Idle;
    }
}

/// Aiming or placing: the guide follows the pointer while the left button is down; on
/// release the aimed ball is flung, or the new ball added with its throw.
fn guide(
    held: bool,
    pointer: Option<DVec2>,
    balls: &Query<&Position, With<Ball>>,
    (aim_guide, new_ball): &mut (ResMut<AimGuide>, ResMut<NewBallGuide>),
    intents: &mut MessageWriter<Intent>,
) {
    if let Some(aim) = aim_guide.0 {
        let Ok(position) = balls.get(aim.ball) else {
            aim_guide.0 = None; // the ball is gone (reset, count lowered)
            return;
        };
        let velocity = pointer.map_or(aim.velocity, |p| fling_velocity(position.0, p));
        if held {
            aim_guide.0 = Some(Aim { velocity, ..aim });
        } else {
            intents.write(Intent::Fling {
                ball: aim.ball,
                velocity,
            });
            aim_guide.0 = None;
        }
    }
    if let Some(ball) = new_ball.0 {
        let velocity = pointer.map_or(ball.velocity, |p| fling_velocity(ball.position, p));
        let ball = BallState { velocity, ..ball };
        if held {
            new_ball.0 = Some(ball);
        } else {
            intents.write(Intent::Spawn(ball));
            new_ball.0 = None;
        }
    }
}

/// Adds the pointer at `at` (real seconds `now`) to a carry's `trail`, keeping the last
/// [`THROW_WINDOW`] of it, and at least two samples however slow the frames.
fn follow(trail: &mut VecDeque<(f64, DVec2)>, now: f64, at: DVec2) {
    trail.push_back((now, at));
    while trail.len() > 2 && trail[1].0 <= now - THROW_WINDOW {
        trail.pop_front();
    }
}

/// The pointer's velocity over its recent `trail`, pixels per second: zero when it was still
/// or the trail is too short to tell; at most [`MAX_FLING_SPEED`].
pub fn throw_velocity(trail: &VecDeque<(f64, DVec2)>) -> DVec2 {
    match (trail.front(), trail.back()) {
        (Some(&(t0, p0)), Some(&(t1, p1))) if t1 - t0 > 1e-3 => {
            ((p1 - p0) / (t1 - t0)).clamp_length_max(MAX_FLING_SPEED)
        }
        _ => DVec2::ZERO,
    }
}

fn pointer_at(window: &Window, camera: (&Camera, &GlobalTransform)) -> Option<Pointer> {
    Some(Pointer {
        window: window.cursor_position()?,
        arena: pointer_in_arena(window, camera)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_trail_keeps_its_window_and_at_least_two_samples() {
        let mut trail = VecDeque::new();
        for (t, x) in [
            (0.0, 0.0),
            (0.05, 5.0),
            (0.3, 30.0),
            (0.32, 34.0),
            (0.35, 40.0),
        ] {
            follow(&mut trail, t, DVec2::new(x, 0.0));
        }
        // The last tenth of a second and the sample just before it.
        let kept: Vec<f64> = trail.iter().map(|s| s.0).collect();
        assert_eq!(kept, vec![0.05, 0.3, 0.32, 0.35]);
        let mut slow = VecDeque::new();
        follow(&mut slow, 0.0, DVec2::ZERO);
        follow(&mut slow, 0.5, DVec2::new(50.0, 0.0));
        assert_eq!(throw_velocity(&slow), DVec2::new(100.0, 0.0));
    }

    #[test]
    fn a_throw_is_the_pointers_recent_velocity() {
        let trail: VecDeque<_> = [(1.0, DVec2::ZERO), (1.05, DVec2::new(10.0, -5.0))].into();
        let v = throw_velocity(&trail);
        assert!((v - DVec2::new(200.0, -100.0)).length() < 1e-9, "{v}");
        // Too short to tell, or empty: no throw.
        assert_eq!(throw_velocity(&[(1.0, DVec2::ONE)].into()), DVec2::ZERO);
        assert_eq!(throw_velocity(&VecDeque::new()), DVec2::ZERO);
        // Capped.
        let fast: VecDeque<_> = [(0.0, DVec2::ZERO), (0.01, DVec2::new(1e6, 0.0))].into();
        assert!((throw_velocity(&fast).length() - MAX_FLING_SPEED).abs() < 1e-6);
    }
}
