//! The View group: what the viewport is drawing, and how fast.

use egui::Ui;

use crate::render::progressive::Quality;
use crate::render::viewport::BackendInfo;

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
    /// Viewport size in pixels.
    pub viewport_px: [u32; 2],
}

/// The View group.
#[derive(Default)]
pub struct ViewPanel;

impl ViewPanel {
    /// Draws the group.
    pub fn ui(&mut self, ui: &mut Ui, stats: &ViewStats) {
        egui::CollapsingHeader::new("View")
            .default_open(false)
            .show(ui, |ui| {
                match &stats.backend {
                    Some(b) => ui.label(format!("backend: {}\nadapter: {}", b.backend, b.adapter)),
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
