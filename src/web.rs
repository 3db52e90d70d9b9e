//! Everything wasm-only: start-up in the page, URL options, the page's test contract and the
//! on-page error box. The page holds two builds of this crate (index.html loads one): without
//! feature `webgl` it draws with WebGPU, and hands over to the other build when WebGPU fails to
//! start (`fall_back_to_webgl`); with it, with WebGL2. Gated as a whole module (with
//! `ui/platform_web.rs`, the browser's file reading), so wasm-only code stays out of the rest
//! of the crate.
//!
//! Test contract: `<body>` carries `data-ready` (first full-quality image shown),
//! `data-backend` (`webgpu` | `webgl2`), `data-adapter` and `data-quality`
//! (e.g. `full 640x480x128`); `window.cloudsketch.state()` returns the document and view;
//! `window.cloudsketch.set("/reference/in_front=true")` makes one undoable edit by JSON
//! Pointer, as the CLI's `--set` does. The page opens `#s=…` share links and `?preset=NAME`.
//! `?bench=ca` times the cellular automaton's step and smoothing on the benchmarks' grid (as
//! `cloudsketch bench --only simulate` does natively) once the app runs, and puts the figures
//! in the state as `bench`.

use std::cell::RefCell;

use wasm_bindgen::JsCast as _;
use wasm_bindgen::prelude::*;

use crate::ui::{CloudApp, Host, Opening, PageStatus, Start, StartOptions};

thread_local! {
    static STATE: RefCell<String> = const { RefCell::new(String::new()) };
    static EDITS: RefCell<Vec<String>> = const { RefCell::new(Vec::new()) };
    static BENCH: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Starts the app in the page's `#cloudsketch_canvas`.
pub fn start() {
    let _ = eframe::WebLogger::init(log::LevelFilter::Info);
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        show_error(&format!(
            "cloudsketch stopped after an internal error: {info}"
        ));
        previous(info);
    }));
    install_state_accessor();
    let start = scene_from_url();
    let bench = url_param("bench");
    let options = StartOptions {
        scene: start.scene,
        host: Some(Box::new(WebHost)),
        initial_cost: 4e-8,
        notice: start.notice,
        file: start.file,
        autosave: true,
        marching: match url_param("slices").as_deref() {
            Some("march") => Some(true),
            Some("raster") => Some(false),
            _ => None,
        },
        refine_whole: url_param("refine").as_deref() == Some("whole"),
    };
    wasm_bindgen_futures::spawn_local(async move {
        if let Err(message) = run(options).await {
            log::error!("{message}");
            // The link or preset stays in the address bar for the WebGL2 build.
            if !fall_back_to_webgl() {
                show_error(&message);
            }
            return;
        }
        crate::ui::forget_opening_in_url();
        if bench.as_deref() == Some("ca") {
            bench_automaton();
        }
    });
}

async fn run(options: StartOptions) -> Result<(), String> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or("no document")?;
    let canvas = document
        .get_element_by_id("cloudsketch_canvas")
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
        .ok_or("the page has no <canvas id=\"cloudsketch_canvas\">")?;
    let runner = eframe::WebRunner::new();
    runner
        .start(canvas, web_options(), Box::new(move |cc| Ok(Box::new(CloudApp::new(cc, options)))))
        .await
        .map_err(|e| {
            format!(
                "This browser offers neither WebGPU nor WebGL2, which cloudsketch needs to draw clouds. \
                 Try a current Chrome, Edge, Firefox or Safari with hardware acceleration on. ({})",
                e.as_string().unwrap_or_else(|| format!("{e:?}"))
            )
        })?;
    if let Some(loading) = document.get_element_by_id("loading") {
        loading.remove();
    }
    Ok(())
}

/// The page's options: the wgpu set-up of this build (see
/// [`crate::render::viewport::choose_web_backends`]).
fn web_options() -> eframe::WebOptions {
    let mut options = eframe::WebOptions::default();
    crate::render::viewport::choose_web_backends(
        &mut options.wgpu_options,
        cfg!(feature = "webgl"),
    );
    options
}

/// Asks the page to start its WebGL2 build instead (index.html defines
/// `window.cloudsketchFallback` only while this is the WebGPU-only build); whether it will.
fn fall_back_to_webgl() -> bool {
    let Some(window) = web_sys::window() else {
        return false;
    };
    js_sys::Reflect::get(&window, &JsValue::from_str("cloudsketchFallback"))
        .ok()
        .and_then(|f| f.dyn_into::<js_sys::Function>().ok())
        .and_then(|f| f.call0(&window).ok())
        .is_some_and(|answer| answer.is_truthy())
}

/// The starting document: a share link (`#s=…`) or `?preset=NAME` opens that (keeping the
/// last session aside), a plain visit continues the last session (see
/// [`crate::ui::start_session`]). Once the app runs, the link or preset leaves the address bar
/// ([`start`]), so a reload continues the session instead of opening it again.
fn scene_from_url() -> Start {
    let location = web_sys::window().map(|w| w.location());
    let hash = location
        .as_ref()
        .and_then(|l| l.hash().ok())
        .unwrap_or_default();
    let preset = url_param("preset");
    if hash.starts_with("#s=") {
        crate::ui::start_session(Opening::Link(&hash), true)
    } else if let Some(name) = &preset {
        crate::ui::start_session(Opening::Preset(name), true)
    } else {
        crate::ui::start_session(Opening::Nothing, true)
    }
}

