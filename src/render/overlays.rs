//! Overlays drawn with gizmos on top of the balls: AABBs, contact points, velocity arrows
//! (each switched in [`ViewSettings`]); and while the player drags, the snooker-style aiming
//! guide, the new ball's ghost and throw, and a carried ball's spring. Runs in the windowed
//! app's `Update`.

use bevy::prelude::*;

use super::interpolate::{drawn_position, interpolation_fraction};
use crate::app::view::{AimGuide, NewBallGuide, ViewSettings};
use crate::sim::aim::{AimTarget, predict_first_hit, time_to_wall};
use crate::sim::geometry::Circle;
use crate::sim::{
    Ball, Carried, ContactPoints, Position, PreviousPosition, Radius, RunControl, SimParams,
    Velocity,
};

/// Seconds of motion a velocity arrow shows.
const ARROW_SECONDS: f32 = 0.2;
/// How far ahead the guide looks for a hit, seconds.
const GUIDE_HORIZON: f64 = 10.0;
/// Length of the guide's exit-direction arrows, pixels.
const EXIT_ARROW_LENGTH: f32 = 60.0;

const AABB_COLOUR: Color = Color::srgba(0.5, 0.8, 1.0, 0.5);
const CONTACT_COLOUR: Color = Color::srgb(1.0, 0.9, 0.2);
const ARROW_COLOUR: Color = Color::srgba(1.0, 1.0, 1.0, 0.7);
const GUIDE_COLOUR: Color = Color::srgb(0.95, 0.95, 0.95);
const CARRY_COLOUR: Color = Color::srgba(1.0, 1.0, 1.0, 0.6);

pub(super) fn plugin(app: &mut App) {
    app.add_systems(
        Update,
        (
            draw_aabbs,
            draw_contacts,
            draw_velocities,
            draw_aim_guide,
            draw_new_ball_guide,
            draw_carry_springs,
        ),
    );
}

fn draw_aabbs(
    view: Res<ViewSettings>,
    fixed: Res<Time<Fixed>>,
    run: Res<RunControl>,
    balls: Query<(&PreviousPosition, &Position, &Radius), With<Ball>>,
    mut gizmos: Gizmos,
) {
    if !view.show_aabbs {
        return;
    }
    let fraction = interpolation_fraction(&fixed, &run);
    for (previous, position, radius) in &balls {
        let centre = drawn_position(previous, position, fraction);
        gizmos.rect_2d(centre, Vec2::splat(2.0 * radius.0 as f32), AABB_COLOUR);
    }
}

fn draw_contacts(view: Res<ViewSettings>, contacts: Res<ContactPoints>, mut gizmos: Gizmos) {
    if !view.show_contacts {
        return;
    }
    for contact in &contacts.0 {
        let point = contact.point.as_vec2();
        gizmos.cross_2d(point, 4.0, CONTACT_COLOUR);
        gizmos.line_2d(
            point,
            point + contact.normal.as_vec2() * 8.0,
            CONTACT_COLOUR,
        );
    }
}

fn draw_velocities(
    view: Res<ViewSettings>,
    fixed: Res<Time<Fixed>>,
    run: Res<RunControl>,
    balls: Query<(&PreviousPosition, &Position, &Velocity), With<Ball>>,
    mut gizmos: Gizmos,
) {
    if !view.show_velocities {
        return;
    }
    let fraction = interpolation_fraction(&fixed, &run);
    for (previous, position, velocity) in &balls {
        let start = drawn_position(previous, position, fraction);
        let end = start + velocity.as_vec2() * ARROW_SECONDS;
        if start.distance(end) > 1.0 {
            gizmos.arrow_2d(start, end, ARROW_COLOUR);
        }
    }
}

