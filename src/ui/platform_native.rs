//! The desktop side of the UI's one platform seam (`platform_web.rs` is the browser's): what
//! the GL backend is called, reading user files (dropped files and typed paths), saving scene
//! files and the autosave in the user's data folder.

use super::guide::Loaded;
use super::press_record::{PressRecord, with_record};
use crate::limits::MAX_FILE_BYTES as MAX_BYTES;

/// What the GL backend is called here.
pub const GL_BACKEND_NAME: &str = "gl";

/// Whether this platform has a file picker button (the browser's file input).
pub const HAS_PICKER: bool = false;

/// What Record makes here (the timeline's button and the Export group's "every frame of the
/// range").
pub const RECORD_HINT: &str = "Record every frame of the timeline's range at full quality, one after another, at the Export group's PNG width and the view's shape: STEM_####.png beside the scene file";

/// Whether refinement waits for the GPU's report of each chunk before the next: not natively
/// (the desktop window has no measure of its drags; the page does).
pub const FENCED_REFINEMENT: bool = false;

/// Keeps the GPU's reports of finished work coming for fenced refinement: natively refinement
/// is not fenced ([`FENCED_REFINEMENT`]), so `poll` is not called.
pub fn poll_reports(_poll: impl Fn() + 'static) {}

/// Reads a dropped file at once.
pub fn read_dropped(file: egui::DroppedFileHandle, _ctx: &egui::Context) -> Option<Loaded> {
    let name = file.path().display().to_string();
    Some(
        crate::files::read_bounded(file.path(), MAX_BYTES)
            .map(|b| (name.clone(), b))
            .map_err(|e| format!("{name}: {e}")),
    )
}

/// Reads a file by path.
pub fn read_path(path: &str) -> Loaded {
    let at = std::path::Path::new(path);
    crate::files::read_bounded(at, MAX_BYTES)
        .map(|b| (path.to_string(), b))
        .map_err(|e| e.at(at))
}

/// Feeds this frame's events to the press record: natively egui's events carry every cursor
/// move (and no pen pressure). Called once a frame by the tools that draw strokes.
pub fn record_frame(input: &egui::InputState) {
    let down = input.pointer.primary_down();
    with_record(|r| record_events(r, &input.events, down));
}

/// Feeds one frame of egui's events to `record`. `still_down` is egui's view of the primary
/// button after them, which ends a press whose release the record missed.
fn record_events(record: &mut PressRecord, events: &[egui::Event], still_down: bool) {
    use egui::{Event, PointerButton::Primary};
    for event in events {
        match event {
            Event::PointerButton {
                pos,
                button: Primary,
                pressed: true,
                ..
            } => record.pressed(Some((*pos, None))),
            Event::PointerButton {
                pos,
                button: Primary,
                pressed: false,
                ..
            } => record.released(Some((*pos, None))),
            Event::PointerMoved(p) if record.is_down() => record.moved(&[(*p, None)]),
            _ => {}
        }
    }
    if !still_down && record.is_down() {
        record.lost();
    }
}

/// Where the autosave lives: `$XDG_DATA_HOME/cloudsketch`, else `~/.local/share/cloudsketch`.
fn autosave_dir() -> Option<std::path::PathBuf> {
    let base = std::env::var_os("XDG_DATA_HOME")
        .map(std::path::PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME").map(|h| std::path::Path::new(&h).join(".local/share"))
        })?;
    Some(base.join("cloudsketch"))
}

/// A file of the app's own in its data folder, within the size cap.
fn load_data(name: &str) -> Option<String> {
    crate::files::read_bounded_text(&autosave_dir()?.join(name), MAX_BYTES).ok()
}

