//! The 3D view: camera input, the tools, the progressive volume image (a preview while the
//! view changes, refined when it is still), the overlays and the status line.

use egui::{Color32, Sense};

use super::guide::Guide;
use super::notice::Notices;
use super::panels::{GeometryUpdate, ViewStats};
use super::selection::Selection;
use super::tools::{ToolContext, Toolbox, ViewInput};
use crate::derive::Derived;
use crate::render::SliceJob;
use crate::render::View;
use crate::render::capture::{Capture, chunks_for};
use crate::render::crop::{OUTSIDE_SHAFTS_DIVISOR, PixelCrop};

/// Seconds of a frame an export's capture may take (the rest is the view's: a drag during an
/// export keeps its frames).
const CAPTURE_BUDGET: f64 = 0.04;
/// The same while cached playback caches (the view renders nothing else): within the
/// interactive frame's 0.3 s.
const CACHE_BUDGET: f64 = 0.2;
use crate::derive::PUFFS_OVER_CAP;
use crate::render::progressive::{Budget, Progressive, slice_weight};
use crate::render::viewport::{BackdropPaint, ShaftsApart, ViewportPaint, paint_callback};
use crate::render::viewport::{JobFence, ReportPoll};
use crate::scene::Document;

/// How often a viewport whose refinement waits for the GPU looks again without word from it
/// (the GPU's report of a chunk wakes it: this is in case none comes).
const FENCE_POLL: std::time::Duration = std::time::Duration::from_millis(400);

/// How soon a report of the GPU wakes the app. Not zero: egui answers an immediate request
/// with two frames, and on a CPU adapter the second, which shows nothing new, took the CPU
/// from the next chunk (a refinement drew twice the frames it needed).
const WAKE: std::time::Duration = std::time::Duration::from_millis(1);

/// The viewport's own state.
pub struct Viewport {
    progressive: Progressive,
    /// The GPU's reports of the jobs this viewport gave it (made with the first frame, as it
    /// wakes the UI).
    fence: Option<JobFence>,
    /// Polls the GPU for finished work where its reports do not come by themselves (WebGL2).
    reports: Option<ReportPoll>,
    /// What it reports (backend, quality, frame time, size).
    pub stats: ViewStats,
    /// The first full-quality image has been shown.
    pub ready: bool,
    /// Set by panels and F (frame the selection, else the cloud); applied once the viewport's
    /// size is known.
    pub frame_request: bool,
    /// Where the view was drawn last frame (in points).
    pub rect: egui::Rect,
    /// A capture asked for by the Export group: size in pixels, transparent background.
    pub capture_request: Option<([u32; 2], bool)>,
    /// The capture under way (advanced by the paint callback every frame), and the clouds'
    /// revision it draws.
    capture: Option<Capture>,
    capture_geometry: u64,
    /// The density's generation a cache's capture was last drawn with.
    capture_density: u64,
    /// A finished capture: its size and pixels (straight-alpha RGBA), or why it failed.
    pub captured: Option<([u32; 2], Result<Vec<u8>, String>)>,
    /// A kept frame of cached playback to show instead of rendering (this frame only).
    pub flipbook: Option<egui::TextureHandle>,
    /// Cached playback is caching: the view renders nothing of its own (its capture renders
    /// each frame), so the capture may take most of a frame.
    pub caching: bool,
    /// The frames captured are a recording's (an export): drawn with the document's light,
    /// not the view's preview of it.
    pub recording: bool,
}

impl Viewport {
    /// The share of the capture under way that is done, if one is.
    pub fn capture_progress(&self) -> Option<f32> {
        self.capture.as_ref().map(Capture::progress)
    }

    /// Whether a capture is asked for or under way.
    pub fn capturing(&self) -> bool {
        self.capture.is_some() || self.capture_request.is_some()
    }

    /// Drops the capture under way (the export was cancelled): nothing more is drawn for it.
    pub fn cancel_capture(&mut self) {
        self.capture = None;
        self.capture_request = None;
    }
}

/// Everything the viewport works on this frame: what the tools work on, the tools, the
/// reference image.
pub struct ViewportContext<'a> {
    /// Document, derivation cache, selection and messages.
    pub cx: ToolContext<'a>,
    /// The sketch tools.
    pub tool: &'a mut Toolbox,
    /// The reference image's view.
    pub guide: &'a mut Guide,
}

