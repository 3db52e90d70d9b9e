//! No subcommand: the desktop app in a window.

use crate::ui::{CloudApp, Opening, Start, StartOptions};

/// Opens the desktop window on a scene file or share link when one is given (keeping the
/// last session aside), else on the last session (autosaved), else on the default scene.
pub fn run(open: Option<&str>) -> Result<(), String> {
    let bytes = match open {
        Some(arg) if !arg.contains("#s=") => Some(
            std::fs::metadata(arg)
                .map_err(|e| format!("{arg}: {e}"))
                .and_then(|m| {
                    if m.len() > crate::limits::MAX_FILE_BYTES {
                        Err(format!(
                            "{arg}: more than the {} MiB a scene file may have",
                            crate::limits::MAX_FILE_BYTES >> 20
                        ))
                    } else {
                        std::fs::read(arg).map_err(|e| format!("{arg}: {e}"))
                    }
                })?,
        ),
        _ => None,
    };
    let opening = match (open, &bytes) {
        (Some(path), Some(bytes)) => Opening::File(path, bytes),
        (Some(link), None) => Opening::Link(link),
        _ => Opening::Nothing,
    };
    let start = crate::ui::start_session(opening);
    if let Some((message, true)) = &start.notice {
        eprintln!("error: {message}");
    }
    let Start {
        scene,
        notice,
        file,
        ..
    } = start;
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
                    file,
                    autosave: true,
                    ..Default::default()
                },
            )))
        }),
    )
    .map_err(|e| format!("could not open the desktop window: {e}"))
}