/// The guide: the path to the first ball the aimed ball would hit (or to the wall), both
/// balls' ghosts at the hit (the struck one where its own motion takes it), the collision
/// point, and the directions both leave in, each arrow in its ball's colour.
fn draw_aim_guide(
    guide: Res<AimGuide>,
    params: Res<SimParams>,
    balls: Query<(Entity, &Position, &Velocity, &Radius, &Sprite), With<Ball>>,
    mut gizmos: Gizmos,
) {
    let Some(aim) = guide.0 else { return };
    let Ok((_, position, _, radius, sprite)) = balls.get(aim.ball) else {
        return;
    };
    let cue = Circle::new(position.0, radius.0);
    let horizon = time_to_wall(cue.center, aim.velocity, cue.radius, params.half_extents())
        .min(GUIDE_HORIZON);
    let targets = balls.iter().filter(|(entity, ..)| *entity != aim.ball).map(
        |(entity, position, velocity, radius, _)| AimTarget {
            id: entity,
            circle: Circle::new(position.0, radius.0),
            velocity: velocity.0,
            inverse_mass: params.mass_model.inverse_mass(radius.0),
        },
    );
    let inverse_mass = params.mass_model.inverse_mass(cue.radius);
    let start = cue.center.as_vec2();
    match predict_first_hit(
        cue,
        aim.velocity,
        inverse_mass,
        targets,
        params.restitution,
        horizon,
    ) {
        Some(hit) => {
            let at_hit = hit.cue_center.as_vec2();
            let struck = balls.get(hit.target).ok();
            let struck_colour = struck.map_or(GUIDE_COLOUR, |ball| ball.4.color);
            let struck_radius = struck.map_or(0.0, |ball| ball.3.0 as f32);
            let struck_at_hit = hit.target_center.as_vec2();
            gizmos.line_2d(start, at_hit, GUIDE_COLOUR);
            gizmos.circle_2d(at_hit, cue.radius as f32, GUIDE_COLOUR);
            if let Some((_, now, ..)) = struck
                && now.0.as_vec2().distance(struck_at_hit) > 0.5
            {
                gizmos.line_2d(now.0.as_vec2(), struck_at_hit, dimmed(struck_colour));
            }
            gizmos.circle_2d(struck_at_hit, struck_radius, struck_colour);
            gizmos.circle_2d(hit.point.as_vec2(), 3.0, CONTACT_COLOUR);
            for (from, velocity, colour) in [
                (at_hit, hit.cue_velocity_after, sprite.color),
                (struck_at_hit, hit.target_velocity_after, struck_colour),
            ] {
                if let Some(direction) = velocity.as_vec2().try_normalize() {
                    gizmos.arrow_2d(from, from + direction * EXIT_ARROW_LENGTH, colour);
                }
            }
        }
        None if horizon.is_finite() => {
            let end = (cue.center + aim.velocity * horizon).as_vec2();
            gizmos.line_2d(start, end, GUIDE_COLOUR);
            gizmos.circle_2d(end, cue.radius as f32, GUIDE_COLOUR);
        }
        None => {}
    }
}

/// The ball a drag from empty space will add (a ghost) and its throw (an arrow).
fn draw_new_ball_guide(guide: Res<NewBallGuide>, mut gizmos: Gizmos) {
    let Some(ball) = guide.0 else { return };
    let centre = ball.position.as_vec2();
    gizmos.circle_2d(centre, ball.radius as f32, GUIDE_COLOUR);
    let throw = ball.velocity.as_vec2() * ARROW_SECONDS;
    if throw.length() > 1.0 {
        gizmos.arrow_2d(centre, centre + throw, GUIDE_COLOUR);
    }
}

/// Each carried ball's spring: a line from the ball to the pointer it follows.
fn draw_carry_springs(
    fixed: Res<Time<Fixed>>,
    run: Res<RunControl>,
    balls: Query<(&PreviousPosition, &Position, &Carried)>,
    mut gizmos: Gizmos,
) {
    let fraction = interpolation_fraction(&fixed, &run);
    for (previous, position, carried) in &balls {
        let centre = drawn_position(previous, position, fraction);
        let target = carried.target.as_vec2();
        gizmos.line_2d(centre, target, CARRY_COLOUR);
        gizmos.circle_2d(target, 3.0, CARRY_COLOUR);
    }
}

/// `colour` at half its opacity.
fn dimmed(colour: Color) -> Color {
    colour.with_alpha(colour.alpha() * 0.5)
}
