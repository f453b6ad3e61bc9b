//! The toy's shared state, below its parts: the scene being played and the requests that
//! change it ([`scenes`]), and the view state the UI writes and rendering reads ([`view`]).
//! [`render`](crate::render) and [`ui`](crate::ui) build on this module and never on each
//! other; [`play`](crate::play) puts them together. Windowed app only (`gui` feature).

pub mod scenes;
pub mod view;

use bevy::prelude::*;

/// The scene requests and the view state.
pub fn plugin(app: &mut App) {
    app.init_resource::<view::ViewSettings>()
        .insert_resource(view::PlayArea {
            panel_width: view::PANEL_WIDTH,
            ..default()
        })
        .init_resource::<view::AimGuide>()
        .init_resource::<view::NewBallGuide>()
        .init_resource::<view::PanelVisible>()
        .init_resource::<view::HelpVisible>()
        .init_resource::<view::UiRng>()
        .add_plugins(scenes::plugin);
}