/// The page address's query parameter `name` (`?name=value`).
fn url_param(name: &str) -> Option<String> {
    let search = web_sys::window()?.location().search().ok()?;
    web_sys::UrlSearchParams::new_with_str(&search)
        .ok()?
        .get(name)
}

/// `?bench=ca`: the automaton's step and smoothing on the benchmarks' grid, timed by the page's
/// clock (medians; the page's state shows them as `bench`). The step runs on pairs of words
/// (SIMD); the same step a word at a time is its baseline, and both must give the same bits.
fn bench_automaton() {
    use crate::simulate::{bench_simulation, simulation_under_parcels, time_steps};
    let performance = web_sys::window().and_then(|w| w.performance());
    let now = move || performance.as_ref().map_or(0.0, |p| p.now() / 1000.0);
    let mut sim = bench_simulation();
    sim.advance(1);
    let mut words = sim.clone();
    words.set_paired(false);
    let word_step = time_steps(&mut words, &now);
    let step = time_steps(&mut sim, &now);
    // The same bits both ways: on this grid, and on grids whose rows are one to four words
    // with a ragged last word (each row length has its own copy of the rule's loop).
    let same = |a: &crate::simulate::Simulation, b: &crate::simulate::Simulation| {
        let (a, b) = (a.automaton(), b.automaton());
        a.step == b.step && a.hum == b.hum && a.act == b.act && a.cld == b.cld
    };
    let pairs_match = same(&sim, &words)
        && [40, 100, 130, 200].into_iter().all(|nx| {
            let mut pairs = simulation_under_parcels([nx, 24, 40], 0.5);
            let mut words = pairs.clone();
            words.set_paired(false);
            pairs.advance(10);
            words.advance(10);
            pairs.automaton().cloud_cells() > 0 && same(&pairs, &words)
        });
    // Over a dropped step's counts, as the player smooths.
    let mut old = sim.smoothed();
    let mut smoothing: Vec<f64> = (0..5)
        .map(|_| {
            let t = now();
            old = std::hint::black_box(sim.smoothed_over(std::mem::take(&mut old)));
            now() - t
        })
        .collect();
    smoothing.sort_by(f64::total_cmp);
    let cells = sim.automaton().dims.iter().product::<usize>();
    let figures = serde_json::json!({
        "ca_step_ms": step * 1e3,
        "ca_word_step_ms": word_step * 1e3,
        "ca_pairs_match": pairs_match,
        "ca_smoothing_ms": smoothing[2] * 1e3,
        "cells": cells,
        "gcells_per_s": cells as f64 / step / 1e9,
    });
    log::info!("bench: {figures}");
    BENCH.with(|b| b.replace(Some(figures.to_string())));
}

/// Shows a message in the page's error box (and keeps the page usable as a page).
fn show_error(message: &str) {
    let Some(document) = web_sys::window().and_then(|w| w.document()) else {
        return;
    };
    if let Some(loading) = document.get_element_by_id("loading") {
        loading.remove();
    }
    if let Some(el) = document.get_element_by_id("error") {
        el.set_text_content(Some(message));
        let _ = el.set_attribute("style", "display:block");
    }
}

/// `window.cloudsketch.state()`.
fn install_state_accessor() {
    let Some(window) = web_sys::window() else {
        return;
    };
    let state = Closure::<dyn Fn() -> JsValue>::new(|| {
        let state = STATE.with(|s| js_sys::JSON::parse(&s.borrow()).unwrap_or(JsValue::NULL));
        if let Some(bench) = BENCH.with(|b| b.borrow().clone())
            && let Ok(figures) = js_sys::JSON::parse(&bench)
        {
            let _ = js_sys::Reflect::set(&state, &"bench".into(), &figures);
        }
        state
    });
    let set = Closure::<dyn Fn(String)>::new(|assignment: String| {
        EDITS.with(|e| e.borrow_mut().push(assignment));
        crate::ui::wake();
    });
    let api = js_sys::Object::new();
    let _ = js_sys::Reflect::set(&api, &"state".into(), state.as_ref());
    let _ = js_sys::Reflect::set(&api, &"set".into(), set.as_ref());
    let _ = js_sys::Reflect::set(&window, &"cloudsketch".into(), &api);
    state.forget(); // lives as long as the page
    set.forget();
}

struct WebHost;

impl Host for WebHost {
    fn take_edits(&mut self) -> Vec<String> {
        EDITS.with(|e| std::mem::take(&mut *e.borrow_mut()))
    }

    fn publish(&mut self, status: &PageStatus) {
        STATE.with(|s| s.replace(status.state.clone()));
        let Some(body) = web_sys::window()
            .and_then(|w| w.document())
            .and_then(|d| d.body())
        else {
            return;
        };
        let set = |name: &str, value: &str| {
            if body.get_attribute(name).as_deref() != Some(value) {
                let _ = body.set_attribute(name, value);
            }
        };
        if status.ready {
            set("data-ready", "true");
        }
        set("data-backend", &status.backend);
        set("data-adapter", &status.adapter);
        set("data-quality", &status.quality);
    }
}
