//! The browser side of the UI's one platform seam (`platform_native.rs` is the desktop's):
//! what the GL backend is called; reading user files — the page's hidden
//! `<input type=file>`s (`guide_input` for pictures, `scene_input` for scenes) and dropped
//! files, read asynchronously into an inbox the app polls each frame; saving as a download;
//! the autosave in localStorage; links pasted into the address bar.

use std::cell::RefCell;

use wasm_bindgen::JsCast as _;
use wasm_bindgen::prelude::*;

use super::guide::Loaded;
use super::press_record::{Sample, with_record};

use crate::limits::MAX_FILE_BYTES;

/// What the GL backend is called here.
pub const GL_BACKEND_NAME: &str = "webgl2";

/// Whether this platform has a file picker button.
pub const HAS_PICKER: bool = true;

/// What Record makes here (the timeline's button and the Export group's "every frame of the
/// range").
pub const RECORD_HINT: &str = "Record every frame of the timeline's range at full quality, one after another, at the Export group's PNG width and the view's shape: a WebM at the scene's frame rate where the browser encodes video (else, and with a transparent background, PNGs in one zip: STEM_####.png)";

/// Whether refinement waits for the GPU's report of each chunk before the next: a browser runs
/// frames ahead of the GPU, so chunks queued there would hold up the first frame of a drag.
/// WebGPU reports as soon as the work is done; WebGL2's reports come through [`poll_reports`].
pub const FENCED_REFINEMENT: bool = true;

/// How often [`poll_reports`] polls.
const REPORT_POLL_MS: i32 = 8;

/// Keeps the GPU's reports of finished work coming for fenced refinement where the device must
/// be polled for them (WebGL2): calls `poll` every few milliseconds, between frames, for as
/// long as the page is open (`poll` does nothing while no job is out).
pub fn poll_reports(poll: impl Fn() + 'static) {
    let Some(window) = web_sys::window() else {
        return;
    };
    let tick = Closure::<dyn Fn()>::new(poll);
    if let Err(e) = window.set_interval_with_callback_and_timeout_and_arguments_0(
        tick.as_ref().unchecked_ref(),
        REPORT_POLL_MS,
    ) {
        log::warn!("no timer to poll the GPU's reports: {e:?}");
        return;
    }
    // The timer calls it for the page's life.
    tick.forget();
}

/// Largest file read.
const MAX_BYTES: f64 = MAX_FILE_BYTES as f64;

thread_local! {
    static INBOX: RefCell<Vec<Loaded>> = const { RefCell::new(Vec::new()) };
    static REPAINT: RefCell<Option<egui::Context>> = const { RefCell::new(None) };
    static LINKS: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
    static SCENE_FILES: RefCell<Vec<Loaded>> = const { RefCell::new(Vec::new()) };
}

fn deliver(loaded: Loaded) {
    INBOX.with(|i| i.borrow_mut().push(loaded));
    wake();
}

/// localStorage keys of the autosave, of the session kept aside and of the user's presets.
const AUTOSAVE_KEY: &str = "cloudsketch.autosave";
const PREVIOUS_KEY: &str = "cloudsketch.autosave.previous";
const LOOKS_KEY: &str = "cloudsketch.presets";
const GROUPS_KEY: &str = "cloudsketch.groups";

fn storage() -> Option<web_sys::Storage> {
    web_sys::window().and_then(|w| w.local_storage().ok().flatten())
}

/// The page's stored item `key`, if any.
fn load_item(key: &str) -> Option<String> {
    storage()?.get_item(key).ok().flatten()
}

/// Stores `json` under `key` (the browser's quota may refuse it).
fn store_item(key: &str, json: &str) -> Result<(), String> {
    let storage = storage().ok_or("this browser keeps no local storage for the page")?;
    storage
        .set_item(key, json)
        .map_err(|_| "the browser's storage for this page is full".to_owned())
}

/// The last autosaved document, if any.
pub fn load_autosave() -> Option<String> {
    load_item(AUTOSAVE_KEY)
}

/// Writes the autosave (the browser's quota may refuse a large reference image).
pub fn store_autosave(json: &str) -> Result<(), String> {
    store_item(AUTOSAVE_KEY, json)
}

/// The user's own presets, if any were saved.
pub fn load_looks() -> Option<String> {
    load_item(LOOKS_KEY)
}

/// Writes the user's own presets.
pub fn store_looks(json: &str) -> Result<(), String> {
    store_item(LOOKS_KEY, json)
}

