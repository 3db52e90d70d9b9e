//! The desktop side of the UI's one platform seam (`platform_web.rs` is the browser's): what
//! the GL backend is called, and reading user files (dropped files and typed paths).

use super::guide::Loaded;
use crate::limits::MAX_FILE_BYTES as MAX_BYTES;

/// What the GL backend is called here.
pub const GL_BACKEND_NAME: &str = "gl";

/// Whether this platform has a file picker button (the browser's file input).
pub const HAS_PICKER: bool = false;

/// Reads a dropped file at once.
pub fn read_dropped(file: egui::DroppedFileHandle, _ctx: &egui::Context) -> Option<Loaded> {
    let name = file.path().display().to_string();
    if let Ok(meta) = std::fs::metadata(file.path())
        && meta.len() > MAX_BYTES
    {
        return Some(Err(format!("{name}: larger than {} MiB", MAX_BYTES >> 20)));
    }
    Some(
        file.bytes()
            .map(|b| (name.clone(), b))
            .map_err(|e| format!("{name}: {e}")),
    )
}

/// Reads a file by path.
pub fn read_path(path: &str) -> Loaded {
    let meta = std::fs::metadata(path).map_err(|e| format!("{path}: {e}"))?;
    if meta.len() > MAX_BYTES {
        return Err(format!("{path}: larger than {} MiB", MAX_BYTES >> 20));
    }
    std::fs::read(path)
        .map(|b| (path.to_string(), b))
        .map_err(|e| format!("{path}: {e}"))
}

/// Pointer samples beyond egui's events: none natively, where every cursor move is an event
/// (egui's native events carry no pen pressure).
pub fn take_pointer_samples() -> Option<Vec<(egui::Pos2, Option<f32>)>> {
    None
}

/// Asks for a frame (natively every outside input is an egui event already: nothing to do).
pub fn wake() {}

/// Nothing to install natively (dropped files arrive through egui).
pub fn install(_ctx: &egui::Context) {}

/// Opens the platform's file picker (none natively: the panel offers a path field).
pub fn open_picker() {}

/// Files that finished loading since the last call (reads are synchronous natively).
pub fn take_loaded() -> Vec<Loaded> {
    Vec::new()
}
