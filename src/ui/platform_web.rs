//! The browser side of the UI's one platform seam (`platform_native.rs` is the desktop's):
//! what the GL backend is called, and reading user files — the page's hidden
//! `<input type=file id="guide_input">` and dropped files, both read asynchronously into an
//! inbox the app polls each frame.

use std::cell::RefCell;

use wasm_bindgen::JsCast as _;
use wasm_bindgen::prelude::*;

use super::guide::Loaded;

use crate::limits::MAX_FILE_BYTES;

/// What the GL backend is called here.
pub const GL_BACKEND_NAME: &str = "webgl2";

/// Whether this platform has a file picker button.
pub const HAS_PICKER: bool = true;

/// Largest file read.
const MAX_BYTES: f64 = MAX_FILE_BYTES as f64;

thread_local! {
    static INBOX: RefCell<Vec<Loaded>> = const { RefCell::new(Vec::new()) };
    static REPAINT: RefCell<Option<egui::Context>> = const { RefCell::new(None) };
}

fn deliver(loaded: Loaded) {
    INBOX.with(|i| i.borrow_mut().push(loaded));
    REPAINT.with(|c| {
        if let Some(ctx) = c.borrow().as_ref() {
            ctx.request_repaint();
        }
    });
}

async fn read_file(file: web_sys::File) -> Loaded {
    let name = file.name();
    if file.size() > MAX_BYTES {
        return Err(format!("{name}: larger than {} MiB", MAX_FILE_BYTES >> 20));
    }
    let buffer = wasm_bindgen_futures::JsFuture::from(file.array_buffer())
        .await
        .map_err(|e| format!("{name}: {e:?}"))?;
    Ok((name, js_sys::Uint8Array::new(&buffer).to_vec()))
}

/// Starts reading a dropped file; the result arrives through [`take_loaded`].
pub fn read_dropped(file: egui::DroppedFileHandle, ctx: &egui::Context) -> Option<Loaded> {
    REPAINT.with(|c| *c.borrow_mut() = Some(ctx.clone()));
    let name = file.path().display().to_string();
    wasm_bindgen_futures::spawn_local(async move {
        let result = match file.bytes_async().await {
            Ok(b) if b.len() as u64 > MAX_FILE_BYTES => {
                Err(format!("{name}: larger than {} MiB", MAX_FILE_BYTES >> 20))
            }
            Ok(b) => Ok((name.clone(), b)),
            Err(e) => Err(format!("{name}: {e}")),
        };
        deliver(result);
    });
    None
}

/// Reads a file by path (not available in the browser).
pub fn read_path(path: &str) -> Loaded {
    Err(format!(
        "{path}: the browser cannot open paths; use Load… or drop the file"
    ))
}

fn input() -> Option<web_sys::HtmlInputElement> {
    web_sys::window()?
        .document()?
        .get_element_by_id("guide_input")?
        .dyn_into()
        .ok()
}

/// Installs the change listener of the page's file input (once, at start-up).
pub fn install(ctx: &egui::Context) {
    REPAINT.with(|c| *c.borrow_mut() = Some(ctx.clone()));
    let Some(el) = input() else {
        log::warn!("the page has no #guide_input: the Load… button will do nothing");
        return;
    };
    let on_change = Closure::<dyn FnMut(web_sys::Event)>::new(move |_event: web_sys::Event| {
        let Some(el) = input() else { return };
        if let Some(file) = el.files().and_then(|f| f.get(0)) {
            wasm_bindgen_futures::spawn_local(async move { deliver(read_file(file).await) });
        }
        el.set_value(""); // choosing the same file again fires again
    });
    let _ = el.add_event_listener_with_callback("change", on_change.as_ref().unchecked_ref());
    on_change.forget(); // lives as long as the page
}

/// Opens the browser's file picker (called from a click, so the browser allows it).
pub fn open_picker() {
    if let Some(el) = input() {
        el.click();
    }
}

/// Files that finished loading since the last call.
pub fn take_loaded() -> Vec<Loaded> {
    INBOX.with(|i| std::mem::take(&mut *i.borrow_mut()))
}
