//! The Scene group: new scenes from presets, the user's own presets (media and lighting
//! saved under a name), what the scene holds, and its ellipsoids (a list to select from, and
//! the selected one's centre, radii and strength).

use egui::Ui;

use std::sync::Arc;

use crate::limits;
use crate::scene::{Document, Edit, Looks, Motion, Preset, Scene, StrokeKind};
use crate::ui::ellipsoids;
use crate::ui::notice::Notices;
use crate::ui::platform;
use crate::ui::selection::{Item, Selection};
use crate::ui::widgets::{mark, rotation_fields, vec3_fields};

/// The Scene group.
pub struct ScenePanel {
    /// The user's own presets, as stored by the app.
    pub looks: Looks,
    /// The name typed for the next saved preset.
    look_name: String,
}

impl Default for ScenePanel {
    fn default() -> Self {
        let looks = platform::load_looks()
            .and_then(|json| Looks::from_json(&json).map_err(|e| log::warn!("{e}")).ok())
            .unwrap_or_default();
        Self {
            looks,
            look_name: String::new(),
        }
    }
}

impl ScenePanel {
    /// The user's presets: each applies its media and lighting to the scene (one undo step;
    /// right-click deletes it); a name and Save keep the current ones.
    fn my_presets(&mut self, ui: &mut Ui, doc: &mut Document, notices: &mut Notices) {
        let now = ui.input(|i| i.time);
        let mut apply = None;
        let mut delete = None;
        ui.horizontal_wrapped(|ui| {
            ui.label("Mine:");
            if self.looks.looks.is_empty() {
                ui.weak("none yet");
            }
            for look in &self.looks.looks {
                let button = ui.small_button(&look.name).on_hover_text(
                    "Its media and lighting on this scene (Ctrl+Z undoes); right-click to delete",
                );
                if button.clicked() {
                    apply = Some(look.name.clone());
                }
                button.context_menu(|ui| {
                    if ui.button("Delete this preset").clicked() {
                        delete = Some(look.name.clone());
                        ui.close();
                    }
                });
            }
        });
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.look_name)
                    .desired_width(150.0)
                    .hint_text("name"),
            );
            if ui
                .button("Save look")
                .on_hover_text("Keep this scene's media and lighting as a preset of your own")
                .clicked()
            {
                match self.looks.save(&self.look_name, doc.scene()) {
                    Ok(name) => {
                        self.store(notices, now, format!("Saved the preset {name:?}"));
                        self.look_name.clear();
                    }
                    Err(e) => notices.error(now, e),
                }
            }
        });
        if let Some(look) = apply.and_then(|name| self.looks.get(&name).cloned()) {
            doc.apply(Edit::Replace(Box::new(look.applied_to(doc.scene()))), None);
            notices.note(now, format!("Applied {:?} (Ctrl+Z undoes)", look.name));
        }
        if let Some(name) = delete {
            self.looks.remove(&name);
            self.store(notices, now, format!("Deleted the preset {name:?}"));
        }
    }

    /// Writes the list to the app's store, saying how it went.
    fn store(&self, notices: &mut Notices, now: f64, done: String) {
        match platform::store_looks(&self.looks.to_json()) {
            Ok(()) => notices.note(now, done),
            Err(e) => notices.error(now, format!("The presets could not be kept: {e}")),
        }
    }

    /// Draws the group.
    pub fn ui(
        &mut self,
        ui: &mut Ui,
        doc: &mut Document,
        selection: &mut Selection,
        notices: &mut Notices,
    ) {
        // Closed at first: a new user starts from File, Sketch and Render.
        crate::ui::widgets::group(ui, "Scene", false, |ui| {
            ui.horizontal_wrapped(|ui| {
                ui.label("New:");
                for (preset, name) in Preset::ALL {
                    let button = ui.small_button(name).on_hover_text(format!(
                        "Start again from the {name} preset (Ctrl+Z undoes)"
                    ));
                    mark(ui, &format!("preset:{name}"), button.rect);
                    if button.clicked() {
                        // A preset brings its own camera, framed for its cloud.
                        let scene = Scene::preset(preset);
                        doc.apply(Edit::Replace(Box::new(scene)), None);
                    }
                }
            });
            self.my_presets(ui, doc, notices);
            ui.label(contents(doc.scene()));
            ellipsoid_list(ui, doc, selection);
        });
    }
}

