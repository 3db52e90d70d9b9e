//! The Light group: sun, sky and background.

use egui::Ui;

use crate::limits;
use crate::scene::{Document, Edit};
use crate::ui::widgets::{param_f32, srgb_button};

/// The Light group.
#[derive(Default)]
pub struct LightPanel;

impl LightPanel {
    /// Draws the group; each change is an undoable edit.
    pub fn ui(&mut self, ui: &mut Ui, doc: &mut Document) {
        egui::CollapsingHeader::new("Light")
            .default_open(true)
            .show(ui, |ui| {
                let mut l = doc.scene().light.clone();
                param_f32(ui, &mut l.sun_azimuth_deg, &limits::SUN_AZIMUTH, "sun azimuth °",
                    "Compass direction the sunlight comes from");
                param_f32(ui, &mut l.sun_elevation_deg, &limits::SUN_ELEVATION, "sun elevation °",
                    "Height of the sun above the horizon");
                param_f32(ui, &mut l.sun_intensity, &limits::SUN_INTENSITY, "sun intensity",
                    "Brightness of direct sunlight");
                param_f32(ui, &mut l.ambient, &limits::AMBIENT, "ambient",
                    "Brightness of the sky light that fills the shadowed side");
                srgb_button(ui, "sun colour", &mut l.sun_color);
                srgb_button(ui, "sky colour", &mut l.sky_color);
                srgb_button(ui, "background", &mut l.background);
                if l != doc.scene().light {
                    doc.apply(Edit::SetLight(l), Some("light"));
                }
            });
    }
}
