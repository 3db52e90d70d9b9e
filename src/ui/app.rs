//! The application: owns the document, the derivation cache, the viewport and the side
//! panel's views, runs the frame loop and the global shortcuts, and publishes the page status.

use super::autosave::Autosave;
use super::guide::Guide;
use super::notice::Notices;
use super::panels::{
    ExportPanel, LIGHT, RENDER, ScenePanel, SimulationPanel, SketchPanel, Timeline, ViewPanel,
    ViewStats,
};
use super::scene_files::SceneFiles;
use super::selection::Selection;
use super::shortcuts::Shortcut;
use super::tools::{ToolContext, Toolbox};
use super::transform::Axis;
use super::viewport::{Viewport, ViewportContext};
use crate::derive::Derived;
use crate::render::viewport::{BackendInfo, FillPaint, ReportPoll, install, paint_callback};
use crate::scene::{Document, Edit, Scene};

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

/// Receives [`PageStatus`] updates: the web page's test contract, and natively the desktop
/// window's `--screenshot` (`cli/desktop.rs`).
pub trait Host {
    /// Called after a frame when anything in the status changed.
    fn publish(&mut self, status: &PageStatus);

    /// Edits asked for by the host since the last frame, as `--set` assignments
    /// (`/reference/in_front=true`): each becomes one undoable edit, as if made in the panel.
    fn take_edits(&mut self) -> Vec<String> {
        Vec::new()
    }

    /// Called at the end of every frame with the status as last published (the desktop
    /// window's `--screenshot` watches for the first full-quality image here).
    fn end_frame(&mut self, _ctx: &egui::Context, _status: &PageStatus) {}
}

/// How the app starts.
pub struct StartOptions {
    /// The document to open.
    pub scene: Scene,
    /// Where status goes.
    pub host: Option<Box<dyn Host>>,
    /// Guessed cost of the volume pass in seconds per pixel·slice, refined by measurement.
    pub initial_cost: f64,
    /// What to tell the user at start (a restored session, a bad link), and whether it
    /// reports a failure.
    pub notice: Option<(String, bool)>,
    /// The file the document came from (what Save writes).
    pub file: Option<String>,
    /// Write the document to the platform's store as it changes (the app; not tests).
    pub autosave: bool,
    /// Marched (`Some(true)`) or rasterised slices instead of the adapter's default (the
    /// page's `?slices=march|raster`).
    pub marching: Option<bool>,
    /// Full quality at the view's whole resolution however long it takes, instead of the
    /// resolution the planner fits in its budget from the measured speed (the page's
    /// `?refine=whole`: images compared across page loads on a busy machine).
    pub refine_whole: bool,
}

impl Default for StartOptions {
    fn default() -> Self {
        Self {
            scene: Scene::default(),
            host: None,
            initial_cost: 2e-8,
            notice: None,
            file: None,
            autosave: false,
            marching: None,
            refine_whole: false,
        }
    }
}

/// Width of the side panel in points.
const PANEL_WIDTH: f32 = 300.0;

/// The side panel's views.
#[derive(Default)]
struct Panels {
    timeline: Timeline,
    export: ExportPanel,
    sketch: SketchPanel,
    scene: ScenePanel,
    simulation: SimulationPanel,
    view: ViewPanel,
}

/// The cloudsketch app.
pub struct CloudApp {
    doc: Document,
    derived: Derived,
    viewport: Viewport,
    tool: Toolbox,
    selection: Selection,
    notices: Notices,
    guide: Guide,
    panels: Panels,
    /// The side panel is shown (N or its button toggles it, as Blender's sidebar).
    panel_open: bool,
    host: Option<Box<dyn Host>>,
    last_status: Option<PageStatus>,
    /// CPU time of the last frame (app and rendering), as eframe measures it.
    cpu_seconds: Option<f32>,
    /// The document's JSON as last published, with the revision it was made at.
    published: Option<(u64, String)>,
    /// When to write the autosave (`None`: not autosaving).
    autosave: Option<Autosave>,
    /// Open, Save, Copy link and the unsaved marker.
    files: SceneFiles,
    /// Cached playback of the frame range.
    flipbook: super::flipbook::Flipbook,
    /// When the last frame played (the app's clock), while playing.
    last_tick: Option<f64>,
    /// The stalls a press is held through (a click across a slow frame still clicks).
    held: super::click_timing::HeldClock,
    /// The cache's next capture, asked for once the view has drawn the frame's time (and a
    /// simulation has caught up with it): its size, and frames waited.
    flipbook_capture: Option<([u32; 2], u32)>,
}

impl CloudApp {
    /// Creates the app and its GPU resources.
    pub fn new(cc: &eframe::CreationContext<'_>, options: StartOptions) -> Self {
        let backend = cc
            .wgpu_render_state
            .as_ref()
            .map(|rs| install(rs, super::platform::GL_BACKEND_NAME, options.marching));
        let reports = cc.wgpu_render_state.as_ref().map(ReportPoll::new);
        if backend.is_none() {
            log::error!("no wgpu render state: the volume cannot be drawn");
        }
        cc.egui_ctx.set_visuals(egui::Visuals::dark());
        super::widgets::install_fonts(&cc.egui_ctx);
        super::platform::install(&cc.egui_ctx);
        // The side panel's groups as the user left them (the app's, like the autosave).
        if options.autosave
            && let Some(json) = super::platform::load_groups()
        {
            super::widgets::install_groups(&cc.egui_ctx, super::widgets::Groups::from_json(&json));
        }
        let doc = Document::new(options.scene);
        let mut notices = Notices::default();
        match options.notice {
            Some((text, true)) => notices.error(0.0, text),
            Some((text, false)) => notices.note(0.0, text),
            None => {}
        }
        Self {
            files: SceneFiles::new(&doc, options.file),
            autosave: options.autosave.then(|| Autosave::new(&doc)),
            doc,
            derived: Derived::default(),
            viewport: Viewport::new(
                options.initial_cost,
                options.refine_whole,
                ViewStats {
                    backend,
                    ..Default::default()
                },
                reports,
            ),
            tool: Toolbox::default(),
            selection: Selection::default(),
            notices,
            guide: Guide::default(),
            panels: Panels::default(),
            panel_open: true,
            host: options.host,
            last_status: None,
            cpu_seconds: None,
            published: None,
            flipbook: Default::default(),
            last_tick: None,
            held: Default::default(),
            flipbook_capture: None,
        }
    }

