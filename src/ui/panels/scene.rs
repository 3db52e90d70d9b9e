//! The Scene group: new scenes from presets.

use egui::Ui;

use crate::scene::{Document, Edit, Preset, Scene};

/// The Scene group.
#[derive(Default)]
pub struct ScenePanel;

impl ScenePanel {
    /// Draws the group.
    pub fn ui(&mut self, ui: &mut Ui, doc: &mut Document) {
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
                            scene.camera = doc.scene().camera.clone();
                            doc.apply(Edit::Replace(Box::new(scene)), None);
                        }
                    }
                });
                ui.label(format!("{} ellipsoids", doc.scene().ellipsoids.len()));
            });
    }
}