/// Which side-panel groups the user left open, if stored.
pub fn load_groups() -> Option<String> {
    load_item(GROUPS_KEY)
}

/// Writes which side-panel groups are open.
pub fn store_groups(json: &str) -> Result<(), String> {
    store_item(GROUPS_KEY, json)
}

/// The session kept aside by [`keep_previous_autosave`], if any.
pub fn load_previous_autosave() -> Option<String> {
    load_item(PREVIOUS_KEY)
}

/// Keeps the last autosave aside (under its own key) before a new session writes over it.
pub fn keep_previous_autosave() {
    if let (Some(storage), Some(json)) = (storage(), load_autosave()) {
        let _ = storage.set_item(PREVIOUS_KEY, &json);
    }
}

/// Seconds since the page opened (`performance.now()`), for timing work within a frame.
pub fn now() -> f64 {
    web_sys::window()
        .and_then(|w| w.performance())
        .map_or(0.0, |p| p.now() / 1000.0)
}

/// Asks for a frame: something arrived from outside egui's events (a file, a page edit).
pub fn wake() {
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

fn input(id: &str) -> Option<web_sys::HtmlInputElement> {
    web_sys::window()?
        .document()?
        .get_element_by_id(id)?
        .dyn_into()
        .ok()
}

/// The page's address without its query and fragment: what share links start with.
pub fn page_base() -> String {
    let Some(location) = web_sys::window().map(|w| w.location()) else {
        return crate::share::DEFAULT_BASE.to_owned();
    };
    match (location.origin(), location.pathname()) {
        (Ok(origin), Ok(path)) => format!("{origin}{path}"),
        _ => crate::share::DEFAULT_BASE.to_owned(),
    }
}

/// Takes a share link (`#s=…`) or a preset (`?preset=…`) out of the address bar once it is
/// open, so a reload continues the autosaved session (which then holds that scene and every
/// change since) instead of opening the link again over it.
pub fn forget_opening_in_url() {
    let Some(window) = web_sys::window() else {
        return;
    };
    let location = window.location();
    let search = location.search().unwrap_or_default();
    let params = web_sys::UrlSearchParams::new_with_str(&search).ok();
    let preset = params.as_ref().is_some_and(|p| p.has("preset"));
    if !preset && !location.hash().unwrap_or_default().starts_with("#s=") {
        return;
    }
    if let Some(p) = &params {
        p.delete("preset");
    }
    let rest = params
        .map(|p| String::from(p.to_string()))
        .unwrap_or_default();
    let query = if rest.is_empty() {
        String::new()
    } else {
        format!("?{rest}")
    };
    let url = format!("{}{query}", location.pathname().unwrap_or_default());
    if let Ok(history) = window.history() {
        let _ = history.replace_state_with_url(&JsValue::NULL, "", Some(&url));
    }
}

/// Share links pasted into the address bar of the open page since the last call.
pub fn take_links() -> Vec<String> {
    LINKS.with(|l| std::mem::take(&mut *l.borrow_mut()))
}

/// Saves a scene file as a download named `name`.
pub fn save_file(name: &str, text: &str) -> Result<String, String> {
    save_bytes(name, text.as_bytes(), "application/json")
}

fn refused(e: JsValue) -> String {
    format!("the browser refused the download ({})", js_error(&e))
}

/// Saves bytes as a download named `name` of media type `mime`.
pub fn save_bytes(name: &str, bytes: &[u8], mime: &str) -> Result<String, String> {
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(mime);
    let blob =
        web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options).map_err(refused)?;
    download_blob(name, &blob)
}

/// Saves the concatenation of `pieces` as a download named `name` of media type `mime`: one
/// blob made from them, so the whole is never built in the wasm's memory (a recording's zip),
/// nor, as a rule, copied into the page's JavaScript heap on its way (the blob reads the
/// pieces where they lie).
pub fn save_pieces(name: &str, pieces: &[&[u8]], mime: &str) -> Result<String, String> {
    let options = web_sys::BlobPropertyBag::new();
    options.set_type(mime);
    let total: usize = pieces.iter().map(|p| p.len()).sum();
    let parts = js_sys::Array::new();
    for piece in pieces {
        // SAFETY: a view of the wasm's memory is valid until that memory grows. Nothing here
        // allocates in it but, rarely, wasm-bindgen's table of JavaScript values, when it
        // takes a slot for a view it has to grow; a view made before that growth reads as
        // empty. The blob's size shows it, and the pieces are then copied instead.
        let view = unsafe { js_sys::Uint8Array::view(piece) };
        parts.push(&view);
    }
    let blob = web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options);
    parts.set_length(0);
    let blob = match blob {
        Ok(blob) if blob.size() as usize == total => blob,
        _ => {
            for piece in pieces {
                parts.push(&js_sys::Uint8Array::from(*piece));
            }
            web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &options)
                .map_err(refused)?
        }
    };
    download_blob(name, &blob)
}

