//! The player's controls: the egui side panel ([`panel`]), the pointer on the balls
//! ([`hands`]) and the wheel and keys ([`input`]), sharing [`pointer`](mod@pointer)'s helpers.
//! They read simulation state and change it only through intents (flings, carries, spawns,
//! removals, the ball count), the parameter resources (edited as clamped copies), single
//! steps and scene requests. Runs in the windowed app only.

pub mod figures;
pub mod hands;
pub mod help;
pub mod input;
pub mod panel;
pub mod pointer;
pub mod readouts;

use bevy::prelude::*;
use bevy_egui::EguiPlugin;

pub fn plugin(app: &mut App) {
    app.add_plugins(EguiPlugin::default()).add_plugins((
        panel::plugin,
        readouts::plugin,
        input::plugin,
    ));
}
