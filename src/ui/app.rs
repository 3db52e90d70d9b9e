//! The application state and the frame loop.

use std::hash::{Hash, Hasher};

use egui::{Color32, Sense};

use crate::render::gpu_types::{Slicing, VolumeUniforms};
use crate::render::progressive::{Budget, Progressive, Quality};
use crate::render::viewport::{BackendInfo, ViewportPaint, install};
use crate::render::{SliceJob, VolumeCache};
use crate::scene::{Edit, History, Scene};

/// What the page (or any embedder) is told after each frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PageStatus {
    /// The first full-quality image has been shown.
    pub ready: bool,
    /// Active graphics backend (`webgpu`, `webgl2`, …).
    pub backend: String,
    /// Adapter name.
    pub adapter: String,
    /// Quality of the image on screen, e.g. `full 640x480x128`.
    pub quality: String,
    /// The document and view as JSON.
    pub state: String,
}

/// Receives [`PageStatus`] updates (the web page's test contract; nothing natively).
pub trait Host {
    /// Called after a frame when anything in the status changed.
    fn publish(&mut self, status: &PageStatus);
}

/// How the app starts.
pub struct StartOptions {
    /// The document to open.
    pub scene: Scene,
    /// Where status goes.
    pub host: Option<Box<dyn Host>>,
    /// Guessed cost of the volume pass in seconds per pixel·slice, refined by measurement.
    pub initial_cost: f64,
}

impl Default for StartOptions {
    fn default() -> Self {
        Self {
            scene: Scene::default(),
            host: None,
            initial_cost: 2e-8,
        }
    }
}

/// The cloudsketch app.
pub struct CloudApp {
    pub(super) scene: Scene,
    pub(super) history: History,
    cache: VolumeCache,
    progressive: Progressive,
    pub(super) backend: Option<BackendInfo>,
    host: Option<Box<dyn Host>>,
    pub(super) shown: Option<Quality>,
    pub(super) refining: Option<f32>,
    ready: bool,
    last_status: Option<PageStatus>,
    /// The document as last published, with its JSON.
    published_scene: Option<(Scene, String)>,
    pub(super) viewport_px: [u32; 2],
    pub(super) frame_seconds: Option<f64>,
    /// Set by panels; applied to the camera once the viewport's size is known.
    pub(super) frame_request: bool,
    /// Sketch tools, plane selection and messages.
    pub(super) sketch: super::sketch_tool::SketchUi,
    /// The guide image underlay.
    pub(super) guide: super::guide::Guide,
}

impl CloudApp {
    /// Creates the app and its GPU resources.
    pub fn new(cc: &eframe::CreationContext<'_>, options: StartOptions) -> Self {
        let backend = cc.wgpu_render_state.as_ref().map(install);
        if backend.is_none() {
            log::error!("no wgpu render state: the volume cannot be drawn");
        }
        cc.egui_ctx.set_visuals(egui::Visuals::dark());
        super::files::install(&cc.egui_ctx);
        Self {
            scene: options.scene,
            history: History::default(),
            cache: VolumeCache::default(),
            progressive: Progressive::new(options.initial_cost, Budget::default()),
            backend,
            host: options.host,
            shown: None,
            refining: None,
            ready: false,
            last_status: None,
            published_scene: None,
            viewport_px: [0, 0],
            frame_seconds: None,
            frame_request: false,
            sketch: Default::default(),
            guide: Default::default(),
        }
    }

    /// Applies an edit with undo.
    pub(super) fn apply(&mut self, edit: Edit, merge_key: Option<&'static str>) -> bool {
        self.history.apply(&mut self.scene, edit, merge_key)
    }

