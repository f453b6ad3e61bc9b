//! Drawing the simulation: a 2D camera, one sprite per ball and the arena's walls following the
//! window. Reads simulation state and sets only the arena size; runs in `Update`/`PostUpdate`
//! of the windowed app, never in the headless one.
//!
//! Every ball's sprite shares one anti-aliased circle texture made at start-up, so all balls
//! draw as one batch and stay round at any size.

use bevy::asset::RenderAssetUsages;
use bevy::image::{Image, ImageSampler};
use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use bevy::window::PrimaryWindow;

use crate::sim::{Ball, BallId, Position, Radius, SimParams};

/// Side of the shared circle texture, texels: large enough that a ball 256 px wide is crisp.
const CIRCLE_TEXTURE_SIZE: u32 = 256;
/// Background behind the arena.
const BACKGROUND: Color = Color::srgb(0.06, 0.07, 0.09);

pub fn plugin(app: &mut App) {
    app.insert_resource(ClearColor(BACKGROUND))
        // The texture must exist before any scene's balls are spawned (in `Startup`).
        .add_systems(PreStartup, make_circle_texture)
        .add_systems(Startup, spawn_camera)
        .add_observer(give_ball_a_sprite)
        .add_systems(Update, fit_arena_to_window)
        .add_systems(
            PostUpdate,
            place_ball_sprites.before(TransformSystems::Propagate),
        );
}

/// The texture every ball sprite draws: a white disc with a one-texel soft edge.
#[derive(Resource)]
struct CircleTexture(Handle<Image>);

fn spawn_camera(mut commands: Commands) {
    commands.spawn((Name::new("Camera"), Camera2d));
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

fn give_ball_a_sprite(
    added: On<Add, Ball>,
    balls: Query<(&BallId, &Radius)>,
    texture: Option<Res<CircleTexture>>,
    mut commands: Commands,
) {
    let (Ok((id, radius)), Some(texture)) = (balls.get(added.entity), texture) else {
        return;
    };
    commands.entity(added.entity).insert((
        Sprite {
            image: texture.0.clone(),
            color: ball_colour(*id),
            custom_size: Some(Vec2::splat(2.0 * radius.0 as f32)),
            ..default()
        },
        Transform::default(),
    ));
}

fn place_ball_sprites(mut balls: Query<(&Position, &mut Transform), With<Ball>>) {
    for (position, mut transform) in &mut balls {
        transform.translation = position.as_vec2().extend(0.0);
    }
}

/// The arena is the window's play area: its walls follow a resize (balls left outside are
/// brought back in by the movement stage's wall containment).
fn fit_arena_to_window(
    window: Single<&Window, With<PrimaryWindow>>,
    mut params: ResMut<SimParams>,
) {
    let size = DVec2::new(window.width() as f64, window.height() as f64);
    if params.arena_size != size {
        params.arena_size = size;
    }
}
