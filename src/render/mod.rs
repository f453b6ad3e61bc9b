//! Drawing the simulation: a 2D camera placed as the view says, the arena's floor and border,
//! one sprite per ball, overlays and effects. Reads simulation state and the view state
//! ([`app::view`](crate::app::view)); writes only the view's fit to the window. Runs in the
//! windowed app's `Update`/`PostUpdate`, never in the headless one.
//!
//! Every ball's sprite shares one anti-aliased circle texture made at start-up, so all balls
//! draw as one batch and stay round at any size. Sprites are placed between the last two
//! fixed steps by `Time<Fixed>::overstep_fraction`, so motion is smooth at any display rate.

pub mod effects;
pub mod interpolate;
pub mod overlays;

use bevy::asset::RenderAssetUsages;
use bevy::image::{Image, ImageSampler};
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use bevy::window::PrimaryWindow;

use crate::app::view::{
    ColourMode, HOT_SPEED, PlayArea, SIZE_COLOUR_RANGE, ViewSettings, heat_colour,
};
use crate::sim::{
    Ball, BallId, Position, PreviousPosition, Radius, Rest, RunControl, SimParams, Velocity,
};
use interpolate::{drawn_position, interpolation_fraction};

/// Side of the shared circle texture, texels: large enough that a ball 256 px wide is crisp.
const CIRCLE_TEXTURE_SIZE: u32 = 256;
/// Background outside the arena.
const BACKGROUND: Color = Color::srgb(0.03, 0.035, 0.045);
/// The arena's floor, drawn behind the balls.
const ARENA_FLOOR: Color = Color::srgb(0.07, 0.08, 0.1);
/// The arena's walls, drawn as a line around the floor.
const ARENA_BORDER: Color = Color::srgb(0.35, 0.4, 0.5);
/// How much darker a sleeping ball is drawn (with the view's toggle on), 0 to 1.
const SLEEP_DIMMING: f32 = 0.25;

pub fn plugin(app: &mut App) {
    app.insert_resource(ClearColor(BACKGROUND))
        // The texture must exist before any scene's balls are spawned (in `Startup`).
        .add_systems(PreStartup, make_circle_texture)
        .add_systems(Startup, (spawn_camera, spawn_arena_floor))
        .add_observer(give_ball_a_sprite)
        .add_systems(Update, keep_view_fitted)
        .add_systems(
            PostUpdate,
            (place_ball_sprites, colour_balls, place_camera_and_floor)
                .before(TransformSystems::Propagate),
        )
        .add_plugins((overlays::plugin, effects::plugin));
}

/// The texture every ball sprite draws: a white disc with a one-texel soft edge.
#[derive(Resource)]
struct CircleTexture(Handle<Image>);

#[derive(Component)]
struct ArenaFloor;

fn spawn_camera(mut commands: Commands) {
    commands.spawn((Name::new("Camera"), Camera2d));
}

fn spawn_arena_floor(mut commands: Commands) {
    commands.spawn((
        Name::new("Arena floor"),
        ArenaFloor,
        Sprite::from_color(ARENA_FLOOR, Vec2::ONE),
        Transform::from_xyz(0.0, 0.0, -1.0),
    ));
}

fn make_circle_texture(mut commands: Commands, mut images: ResMut<Assets<Image>>) {
    let size = CIRCLE_TEXTURE_SIZE;
    let radius = size as f32 / 2.0;
    let mut data = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let offset = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - Vec2::splat(radius);
            let coverage = (radius - offset.length()).clamp(0.0, 1.0);
            data.extend_from_slice(&[255, 255, 255, (coverage * 255.0).round() as u8]);
        }
    }
    let mut image = Image::new(
        Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        data,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    );
    image.sampler = ImageSampler::linear();
    commands.insert_resource(CircleTexture(images.add(image)));
}

/// A distinct, pleasant colour per ball: hues spaced by the golden angle.
pub fn ball_colour(id: BallId) -> Color {
    let hue = (id.0 as f32 * 137.507_77) % 360.0;
    Color::hsl(hue, 0.65, 0.6)
}