impl Viewport {
    /// A viewport whose planner starts from a guessed cost (seconds per pixel·slice);
    /// `reports` makes the GPU's reports of finished work arrive where they need polling.
    /// `whole` refines at the view's whole resolution whatever the time (a page option for
    /// image comparisons).
    pub fn new(
        initial_cost: f64,
        whole: bool,
        stats: ViewStats,
        reports: Option<ReportPoll>,
    ) -> Self {
        let budget = Budget {
            refine_total: if whole {
                f64::INFINITY
            } else {
                Budget::default().refine_total
            },
            ..Budget::default()
        };
        Self {
            progressive: Progressive::new(initial_cost, budget)
                .fenced(super::platform::FENCED_REFINEMENT),
            fence: None,
            reports,
            stats,
            ready: false,
            frame_request: false,
            rect: egui::Rect::NOTHING,
            capture_request: None,
            capture: None,
            capture_geometry: 0,
            capture_density: 0,
            captured: None,
            flipbook: None,
            caching: false,
            recording: false,
        }
    }

    /// Frames the selection (F), or the whole cloud when nothing is selected.
    fn frame(
        &mut self,
        doc: &mut Document,
        derived: &mut Derived,
        selection: &Selection,
        aspect: f32,
    ) {
        let target = selection.bounds(doc.scene()).or_else(|| {
            let volumes = derived.update(doc.scene(), doc.revisions());
            let density = &volumes.density.data;
            // The grid box is padded around the visible cloud: frame a little tighter.
            (!density.is_empty()).then(|| {
                let (center, radius) = density.bounding_sphere();
                (center, radius * 0.8)
            })
        });
        if let Some((center, radius)) = target {
            let mut camera = doc.scene().camera.clone();
            camera.frame(center, radius, aspect);
            doc.set_camera(camera);
        }
    }

