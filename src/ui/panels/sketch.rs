//! The Sketch group: the tools, the drawing-plane list and the selected plane's controls.

use egui::Ui;

use crate::derive::{Derived, Shape};
use crate::limits;
use crate::scene::{Document, Edit, StrokeKind};
use crate::ui::notice::Notices;
use crate::ui::selection::{Item, Selection, delete, duplicate};
use crate::ui::tool::Tool;
use crate::ui::tools::Toolbox;
use crate::ui::widgets::{param, rotation_fields, vec3_fields};

/// The Sketch group.
#[derive(Default)]
pub struct SketchPanel;

impl SketchPanel {
    /// Draws the group.
    pub fn ui(
        &mut self,
        ui: &mut Ui,
        doc: &mut Document,
        derived: &Derived,
        tool: &mut Toolbox,
        selection: &mut Selection,
        notices: &mut Notices,
    ) {
        crate::ui::widgets::group(ui, "Sketch", true, |ui| {
            ui.horizontal_wrapped(|ui| {
                    for (t, label, tip) in [
                        (Tool::Navigate, "Navigate", "V: drag orbits the view"),
                        (Tool::Sketch, "✏ Sketch", "D: drag draws a cloud's outline"),
                        (
                            Tool::Cut,
                            "✂ Cut",
                            "C: drag draws a line; the cloud below it is removed",
                        ),
                        (
                            Tool::Ellipsoid,
                            "Ellipsoid",
                            "E: a click adds an ellipsoid where it lands on the cloud (or at the focus point); a drag orbits",
                        ),
                        (
                            Tool::Move,
                            "⬌ Move",
                            "Shift+G: drag moves the selected drawing plane or ellipsoid across the view (Shift: toward or away), or along an arrow. G alone grabs the selection without the tool (X/Y/Z lock, type a distance, Enter or a click confirms, Esc cancels)",
                        ),
                        (
                            Tool::Scale,
                            "Scale",
                            "Shift+S: drag right or up grows the selected ellipsoid; X, Y or Z scales one axis, Ctrl snaps to tenths. S alone scales the selection without the tool",
                        ),
                        (
                            Tool::Rotate,
                            "⟳ Rotate",
                            "Shift+R: drag turns the selected drawing plane or ellipsoid; X, Y or Z locks the axis, Ctrl snaps to 15°. R alone rotates the selection without the tool",
                        ),
                    ] {
                        ui.selectable_value(&mut tool.tool, t, label)
                            .on_hover_text(tip);
                    }
                });
            ui.horizontal(|ui| {
                ui.checkbox(&mut tool.show_all_planes, "all grids");
                ui.checkbox(&mut tool.hide_guides, "hide guides")
                    .on_hover_text("H");
                ui.checkbox(&mut tool.show_skeleton, "skeleton")
                    .on_hover_text("K: the selected outline's skeleton and spheres");
            });
            ui.checkbox(&mut tool.sketch.behind, "behind the cloud").on_hover_text(
                    "Q: a new outline drawn over the cloud lands on its far side (off: its near side, so it goes in front)",
                );
            let planes = &doc.scene().planes;
            if planes.is_empty() {
                ui.label("No drawing planes yet. Pick Sketch and drag an outline in the view.");
                return;
            }
            ui.label("Drawing planes:");
            let mut clicked = None;
            for (i, plane) in planes.iter().enumerate() {
                let selected = selection.contains(Item::Plane(i));
                // A plane whose stroke the field cannot use says so, and why.
                let shape = derived.derived_shape(plane);
                let response = match shape.as_deref() {
                    Some(Shape::Unusable(e)) => ui
                        .selectable_label(
                            selected,
                            egui::RichText::new(format!("{} (not used)", plane.name))
                                .color(ui.visuals().warn_fg_color),
                        )
                        .on_hover_text(format!("This stroke adds nothing to the cloud: {e}")),
                    _ if plane.hidden => ui
                        .selectable_label(
                            selected,
                            egui::RichText::new(format!("{} (hidden)", plane.name)).weak(),
                        )
                        .on_hover_text("Hidden: left out of the cloud (Shift+H shows it)"),
                    _ => ui.selectable_label(selected, plane.name.as_str()),
                };
                if response.clicked() {
                    clicked = Some((i, selected));
                }
            }
            if let Some((i, was)) = clicked {
                if ui.input(|i| i.modifiers.shift) {
                    selection.toggle(Item::Plane(i));
                } else {
                    selection.set_plane((!was).then_some(i));
                }
            }
            if let Some(i) = selection.plane().filter(|&i| i < doc.scene().planes.len()) {
                ui.separator();
                let notes = match derived.derived_shape(&doc.scene().planes[i]).as_deref() {
                    Some(Shape::Unusable(e)) => vec![format!("Not used: {e}")],
                    Some(Shape::Outline { warnings, .. }) => warnings.clone(),
                    _ => Vec::new(),
                };
                for note in notes {
                    ui.label(
                        egui::RichText::new(note)
                            .small()
                            .color(ui.visuals().warn_fg_color),
                    );
                }
                plane_controls(ui, doc, i);
                ui.horizontal(|ui| {
                    let now = ui.input(|i| i.time);
                    if ui.button("Duplicate").on_hover_text("Ctrl+D").clicked()
                        && let Some(m) = duplicate(doc, selection)
                    {
                        notices.note(now, m);
                    }
                    if ui.button("Delete").on_hover_text("Delete").clicked()
                        && let Some(m) = delete(doc, selection)
                    {
                        notices.note(now, m);
                    }
                });
            }
        });
    }
}

/// The billows sliders of one primitive (a plane's outline or an ellipsoid).
pub(super) fn billows_controls(ui: &mut Ui, billows: &mut crate::scene::Billows) {
    param(ui, &mut billows.levels, &limits::BILLOW_LEVELS);
    ui.add_enabled_ui(billows.levels > 0, |ui| {
        param(ui, &mut billows.ratio, &limits::BILLOW_RATIO);
        param(ui, &mut billows.coverage, &limits::BILLOW_COVERAGE);
    });
}

fn plane_controls(ui: &mut Ui, doc: &mut Document, i: usize) {
    let mut plane = (*doc.scene().planes[i]).clone();
    ui.label(egui::RichText::new(&plane.name).strong());
    if plane.kind == StrokeKind::Outline {
        let s = &mut plane.sketch;
        param(ui, &mut s.inflate, &limits::INFLATE);
        param(ui, &mut s.simplify, &limits::SIMPLIFY);
        param(ui, &mut s.prune, &limits::PRUNE);
        ui.checkbox(&mut s.extend, "3D extension")
            .on_hover_text("Grow copies of the cloud's bumps toward and away from you, so it is round from the side");
        ui.add_enabled_ui(s.extend, |ui| {
            param(ui, &mut s.copies, &limits::COPIES);
        });
        param(ui, &mut s.blend, &limits::BLEND);
        billows_controls(ui, &mut plane.billows);
    }
    vec3_fields(ui, "move", &mut plane.origin, 0.05);
    rotation_fields(ui, &mut plane.rotation);
    ui.checkbox(&mut plane.hidden, "hidden")
        .on_hover_text("Shift+H: leave it out of the cloud, kept in the scene (Alt+H shows all)");
    if plane != *doc.scene().planes[i] {
        doc.apply(Edit::SetPlane(i, plane), Some("plane"));
    }
}
