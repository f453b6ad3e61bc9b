//! The help overlay: every mouse and key input and what it does, shown by `?`, F1 or the
//! panel's Help button. Drawn in `EguiPrimaryContextPass` by the panel's system.

use bevy_egui::egui;

/// The help overlay: every mouse and key input.
pub fn help_window(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Controls")
        .open(open)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::RIGHT_TOP, [-12.0, 12.0])
        .show(ctx, |ui| {
            egui::Grid::new("help").num_columns(2).show(ui, |ui| {
                for (input, action) in INPUTS {
                    ui.strong(*input);
                    ui.label(*action);
                    ui.end_row();
                }
            });
        });
}

/// Every input and what it does, for the help overlay (the README's input table says the same).
pub const INPUTS: &[(&str, &str)] = &[
    (
        "left drag from a ball",
        "aim and fling it (the guide shows its first hit)",
    ),
    (
        "right drag / Shift + left drag on a ball",
        "carry it; release throws it",
    ),
    (
        "left click or drag in empty space",
        "add a ball, thrown along the drag",
    ),
    ("right click / Delete on a ball", "remove it"),
    ("wheel", "zoom at the pointer"),
    ("middle drag / Space + left drag", "pan"),
    ("F", "fit the arena in the window"),
    ("Space", "pause or resume"),
    ("N", "one step"),
    ("R", "reset the scene"),
    ("H", "hide or show the panel"),
    ("?", "this help"),
];