    fn undo(&mut self, now: f64) {
        match self.doc.undo() {
            Some(what) => self.notices.note(now, format!("Undid: {what}")),
            None => self.notices.note(now, "Nothing to undo"),
        }
        self.selection.retain_valid(self.doc.scene());
    }

    fn redo(&mut self, now: f64) {
        match self.doc.redo() {
            Some(what) => self.notices.note(now, format!("Redid: {what}")),
            None => self.notices.note(now, "Nothing to redo"),
        }
        self.selection.retain_valid(self.doc.scene());
    }

    /// Acts on each of a frame's shortcuts in the order they were pressed (see
    /// [`super::shortcuts`]).
    fn shortcuts(&mut self, ctx: &egui::Context, pressed: &[Shortcut]) {
        for &shortcut in pressed {
            self.shortcut(ctx, shortcut);
        }
    }

    /// One shortcut: undo, redo, frame, the panel, play, standard views, export and the file
    /// keys here; the tools' keys go to the tool.
    fn shortcut(&mut self, ctx: &egui::Context, shortcut: Shortcut) {
        let now = ctx.input(|i| i.time);
        match shortcut {
            Shortcut::Undo => self.undo(now),
            Shortcut::Redo => self.redo(now),
            Shortcut::Frame => self.viewport.frame_request = true,
            Shortcut::TogglePanel => self.panel_open = !self.panel_open,
            // Alt+A plays and pauses (Blender's shortcut before Space took it over).
            Shortcut::PlayPause => self.panels.timeline.playing = !self.panels.timeline.playing,
            Shortcut::InsertKey => {
                self.panels.timeline.shot_view = self.panels.view.through_shot;
                let said = self
                    .panels
                    .timeline
                    .insert_keys(&mut self.doc, &self.selection);
                self.notices.note(now, said);
            }
            Shortcut::DeleteKeys => {
                self.panels.timeline.selected.clear();
                let said = self
                    .panels
                    .timeline
                    .delete_keys(&mut self.doc, &self.selection);
                self.notices.note(now, said);
            }
            // Delete over the timeline with keys selected deletes them, not the items.
            Shortcut::Delete
                if self.panels.timeline.hovered && !self.panels.timeline.selected.is_empty() =>
            {
                let said = self
                    .panels
                    .timeline
                    .delete_keys(&mut self.doc, &self.selection);
                self.notices.note(now, said);
            }
            Shortcut::StepFrame(by) => self.panels.timeline.step_frame(&mut self.doc, by.into()),
            Shortcut::JumpKey(forward) => {
                self.panels
                    .timeline
                    .jump_to_key(&mut self.doc, &self.selection, forward)
            }
            Shortcut::View(view) => {
                let mut camera = self.doc.scene().camera.clone();
                camera.set_view(view);
                self.doc.set_camera(camera);
            }
            Shortcut::ShotView => {
                let said = self.panels.view.toggle_shot(&self.doc);
                self.notices.note(now, said);
            }
            Shortcut::Orthographic => {
                let mut camera = self.doc.scene().camera.clone();
                camera.orthographic = !camera.orthographic;
                self.doc.set_camera(camera);
            }
            Shortcut::Save | Shortcut::SaveAs | Shortcut::Open | Shortcut::CopyLink => self
                .files
                .shortcut(ctx, shortcut, &self.doc, &mut self.notices),
            Shortcut::Export => {
                let ask = self.panels.export.start(
                    &self.doc,
                    &mut self.notices,
                    now,
                    self.viewport.stats.viewport_px,
                    &self.files.name,
                );
                self.export_asked(ask, now);
            }
            _ => {
                let mut tc = ToolContext {
                    doc: &mut self.doc,
                    derived: &mut self.derived,
                    selection: &mut self.selection,
                    notices: &mut self.notices,
                };
                self.tool.shortcut(shortcut, &mut tc, now);
            }
        }
    }