/// The ellipsoids as a list to select from, and the selected one's numbers.
fn ellipsoid_list(ui: &mut Ui, doc: &mut Document, selection: &mut Selection) {
    let count = doc.scene().ellipsoids.len();
    if count == 0 {
        return;
    }
    let mut clicked = None;
    egui::ScrollArea::vertical()
        .id_salt("ellipsoids")
        .max_height(90.0)
        .show(ui, |ui| {
            ui.horizontal_wrapped(|ui| {
                for i in 0..count {
                    let selected = selection.contains(Item::Ellipsoid(i));
                    let mut label = egui::RichText::new(format!("E{}", i + 1));
                    if doc.scene().ellipsoids[i].hidden {
                        label = label.weak().italics();
                    }
                    let r = ui.selectable_label(selected, label).on_hover_text(
                        "Click to select, Shift+click to add; italic ones are hidden (Shift+H)",
                    );
                    mark(ui, &format!("ellipsoid:{}", i + 1), r.rect);
                    if r.clicked() {
                        clicked = Some((i, selected));
                    }
                }
            });
        });
    if let Some((i, was)) = clicked {
        if ui.input(|i| i.modifiers.shift) {
            selection.toggle(Item::Ellipsoid(i));
        } else if was {
            selection.clear();
        } else {
            selection.set(Item::Ellipsoid(i));
        }
    }
    let Some(i) = selection.ellipsoid().filter(|&i| i < count) else {
        return;
    };
    let mut e = (*doc.scene().ellipsoids[i]).clone();
    ui.label(egui::RichText::new(format!("Ellipsoid {}", i + 1)).strong());
    vec3_fields(ui, "centre", &mut e.center, 0.05);
    let radii = e.radii;
    vec3_fields(ui, "radii", &mut e.radii, 0.02);
    rotation_fields(ui, &mut e.rotation);
    if e.radii != radii {
        // (Only a typed size: a shrinking moving one may be smaller than a field allows.)
        e.radii = e.radii.max(glam::Vec3::splat(0.01));
    }
    ui.add(egui::Slider::new(&mut e.strength, -2.0..=2.0).text("strength"))
        .on_hover_text("How much it adds to the cloud; below zero it carves the cloud away");
    super::sketch::billows_controls(ui, &mut e.billows);
    ui.checkbox(&mut e.hidden, "hidden")
        .on_hover_text("Shift+H: leave it out of the cloud, kept in the scene (Alt+H shows all)");
    let before = e.motion;
    motion_controls(ui, &mut e.motion);
    if e.motion != before {
        set_motion(doc, selection, i, e.motion);
        return;
    }
    if e.motion.is_some() && wind_field_controls(ui, doc) {
        // The wind moved the ellipsoids: `e` is where this one stood before.
        return;
    }
    if e != *doc.scene().ellipsoids[i] {
        ellipsoids::set(doc, i, e, Some("ellipsoid"));
    }
}

/// The selected ellipsoid's motion (Schpok et al. 2003 §3.1's particles): whether it moves,
/// its rise, growth and spread, and whether the wind field carries it.
fn motion_controls(ui: &mut Ui, motion: &mut Option<Motion>) {
    let mut moves = motion.is_some();
    let r = ui.checkbox(&mut moves, "moves with time").on_hover_text(
        "Rise, grow and drift with the wind as the scene plays (for every selected ellipsoid); \
         its centre and radii then come from its motion, not from keys",
    );
    mark(ui, "motion:moves", r.rect);
    if moves != motion.is_some() {
        *motion = moves.then(Motion::default);
    }
    let Some(m) = motion else { return };
    ui.indent("motion", |ui| {
        crate::ui::widgets::param(ui, &mut m.rise, &limits::RISE);
        crate::ui::widgets::param(ui, &mut m.growth, &limits::GROWTH);
        crate::ui::widgets::param(ui, &mut m.spread, &limits::SPREAD);
        ui.checkbox(&mut m.carried, "carried by the wind field")
            .on_hover_text("The wind field below moves it (shear: faster the higher it is)");
    });
}

/// Sets `motion` on every selected ellipsoid (`shown` among them), each keeping where it
/// starts: one undo step per drag.
fn set_motion(doc: &mut Document, selection: &Selection, shown: usize, motion: Option<Motion>) {
    let mut list = doc.scene().ellipsoids.clone();
    let chosen = selection
        .items()
        .iter()
        .filter_map(|item| match item {
            Item::Ellipsoid(j) => Some(*j),
            _ => None,
        })
        .chain([shown]);
    for j in chosen {
        let Some(slot) = list.get_mut(j) else {
            continue;
        };
        // The document starts a newly moving ellipsoid where it stands now.
        let new = motion.map(|m| match slot.motion {
            Some(own) => Motion {
                from: own.from,
                size: own.size,
                ..m
            },
            None => m,
        });
        if slot.motion != new {
            Arc::make_mut(slot).motion = new;
        }
    }
    doc.apply(Edit::SetEllipsoids(list), Some("motion"));
}

/// The wind field that carries every moving ellipsoid; returns whether it changed.
fn wind_field_controls(ui: &mut Ui, doc: &mut Document) -> bool {
    let mut w = doc.scene().wind_field;
    ui.label("Wind field (every moving ellipsoid)");
    ui.indent("wind field", |ui| {
        let p = &limits::PARTICLE_WIND;
        crate::ui::widgets::param_as(ui, &mut w.velocity[0], p, "carrying wind x");
        crate::ui::widgets::param_as(ui, &mut w.velocity[1], p, "carrying wind z");
        crate::ui::widgets::param(ui, &mut w.shear, &limits::PARTICLE_SHEAR);
        crate::ui::widgets::param(ui, &mut w.turbulence, &limits::PARTICLE_TURBULENCE);
    });
    w != doc.scene().wind_field && doc.apply(Edit::SetWindField(w), Some("wind field"))
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
