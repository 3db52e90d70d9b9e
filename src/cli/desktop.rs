//! No subcommand: the desktop app in a window.

use crate::ui::{CloudApp, StartOptions};

/// Opens the desktop window on the last session (autosaved), else the default scene.
pub fn run() -> Result<(), String> {
    let (scene, notice) = crate::ui::start_session(None);
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("cloudsketch")
            .with_inner_size([1280.0, 800.0]),
        ..Default::default()
    };
    eframe::run_native(
        "cloudsketch",
        options,
        Box::new(|cc| {
            Ok(Box::new(CloudApp::new(
                cc,
                StartOptions {
                    scene,
                    initial_cost: 1e-8,
                    notice,
                    autosave: true,
                    ..Default::default()
                },
            )))
        }),
    )
    .map_err(|e| format!("could not open the desktop window: {e}"))
}