/// Hands a blob to the browser as a download named `name`.
fn download_blob(name: &str, blob: &web_sys::Blob) -> Result<String, String> {
    let fail = refused;
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let url = web_sys::Url::create_object_url_with_blob(blob).map_err(fail)?;
    let anchor: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(fail)?
        .dyn_into()
        .map_err(|e| fail(e.into()))?;
    anchor.set_href(&url);
    anchor.set_download(name);
    anchor.click();
    let _ = web_sys::Url::revoke_object_url(&url);
    Ok(format!("{name} (a download)"))
}

/// Encodes an RGBA image as PNG with the browser's own encoder (no codec in the wasm) and
/// downloads it as `name`; the download starts once the browser has encoded it.
pub fn save_png(name: &str, width: u32, height: u32, rgba: Vec<u8>) -> Result<String, String> {
    let canvas = web_sys::OffscreenCanvas::new(width, height).map_err(refused)?;
    let context: web_sys::OffscreenCanvasRenderingContext2d = canvas
        .get_context("2d")
        .map_err(refused)?
        .ok_or("no 2D canvas")?
        .dyn_into()
        .map_err(|e| refused(e.into()))?;
    let data = web_sys::ImageData::new_with_u8_clamped_array_and_sh(
        wasm_bindgen::Clamped(&rgba),
        width,
        height,
    )
    .map_err(refused)?;
    context.put_image_data(&data, 0.0, 0.0).map_err(refused)?;
    let promise = canvas.convert_to_blob().map_err(refused)?;
    let owned = name.to_owned();
    wasm_bindgen_futures::spawn_local(async move {
        let name = owned;
        match wasm_bindgen_futures::JsFuture::from(promise).await {
            Ok(blob) => {
                if let Ok(blob) = blob.dyn_into::<web_sys::Blob>()
                    && let Err(e) = download_blob(&name, &blob)
                {
                    log::error!("{e}");
                }
            }
            Err(e) => log::error!("the browser could not encode the PNG ({})", js_error(&e)),
        }
    });
    Ok(format!("{name} (a download)"))
}

/// Whether Ctrl+O's picker is opened by the page's own key listener, in the key's event: from
/// the app's frame after it, the browser refused it where that frame came late (its user
/// activation lapses), and the key did nothing (a page test on a busy machine).
pub const KEY_OPENS_PICKER: bool = true;

/// Opens the browser's file picker for a scene file (called from a click or a key, so the
/// browser allows it).
pub fn open_scene_picker() {
    if let Some(el) = input("scene_input") {
        el.click();
    }
}

/// Every position of the primary pointer while a button is held, coalesced samples
/// included: the browser hands the page one move per frame, and a frame on a CPU adapter can
/// take 150 ms, so a stroke drawn from the per-frame moves alone loses its shape.
/// Keeps the browser from acting on the app's own Ctrl/Cmd shortcuts that eframe lets through:
/// Ctrl+D (duplicate) would open the bookmark dialog, Ctrl+S save the page, Ctrl+O open a
/// file in the tab, Ctrl+L go to the address bar. Text fields keep every key. Ctrl+O opens the
/// scene picker here, in the key's own event ([`KEY_OPENS_PICKER`]).
fn keep_browser_shortcuts() {
    let Some(document) = web_sys::window().and_then(|w| w.document()) else {
        return;
    };
    let on_key = Closure::<dyn FnMut(web_sys::KeyboardEvent)>::new(|e: web_sys::KeyboardEvent| {
        let typing = e
            .target()
            .and_then(|t| t.dyn_into::<web_sys::HtmlInputElement>().ok())
            .is_some();
        // Ctrl+D duplicates (not a bookmark), Ctrl+S saves and Ctrl+O opens the app's scene,
        // Ctrl+L copies its link (not the address bar), Ctrl+E exports (not a web search).
        let ours = ["d", "s", "o", "l", "e"]
            .iter()
            .any(|k| e.key().eq_ignore_ascii_case(k));
        if !typing && (e.ctrl_key() || e.meta_key()) && ours {
            e.prevent_default();
            if e.key().eq_ignore_ascii_case("o") && !e.shift_key() && !e.alt_key() && !e.repeat() {
                open_scene_picker();
            }
        }
    });
    // In the capture phase: eframe stops the event's propagation at the canvas.
    let _ = document.add_event_listener_with_callback_and_bool(
        "keydown",
        on_key.as_ref().unchecked_ref(),
        true,
    );
    on_key.forget(); // lives as long as the page
}

