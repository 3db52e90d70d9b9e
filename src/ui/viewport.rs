//! The 3D view: camera input, the tools, the progressive volume image (a preview while the
//! view changes, refined when it is still), the overlays and the status line.

use egui::{Color32, Sense};

use super::guide::Guide;
use super::notice::Notices;
use super::panels::ViewStats;
use super::selection::Selection;
use super::sketch_tool::{SketchTool, ToolContext};
use crate::derive::Derived;
use crate::render::View;
use crate::render::progressive::{Budget, Progressive};
use crate::render::viewport::ViewportPaint;
use crate::render::SliceJob;
use crate::scene::Document;

/// The viewport's own state.
pub struct Viewport {
    progressive: Progressive,
    /// What it reports (backend, quality, frame time, size).
    pub stats: ViewStats,
    /// The first full-quality image has been shown.
    pub ready: bool,
    /// Set by panels and F; applied once the viewport's size is known.
    pub frame_request: bool,
}

/// Everything the viewport works on this frame.
pub struct ViewportContext<'a> {
    /// The document.
    pub doc: &'a mut Document,
    /// The derivation cache.
    pub derived: &'a mut Derived,
    /// The sketch tools.
    pub tool: &'a mut SketchTool,
    /// The selection.
    pub selection: &'a mut Selection,
    /// Messages.
    pub notices: &'a mut Notices,
    /// The guide image.
    pub guide: &'a Guide,
}

impl Viewport {
    /// A viewport whose planner starts from a guessed cost (seconds per pixel·slice).
    pub fn new(initial_cost: f64, stats: ViewStats) -> Self {
        Self {
            progressive: Progressive::new(initial_cost, Budget::default()),
            stats,
            ready: false,
            frame_request: false,
        }
    }

    /// Frames the cloud (F).
    fn frame_cloud(&mut self, doc: &mut Document, derived: &mut Derived, aspect: f32) {
        let volumes = derived.update(doc.scene(), doc.revisions());
        if volumes.density.data.is_empty() {
            return;
        }
        let (center, radius) = volumes.density.data.bounding_sphere();
        // The grid box is padded around the visible cloud; frame a little tighter than its sphere.
        let mut camera = doc.scene().camera.clone();
        camera.frame(center, radius * 0.8, aspect);
        doc.set_camera(camera);
    }

    /// Draws the viewport into the rest of `ui`.
    pub fn show(&mut self, ui: &mut egui::Ui, cx: ViewportContext<'_>) {
        let rect = ui.available_rect_before_wrap();
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        if self.frame_request {
            self.frame_request = false;
            self.frame_cloud(cx.doc, cx.derived, rect.aspect_ratio());
        }
        let mut tc = ToolContext {
            doc: cx.doc,
            derived: cx.derived,
            selection: cx.selection,
            notices: cx.notices,
        };
        let drawing = cx.tool.input(ui, &response, rect, &mut tc);
        let mut camera = cx.doc.scene().camera.clone();
        if super::camera_input::handle(ui, &response, &mut camera, !drawing) {
            cx.doc.set_camera(camera);
        }

        let painter = ui.painter_at(rect);
        let scene = cx.doc.scene();
        let [r, g, b] = scene.light.background.map(|v| (v * 255.0).round() as u8);
        painter.rect_filled(rect, 0.0, Color32::from_rgb(r, g, b));
        cx.guide.paint(&painter, rect);

        let ppp = ui.ctx().pixels_per_point();
        let px = [
            (rect.width() * ppp).round().max(1.0) as u32,
            (rect.height() * ppp).round().max(1.0) as u32,
        ];
        self.stats.viewport_px = px;
        let volumes = cx.derived.update(scene, cx.doc.revisions());
        let key = view_key(cx.doc, px);
        let now = ui.input(|i| i.time);
        let plan = self.progressive.plan(
            now,
            key,
            px,
            scene.render.slices,
            response.is_pointer_button_down_on(),
        );
        self.stats.shown = plan.shown;
        self.stats.refining = plan.refining;
        self.stats.frame_seconds = self.progressive.last_frame_seconds();
        if plan.shown.is_some_and(|q| q.full) {
            self.ready = true;
        }
        let job = plan.job.map(|j| SliceJob {
            target: j.target,
            size: j.size,
            total: j.total,
            range: j.range,
            clear: j.clear,
            view: View {
                camera: scene.camera.clone(),
                light: scene.light.clone(),
                render: scene.render.clone(),
                aspect: rect.aspect_ratio(),
            },
        });
        if self.stats.backend.is_some() {
            painter.add(egui_wgpu::Callback::new_paint_callback(
                rect,
                ViewportPaint {
                    volumes,
                    job,
                    display: plan.display,
                },
            ));
        }
        if plan.repaint {
            ui.ctx().request_repaint();
        }
        self.status_line(ui, rect, cx.doc, cx.notices, now);
        cx.tool.overlay(ui, rect, cx.doc, cx.selection);
    }

    fn status_line(&self, ui: &egui::Ui, rect: egui::Rect, doc: &Document, notices: &Notices, now: f64) {
        let painter = ui.painter_at(rect);
        let mut text = String::new();
        if self.stats.backend.is_none() {
            text.push_str("No GPU renderer: the cloud cannot be drawn.");
        } else if let Some(p) = self.stats.refining {
            text.push_str(&format!("refining {:.0}%", p * 100.0));
        }
        let scene = doc.scene();
        if scene.ellipsoids.is_empty() && scene.planes.is_empty() {
            text.push_str("Empty scene: open Scene ▸ New cumulus, or sketch a cloud.");
        }
        // Status line: backend, adapter and the volume's current quality.
        if let Some(b) = &self.stats.backend {
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
            if let Some(q) = self.stats.shown {
                status.push_str(&format!(" · {q}"));
            }
            if let Some(s) = self.stats.frame_seconds {
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
        if let Some(n) = notices.visible(now) {
            let color = if n.error {
                Color32::from_rgb(255, 140, 140)
            } else {
                Color32::from_white_alpha(220)
            };
            painter.text(
                rect.left_top() + egui::vec2(10.0, 10.0),
                egui::Align2::LEFT_TOP,
                &n.text,
                egui::FontId::proportional(14.0),
                color,
            );
            if !n.error {
                ui.ctx()
                    .request_repaint_after(std::time::Duration::from_millis(500));
            }
        }
    }
}

/// Identifies everything that changes the viewport's image: the revisions of the parts the
/// image depends on, and the viewport's size (no hashing of the scene itself).
fn view_key(doc: &Document, px: [u32; 2]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    doc.revisions().hash(&mut h);
    px.hash(&mut h);
    h.finish()
}
