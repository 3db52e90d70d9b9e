//! The View group: what the viewport is drawing, and how fast.

use egui::Ui;

use crate::render::progressive::Quality;
use crate::render::viewport::BackendInfo;
use crate::scene::{Document, Edit, StandardView};

/// The standard views with their keys (the number row or the numpad; Ctrl: the opposite side).
const VIEWS: [(StandardView, &str, &str); 6] = [
    (StandardView::Front, "Front", "1"),
    (StandardView::Right, "Right", "3"),
    (StandardView::Top, "Top", "7"),
    (StandardView::Back, "Back", "Ctrl+1"),
    (StandardView::Left, "Left", "Ctrl+3"),
    (StandardView::Bottom, "Bottom", "Ctrl+7"),
];

/// What the viewport reports about itself.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewStats {
    /// The graphics backend, once known.
    pub backend: Option<BackendInfo>,
    /// Quality of the image on screen.
    pub shown: Option<Quality>,
    /// Refinement progress, while refining.
    pub refining: Option<f32>,
    /// Interval of the last frame that drew volume work, in seconds.
    pub frame_seconds: Option<f64>,
    /// How much longer refinements have taken than the planner's model predicted.
    pub late: f64,
    /// Volume jobs planned so far.
    pub jobs: u64,
    /// Viewport size in pixels.
    pub viewport_px: [u32; 2],
    /// The last geometry update of the density volume: how many there have been, its wall time
    /// in milliseconds, the texels it re-evaluated and the grid's texels.
    pub geometry_update: Option<GeometryUpdate>,
    /// Puffs the field leaves out for the cap on billows (0: none).
    pub puffs_left_out: usize,
    /// A simulation still stepping toward the scene's time (a far jump catches up over frames).
    pub catching_up: bool,
    /// The light grid and octaves the view previews at, where they are less than the
    /// document's (a CPU adapter: [`crate::limits::CPU_PREVIEW_LIGHT`]).
    pub light_preview: Option<[u32; 2]>,
    /// The planner's cost of refinement work, seconds per pixel·slice.
    pub cost: f64,
}

/// One geometry update of the density volume, as the viewport timed it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GeometryUpdate {
    /// Updates so far.
    pub count: u64,
    /// Wall time of this one (milliseconds).
    pub ms: f64,
    /// Texels it re-evaluated (the rest were copied).
    pub texels: u64,
    /// Texels of the grid.
    pub of: u64,
}

/// The View group, and whether the view looks through the shot camera.
#[derive(Default)]
pub struct ViewPanel {
    /// The view looks through the document's shot camera (numpad 0), following it as its
    /// keys move it; orbiting leaves it.
    pub through_shot: bool,
    /// The shot as the view last took it (a view that moved since was moved by the user).
    taken: Option<crate::scene::OrbitCamera>,
}

impl ViewPanel {
    /// Numpad 0: look through the shot camera, or back to the free view. Returns what to tell
    /// the user.
    pub fn toggle_shot(&mut self, doc: &Document) -> &'static str {
        if doc.scene().shot.is_none() {
            self.through_shot = false;
            return "No shot camera: View › Set shot from view makes one";
        }
        self.through_shot = !self.through_shot;
        if self.through_shot {
            "Looking through the shot camera (orbit or 0 to leave)"
        } else {
            "Free view"
        }
    }

    /// Once a frame, before the view: while looking through the shot, the camera is the
    /// shot's (posed at the document's time); a view the user moved since leaves the shot.
    pub fn follow_shot(&mut self, doc: &mut Document) {
        let shot = doc.scene().shot.clone().filter(|_| self.through_shot);
        let Some(shot) = shot else {
            self.through_shot = false;
            self.taken = None;
            return;
        };
        if self
            .taken
            .as_ref()
            .is_some_and(|taken| *taken != doc.scene().camera)
        {
            self.through_shot = false;
            self.taken = None;
            return;
        }
        doc.set_camera(shot.clone());
        self.taken = Some(shot);
    }
    /// Draws the group: standard views and the projection, then what the viewport draws.
    pub fn ui(&mut self, ui: &mut Ui, stats: &ViewStats, doc: &mut Document) {
        crate::ui::widgets::group(ui, "View", false, |ui| {
            let mut camera = doc.scene().camera.clone();
            ui.horizontal_wrapped(|ui| {
                for (view, label, key) in VIEWS {
                    if ui.button(label).on_hover_text(key).clicked() {
                        camera.set_view(view);
                    }
                }
            });
            ui.checkbox(&mut camera.orthographic, "orthographic")
                .on_hover_text("5: parallel projection, as for drawing outlines");
            doc.set_camera(camera);
            ui.horizontal_wrapped(|ui| {
                ui.label("shot:");
                let set = ui.button("Set from view").on_hover_text(
                    "The shot camera (what `cloudsketch render --shot` renders, keyable with I while looking through it) takes this view",
                );
                crate::ui::widgets::mark(ui, "shot:set", set.rect);
                if set.clicked() {
                    let view = doc.scene().camera.clone();
                    doc.apply(Edit::SetShot(Some(view.clone())), None);
                    if self.through_shot {
                        self.taken = Some(view);
                    }
                }
                let has = doc.scene().shot.is_some();
                let look = ui
                    .add_enabled(has, egui::Button::selectable(self.through_shot, "Look through"))
                    .on_hover_text("0: look through the shot camera (orbiting leaves it)");
                crate::ui::widgets::mark(ui, "shot:look", look.rect);
                if look.clicked() {
                    self.toggle_shot(doc);
                }
                if ui
                    .add_enabled(has, egui::Button::new("Clear"))
                    .on_hover_text("Remove the shot camera and its keys")
                    .clicked()
                {
                    doc.apply(Edit::SetShot(None), None);
                }
            });
            match &stats.backend {
                Some(b) => ui.label(format!(
                    "backend: {}\nadapter: {}\nslices: {}",
                    b.backend, b.adapter, b.slices
                )),
                None => ui.colored_label(egui::Color32::LIGHT_RED, "no GPU renderer"),
            };
            if let Some(q) = stats.shown {
                ui.label(format!("volume: {q} (width × height × slices)"));
            }
            if let Some(p) = stats.refining {
                ui.add(egui::ProgressBar::new(p).text("refining"));
            }
            if let Some(s) = stats.frame_seconds {
                ui.label(format!("last volume frame: {:.0} ms", s * 1000.0));
            }
            ui.label(format!(
                "viewport: {}×{} px",
                stats.viewport_px[0], stats.viewport_px[1]
            ));
            ui.small("Drag: orbit · Shift/right/middle drag: pan · wheel: zoom · F: frame");
        });
    }
}