/// A pointer event's position in the canvas (points) and the pen's pressure (a mouse reports
/// a constant 0.5, so only a pen's is kept).
fn sample_at(e: &web_sys::PointerEvent, zoom: f32) -> Option<Sample> {
    let canvas = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id("cloudsketch_canvas"))?;
    let rect = canvas.get_bounding_client_rect();
    let pos = egui::pos2(
        (e.client_x() as f32 - rect.left() as f32) / zoom,
        (e.client_y() as f32 - rect.top() as f32) / zoom,
    );
    Some((pos, (e.pointer_type() == "pen").then(|| e.pressure())))
}

fn install_pointer_samples(ctx: &egui::Context) {
    let Some(document) = web_sys::window().and_then(|w| w.document()) else {
        return;
    };
    let Some(canvas) = document.get_element_by_id("cloudsketch_canvas") else {
        return;
    };
    // Press and release are heard in the capture phase on the document, before eframe's own
    // canvas listeners (which may run a frame inside them): a frame that sees the release
    // also finds the whole press → release recorded.
    let down_ctx = ctx.clone();
    let on_down =
        Closure::<dyn FnMut(web_sys::PointerEvent)>::new(move |e: web_sys::PointerEvent| {
            if e.is_primary()
                && e.target().is_some_and(|t| {
                    t.dyn_ref::<web_sys::Element>()
                        .is_some_and(|el| el.id() == "cloudsketch_canvas")
                })
            {
                let at = sample_at(&e, down_ctx.zoom_factor());
                with_record(|r| r.pressed(at));
            }
        });
    let _ = document.add_event_listener_with_callback_and_bool(
        "pointerdown",
        on_down.as_ref().unchecked_ref(),
        true,
    );
    on_down.forget(); // lives as long as the page
    let on_up = Closure::<dyn FnMut(web_sys::PointerEvent)>::new(|e: web_sys::PointerEvent| {
        if e.is_primary() {
            with_record(|r| r.released(None));
        }
    });
    let _ = document.add_event_listener_with_callback_and_bool(
        "pointerup",
        on_up.as_ref().unchecked_ref(),
        true,
    );
    on_up.forget(); // lives as long as the page
    let _ = canvas;
    let ctx = ctx.clone();
    let on_move =
        Closure::<dyn FnMut(web_sys::PointerEvent)>::new(move |e: web_sys::PointerEvent| {
            if !e.is_primary() {
                return;
            }
            if e.buttons() == 0 {
                // No button down: a press whose release the page never heard is over.
                with_record(|r| {
                    if r.is_down() {
                        r.lost();
                    }
                });
                return;
            }
            let zoom = ctx.zoom_factor();
            let coalesced = e.get_coalesced_events();
            let mut new: Vec<Sample> = Vec::new();
            if coalesced.length() == 0 {
                new.extend(sample_at(&e, zoom));
            }
            for c in coalesced.iter() {
                if let Ok(m) = c.dyn_into::<web_sys::PointerEvent>() {
                    new.extend(sample_at(&m, zoom));
                }
            }
            with_record(|r| r.moved(&new));
        });
    let _ =
        document.add_event_listener_with_callback("pointermove", on_move.as_ref().unchecked_ref());
    on_move.forget(); // lives as long as the page
}

/// Nothing to feed: the page's listeners record every sample as it comes (egui's events in
/// the browser hold one move per frame).
pub fn record_frame(_input: &egui::InputState) {}

