//! The View group: what the viewport is drawing, and how fast.

use egui::Ui;

use crate::render::progressive::Quality;
use crate::render::viewport::BackendInfo;
use crate::scene::{Document, StandardView};

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

/// The View group.
#[derive(Default)]
pub struct ViewPanel;

impl ViewPanel {
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
