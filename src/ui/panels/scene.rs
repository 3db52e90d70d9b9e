//! The Scene group: new scenes from presets.

use egui::Ui;

use crate::scene::{Document, Edit, Preset, Scene, StrokeKind};

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
                ui.label(contents(doc.scene()));
            });
    }
}

/// What a scene holds, in words: "2 outlines, 1 cut, 6 ellipsoids".
pub fn contents(scene: &Scene) -> String {
    let outlines = scene
        .planes
        .iter()
        .filter(|p| p.kind == StrokeKind::Outline)
        .count();
    let cuts = scene.planes.len() - outlines;
    let n = |count: usize, one: &str, many: &str| {
        format!("{count} {}", if count == 1 { one } else { many })
    };
    format!(
        "{}, {}, {}",
        n(outlines, "outline", "outlines"),
        n(cuts, "cut", "cuts"),
        n(scene.ellipsoids.len(), "ellipsoid", "ellipsoids")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::DrawingPlane;

    #[test]
    fn contents_counts_each_kind() {
        let mut scene = Scene::default();
        for kind in [StrokeKind::Outline, StrokeKind::Cut, StrokeKind::Outline] {
            scene.planes.push(std::sync::Arc::new(DrawingPlane {
                kind,
                ..Default::default()
            }));
        }
        assert_eq!(contents(&scene), "2 outlines, 1 cut, 6 ellipsoids");
        assert_eq!(
            contents(&Scene::preset(crate::scene::Preset::Empty)),
            "0 outlines, 0 cuts, 0 ellipsoids"
        );
    }
}