/// Installs the page's listeners: pointer samples, the file inputs' changes and the address
/// bar's fragment (once, at start-up).
pub fn install(ctx: &egui::Context) {
    REPAINT.with(|c| *c.borrow_mut() = Some(ctx.clone()));
    install_pointer_samples(ctx);
    keep_browser_shortcuts();
    for id in ["guide_input", "scene_input"] {
        let inbox = if id == "scene_input" {
            &SCENE_FILES
        } else {
            &INBOX
        };
        let Some(el) = input(id) else {
            log::warn!("the page has no #{id}: its Open or Load button will do nothing");
            continue;
        };
        let on_change = Closure::<dyn FnMut(web_sys::Event)>::new(move |_event: web_sys::Event| {
            let Some(el) = input(id) else { return };
            if let Some(file) = el.files().and_then(|f| f.get(0)) {
                wasm_bindgen_futures::spawn_local(async move {
                    let loaded = read_file(file).await;
                    inbox.with(|i| i.borrow_mut().push(loaded));
                    wake();
                });
            }
            el.set_value(""); // choosing the same file again fires again
        });
        let _ = el.add_event_listener_with_callback("change", on_change.as_ref().unchecked_ref());
        on_change.forget(); // lives as long as the page
    }
    let on_hash = Closure::<dyn FnMut(web_sys::Event)>::new(|_event: web_sys::Event| {
        let hash = web_sys::window()
            .and_then(|w| w.location().hash().ok())
            .unwrap_or_default();
        if hash.starts_with("#s=") {
            LINKS.with(|l| l.borrow_mut().push(hash));
            forget_opening_in_url();
            wake();
        }
    });
    if let Some(window) = web_sys::window() {
        let _ =
            window.add_event_listener_with_callback("hashchange", on_hash.as_ref().unchecked_ref());
    }
    on_hash.forget(); // lives as long as the page
}

/// Opens the browser's file picker for a picture (called from a click, so the browser allows
/// it).
pub fn open_picker() {
    if let Some(el) = input("guide_input") {
        el.click();
    }
}

/// Files that finished loading since the last call: pictures picked for the guide and
/// dropped files.
pub fn take_loaded() -> Vec<Loaded> {
    INBOX.with(|i| std::mem::take(&mut *i.borrow_mut()))
}

/// Scene files picked with Open since the last call.
pub fn take_scene_files() -> Vec<Loaded> {
    SCENE_FILES.with(|i| std::mem::take(&mut *i.borrow_mut()))
}

thread_local! {
    static DECODED: RefCell<Vec<(u64, Decoded)>> = const { RefCell::new(Vec::new()) };
}

/// A decoded picture, or why it could not be decoded.
pub type Decoded = Result<egui::ColorImage, String>;

/// Decodes a PNG or JPEG with the browser's own decoder (no image codecs in the page's wasm):
/// asynchronously; the result arrives through [`take_decoded`] under `key`.
pub fn decode_image(key: u64, bytes: std::sync::Arc<Vec<u8>>) {
    wasm_bindgen_futures::spawn_local(async move {
        let result = browser_decode(&bytes).await;
        DECODED.with(|d| d.borrow_mut().push((key, result)));
        wake();
    });
}

/// Pictures decoded since the last call.
pub fn take_decoded() -> Vec<(u64, Decoded)> {
    DECODED.with(|d| std::mem::take(&mut *d.borrow_mut()))
}

/// `createImageBitmap` on the bytes, drawn (scaled down to the texture cap) into an
/// `OffscreenCanvas` and read back as RGBA.
async fn browser_decode(bytes: &[u8]) -> Decoded {
    use crate::limits::{MAX_DECODE_SIDE, MAX_GUIDE_SIDE};
    let fail = |what: &str, e: JsValue| format!("{what}: {}", js_error(&e));
    let window = web_sys::window().ok_or("no window")?;
    let parts = js_sys::Array::of1(&js_sys::Uint8Array::from(bytes));
    let blob = web_sys::Blob::new_with_u8_array_sequence(&parts)
        .map_err(|e| fail("cannot read the image", e))?;
    let promise = window
        .create_image_bitmap_with_blob(&blob)
        .map_err(|e| fail("cannot decode the image", e))?;
    let bitmap: web_sys::ImageBitmap = wasm_bindgen_futures::JsFuture::from(promise)
        .await
        .map_err(|_| "not a PNG or JPEG image the browser can decode".to_string())?
        .dyn_into()
        .map_err(|e| fail("cannot decode the image", e))?;
    let (w, h) = (bitmap.width(), bitmap.height());
    if w == 0 || h == 0 || w.max(h) > MAX_DECODE_SIDE {
        bitmap.close();
        return Err(format!(
            "the image is {w}×{h}: at most {MAX_DECODE_SIDE} px a side"
        ));
    }
    let scale = (MAX_GUIDE_SIDE as f64 / w.max(h) as f64).min(1.0);
    let (tw, th) = (
        ((w as f64 * scale).round() as u32).max(1),
        ((h as f64 * scale).round() as u32).max(1),
    );
    let canvas = web_sys::OffscreenCanvas::new(tw, th).map_err(|e| fail("no canvas", e))?;
    let context: web_sys::OffscreenCanvasRenderingContext2d = canvas
        .get_context("2d")
        .map_err(|e| fail("no 2D context", e))?
        .ok_or("no 2D context")?
        .dyn_into()
        .map_err(|e| fail("no 2D context", e.into()))?;
    context
        .draw_image_with_image_bitmap_and_dw_and_dh(&bitmap, 0.0, 0.0, tw as f64, th as f64)
        .map_err(|e| fail("cannot draw the image", e))?;
    bitmap.close();
    let data = context
        .get_image_data(0.0, 0.0, tw as f64, th as f64)
        .map_err(|e| fail("cannot read the image's pixels", e))?;
    Ok(egui::ColorImage::from_rgba_unmultiplied(
        [tw as usize, th as usize],
        &data.data(),
    ))
}

