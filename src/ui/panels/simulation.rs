//! The Simulation group (Dobashi et al. 2000): turn the cellular automaton on for the scene
//! (the ellipsoids become its air parcels), its grid, step rate, probabilities and wind by
//! height; a single step and a reset. Play is the scene clock's (Alt+A): the simulation's
//! time is the scene's. Each change is one undo step (a slider drag folds into one).

use egui::Ui;

use crate::scene::{Document, Edit};
use crate::simulate::Settings;
use crate::ui::widgets::mark;

const TITLE: &str = "Simulation";

/// The Simulation group (its state is the document's: nothing of its own yet).
#[derive(Default)]
pub struct SimulationPanel;

impl SimulationPanel {
    /// Draws the group.
    pub fn ui(&mut self, ui: &mut Ui, doc: &mut Document) {
        let simulated = doc.scene().simulation.is_some();
        crate::ui::widgets::group(ui, TITLE, simulated, |ui| {
            let current = doc.scene().simulation.as_deref().cloned();
            let mut on = current.is_some();
            let r = ui
                    .checkbox(&mut on, "simulate clouds (cellular automaton)")
                    .on_hover_text("The ellipsoids become air parcels: clouds form and dissolve inside them as the scene plays");
            mark(ui, "simulation:on", r.rect);
            if on != current.is_some() {
                let settings = on.then(|| around(doc));
                doc.apply(Edit::SetSimulation(settings), None);
                return;
            }
            let Some(mut s) = current else {
                return;
            };
            ui.horizontal(|ui| {
                ui.label("cells");
                for (c, axis) in s.cells.iter_mut().zip(["x", "y (up)", "z"]) {
                    ui.add(
                        egui::DragValue::new(c)
                            .range(4..=256)
                            .prefix(format!("{axis} ")),
                    );
                }
            });
            ui.add(
                egui::Slider::new(&mut s.cell_size, 0.02..=2.0)
                    .logarithmic(true)
                    .text("cell size"),
            );
            ui.add(
                egui::Slider::new(&mut s.rate, 0.5..=60.0)
                    .logarithmic(true)
                    .text("steps per second"),
            );
            ui.add(egui::Slider::new(&mut s.p_hum, 0.0..=1.0).text("vapour supply"))
                .on_hover_text("p_hum at a parcel's centre: how fast vapour comes back");
            ui.add(egui::Slider::new(&mut s.p_act, 0.0..=0.1).text("activation"))
                .on_hover_text("p_act at a parcel's centre: how often condensation starts");
            ui.add(egui::Slider::new(&mut s.p_ext_inside, 0.0..=0.2).text("dissolve inside"))
                .on_hover_text("p_ext at a parcel's centre");
            ui.add(egui::Slider::new(&mut s.p_ext_outside, 0.0..=1.0).text("dissolve outside"))
                .on_hover_text("p_ext away from every parcel");
            ui.add(egui::Slider::new(&mut s.wind[0], -4.0..=4.0).text("wind at the bottom"))
                .on_hover_text(
                    "Cells per step along x in the lowest layer; linear up to the top's",
                );
            ui.add(egui::Slider::new(&mut s.wind[1], -4.0..=4.0).text("wind at the top"));
            ui.add(egui::Slider::new(&mut s.smoothing, 0..=4).text("smoothing (cells)"));
            ui.horizontal(|ui| {
                ui.label("seed");
                ui.add(egui::DragValue::new(&mut s.seed));
            });
            if s != *doc.scene().simulation.as_deref().unwrap_or(&s) {
                s.sanitize();
                doc.apply(Edit::SetSimulation(Some(s.clone())), Some(TITLE));
            }
            ui.horizontal(|ui| {
                if ui
                    .button("Step")
                    .on_hover_text("One step forward (the scene time moves by a step)")
                    .clicked()
                {
                    doc.set_time(doc.scene().time + 1.0 / s.rate);
                }
                if ui
                    .button("Reset")
                    .on_hover_text("Back to the first step (time 0)")
                    .clicked()
                {
                    doc.set_time(0.0);
                }
                ui.label(format!(
                    "step {}",
                    (doc.scene().time * s.rate).floor() as u64
                ));
            });
        });
    }
}

/// Settings whose grid holds the scene's ellipsoids (with room around them), or the defaults.
fn around(doc: &Document) -> Settings {
    let mut s = Settings::default();
    let boxes = doc.scene().ellipsoids.iter().map(|e| {
        let r = e.radii.max_element();
        (
            e.center - glam::Vec3::splat(r),
            e.center + glam::Vec3::splat(r),
        )
    });
    if let Some((lo, hi)) = boxes.reduce(|(a, b), (c, d)| (a.min(c), b.max(d))) {
        let lo = lo - glam::Vec3::new(4.0, 1.0, 4.0);
        let hi = hi + glam::Vec3::new(4.0, 2.0, 4.0);
        let size = hi - lo;
        s.cell_size = (size.max_element() / 128.0).max(0.05);
        s.cells = (size / s.cell_size)
            .ceil()
            .as_uvec3()
            .to_array()
            .map(|c| c.clamp(4, 256));
        s.origin = lo.to_array();
    }
    s
}