fn colour_of(mode: ColourMode, id: BallId, radius: f64, velocity: DVec2) -> Color {
    match mode {
        ColourMode::ByBall => ball_colour(id),
        ColourMode::BySize => {
            let (small, large) = SIZE_COLOUR_RANGE;
            heat_colour((radius - small) / (large - small))
        }
        ColourMode::BySpeed => heat_colour(velocity.length() / HOT_SPEED),
    }
}

fn give_ball_a_sprite(
    added: On<Add, Ball>,
    balls: Query<(&BallId, &Radius, &Position, &Velocity)>,
    texture: Option<Res<CircleTexture>>,
    view: Res<ViewSettings>,
    mut commands: Commands,
) {
    let (Ok((id, radius, position, velocity)), Some(texture)) = (balls.get(added.entity), texture)
    else {
        return;
    };
    commands.entity(added.entity).insert((
        PreviousPosition(position.0),
        Sprite {
            image: texture.0.clone(),
            color: colour_of(view.colour_mode, *id, radius.0, velocity.0),
            custom_size: Some(Vec2::splat(2.0 * radius.0 as f32)),
            ..default()
        },
        Transform::from_translation(position.as_vec2().extend(0.0)),
    ));
}

fn place_ball_sprites(
    fixed: Res<Time<Fixed>>,
    run: Res<RunControl>,
    mut balls: Query<(&PreviousPosition, &Position, &mut Transform), With<Ball>>,
) {
    let fraction = interpolation_fraction(&fixed, &run);
    balls
        .par_iter_mut()
        .for_each(|(previous, position, mut transform)| {
            transform.translation = drawn_position(previous, position, fraction).extend(0.0);
        });
}

fn colour_balls(
    view: Res<ViewSettings>,
    mut balls: Query<(&BallId, &Radius, &Velocity, Ref<Rest>, &mut Sprite), With<Ball>>,
) {
    // Colours by ball and by size change only with the mode or the sleep; by speed, every
    // frame.
    let every_ball = view.is_changed() || view.colour_mode == ColourMode::BySpeed;
    balls
        .par_iter_mut()
        .for_each(|(id, radius, velocity, rest, mut sprite)| {
            if every_ball || rest.is_changed() {
                let colour = colour_of(view.colour_mode, *id, radius.0, velocity.0);
                sprite.color = if view.dim_sleeping && rest.is_asleep() {
                    colour.darker(SLEEP_DIMMING)
                } else {
                    colour
                };
            }
        });
}

/// Keeps the view fitted to the arena while it follows the fit (see [`PlayArea`]): a new
/// scene, `F`, a resized window or arena.
fn keep_view_fitted(
    window: Single<&Window, With<PrimaryWindow>>,
    params: Res<SimParams>,
    mut play_area: ResMut<PlayArea>,
) {
    let mut fitted = *play_area;
    fitted.keep_fitted(params.arena_size.as_vec2(), window.size());
    if fitted != *play_area {
        *play_area = fitted;
    }
}

/// Places and zooms the camera as the play area says, and sizes the arena's floor and border.
fn place_camera_and_floor(
    play_area: Res<PlayArea>,
    params: Res<SimParams>,
    mut camera: Single<(&mut Transform, &mut Projection), (With<Camera2d>, Without<ArenaFloor>)>,
    mut floor: Single<(&mut Transform, &mut Sprite), With<ArenaFloor>>,
    mut gizmos: Gizmos,
) {
    let (transform, projection) = &mut *camera;
    transform.translation = play_area.center.extend(transform.translation.z);
    if let Projection::Orthographic(orthographic) = &mut **projection
        && orthographic.scale != play_area.zoom
    {
        orthographic.scale = play_area.zoom;
    }
    let arena = params.arena_size.as_vec2();
    floor.0.translation = Vec3::new(0.0, 0.0, -1.0);
    floor.1.custom_size = Some(arena);
    gizmos.rect_2d(Isometry2d::IDENTITY, arena, ARENA_BORDER);
}