    fn shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (undo, redo, frame) = ctx.input_mut(|i| {
            let redo = i.consume_key(
                egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
                egui::Key::Z,
            ) || i.consume_key(egui::Modifiers::COMMAND, egui::Key::Y);
            let undo = i.consume_key(egui::Modifiers::COMMAND, egui::Key::Z);
            let frame = i.consume_key(egui::Modifiers::NONE, egui::Key::F);
            (undo, redo, frame)
        });
        if undo {
            self.history.undo(&mut self.scene);
        }
        if redo {
            self.history.redo(&mut self.scene);
        }
        if frame {
            self.frame_request = true;
        }
    }

    /// Frames the cloud (F).
    fn frame_cloud(&mut self, aspect: f32) {
        let volume = self.cache.update(&self.scene);
        if volume.grid.is_empty() {
            return;
        }
        let (center, radius) = volume.grid.bounding_sphere();
        // The grid box is padded around the visible cloud; frame a little tighter than its sphere.
        self.scene.camera.frame(center, radius * 0.8, aspect);
    }

    fn viewport(&mut self, ui: &mut egui::Ui) {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        if self.frame_request {
            self.frame_request = false;
            self.frame_cloud(rect.aspect_ratio());
        }
        let drawing = self.sketch_input(ui, &response, rect);
        super::camera_input::handle(ui, &response, &mut self.scene.camera, !drawing);

        let painter = ui.painter_at(rect);
        let [r, g, b] = self
            .scene
            .light
            .background
            .map(|v| (v * 255.0).round() as u8);
        painter.rect_filled(rect, 0.0, Color32::from_rgb(r, g, b));
        self.paint_guide(&painter, rect);

        let ppp = ui.ctx().pixels_per_point();
        let px = [
            (rect.width() * ppp).round().max(1.0) as u32,
            (rect.height() * ppp).round().max(1.0) as u32,
        ];
        self.viewport_px = px;
        let volume = self.cache.update(&self.scene);
        let key = view_key(&self.scene, px, volume.generation);
        let now = ui.input(|i| i.time);
        let plan = self.progressive.plan(
            now,
            key,
            px,
            self.scene.render.slices,
            response.is_pointer_button_down_on(),
        );
        self.shown = plan.shown;
        self.refining = plan.refining;
        self.frame_seconds = self.progressive.last_frame_seconds();
        if plan.shown.is_some_and(|q| q.full) {
            self.ready = true;
        }
        let aspect = rect.width() / rect.height().max(1.0);
        let job = plan.job.map(|j| SliceJob {
            target: j.target,
            size: j.size,
            range: j.range,
            clear: j.clear,
            uniforms: VolumeUniforms::new(
                &self.scene,
                &self.scene.camera,
                &volume.grid,
                aspect,
                Slicing { total: j.total },
            ),
        });
        if self.backend.is_some() {
            painter.add(egui_wgpu::Callback::new_paint_callback(
                rect,
                ViewportPaint {
                    volume,
                    job,
                    display: plan.display,
                },
            ));
        }
        if plan.repaint {
            ui.ctx().request_repaint();
        }
        self.overlay(ui, rect);
        self.sketch_overlay(ui, rect);
    }

    fn overlay(&self, ui: &egui::Ui, rect: egui::Rect) {
        let painter = ui.painter_at(rect);
        let mut text = String::new();
        if self.backend.is_none() {
            text.push_str("No GPU renderer: the cloud cannot be drawn.");
        } else if let Some(p) = self.refining {
            text.push_str(&format!("refining {:.0}%", p * 100.0));
        }
        if self.scene.ellipsoids.is_empty() && self.scene.planes.is_empty() {
            text.push_str("Empty scene: open Scene ▸ New cumulus, or sketch a cloud.");
        }
        // Status line: backend, adapter and the volume's current quality.
        if let Some(b) = &self.backend {
            let adapter: String = if b.adapter.chars().count() > 40 {
                b.adapter
                    .chars()
                    .take(39)
                    .chain(std::iter::once('…'))
                    .collect()
            } else {
                b.adapter.clone()
            };
            let mut status = format!("{} · {adapter}", b.backend);
            if let Some(q) = self.shown {
                status.push_str(&format!(" · {q}"));
            }
            if let Some(s) = self.frame_seconds {
                status.push_str(&format!(" · {:.0} ms", s * 1000.0));
            }
            painter.text(
                rect.right_bottom() + egui::vec2(-8.0, -6.0),
                egui::Align2::RIGHT_BOTTOM,
                status,
                egui::FontId::proportional(11.0),
                Color32::from_white_alpha(150),
            );
        }
        if !text.is_empty() {
            painter.text(
                rect.left_bottom() + egui::vec2(8.0, -8.0),
                egui::Align2::LEFT_BOTTOM,
                text,
                egui::FontId::proportional(13.0),
                Color32::from_white_alpha(200),
            );
        }
    }

    fn publish(&mut self) {
        let Some(host) = self.host.as_mut() else {
            return;
        };
        let backend = self.backend.clone().unwrap_or(BackendInfo {
            backend: "none",
            adapter: String::new(),
        });
        let quality = self.shown.map(|q| q.to_string()).unwrap_or_default();
        // The document is serialised again only when it changed (this runs every frame).
        if self
            .published_scene
            .as_ref()
            .is_none_or(|(scene, _)| *scene != self.scene)
        {
            let json = serde_json::to_string(&self.scene).unwrap_or_default();
            self.published_scene = Some((self.scene.clone(), json));
        }
        let scene_json = self
            .published_scene
            .as_ref()
            .map(|(_, json)| json.as_str())
            .unwrap_or("null");
        let view = serde_json::json!({
            "viewport": self.viewport_px,
            "quality": quality,
            "frame_ms": self.frame_seconds.map(|s| (s * 1000.0).round()),
            "refining": self.refining,
            "backend": backend.backend,
            "adapter": backend.adapter,
            "undo": self.history.undo_len(),
            "redo": self.history.redo_len(),
            "tool": self.sketch.tool.name(),
            "selected_plane": self.sketch.selected,
            "guides_hidden": self.sketch.hide_guides,
            "guide_image": self.guide.image.as_ref().map(|g| serde_json::json!({
                "name": g.name, "size": g.size, "opacity": self.guide.opacity, "visible": self.guide.visible,
            })),
            "guide_error": self.guide.error,
            "notice": self.sketch.notice.as_ref().map(|n| serde_json::json!({"text": n.text, "error": n.error})),
        });
        let state = format!("{{\"scene\":{scene_json},\"view\":{view}}}");
        let status = PageStatus {
            ready: self.ready,
            backend: backend.backend.to_string(),
            adapter: backend.adapter,
            quality,
            state,
        };
        if self.last_status.as_ref() != Some(&status) {
            host.publish(&status);
            self.last_status = Some(status);
        }
    }
}

/// Identifies everything that changes the viewport's image.
fn view_key(scene: &Scene, px: [u32; 2], generation: u64) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    px.hash(&mut h);
    generation.hash(&mut h);
    // Camera, light and render settings: hash their exact JSON form (f32s written losslessly).
    serde_json::to_string(&(&scene.camera, &scene.light, &scene.render))
        .unwrap_or_default()
        .hash(&mut h);
    h.finish()
}

impl eframe::App for CloudApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.shortcuts(&ctx);
        self.sketch_shortcuts(&ctx);
        self.guide_input(&ctx);
        egui::Panel::right("controls")
            .resizable(true)
            .default_size(270.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.side_panel(ui));
            });
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport(ui));
        if !ctx.input(|i| i.pointer.any_down()) {
            self.history.end_merge();
        }
        self.publish();
    }
}