    /// Draws the viewport into the rest of `ui`.
    pub fn show(&mut self, ui: &mut egui::Ui, vc: ViewportContext<'_>) {
        let rect = ui.available_rect_before_wrap();
        self.rect = rect;
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let ViewportContext {
            mut cx,
            tool,
            guide,
        } = vc;
        if self.frame_request {
            self.frame_request = false;
            self.frame(cx.doc, cx.derived, cx.selection, rect.aspect_ratio());
        }
        let input = ViewInput {
            ui,
            response: &response,
            rect,
        };
        let drawing = tool.input(&input, &mut cx);
        let mut camera = cx.doc.scene().camera.clone();
        let quick = tool.quick_drags();
        if super::camera_input::handle(ui, &response, &mut camera, !drawing, quick) {
            cx.doc.set_camera(camera);
        }

        // A flat background is the frame's clear colour (`CloudApp::clear_color`): no
        // full-view pass of its own, one full-screen pass less on CPU adapters. A gradient, the
        // ground or shafts of light are the view behind the cloud, drawn into a texture when
        // they change and laid from it (under the reference image and the cloud): its place
        // is kept here, and it is made once the cloud's box on screen is known.
        let painter = ui.painter_at(rect);
        let backdrop_slot = painter.add(egui::Shape::Noop);
        let scene = cx.doc.scene();
        // What this frame shows, for the sky and the volume alike. A PNG export draws the
        // document's own light; the view previews it coarser on a CPU adapter.
        let exported = View {
            camera: scene.camera.clone(),
            light: scene.light.clone(),
            render: scene.render.clone(),
            drift: crate::render::gpu_types::Drifts::of(scene),
            aspect: rect.aspect_ratio(),
            crop: crate::render::FULL_VIEW,
        };
        let on_cpu = self.stats.backend.as_ref().is_some_and(|b| b.on_cpu);
        let view = View {
            render: if on_cpu {
                scene
                    .render
                    .with_light_at_most(crate::limits::CPU_PREVIEW_LIGHT)
            } else {
                scene.render.clone()
            },
            ..exported.clone()
        };
        self.stats.light_preview = (view.render.light_resolution != scene.render.light_resolution
            || view.render.light_octaves != scene.render.light_octaves)
            .then_some([view.render.light_resolution, view.render.light_octaves]);
        guide.paint(&painter, rect, cx.doc, false);
        let ppp = ui.ctx().pixels_per_point();
        let px = [
            (rect.width() * ppp).round().max(1.0) as u32,
            (rect.height() * ppp).round().max(1.0) as u32,
        ];
        self.stats.viewport_px = px;
        let frame = self.flipbook.take();
        if frame.is_some() || self.caching {
            // Cached playback: the kept frame (while caching, the last one cached), nothing
            // rendered but the cache's capture.
            if let Some(frame) = frame {
                let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                painter.image(frame.id(), rect, uv, Color32::WHITE);
            }
            if self.caching {
                // The frame's time derived (a simulation steps toward it over several frames:
                // the cache asks its capture once it has caught up).
                let volumes = cx.derived.update(scene, cx.doc.revisions());
                self.stats.catching_up = cx.derived.catching_up;
                if cx.derived.catching_up {
                    ui.ctx().request_repaint();
                }
                // At the view's own quality (its light previewed on a CPU adapter): the
                // frames play where the view shows them. A recording is an export: the
                // document's light.
                let drawn = if self.recording { &exported } else { &view };
                let capture =
                    self.drive_capture(ui, &mut cx, drawn, &volumes.density, CACHE_BUDGET);
                if let Some(capture) = capture.filter(|_| self.stats.backend.is_some()) {
                    painter.add(paint_callback(
                        rect,
                        ViewportPaint {
                            volumes,
                            job: None,
                            display: None,
                            capture: Some(capture),
                            fence: None,
                            job_id: 0,
                            own_submission: false,
                            due_after_start: None,
                            crop: crate::render::FULL_VIEW,
                            flat: None,
                        },
                    ));
                }
            }
            let now = ui.input(|i| i.time);
            self.overlays(ui, rect, &mut cx, tool, guide, now);
            return;
        }

        // The geometry, timed.
        let (before, t0) = (cx.derived.work(), super::platform::now());
        let density = cx.derived.density(scene, cx.doc.revisions());
        let work = cx.derived.work();
        if work.bakes > before.bakes {
            let count = self.stats.geometry_update.map_or(0, |g| g.count) + 1;
            self.stats.geometry_update = Some(GeometryUpdate {
                count,
                ms: (super::platform::now() - t0) * 1e3,
                texels: work.baked_texels - before.baked_texels,
                of: density.data.values.len() as u64,
            });
        }
        let volumes = cx.derived.update(scene, cx.doc.revisions());
        // An edit that takes the billows over their cap (more puffs, a finer field grid) is
        // told once, as opening such a document is (whose notice already says it).
        let left_out = cx.derived.puffs_left_out();
        let now = ui.input(|i| i.time);
        let told = cx
            .notices
            .latest
            .as_ref()
            .is_some_and(|n| n.text.contains(PUFFS_OVER_CAP) && now - n.at < 1.0);
        if left_out > 0 && self.stats.puffs_left_out == 0 && !told {
            cx.notices.note(
                now,
                format!(
                    "Billows: the finest level of puffs is left out ({left_out} {PUFFS_OVER_CAP} \
                     of {})",
                    crate::limits::MAX_PUFFS
                ),
            );
        }
        self.stats.puffs_left_out = left_out;
        self.stats.catching_up = cx.derived.catching_up;
        if cx.derived.catching_up {
            // A simulation still stepping toward the scene's time: keep the frames coming.
            ui.ctx().request_repaint();
        }
        // Draw the volume only over the part of the view its box covers: fewer pixels to
        // slice, refine and composite on every frame. Shafts of light there are drawn among
        // the slices; over the rest of the view, where no cloud lies in front of them, apart
        // (see `outside_shafts`).
        let density = &volumes.density.data;
        let crop = (!density.is_empty())
            .then(|| {
                scene
                    .camera
                    .ndc_bounds(density.min, density.min + density.size, view.aspect)
            })
            .flatten()
            .map(|ndc| PixelCrop::snap(ndc, px));
        let crop_area = crop.map(|c| {
            let [x0, y0, x1, y1] = c.px;
            egui::Rect::from_min_max(
                rect.min + egui::vec2(x0 as f32, y0 as f32) / ppp,
                rect.min + egui::vec2(x1 as f32, y1 as f32) / ppp,
            )
        });
        // A drag (not a press: a click would draw the view behind the cloud twice).
        let dragging = response.dragged();
        let shafts = (scene.light.shafts && !density.is_empty()).then(|| ShaftsApart {
            total: if dragging {
                OUTSIDE_PREVIEW_SLICES.min(scene.render.slices)
            } else {
                scene.render.slices
            },
            size: px.map(|v| v.div_ceil(OUTSIDE_SHAFTS_DIVISOR * if dragging { 2 } else { 1 })),
        });
        let shells_apart = shafts.is_some();
        let has_backdrop = scene.light.physical_sky
            || scene.light.sky_gradient
            || scene.light.ground
            || shafts.is_some();
        // Without a backdrop the cloud's composite maps its light with the flat background's
        // (the frame's clear colour, `CloudApp::clear_color`).
        let flat = (!has_backdrop).then(|| {
            crate::render::tone::background_display(scene.light.background, scene.light.exposure)
        });
        if has_backdrop && self.stats.backend.is_some() {
            let volumes = (!density.is_empty()).then(|| volumes.clone());
            let paint = backdrop(
                cx.doc,
                &view,
                px,
                crop.map(|c| c.px),
                volumes,
                shafts,
                dragging,
            );
            painter.set(backdrop_slot, paint_callback(rect, paint));
        }
        let key = view_key(cx.doc, volumes.density.generation, px, crop.map(|c| c.px));
        let now = ui.input(|i| i.time);
        let crop_size = crop.map_or([1, 1], |c| c.size());
        let fence = self
            .fence
            .get_or_insert_with(|| {
                let ctx = ui.ctx().clone();
                let fence = JobFence::new(
                    move |after: f64| {
                        // NaN or negative: at once.
                        let after = std::time::Duration::try_from_secs_f64(after.min(5.0));
                        ctx.request_repaint_after(WAKE.max(after.unwrap_or_default()));
                    },
                    super::platform::now,
                );
                // A fenced chunk waits for the report of the one before: where reports need
                // polling, poll while a job is out, between frames (a report wakes the app).
                if let Some(reports) = self.reports.clone().filter(ReportPoll::needed)
                    && super::platform::FENCED_REFINEMENT
                {
                    let fence = fence.clone();
                    super::platform::poll_reports(move || {
                        if fence.outstanding() {
                            reports.poll();
                        }
                    });
                }
                fence
            })
            .clone();
        // The slices' cost with the shafts' second target and shells among them.
        self.progressive.weigh_slices(slice_weight(shells_apart));
        let plan = self.progressive.plan(
            now,
            key,
            crop_size,
            scene.render.slices,
            response.is_pointer_button_down_on(),
            fence.report(),
        );
        self.stats.shown = plan.shown;
        self.stats.refining = plan.refining;
        self.stats.frame_seconds = self.progressive.last_frame_seconds();
        self.stats.late = self.progressive.late();
        self.stats.cost = self.progressive.cost();
        self.stats.jobs = self.progressive.jobs();
        if plan.shown.is_some_and(|q| q.full) {
            self.ready = true;
        }
        self.drive_capture(ui, &mut cx, &exported, &volumes.density, CAPTURE_BUDGET);
        let capture = self.capture.clone();
        if crop.is_none() && capture.is_some() && self.stats.backend.is_some() {
            // Nothing of the cloud in view: the capture still needs the callback to run.
            painter.add(paint_callback(
                rect,
                ViewportPaint {
                    volumes: volumes.clone(),
                    job: None,
                    display: None,
                    capture: capture.clone(),
                    fence: Some(fence.clone()),
                    job_id: 0,
                    own_submission: false,
                    due_after_start: None,
                    crop: crate::render::FULL_VIEW,
                    flat: None,
                },
            ));
        }
        // A job the GPU never gets counts as done at once.
        let drawn = crop.is_some() && self.stats.backend.is_some();
        if plan.job.is_some() && !drawn {
            fence.finished(plan.job_id);
        }
        if let Some(crop) = crop {
            let job = plan.job.map(|plan| SliceJob {
                plan,
                view: View {
                    crop: crop.ndc(px),
                    ..view.clone()
                },
                // The shafts around the box hold those beyond it.
                shells_apart,
            });
            if let Some(area) = crop_area.filter(|_| self.stats.backend.is_some()) {
                painter.add(paint_callback(
                    area,
                    ViewportPaint {
                        volumes,
                        job,
                        display: plan.display,
                        capture,
                        fence: Some(fence),
                        job_id: plan.job_id,
                        own_submission: plan.own_submission,
                        due_after_start: plan.due_after_start,
                        crop: crop.ndc(px),
                        flat,
                    },
                ));
            }
        }
        if plan.repaint {
            ui.ctx().request_repaint();
        } else if plan.waiting_for_gpu {
            // The GPU's report wakes the UI; this is in case it never comes (or comes after
            // the chunk is due, when the next one may queue behind it).
            let due = plan
                .wake_after
                .map_or(FENCE_POLL, std::time::Duration::from_secs_f64);
            ui.ctx()
                .request_repaint_after(due.min(FENCE_POLL).max(WAKE));
        }
        self.overlays(ui, rect, &mut cx, tool, guide, now);
    }

