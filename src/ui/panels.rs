//! The side panel: collapsible groups of controls, each change an undoable edit.

use egui::{Slider, Ui};

use super::app::CloudApp;
use crate::scene::{Edit, Preset, Scene, limits};

fn srgb_button(ui: &mut Ui, label: &str, color: &mut [f32; 3]) -> bool {
    let mut bytes = color.map(|v| (v * 255.0).round() as u8);
    let before = bytes;
    ui.horizontal(|ui| {
        ui.color_edit_button_srgb(&mut bytes);
        ui.label(label);
    });
    if bytes != before {
        *color = bytes.map(|v| v as f32 / 255.0);
        true
    } else {
        false
    }
}

impl CloudApp {
    /// Draws the side panel.
    pub(super) fn side_panel(&mut self, ui: &mut Ui) {
        ui.heading("cloudsketch");
        ui.horizontal(|ui| {
            if ui
                .add_enabled(self.history.undo_len() > 0, egui::Button::new("⟲ Undo"))
                .on_hover_text("Ctrl+Z")
                .clicked()
            {
                self.history.undo(&mut self.scene);
            }
            if ui
                .add_enabled(self.history.redo_len() > 0, egui::Button::new("⟳ Redo"))
                .on_hover_text("Ctrl+Shift+Z")
                .clicked()
            {
                self.history.redo(&mut self.scene);
            }
            if ui
                .button("Frame")
                .on_hover_text("F: frame the cloud")
                .clicked()
            {
                self.frame_request = true;
            }
        });
        ui.separator();
        self.sketch_group(ui);
        self.guide_group(ui);
        self.render_group(ui);
        self.light_group(ui);
        self.scene_group(ui);
        self.view_group(ui);
    }

    fn render_group(&mut self, ui: &mut Ui) {
        egui::CollapsingHeader::new("Render")
            .default_open(true)
            .show(ui, |ui| {
                let mut r = self.scene.render.clone();
                ui.add(
                    Slider::new(&mut r.slices, limits::SLICES.0..=limits::SLICES.1)
                        .logarithmic(true)
                        .text("quality (slices)"),
                );
                ui.add(
                    Slider::new(&mut r.opacity, 0.0..=20.0)
                        .logarithmic(true)
                        .text("opacity"),
                );
                ui.add(Slider::new(&mut r.softness, 0.01..=0.5).text("edge softness"));
                ui.add(Slider::new(&mut r.noise_amount, 0.0..=1.0).text("noise amount"));
                ui.add(
                    Slider::new(&mut r.noise_scale, 0.2..=50.0)
                        .logarithmic(true)
                        .text("noise size"),
                );
                ui.add(
                    Slider::new(&mut r.noise_octaves, limits::OCTAVES.0..=limits::OCTAVES.1)
                        .text("octaves"),
                );
                ui.add(Slider::new(&mut r.detail, 1.1..=4.0).text("detail (lacunarity)"));
                ui.add(
                    Slider::new(
                        &mut r.field_resolution,
                        limits::FIELD_RESOLUTION.0..=limits::FIELD_RESOLUTION.1,
                    )
                    .text("field grid"),
                );
                if r != self.scene.render {
                    self.apply(Edit::SetRender(r), Some("render"));
                }
            });
    }

    fn light_group(&mut self, ui: &mut Ui) {
        egui::CollapsingHeader::new("Light")
            .default_open(true)
            .show(ui, |ui| {
                let mut l = self.scene.light.clone();
                ui.add(Slider::new(&mut l.sun_azimuth_deg, 0.0..=360.0).text("sun azimuth °"));
                ui.add(Slider::new(&mut l.sun_elevation_deg, -89.0..=89.0).text("sun elevation °"));
                ui.add(Slider::new(&mut l.sun_intensity, 0.0..=5.0).text("sun intensity"));
                ui.add(Slider::new(&mut l.ambient, 0.0..=2.0).text("ambient"));
                srgb_button(ui, "sun colour", &mut l.sun_color);
                srgb_button(ui, "sky colour", &mut l.sky_color);
                srgb_button(ui, "background", &mut l.background);
                if l != self.scene.light {
                    self.apply(Edit::SetLight(l), Some("light"));
                }
            });
    }

    fn scene_group(&mut self, ui: &mut Ui) {
        egui::CollapsingHeader::new("Scene")
            .default_open(true)
            .show(ui, |ui| {
                ui.horizontal(|ui| {
                    for (preset, label) in [
                        (Preset::Cumulus, "New cumulus"),
                        (Preset::Empty, "New empty"),
                    ] {
                        if ui.button(label).clicked() {
                            let mut scene = Scene::preset(preset);
                            scene.camera = self.scene.camera.clone();
                            self.apply(Edit::Replace(Box::new(scene)), None);
                        }
                    }
                });
                ui.label(format!("{} ellipsoids", self.scene.ellipsoids.len()));
            });
    }

    fn view_group(&mut self, ui: &mut Ui) {
        egui::CollapsingHeader::new("View")
            .default_open(false)
            .show(ui, |ui| {
                match &self.backend {
                    Some(b) => ui.label(format!("backend: {}\nadapter: {}", b.backend, b.adapter)),
                    None => ui.colored_label(egui::Color32::LIGHT_RED, "no GPU renderer"),
                };
                if let Some(q) = self.shown {
                    ui.label(format!("volume: {q} (width × height × slices)"));
                }
                if let Some(p) = self.refining {
                    ui.add(egui::ProgressBar::new(p).text("refining"));
                }
                if let Some(s) = self.frame_seconds {
                    ui.label(format!("last volume frame: {:.0} ms", s * 1000.0));
                }
                ui.label(format!(
                    "viewport: {}×{} px",
                    self.viewport_px[0], self.viewport_px[1]
                ));
                ui.small("Drag: orbit · Shift/right/middle drag: pan · wheel: zoom · F: frame");
            });
    }
}