fn js_error(e: &JsValue) -> String {
    e.dyn_ref::<js_sys::Error>()
        .map(|e| String::from(e.message()))
        .unwrap_or_else(|| format!("{e:?}"))
}

#[wasm_bindgen(module = "/web/record.js")]
extern "C" {
    #[wasm_bindgen(js_name = videoSupported)]
    fn video_supported() -> bool;
    type WebmRecorder;
    #[wasm_bindgen(constructor)]
    fn new(width: u32, height: u32, fps: f64) -> WebmRecorder;
    #[wasm_bindgen(method, js_name = addFrame)]
    fn add_frame(this: &WebmRecorder, rgba: &[u8], index: u32);
    #[wasm_bindgen(method)]
    fn failed(this: &WebmRecorder) -> Option<String>;
    #[wasm_bindgen(method)]
    fn busy(this: &WebmRecorder) -> bool;
    #[wasm_bindgen(method)]
    fn finish(this: &WebmRecorder) -> js_sys::Promise;
    #[wasm_bindgen(method)]
    fn cancel(this: &WebmRecorder);
}

/// Record's WebM: the browser's WebCodecs VP9 encoder and webm-muxer (`web/record.js`), and
/// whether it was finished (one dropped unfinished, cancelled or failed, closes its encoder).
struct Webm(WebmRecorder, bool);

impl Drop for Webm {
    fn drop(&mut self) {
        if !self.1 {
            self.0.cancel();
        }
    }
}

impl super::flipbook::VideoSink for Webm {
    fn state(&self) -> super::flipbook::SinkState {
        use super::flipbook::SinkState;
        match self.0.failed() {
            Some(e) => SinkState::Refused(e),
            None if self.0.busy() => SinkState::Busy,
            None => SinkState::Ready,
        }
    }

    fn add(&mut self, rgba: &[u8], index: u32) -> Result<(), String> {
        if let Some(e) = self.0.failed() {
            return Err(e);
        }
        self.0.add_frame(rgba, index);
        Ok(())
    }

    fn finish(
        mut self: Box<Self>,
        name: String,
        cancelled: std::sync::Arc<std::sync::atomic::AtomicBool>,
        done: Box<dyn FnOnce(Result<String, String>)>,
    ) {
        self.1 = true;
        let promise = self.0.finish();
        wasm_bindgen_futures::spawn_local(async move {
            let saved = match wasm_bindgen_futures::JsFuture::from(promise).await {
                _ if cancelled.load(std::sync::atomic::Ordering::Relaxed) => {
                    Err("cancelled".to_owned())
                }
                Ok(blob) => blob
                    .dyn_into::<web_sys::Blob>()
                    .map_err(|_| "the encoder gave no video".to_owned())
                    .and_then(|blob| download_blob(&name, &blob)),
                Err(e) => Err(format!("the video encoder failed: {}", js_error(&e))),
            };
            done(saved);
        });
    }
}

/// A video encoder for Record: the browser's WebM where it has WebCodecs, unless the address
/// asks for PNGs (`?record=png`); `size` must be even.
pub fn video_sink(size: [u32; 2], fps: f64) -> Option<Box<dyn super::flipbook::VideoSink>> {
    let asks_png = web_sys::window()
        .and_then(|w| w.location().search().ok())
        .and_then(|q| web_sys::UrlSearchParams::new_with_str(&q).ok())
        .and_then(|p| p.get("record"))
        .is_some_and(|v| v == "png");
    if asks_png || !video_supported() {
        return None;
    }
    Some(Box::new(Webm(
        WebmRecorder::new(size[0], size[1], fps),
        false,
    )))
}