    /// Starts the capture asked for (its slices over the cloud's box, `density`'s, spread
    /// over frames within `budget` seconds of each), starts it over when the clouds changed under it, and hands a finished one to
    /// `captured`; returns the capture still under way.
    fn drive_capture(
        &mut self,
        ui: &egui::Ui,
        cx: &mut ToolContext<'_>,
        exported: &View,
        density: &crate::derive::Versioned<crate::density::DensityVolume>,
        budget: f64,
    ) -> Option<Capture> {
        // The density changing under a capture (a simulation stepping on, a far jump caught
        // up) starts it over: its chunks, and the box they are drawn over, show one cloud.
        if self.capture_density != density.generation {
            self.capture_density = density.generation;
            if let Some(capture) = self.capture.as_ref().filter(|c| c.drawing()) {
                self.capture = Some(capture.restart());
            }
        }
        let density = &density.data;
        let now = ui.input(|i| i.time);
        if let Some((size, transparent)) = self.capture_request.take() {
            // Its slices spread over frames within a frame's budget, as refinement's are.
            let chunks = chunks_for(exported, density, size, self.progressive.cost(), budget);
            self.capture = Some(Capture::new(exported, size, transparent, chunks));
            self.capture_geometry = cx.doc.revisions().geometry;
        }
        // The clouds changed while the capture was drawn (a move, a stroke, the simulation):
        // its chunks would show two different clouds, so it starts over with the change (with
        // the camera and the light it was asked with).
        let geometry = cx.doc.revisions().geometry;
        if let Some(capture) = self.capture.as_ref().filter(|c| c.drawing())
            && geometry != self.capture_geometry
        {
            self.capture = Some(capture.restart());
            self.capture_geometry = geometry;
            cx.notices.note(
                now,
                "The clouds changed during the capture: it starts over with the change",
            );
        }
        if let Some(capture) = &self.capture {
            if let Some(result) = capture.take() {
                self.captured = Some((capture.size, result));
                self.capture = None;
            } else {
                ui.ctx().request_repaint();
            }
        }
        self.capture.clone()
    }