/// Writes a file of the app's own in its data folder ([`crate::files::write_atomic`]: a crash
/// mid-write keeps the last one).
fn store_data(name: &str, json: &str) -> Result<(), String> {
    let dir = autosave_dir().ok_or("no home folder to keep it in")?;
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let path = dir.join(name);
    crate::files::write_atomic(&path, json.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// The last autosaved document, if any.
pub fn load_autosave() -> Option<String> {
    load_data("autosave.json")
}

/// Writes the autosave.
pub fn store_autosave(json: &str) -> Result<(), String> {
    store_data("autosave.json", json)
}

/// The user's own presets, if any were saved.
pub fn load_looks() -> Option<String> {
    load_data("presets.json")
}

/// Writes the user's own presets.
pub fn store_looks(json: &str) -> Result<(), String> {
    store_data("presets.json", json)
}

/// Which side-panel groups the user left open, if stored.
pub fn load_groups() -> Option<String> {
    load_data("groups.json")
}

/// Writes which side-panel groups are open.
pub fn store_groups(json: &str) -> Result<(), String> {
    store_data("groups.json", json)
}

/// The session kept aside by [`keep_previous_autosave`], if any.
pub fn load_previous_autosave() -> Option<String> {
    load_data("autosave.previous.json")
}

/// Where share links point natively: the web app as `trunk serve` serves it.
pub fn page_base() -> String {
    crate::share::DEFAULT_BASE.to_owned()
}

/// Nothing to take out of an address bar natively.
pub fn forget_opening_in_url() {}

/// Links arrive only through the address bar, which the desktop app has not.
pub fn take_links() -> Vec<String> {
    Vec::new()
}

/// Writes a scene file at `path` (through a temporary file, so a failed write keeps the old).
pub fn save_file(path: &str, text: &str) -> Result<String, String> {
    save_bytes(path, text.as_bytes(), "application/json")
}

/// Writes bytes at `path` ([`crate::files::write_atomic`]). The media type is the browser's
/// concern.
pub fn save_bytes(path: &str, bytes: &[u8], _mime: &str) -> Result<String, String> {
    crate::files::write_atomic(std::path::Path::new(path), bytes)
        .map_err(|e| format!("{path}: {e}"))?;
    Ok(path.to_owned())
}

/// Writes the concatenation of `pieces` as the file at `path`.
pub fn save_pieces(path: &str, pieces: &[&[u8]], mime: &str) -> Result<String, String> {
    save_bytes(path, &pieces.concat(), mime)
}

/// Writes an RGBA image as a PNG file at `path`.
pub fn save_png(path: &str, width: u32, height: u32, rgba: Vec<u8>) -> Result<String, String> {
    let image = crate::render::offscreen::Image {
        width,
        height,
        rgba,
    };
    let png = image
        .to_png()
        .map_err(|e| format!("PNG encoding failed: {e}"))?;
    save_bytes(path, &png, "image/png")
}

/// No picker natively: Open reads the path typed in the File group.
pub fn open_scene_picker() {}

/// Whether Ctrl+O's picker is opened by a key listener of the platform's own (no picker here).
pub const KEY_OPENS_PICKER: bool = false;

/// Scene files picked with Open (none natively: Open reads the typed path at once).
pub fn take_scene_files() -> Vec<Loaded> {
    Vec::new()
}

/// Keeps the last autosave aside before a new session writes over it.
pub fn keep_previous_autosave() {
    if let Some(dir) = autosave_dir() {
        let _ = std::fs::copy(
            dir.join("autosave.json"),
            dir.join("autosave.previous.json"),
        );
    }
}

/// Seconds since the first call, for timing work within a frame.
pub fn now() -> f64 {
    static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    START
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
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

thread_local! {
    static DECODED: std::cell::RefCell<Vec<(u64, Decoded)>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// A decoded picture, or why it could not be decoded.
pub type Decoded = Result<egui::ColorImage, String>;

/// Decodes a PNG or JPEG (here at once, with the `image` crate); the result arrives through
/// [`take_decoded`] under `key`.
pub fn decode_image(key: u64, bytes: std::sync::Arc<Vec<u8>>) {
    let result = decode(&bytes);
    DECODED.with(|d| d.borrow_mut().push((key, result)));
}

/// Pictures decoded since the last call.
pub fn take_decoded() -> Vec<(u64, Decoded)> {
    DECODED.with(|d| std::mem::take(&mut *d.borrow_mut()))
}

/// Decodes PNG or JPEG bytes into RGBA, refusing huge images and scaling big ones down.
fn decode(bytes: &[u8]) -> Decoded {
    use crate::limits::{MAX_DECODE_SIDE, MAX_GUIDE_SIDE};
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot read the image: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_DECODE_SIDE);
    limits.max_image_height = Some(MAX_DECODE_SIDE);
    limits.max_alloc = Some(512 << 20);
    reader.limits(limits);
    if reader.format().is_none() {
        return Err("not a PNG or JPEG image".into());
    }
    let mut img = reader
        .decode()
        .map_err(|e| format!("cannot decode the image: {e}"))?;
    if img.width().max(img.height()) > MAX_GUIDE_SIDE {
        img = img.resize(
            MAX_GUIDE_SIDE,
            MAX_GUIDE_SIDE,
            image::imageops::FilterType::Triangle,
        );
    }
    let rgba = img.to_rgba8();
    Ok(egui::ColorImage::from_rgba_unmultiplied(
        [rgba.width() as usize, rgba.height() as usize],
        rgba.as_raw(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{Event, Modifiers, PointerButton, pos2};

    fn button(x: f32, pressed: bool) -> Event {
        Event::PointerButton {
            pos: pos2(x, 0.0),
            button: PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        }
    }

    fn moved(x: f32) -> Event {
        Event::PointerMoved(pos2(x, 0.0))
    }

    #[test]
    fn egui_events_over_two_frames_make_one_press_with_every_sample() {
        let mut r = PressRecord::default();
        // Hovering with no button down records nothing.
        record_events(&mut r, &[moved(-1.0)], false);
        assert!(r.take_samples().is_empty() && r.press_so_far().is_empty());
        record_events(&mut r, &[button(0.0, true), moved(1.0), moved(2.0)], true);
        assert_eq!(r.press_so_far().len(), 3);
        assert!(r.take_finished().is_none());
        record_events(&mut r, &[moved(3.0), button(4.0, false)], false);
        let xs: Vec<f32> = r.take_finished().unwrap().iter().map(|s| s.0.x).collect();
        assert_eq!(xs, [0.0, 1.0, 2.0, 3.0, 4.0]);
    }

    #[test]
    fn a_press_within_one_frame_is_finished_in_that_frame() {
        let mut r = PressRecord::default();
        let mut events = vec![button(0.0, true)];
        events.extend((1..=60).map(|i| moved(i as f32)));
        events.push(button(60.0, false));
        record_events(&mut r, &events, false);
        assert_eq!(r.take_finished().map(|p| p.len()), Some(61));
    }

    #[test]
    fn a_release_egui_saw_but_the_record_did_not_drops_the_press() {
        let mut r = PressRecord::default();
        record_events(&mut r, &[button(0.0, true), moved(1.0)], true);
        record_events(&mut r, &[], false);
        assert!(!r.is_down() && r.press_so_far().is_empty());
        assert!(r.take_finished().is_none());
        record_events(&mut r, &[moved(2.0)], false);
        assert!(r.take_samples().is_empty());
    }
}

/// A video encoder for Record: none natively (a recording writes PNGs beside the scene file).
pub fn video_sink(_size: [u32; 2], _fps: f64) -> Option<Box<dyn super::flipbook::VideoSink>> {
    None
}
