//! The scene being played and the player's requests to reset, reseed or switch it. Requests
//! arrive as [`SceneRequest`] messages (from the panel and the keys) and are applied as world
//! commands in `Update`; the view is zoomed to fit the new arena, the window keeping its
//! size. A scene that fails to load leaves the current one playing and its error in
//! [`SceneStatus`].

use std::path::PathBuf;

use bevy::prelude::*;
use rand::RngExt;

use super::view::{PlayArea, UiRng};
use crate::sim::SceneFile;

pub(super) fn plugin(app: &mut App) {
    app.add_message::<SceneRequest>()
        .add_message::<SceneLoaded>()
        .init_resource::<SceneStatus>()
        .add_systems(Startup, |mut requests: MessageWriter<SceneRequest>| {
            requests.write(SceneRequest::Reset);
        })
        .add_systems(Update, handle_scene_requests);
}

/// The scene being played, as a file (so reset and reseed rebuild it), and its name.
#[derive(Resource, Clone, Debug, PartialEq)]
pub struct CurrentScene {
    pub file: SceneFile,
    pub origin: String,
}

/// What the player asked to do with the scene.
#[derive(Message, Clone, Debug, PartialEq)]
pub enum SceneRequest {
    /// Rebuild the current scene with the same seed.
    Reset,
    /// Rebuild the current scene with a new random seed.
    NewSeed,
    /// Switch to the scene file at this path.
    Load(PathBuf),
}

/// A scene was (re)loaded: anything that keeps history of the old one starts afresh.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneLoaded;

/// The last scene error, shown in the panel until a scene loads.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct SceneStatus(pub Option<String>);

fn handle_scene_requests(mut requests: MessageReader<SceneRequest>, mut commands: Commands) {
    for request in requests.read().cloned() {
        commands.queue(move |world: &mut World| apply_scene_request(world, request));
    }
}

fn apply_scene_request(world: &mut World, request: SceneRequest) {
    let mut scene = world.resource::<CurrentScene>().clone();
    match request {
        SceneRequest::Reset => {}
        SceneRequest::NewSeed => {
            let seed = world.resource_mut::<UiRng>().0.random::<u64>();
            if let Some(generate) = scene.file.generate.as_mut() {
                generate.seed = seed;
            }
        }
        SceneRequest::Load(path) => match SceneFile::load(&path) {
            Ok(file) => {
                scene = CurrentScene {
                    file,
                    origin: path.display().to_string(),
                }
            }
            Err(error) => {
                world.resource_mut::<SceneStatus>().0 = Some(error.to_string());
                return;
            }
        },
    }
    match scene.file.build(&scene.origin) {
        Ok(setup) => {
            setup.apply(world);
            // The window keeps its size; the view fits the new arena.
            world.resource_mut::<PlayArea>().request_fit();
            world.insert_resource(scene);
            world.resource_mut::<SceneStatus>().0 = None;
            world.write_message(SceneLoaded);
        }
        Err(error) => world.resource_mut::<SceneStatus>().0 = Some(error.to_string()),
    }
}