    /// What is drawn over the cloud: guides in front, the status line, the tool's overlay and
    /// the sun handle.
    fn overlays(
        &self,
        ui: &mut egui::Ui,
        rect: egui::Rect,
        cx: &mut ToolContext<'_>,
        tool: &mut Toolbox,
        guide: &mut Guide,
        now: f64,
    ) {
        guide.paint(&ui.painter_at(rect), rect, cx.doc, true);
        self.status_line(ui, rect, cx.doc, cx.notices, now);
        tool.overlay(ui, rect, cx.doc, cx.derived, cx.selection);
        // H (hide guides) hides the sun handle with the other overlays.
        if self.stats.backend.is_some() && !tool.hide_guides {
            super::sun_handle::show(ui, rect, cx.doc);
        }
    }

    fn status_line(
        &self,
        ui: &egui::Ui,
        rect: egui::Rect,
        doc: &Document,
        notices: &Notices,
        now: f64,
    ) {
        let painter = ui.painter_at(rect);
        let mut text = String::new();
        if self.stats.backend.is_none() {
            text.push_str("No GPU renderer: the cloud cannot be drawn.");
        } else if let Some(p) = self.stats.refining {
            text.push_str(&format!("refining {:.0}%", p * 100.0));
        }
        let scene = doc.scene();
        if scene.ellipsoids.is_empty() && scene.planes.is_empty() {
            text.push_str("Empty scene: open Scene › New cumulus, or sketch a cloud.");
        }
        // Status line: backend, adapter, how the slices are drawn and the volume's current
        // quality.
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
            let mut status = format!("{} · {adapter} · {}", b.backend, b.slices);
            if let Some(q) = self.stats.shown {
                status.push_str(&format!(" · {q}"));
            }
            if let Some(s) = self.stats.frame_seconds {
                status.push_str(&format!(" · {:.0} ms", s * 1000.0));
            }
            if let Some([grid, octaves]) = self.stats.light_preview {
                status.push_str(&format!(" · light previewed at {grid}, {octaves} oct."));
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

/// The view behind the cloud over a view of `px` pixels whose cloud's box on screen is `crop`
/// (pixels; none when out of view), shaded through `volumes`' light, with `shafts` of light
/// around the box: drawn again when the view, the light, the clouds or the size changed (or a
/// drag began or ended: a drag counts fewer shells), else laid as it was. While `dragging`, at
/// a fraction of the size: it is drawn again on every frame then, and on a CPU adapter the
/// ground and the shafts kept a drag's frames over its budget.
fn backdrop(
    doc: &Document,
    view: &View,
    px: [u32; 2],
    crop: Option<[u32; 4]>,
    volumes: Option<crate::derive::Volumes>,
    shafts: Option<ShaftsApart>,
    dragging: bool,
) -> BackdropPaint {
    let scale = if dragging { BACKDROP_DRAG_DIVISOR } else { 1 };
    let size = px.map(|v| v.div_ceil(scale));
    // The box rounded outward: no shafts are laid twice along its edges.
    let crop = crop.map(|[x0, y0, x1, y1]| {
        [
            x0 / scale,
            y0 / scale,
            x1.div_ceil(scale),
            y1.div_ceil(scale),
        ]
    });
    let key = {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        // The density's generation too: the ground's shadows change with a simulation
        // catching up, which bumps no revision.
        let density = volumes.as_ref().map(|v| v.density.generation);
        view_key(doc, density.unwrap_or(0), size, crop).hash(&mut h);
        // The light the view is shaded with (previewed coarser on a CPU adapter).
        (view.render.light_resolution, view.render.light_octaves).hash(&mut h);
        shafts.as_ref().map(|s| (s.total, s.size)).hash(&mut h);
        h.finish()
    };
    BackdropPaint {
        view: view.clone(),
        background: doc.scene().light.background,
        size,
        volumes,
        shafts,
        crop,
        key,
    }
}

/// While a drag is under way the view behind the cloud is drawn at 1/this of the view's size
/// (each side).
const BACKDROP_DRAG_DIVISOR: u32 = 2;

/// While a drag is under way they are counted for an image of this many slices (fewer shells).
const OUTSIDE_PREVIEW_SLICES: u32 = 32;

/// Identifies everything that changes the viewport's image: the revisions of the parts the
/// image depends on, the viewport's size and the crop (no hashing of the scene itself).
fn view_key(doc: &Document, density: u64, px: [u32; 2], crop: Option<[u32; 4]>) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    // What the volume image shows: the reference image is drawn apart, every frame. The
    // density's generation too: a simulation catching up with a far jump in time changes it
    // from frame to frame while the document stays as it is (its image kept the first
    // frame's cloud, or chunks of several).
    let r = doc.revisions();
    (r.geometry, r.light, r.render, r.camera, r.time, density).hash(&mut h);
    px.hash(&mut h);
    crop.hash(&mut h);
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pixel_crop_covers_its_rectangle_and_maps_back() {
        let view = [800, 600];
        let ndc = [-0.31, -0.52, 0.47, 0.2];
        let c = PixelCrop::snap(ndc, view);
        let back = c.ndc(view);
        assert!(back[0] <= ndc[0] && back[1] <= ndc[1] && back[2] >= ndc[2] && back[3] >= ndc[3]);
        assert!(back[2] - back[0] < ndc[2] - ndc[0] + 0.02);
        let full = PixelCrop::snap([-1.0, -1.0, 1.0, 1.0], view);
        assert_eq!(full.px, [0, 0, 800, 600]);
        assert_eq!(full.ndc(view), [-1.0, -1.0, 1.0, 1.0]);
    }

    #[test]
    fn each_frame_a_simulation_catches_up_keys_a_new_image() {
        // A far jump in time: the simulation catches up over frames while the document stays
        // as it is. The view's image key must change with each frame's cloud, or the view
        // keeps a refinement begun on a cloud passed on the way (the page test of the jump
        // cannot tell: which clouds a refinement draws on is a matter of timing there).
        use crate::scene::{Preset, Scene};
        let mut doc = Document::new(Scene::preset(Preset::Simulated));
        let mut derived = Derived::default();
        doc.set_time(60.0);
        let revisions = doc.revisions();
        let mut keys = Vec::new();
        loop {
            let volumes = derived.update(doc.scene(), doc.revisions());
            keys.push(view_key(&doc, volumes.density.generation, [900, 560], None));
            if !derived.catching_up {
                break;
            }
        }
        assert_eq!(doc.revisions(), revisions, "the document stayed as it was");
        assert!(keys.len() >= 3, "caught up over {} frames", keys.len());
        let mut distinct = keys.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(distinct.len(), keys.len(), "a key repeated: {keys:?}");
        // Caught up, the same cloud keeps its image.
        let volumes = derived.update(doc.scene(), doc.revisions());
        let again = view_key(&doc, volumes.density.generation, [900, 560], None);
        assert_eq!(again, *keys.last().unwrap());
    }
}
