//! Overlays drawn with gizmos on top of the balls: AABBs, contact points, velocity arrows and
//! the snooker-style aiming guide. Each is switched in [`ViewSettings`]; the guide shows while
//! a ball is being dragged. Runs in the windowed app's `Update`.

use bevy::prelude::*;

use super::interpolate::{drawn_position, interpolation_fraction};
use crate::app::view::{AimGuide, ViewSettings};
use crate::sim::aim::{AimTarget, predict_first_hit, time_to_wall};
use crate::sim::geometry::Circle;
use crate::sim::{
    Ball, ContactPoints, Position, PreviousPosition, Radius, RunControl, SimParams, Velocity,
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
const EXIT_COLOUR: Color = Color::srgb(1.0, 0.55, 0.2);

pub(super) fn plugin(app: &mut App) {
    app.add_systems(
        Update,
        (draw_aabbs, draw_contacts, draw_velocities, draw_aim_guide),
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

/// The guide: the path to the first ball the aimed ball would hit (or to the wall), the
/// aimed ball's outline at the hit, the collision point, and the directions both leave in.
fn draw_aim_guide(
    guide: Res<AimGuide>,
    params: Res<SimParams>,
    balls: Query<(Entity, &Position, &Velocity, &Radius), With<Ball>>,
    mut gizmos: Gizmos,
) {
    let Some(aim) = guide.0 else { return };
    let Ok((_, position, _, radius)) = balls.get(aim.ball) else {
        return;
    };
    let cue = Circle::new(position.0, radius.0);
    let horizon = time_to_wall(cue.center, aim.velocity, cue.radius, params.half_extents())
        .min(GUIDE_HORIZON);
    let targets = balls.iter().filter(|(entity, ..)| *entity != aim.ball).map(
        |(entity, position, velocity, radius)| AimTarget {
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
            gizmos.line_2d(start, at_hit, GUIDE_COLOUR);
            gizmos.circle_2d(at_hit, cue.radius as f32, GUIDE_COLOUR);
            gizmos.circle_2d(hit.point.as_vec2(), 3.0, CONTACT_COLOUR);
            for (from, velocity) in [
                (at_hit, hit.cue_velocity_after),
                (hit.target_center.as_vec2(), hit.target_velocity_after),
            ] {
                if let Some(direction) = velocity.as_vec2().try_normalize() {
                    gizmos.arrow_2d(from, from + direction * EXIT_ARROW_LENGTH, EXIT_COLOUR);
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
