//! Reading user files on the desktop: dropped files and typed paths (the native side of the
//! one platform seam; `files_web.rs` is the browser's).

use super::guide::Loaded;

/// Whether this platform has a file picker button (the browser's file input).
pub const HAS_PICKER: bool = false;

/// Largest file read (images and documents).
const MAX_BYTES: u64 = 64 << 20;

/// Reads a dropped file at once.
pub fn read_dropped(file: egui::DroppedFileHandle, _ctx: &egui::Context) -> Option<Loaded> {
    let name = file.path().display().to_string();
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

/// Nothing to install natively (dropped files arrive through egui).
pub fn install(_ctx: &egui::Context) {}

/// Opens the platform's file picker (none natively: the panel offers a path field).
pub fn open_picker() {}

/// Files that finished loading since the last call (reads are synchronous natively).
pub fn take_loaded() -> Vec<Loaded> {
    Vec::new()
}
