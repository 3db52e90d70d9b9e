//! The Render group: quality and the cloud's media.

use egui::Ui;

use crate::limits;
use crate::scene::{Document, Edit};
use crate::ui::widgets::{param_f32, param_u32};

/// The Render group.
#[derive(Default)]
pub struct RenderPanel;

impl RenderPanel {
    /// Draws the group; each change is an undoable edit (a slider drag is one step).
    pub fn ui(&mut self, ui: &mut Ui, doc: &mut Document) {
        egui::CollapsingHeader::new("Render")
            .default_open(true)
            .show(ui, |ui| {
                let mut r = doc.scene().render.clone();
                param_u32(ui, &mut r.slices, &limits::SLICES, "quality (slices)",
                    "Slices through the cloud at full quality: more is smoother and slower");
                param_f32(ui, &mut r.opacity, &limits::OPACITY, "opacity",
                    "How much light the cloud's body stops");
                param_f32(ui, &mut r.softness, &limits::SOFTNESS, "edge softness",
                    "Width of the cloud's soft edge");
                param_f32(ui, &mut r.noise_amount, &limits::NOISE_AMOUNT, "noise amount",
                    "How far the noise breaks up the cloud's surface");
                param_f32(ui, &mut r.noise_scale, &limits::NOISE_SCALE, "noise size",
                    "Size of the largest noise puffs, in world units");
                param_u32(ui, &mut r.noise_octaves, &limits::OCTAVES, "octaves",
                    "Layers of finer and finer noise");
                param_f32(ui, &mut r.detail, &limits::DETAIL, "detail (lacunarity)",
                    "How much finer each noise layer is than the one before");
                param_u32(ui, &mut r.field_resolution, &limits::FIELD_RESOLUTION, "field grid",
                    "Resolution of the grid the cloud's shape is sampled on: finer shows smaller features, costs more after each edit");
                if r != doc.scene().render {
                    doc.apply(Edit::SetRender(r), Some("render"));
                }
            });
    }
}