    /// The side panel: undo/redo/frame buttons, then each group's view.
    fn side_panel(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.heading("cloudsketch");
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if ui
                    .small_button("»")
                    .on_hover_text("N: hide this panel")
                    .clicked()
                {
                    self.panel_open = false;
                }
            });
        });
        self.files
            .ui(ui, &mut self.doc, &mut self.selection, &mut self.notices);
        ui.horizontal(|ui| {
            let now = ui.input(|i| i.time);
            if ui
                .add_enabled(self.doc.undo_len() > 0, egui::Button::new("⟲ Undo"))
                .on_hover_text("Ctrl+Z")
                .clicked()
            {
                self.undo(now);
            }
            if ui
                .add_enabled(self.doc.redo_len() > 0, egui::Button::new("⟳ Redo"))
                .on_hover_text("Ctrl+Shift+Z")
                .clicked()
            {
                self.redo(now);
            }
            if ui
                .button("Frame")
                .on_hover_text("F: frame the selection (the whole cloud when nothing is selected)")
                .clicked()
            {
                self.viewport.frame_request = true;
            }
        });
        ui.separator();
        let p = &mut self.panels;
        p.sketch.ui(
            ui,
            &mut self.doc,
            &self.derived,
            &mut self.tool,
            &mut self.selection,
            &mut self.notices,
        );
        self.guide.ui(ui, &mut self.doc, &mut self.notices);
        RENDER.ui(ui, &mut self.doc);
        if let Some(k) = super::panels::take_removed_tier(ui.ctx()) {
            self.doc.apply(crate::scene::Edit::RemoveTier(k), None);
        }
        LIGHT.ui(ui, &mut self.doc);
        p.scene
            .ui(ui, &mut self.doc, &mut self.selection, &mut self.notices);
        p.view.ui(ui, &self.viewport.stats, &mut self.doc);
        p.simulation.ui(ui, &mut self.doc);
        let ask = p.export.ui(
            ui,
            &self.doc,
            &mut self.notices,
            self.viewport.stats.viewport_px,
            &self.files.name,
        );
        self.export_asked(ask, ui.input(|i| i.time));
        self.selection.retain_valid(self.doc.scene());
    }

    /// Does what the Export group asked: a capture of the view, a recording of the range
    /// (through the flipbook's steps), or stopping either.
    fn export_asked(&mut self, ask: super::panels::ExportAsk, now: f64) {
        if ask.capture.is_some() || ask.record.is_some() {
            self.stop_caching(now, "Caching stopped for the export");
        }
        if ask.capture.is_some() {
            self.viewport.capture_request = ask.capture;
        }
        if let Some(r) = ask.record {
            if self.viewport.stats.backend.is_none() {
                self.panels.export.recorded(
                    Err("no GPU renderer: there is nothing to record with".to_owned()),
                    &mut self.notices,
                    now,
                );
                return;
            }
            self.panels.timeline.playing = false;
            let said = self.flipbook.start_record(
                self.doc.scene(),
                r.size,
                r.transparent,
                &r.stem,
                r.video,
            );
            self.notices.note(now, said);
        }
        if ask.cancel_capture {
            self.viewport.cancel_capture();
        }
        if ask.cancel_record {
            self.end_frames();
        }
    }

    /// Cached playback: starts or cancels caching as the timeline asked, advances it a frame
    /// at a time through the viewport's capture, and while playing hands the viewport the
    /// kept frame of the time, if it is still what the view shows.
    fn cache_frames(&mut self, ctx: &egui::Context, now: f64) {
        let timeline = &mut self.panels.timeline;
        if self.flipbook.recording() && std::mem::take(&mut timeline.cache_asked) {
            self.notices
                .note(now, "A recording is under way: cache when it is done");
        }
        if std::mem::take(&mut timeline.cache_asked) && !self.flipbook.building() {
            if self.viewport.stats.backend.is_none() {
                self.notices
                    .error(now, "No GPU renderer: there is nothing to cache");
            } else if self.viewport.capturing() {
                // The PNG export's capture: it finishes first.
                self.notices
                    .note(now, "A PNG export is under way: cache when it is done");
            } else {
                timeline.playing = false;
                if let Some(said) = self
                    .flipbook
                    .start(self.doc.scene(), self.viewport.stats.viewport_px)
                {
                    self.notices.note(now, said);
                }
            }
        }
        if std::mem::take(&mut self.panels.timeline.cache_cancel) {
            self.stop_caching(now, "Caching cancelled: the frames cached so far are kept");
        }
        if self.flipbook.building() {
            self.panels.timeline.playing = false;
            // The time stays on the frame being cached (a scrub meanwhile is taken back, and
            // its capture started again).
            if let Some(t) = self.flipbook.waiting_time(self.doc.scene())
                && t != self.doc.scene().time
            {
                self.doc.set_time(t);
                if self.flipbook_capture.is_none() {
                    self.viewport.cancel_capture();
                    self.flipbook_capture = Some((self.flipbook.size().0, 0));
                }
            }
            // The capture's pixels, once the asked frame's came back (only the flipbook asks
            // for captures while it runs: a PNG export stops caching first, and none starts
            // during a recording). One that came back while another is asked or under way
            // (the time was moved meanwhile) is dropped: nobody else may take it.
            let arrived = self.viewport.captured.take();
            let captured =
                if self.flipbook_capture.is_none() && self.viewport.capture_progress().is_none() {
                    arrived.map(|(_, pixels)| pixels)
                } else {
                    None
                };
            let ask = self.flipbook.step(ctx, self.doc.scene(), captured);
            if let Some(t) = ask.time {
                self.doc.set_time(t);
            }
            if let Some(size) = ask.capture {
                self.flipbook_capture = Some((size, 0));
            }
            if let Some(said) = ask.say {
                self.notices.note(now, said);
            }
            if let Some(recorded) = ask.recorded {
                self.panels
                    .export
                    .recorded(recorded, &mut self.notices, now);
            }
            // Asked once the view has derived the frame's time (a simulation caught up).
            if let Some((size, waited)) = self.flipbook_capture {
                if waited >= 1 && !self.viewport.stats.catching_up {
                    let transparent = self.flipbook.size().1;
                    self.viewport.capture_request = Some((size, transparent));
                    self.flipbook_capture = None;
                } else {
                    self.flipbook_capture = Some((size, waited + 1));
                }
            }
            ctx.request_repaint();
        }
        self.viewport.caching = self.flipbook.building();
        self.viewport.recording = self.flipbook.recording();
        if self.flipbook.building() {
            self.viewport.flipbook = self.flipbook.latest().cloned();
            self.flipbook.showing = false;
            return;
        }
        let shown = (self.panels.timeline.playing && !self.viewport.capturing())
            .then(|| {
                self.flipbook
                    .frame(self.doc.scene(), self.viewport.stats.viewport_px)
                    .cloned()
            })
            .flatten();
        self.flipbook.showing = shown.is_some();
        if shown.is_some() {
            self.flipbook.shown += 1;
        }
        self.viewport.flipbook = shown;
    }

    /// Stops caching, if it runs, back at the time it began from.
    fn stop_caching(&mut self, now: f64, why: &str) {
        if self.flipbook.building() && !self.flipbook.recording() && self.end_frames() {
            self.notices.note(now, why);
        }
    }

    /// Ends the caching or recording under way, if one is, back at the time it began from;
    /// returns whether one was.
    fn end_frames(&mut self) -> bool {
        let Some(t) = self.flipbook.cancel() else {
            return false;
        };
        self.flipbook_capture = None;
        // A frame's capture finished or under way is the cache's: nobody else takes it.
        self.viewport.captured = None;
        self.viewport.cancel_capture();
        self.doc.set_time(t);
        true
    }

    /// The timeline under the view, or the button that shows it again.
    fn timeline_strip(&mut self, ui: &mut egui::Ui, ctx: &egui::Context) {
        let now = ctx.input(|i| i.time);
        // (Also while the strip is hidden: the page state reports the Record button.)
        self.panels.timeline.record_progress = self.panels.export.recording();
        self.panels.timeline.record_blocked = self.panels.export.running();
        if !self.panels.timeline.open {
            self.panels.timeline.hovered = false;
            egui::Area::new(egui::Id::unique("show timeline"))
                .anchor(egui::Align2::LEFT_BOTTOM, egui::vec2(8.0, -8.0))
                .show(ctx, |ui| {
                    let r = ui
                        .button("Timeline")
                        .on_hover_text("Show the timeline: play, scrub, keys");
                    super::widgets::mark(ui, "timeline:toggle", r.rect);
                    if r.clicked() {
                        self.panels.timeline.open = true;
                    }
                });
            return;
        }
        let height = self.panels.timeline.fit(ui.available_width());
        egui::Panel::bottom("timeline")
            .resizable(false)
            .exact_size(height)
            .show(ui, |ui| {
                ui.add_space(2.0);
                // A recording's progress is the Export group's.
                self.panels.timeline.cache_progress = self
                    .flipbook
                    .progress()
                    .filter(|_| !self.flipbook.recording());
                self.panels.timeline.cache_kept = self.flipbook.kept().0;
                if let Some(said) = self.panels.timeline.ui(ui, &mut self.doc, &self.selection) {
                    self.notices.note(now, said);
                }
                ui.add_space(2.0);
            });
        // Record and its Stop are the Export group's recording.
        if std::mem::take(&mut self.panels.timeline.record_asked) {
            let ask = self.panels.export.record(
                &self.doc,
                self.viewport.stats.viewport_px,
                &self.files.name,
            );
            self.export_asked(ask, now);
        }
        if std::mem::take(&mut self.panels.timeline.record_cancel) {
            let ask = self.panels.export.cancel(&mut self.notices, now);
            self.export_asked(ask, now);
        }
        self.selection.retain_valid(self.doc.scene());
    }

    /// Applies the host's edits (see [`Host::take_edits`]); a bad one is a notice.
    fn host_edits(&mut self, ctx: &egui::Context) {
        let Some(host) = self.host.as_mut() else {
            return;
        };
        let now = ctx.input(|i| i.time);
        for assignment in host.take_edits() {
            match crate::scene::set_by_pointer(self.doc.scene(), &assignment) {
                Ok((scene, _)) => {
                    self.doc.apply(Edit::Replace(Box::new(scene)), None);
                }
                Err(e) => self.notices.error(now, e.to_string()),
            }
        }
    }

    /// Files that arrived (dropped, picked, read): scene files open, pictures go to the guide;
    /// and links pasted into the address bar open.
    fn arrivals(&mut self, ctx: &egui::Context) {
        let dropped = ctx.input_mut(|i| std::mem::take(&mut i.raw.dropped_files));
        let mut loaded: Vec<super::guide::Loaded> = dropped
            .into_iter()
            .filter_map(|f| super::platform::read_dropped(f, ctx))
            .collect();
        loaded.extend(super::platform::take_loaded());
        let now = ctx.input(|i| i.time);
        let (mut scenes, pictures): (Vec<_>, Vec<_>) = loaded.into_iter().partition(|item| {
            item.as_ref()
                .is_ok_and(|(name, bytes)| crate::share::file::is_scene_file(name, bytes))
        });
        scenes.extend(super::platform::take_scene_files());
        for item in scenes {
            match item {
                Ok((name, bytes)) => {
                    let cx = (&mut self.doc, &mut self.selection, &mut self.notices);
                    self.files.open(cx, now, &name, &bytes);
                }
                Err(e) => self.notices.error(now, format!("Nothing opened: {e}")),
            }
        }
        self.guide
            .input(ctx, &mut self.doc, &mut self.notices, pictures);
        for url in super::platform::take_links() {
            let cx = (&mut self.doc, &mut self.selection, &mut self.notices);
            self.files.open_link(cx, now, &url);
        }
    }

    /// Writes the document to the platform's store a second after it last changed.
    fn autosave(&mut self, ctx: &egui::Context) {
        let Some(autosave) = self.autosave.as_mut() else {
            return;
        };
        let now = ctx.input(|i| i.time);
        if let Some(groups) = super::widgets::take_changed_groups(ctx)
            && let Err(e) = super::platform::store_groups(&groups.to_json())
        {
            self.notices
                .error(now, format!("The panel's layout was not kept: {e}"));
        }
        if let Some(json) = autosave.due(&self.doc, now)
            && let Some(message) = autosave.written(super::platform::store_autosave(&json))
        {
            self.notices.error(now, message);
        }
        if let Some(wait) = autosave.pending(now) {
            ctx.request_repaint_after(std::time::Duration::from_secs_f64(wait + 0.05));
        }
    }

    fn publish(&mut self, ctx: &egui::Context) {
        let widgets = super::widgets::take_marks(ctx);
        let Some(host) = self.host.as_mut() else {
            return;
        };
        let stats = &self.viewport.stats;
        let backend = stats.backend.clone().unwrap_or(BackendInfo {
            backend: "none",
            adapter: String::new(),
            slices: "none",
            on_cpu: false,
        });
        let quality = stats.shown.map(|q| q.to_string()).unwrap_or_default();
        // The document is serialised again only when a revision changed.
        let revision = self.doc.revisions().any();
        if self.published.as_ref().is_none_or(|(r, _)| *r != revision) {
            // Without the reference image's bytes (up to megabytes, for every change).
            let mut scene = self.doc.scene().clone();
            if let Some(r) = &mut scene.reference {
                std::sync::Arc::make_mut(r).data = Default::default();
            }
            let json = serde_json::to_string(&scene).unwrap_or_default();
            self.published = Some((revision, json));
        }
        let scene_json = self
            .published
            .as_ref()
            .map(|(_, json)| json.as_str())
            .unwrap_or("null");
        let mut view = serde_json::json!({
            "viewport": stats.viewport_px,
            "quality": quality,
            "frame_ms": stats.frame_seconds.map(|s| (s * 1000.0).round()),
            "cpu_ms": self.cpu_seconds.map(|s| (s * 1000.0).round()),
            "refining": stats.refining,
            "geometry_update": stats.geometry_update.map(|g| serde_json::json!({
                "count": g.count, "ms": g.ms, "texels": g.texels, "of": g.of,
            })),
            "backend": backend.backend,
            "adapter": backend.adapter,
            "slices": backend.slices,
            "undo": self.doc.undo_len(),
            "redo": self.doc.redo_len(),
            "tool": self.tool.tool.name(),
            "selected_plane": self.selection.plane(),
            "selected_ellipsoid": self.selection.ellipsoid(),
            "selected_planes": self.selection.items().iter().filter_map(|i| i.plane()).collect::<Vec<_>>(),
            "selected_ellipsoids": self.selection.items().iter().filter_map(|i| i.ellipsoid()).collect::<Vec<_>>(),
            "gizmo": self.tool.gizmo(&self.doc, &self.selection, self.viewport.rect).map(|g| {
                let at = |p: Option<egui::Pos2>| p.map(|p| [p.x, p.y]);
                serde_json::json!({
                    "center": [g.center.x, g.center.y],
                    "x": at(g.handle_end(Axis::X)),
                    "y": at(g.handle_end(Axis::Y)),
                    "z": at(g.handle_end(Axis::Z)),
                })
            }),
            "sun_handle": super::sun_handle::orb(self.viewport.rect).filter(|_| !self.tool.hide_guides).map(|(c, r)| {
                serde_json::json!({ "center": [c.x, c.y], "radius": r })
            }),
            "widgets": widgets,
            "sun": [self.doc.scene().light.sun_azimuth_deg, self.doc.scene().light.sun_elevation_deg],
            "export": {
                "format": self.panels.export.format.name(),
                "transparent": self.panels.export.transparent,
                "range": self.panels.export.range,
                "png_width": self.panels.export.png_width,
                "progress": self.panels.export.progress(),
                "last": self.panels.export.last.as_ref().map(|r| match r {
                    Ok(names) => serde_json::json!({ "files": names }),
                    Err(e) => serde_json::json!({ "error": e }),
                }),
            },
            "axis_lock": self.tool.axis_lock.map(|a| a.name()),
            "modal": self.tool.modal_state().map(|(kind, axis, typed)| serde_json::json!({
                "kind": kind.name(), "axis": axis.map(|a| a.name()), "typed": typed,
            })),
            "behind": self.tool.behind(),
            "playing": self.panels.timeline.playing,
            "guides_hidden": self.tool.hide_guides,
            "skeleton_shown": self.tool.show_skeleton,
            "panel_open": self.panel_open,
            "groups_open": super::widgets::open_groups(ctx),
            "my_presets": self.panels.scene.looks.looks.iter().map(|l| l.name.as_str()).collect::<Vec<_>>(),
            "file": self.files.name,
            "unsaved": self.files.unsaved(&self.doc),
            "link": self.files.last_link,
            "guide_image": self.doc.scene().reference.as_deref().map(|g| serde_json::json!({
                "name": g.name, "size": g.size, "opacity": g.opacity, "visible": g.visible,
                "in_front": g.in_front, "embedded": g.embedded(),
            })),
            "guide_error": self.guide.error,
            "notice": self.notices.latest.as_ref().map(|n| serde_json::json!({"text": n.text, "error": n.error})),
        });
        // Frames drawn and volume jobs planned so far: how many a refinement or an export took.
        view["frames"] = ctx.cumulative_frame_nr().into();
        view["jobs"] = stats.jobs.into();
        view["late"] = stats.late.into();
        view["cost"] = stats.cost.into();
        view["puffs_left_out"] = stats.puffs_left_out.into();
        view["catching_up"] = stats.catching_up.into();
        view["light_preview"] = serde_json::json!(stats.light_preview);
        view["timeline"] = super::panels::timeline_state(&self.panels.timeline, &self.doc);
        view["timeline"]["cache"] = self.flipbook.state();
        view["through_shot"] = self.panels.view.through_shot.into();
        let state = format!("{{\"scene\":{scene_json},\"view\":{view}}}");
        let status = PageStatus {
            ready: self.viewport.ready,
            backend: backend.backend.to_string(),
            adapter: backend.adapter,
            quality,
            state,
        };
        if self.last_status.as_ref() != Some(&status) {
            host.publish(&status);
            self.last_status = Some(status);
        }
        if let Some(status) = &self.last_status {
            host.end_frame(ctx, status);
        }
    }
}

