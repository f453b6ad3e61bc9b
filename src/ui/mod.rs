//! The player's controls: the egui side panel ([`panel`]) and the mouse and keys ([`input`]).
//! They read simulation state and change it only through `SimParams`, `SpawnSettings`,
//! `PendingSteps`, world commands and scene requests. Runs in the windowed app only.

pub mod input;
pub mod panel;

use bevy::prelude::*;
use bevy_egui::EguiPlugin;

use crate::render::PlayArea;

/// The side panel's width, logical pixels.
pub const PANEL_WIDTH: f32 = 290.0;

pub fn plugin(app: &mut App) {
    app.insert_resource(PlayArea {
        panel_width: PANEL_WIDTH,
        ..default()
    })
    .add_plugins(EguiPlugin::default())
    .add_plugins((panel::plugin, input::plugin));
}