impl eframe::App for CloudApp {
    /// Keys that would press a button the user is not looking at: Tab means nothing here (as
    /// in Blender it is no focus key), and while the pointer is over the view no widget keeps
    /// the keyboard, so Space and Enter press nothing and the view's shortcuts always work.
    ///
    /// A click held across a slow frame still clicks ([`super::click_timing`]).
    fn raw_input_hook(&mut self, ctx: &egui::Context, raw: &mut egui::RawInput) {
        use egui::{Event, Key};
        super::click_timing::apply(&mut self.held, ctx, raw);
        raw.events
            .retain(|e| !matches!(e, Event::Key { key: Key::Tab, .. }));
        let over_view = ctx
            .pointer_hover_pos()
            .is_some_and(|p| self.viewport.rect.contains(p));
        if over_view {
            ctx.memory_mut(|m| {
                if let Some(id) = m.focused() {
                    m.surrender_focus(id);
                }
            });
            // During a modal G, R or S, Enter confirms it.
            let modal = self.tool.modal_active();
            raw.events.retain(|e| match e {
                Event::Key {
                    key: Key::Space, ..
                } => false,
                Event::Key {
                    key: Key::Enter, ..
                } => modal,
                _ => true,
            });
        }
    }

    fn clear_color(&self, _visuals: &egui::Visuals) -> [f32; 4] {
        // The flat background as it shows at the document's exposure, sRGB-encoded like
        // egui's colours (as picked at exposure 0: the one tone map, `render::tone`).
        let light = &self.doc.scene().light;
        let [r, g, b] = crate::render::tone::background_display(light.background, light.exposure);
        [r, g, b, 1.0]
    }

    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.cpu_seconds = frame.info().cpu_usage;
        let ctx = ui.ctx().clone();
        let pressed = super::shortcuts::take(&ctx, self.tool.modal_active());
        self.shortcuts(&ctx, &pressed.before_pointer);
        // Playing follows the wall clock (egui's stable dt is a prediction after each wait).
        let wall = ctx.input(|i| i.time);
        let dt = self.last_tick.map_or(0.0, |t| (wall - t) as f32);
        self.last_tick = self.panels.timeline.playing.then_some(wall);
        if self.panels.timeline.tick(&mut self.doc, dt) {
            ctx.request_repaint();
        }
        self.arrivals(&ctx);
        self.host_edits(&ctx);
        self.panels.view.follow_shot(&mut self.doc);
        self.panels.timeline.shot_view = self.panels.view.through_shot;
        let now = ctx.input(|i| i.time);
        if self.panels.export.step(&mut self.notices, now) {
            ctx.request_repaint();
        }
        self.cache_frames(&ctx, now);
        let capture = self.viewport.capture_progress().unwrap_or(0.0);
        self.panels.export.capture_progress = match self.flipbook.progress() {
            Some((done, of)) if self.flipbook.recording() => {
                (done as f32 + capture) / of.max(1) as f32
            }
            _ => capture,
        };
        if let Some((size, pixels)) = self.viewport.captured.take() {
            self.panels
                .export
                .captured(size, pixels, &mut self.notices, now);
        }
        // Fixed width: growing values never shift the buttons under the pointer. With a
        // renderer, the panel's background is its flat fill (`FillPaint`, painted under the
        // panel in a slot kept before it), not egui's.
        let mut open = self.panel_open;
        let own_fill = self.viewport.stats.backend.is_some();
        let fill_slot = own_fill.then(|| ui.painter().add(egui::Shape::Noop));
        let frame = egui::Frame::side_top_panel(ui.style());
        let colour = frame.fill;
        let shown = egui::Panel::right("controls")
            .frame(if own_fill {
                frame.fill(egui::Color32::TRANSPARENT)
            } else {
                frame
            })
            .resizable(false)
            .exact_size(PANEL_WIDTH)
            .show_collapsible(ui, &mut open, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    self.side_panel(ui);
                    // Room under the last group, so scrolled to the end its header stands clear
                    // of the window's edge.
                    ui.add_space(16.0);
                });
            });
        if let (Some(slot), Some(shown)) = (fill_slot, shown) {
            ui.painter().set(
                slot,
                paint_callback(shown.response.rect, FillPaint { colour }),
            );
        }
        self.panel_open &= open;
        if !self.panel_open {
            egui::Area::new(egui::Id::unique("show panel"))
                .anchor(egui::Align2::RIGHT_TOP, egui::vec2(-8.0, 8.0))
                .show(&ctx, |ui| {
                    if ui
                        .button("« panel")
                        .on_hover_text("N: show the side panel")
                        .clicked()
                    {
                        self.panel_open = true;
                    }
                });
        }
        self.timeline_strip(ui, &ctx);
        egui::CentralPanel::no_frame().show(ui, |ui| {
            self.viewport.show(
                ui,
                ViewportContext {
                    cx: ToolContext {
                        doc: &mut self.doc,
                        derived: &mut self.derived,
                        selection: &mut self.selection,
                        notices: &mut self.notices,
                    },
                    tool: &mut self.tool,
                    guide: &mut self.guide,
                },
            )
        });
        // Keys pressed after a pointer button in this frame act once the view has taken it.
        self.shortcuts(&ctx, &pressed.after_pointer);
        // A modal transform's edits fold into one step until it is confirmed.
        if !ctx.input(|i| i.pointer.any_down()) && !self.tool.modal_active() {
            self.doc.end_merge();
        }
        self.autosave(&ctx);
        self.publish(&ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Preset;
    use egui::{Event, Key, Modifiers, RawInput};

    /// The app without a renderer, saving to `file`, after two edits: the stratus preset
    /// opened over the empty scene, then the cumulus over that.
    fn app_with_two_edits(ctx: &egui::Context, file: &std::path::Path) -> CloudApp {
        let cc = eframe::CreationContext::_new_kittest(ctx.clone());
        let mut app = CloudApp::new(
            &cc,
            StartOptions {
                scene: Scene::preset(Preset::Empty),
                file: Some(file.display().to_string()),
                ..Default::default()
            },
        );
        for preset in [Preset::Stratus, Preset::Cumulus] {
            app.doc
                .apply(Edit::Replace(Box::new(Scene::preset(preset))), None);
        }
        app
    }

    /// Runs one frame of the real app holding these key presses.
    fn frame(ctx: &egui::Context, app: &mut CloudApp, keys: &[(Modifiers, Key)]) {
        let events = keys
            .iter()
            .map(|&(modifiers, key)| Event::Key {
                key,
                physical_key: None,
                pressed: true,
                repeat: false,
                modifiers,
            })
            .collect();
        let raw = RawInput {
            screen_rect: Some(crate::ui::test_view()),
            events,
            ..Default::default()
        };
        let mut eframe_frame = eframe::Frame::_new_kittest();
        let mut output = ctx.run_ui(raw, |ui| eframe::App::ui(app, ui, &mut eframe_frame));
        output.textures_delta.clear();
    }

    fn saved(file: &std::path::Path) -> Scene {
        Scene::from_json(&std::fs::read_to_string(file).unwrap())
            .unwrap()
            .0
    }

    #[test]
    fn shortcuts_in_one_frame_act_in_the_order_they_were_pressed() {
        let dir = std::env::temp_dir().join(format!("cloudsketch-keys-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("keys.json");
        let (z, s) = ((Modifiers::COMMAND, Key::Z), (Modifiers::COMMAND, Key::S));
        let stratus = Scene::preset(Preset::Stratus);
        let cumulus = Scene::preset(Preset::Cumulus);

        // Ctrl+Z then Ctrl+S: what is saved is the undone scene.
        let ctx = egui::Context::default();
        let mut app = app_with_two_edits(&ctx, &file);
        frame(&ctx, &mut app, &[z, s]);
        assert_eq!(
            saved(&file).ellipsoids,
            stratus.ellipsoids,
            "undo, then save"
        );
        assert_eq!(app.doc.scene().ellipsoids, stratus.ellipsoids);

        // Ctrl+S then Ctrl+Z: the saved scene is the one before the undo.
        let ctx = egui::Context::default();
        let mut app = app_with_two_edits(&ctx, &file);
        frame(&ctx, &mut app, &[s, z]);
        assert_eq!(
            saved(&file).ellipsoids,
            cumulus.ellipsoids,
            "save, then undo"
        );
        assert_eq!(app.doc.scene().ellipsoids, stratus.ellipsoids);

        // Two presses of Ctrl+Z undo twice.
        let ctx = egui::Context::default();
        let mut app = app_with_two_edits(&ctx, &file);
        frame(&ctx, &mut app, &[z, z, s]);
        assert!(app.doc.scene().ellipsoids.is_empty(), "both edits undone");
        assert!(saved(&file).ellipsoids.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Runs one frame of the real app with these raw events, through its input hook as eframe
    /// runs it.
    fn frame_events(ctx: &egui::Context, app: &mut CloudApp, events: Vec<Event>) {
        let mut raw = RawInput {
            screen_rect: Some(crate::ui::test_view()),
            events,
            ..Default::default()
        };
        eframe::App::raw_input_hook(app, ctx, &mut raw);
        let mut eframe_frame = eframe::Frame::_new_kittest();
        let mut output = ctx.run_ui(raw, |ui| eframe::App::ui(app, ui, &mut eframe_frame));
        output.textures_delta.clear();
    }

    fn press(key: Key) -> Event {
        Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers: Modifiers::NONE,
        }
    }

    #[test]
    fn modal_grab_with_a_lock_and_a_typed_distance_then_esc_puts_it_back_exactly() {
        let dir = std::env::temp_dir().join(format!("cloudsketch-modal-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ctx = egui::Context::default();
        let mut app = app_with_two_edits(&ctx, &dir.join("modal.json"));
        app.selection
            .set(super::super::selection::Item::Ellipsoid(0));
        let before = app.doc.scene().ellipsoids.clone();
        let undo = app.doc.undo_len();
        let at = |x: f32, y: f32| Event::PointerMoved(egui::pos2(x, y));
        frame_events(&ctx, &mut app, vec![at(900.0, 400.0)]);
        // G, the mouse moving, X, "2", the mouse again, Enter: all in two frames.
        frame_events(
            &ctx,
            &mut app,
            vec![press(Key::G), at(940.0, 420.0), at(980.0, 380.0)],
        );
        assert!(app.tool.modal_active());
        assert_ne!(
            app.doc.scene().ellipsoids,
            before,
            "the grab follows the mouse"
        );
        frame_events(
            &ctx,
            &mut app,
            vec![
                press(Key::X),
                press(Key::Num2),
                at(1000.0, 300.0),
                press(Key::Enter),
            ],
        );
        assert!(!app.tool.modal_active(), "Enter confirms");
        let moved = &app.doc.scene().ellipsoids;
        assert_eq!(
            moved[0].center,
            before[0].center + glam::Vec3::new(2.0, 0.0, 0.0)
        );
        assert_eq!(moved[1..], before[1..], "only the selection moves");
        frame_events(&ctx, &mut app, vec![]);
        assert_eq!(app.doc.undo_len(), undo + 1, "one undo step");

        // G, a move, Esc: back exactly, no new step; then Ctrl+Z undoes the confirmed grab.
        let confirmed = app.doc.scene().ellipsoids.clone();
        frame_events(&ctx, &mut app, vec![press(Key::G), at(700.0, 600.0)]);
        frame_events(&ctx, &mut app, vec![at(650.0, 640.0), press(Key::Escape)]);
        assert!(!app.tool.modal_active());
        assert_eq!(app.doc.scene().ellipsoids, confirmed);
        assert_eq!(app.doc.undo_len(), undo + 1);
        frame(&ctx, &mut app, &[(Modifiers::COMMAND, Key::Z)]);
        assert_eq!(app.doc.scene().ellipsoids, before);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn no_text_of_the_side_panel_runs_past_its_edge() {
        // Every group open, a drawing plane and an ellipsoid selected (their controls shown),
        // at the window sizes people have: each piece of text the panel draws lies within its
        // clip (the panel), else the label is cut at the edge.
        let titles = [
            "Sketch",
            "Reference image",
            "Render",
            "Light",
            "Scene",
            "View",
            "Simulation",
            "Export",
        ];
        let open: std::collections::BTreeMap<&str, bool> =
            titles.iter().map(|t| (*t, true)).collect();
        let json = serde_json::json!({ "open": open }).to_string();
        for size in [egui::vec2(1280.0, 800.0), egui::vec2(1920.0, 1080.0)] {
            let ctx = egui::Context::default();
            let dir = std::env::temp_dir().join(format!("cloudsketch-edge-{}", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            let cc = eframe::CreationContext::_new_kittest(ctx.clone());
            let mut app = CloudApp::new(
                &cc,
                StartOptions {
                    scene: Scene::preset(Preset::Cumulus),
                    file: Some(dir.join("edge.json").display().to_string()),
                    ..Default::default()
                },
            );
            let mut scene = Scene::preset(Preset::Cumulus);
            let plane = crate::share::fixture::every_part().planes[0].clone();
            scene.planes.push(plane);
            app.doc.apply(Edit::Replace(Box::new(scene)), None);
            app.selection.set(super::super::selection::Item::Plane(0));
            app.selection
                .toggle(super::super::selection::Item::Ellipsoid(0));
            super::super::widgets::install_groups(
                &ctx,
                super::super::widgets::Groups::from_json(&json),
            );
            let mut cut = Vec::new();
            // The panel is scrolled through (egui draws only what is in view), and the nested
            // groups (the media, the tiers) open by a click on their headers, as a person opens
            // them: each header is found in the frame before, clicked in a frame of its own.
            let mut clicks: Vec<egui::Pos2> = Vec::new();
            let mut opened = Vec::new();
            let over_panel = egui::pos2(size.x - 150.0, size.y * 0.5);
            let mut seen_last_group = false;
            for frame in 0..100 {
                let mut events = vec![Event::PointerMoved(over_panel)];
                if let Some(pos) = clicks.pop() {
                    let button = |pressed| Event::PointerButton {
                        pos,
                        button: egui::PointerButton::Primary,
                        pressed,
                        modifiers: Modifiers::NONE,
                    };
                    events = vec![Event::PointerMoved(pos), button(true), button(false)];
                } else if frame % 2 == 1 {
                    events.push(Event::MouseWheel {
                        unit: egui::MouseWheelUnit::Point,
                        delta: egui::vec2(0.0, -300.0),
                        modifiers: Modifiers::NONE,
                        phase: egui::TouchPhase::Move,
                        source: egui::MouseWheelSource::Wheel,
                    });
                }
                let raw = RawInput {
                    screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, size)),
                    time: Some(frame as f64 * 0.1),
                    events,
                    ..Default::default()
                };
                let mut eframe_frame = eframe::Frame::_new_kittest();
                let mut output =
                    ctx.run_ui(raw, |ui| eframe::App::ui(&mut app, ui, &mut eframe_frame));
                output.textures_delta.clear();
                for clipped in &output.shapes {
                    let egui::epaint::Shape::Text(text) = &clipped.shape else {
                        continue;
                    };
                    let r = text.visual_bounding_rect();
                    let words = text.galley.text();
                    seen_last_group |= words == "noise media as shown";
                    for header in ["Media:", "Tiers ("] {
                        if words.starts_with(header)
                            && !opened.contains(&header)
                            && r.max.y < size.y - 20.0
                        {
                            opened.push(header);
                            clicks.push(r.center());
                        }
                    }
                    // Text of the side panel (the view's own lines are centred over it).
                    if clipped.clip_rect.min.x > size.x * 0.5
                        && r.max.x > clipped.clip_rect.max.x + 0.5
                        && !cut.iter().any(|(t, _, _)| t == words)
                    {
                        cut.push((words.to_owned(), r.max.x, clipped.clip_rect.max.x));
                    }
                }
            }
            assert_eq!(
                super::super::widgets::open_groups(&ctx).len(),
                titles.len(),
                "every group open"
            );
            assert_eq!(opened.len(), 2, "the media and tiers headers clicked");
            assert!(seen_last_group, "scrolled down to the Export group's body");
            assert!(
                cut.is_empty(),
                "at {size:?}, text cut at the panel's edge: {cut:?}"
            );
            std::fs::remove_dir_all(&dir).ok();
        }
    }
}
