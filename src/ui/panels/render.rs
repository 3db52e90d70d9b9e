//! The Render group: quality and the cloud's media.

use egui::Ui;

use super::PartPanel;
use crate::limits;
use crate::scene::{Edit, NoiseBasis, NoiseFilter, RenderSettings};
use crate::ui::widgets::param;

/// The Render group.
pub const RENDER: PartPanel<RenderSettings> =
    PartPanel::new("Render", |s| &s.render, Edit::SetRender, body);

/// Table 2's qualitative controls first (Opacity, Quality, Detail, Dirtiness, Sharpness, cloud
/// size), the finer settings after, the media's filter, noise and motion in a deeper group.
fn body(ui: &mut Ui, r: &mut RenderSettings) {
    param(ui, &mut r.opacity, &limits::OPACITY);
    param(ui, &mut r.slices, &limits::SLICES);
    param(ui, &mut r.detail, &limits::DETAIL);
    param(ui, &mut r.dirtiness, &limits::DIRTINESS);
    param(ui, &mut r.sharpness, &limits::SHARPNESS);
    param(ui, &mut r.noise_scale, &limits::NOISE_SCALE);
    param(ui, &mut r.noise_amount, &limits::NOISE_AMOUNT);
    param(ui, &mut r.softness, &limits::SOFTNESS);
    param(ui, &mut r.noise_octaves, &limits::OCTAVES);
    param(ui, &mut r.field_resolution, &limits::FIELD_RESOLUTION);
    egui::CollapsingHeader::new("Media: filter, basis, wind")
        .default_open(false)
        .show(ui, |ui| {
            egui::ComboBox::from_label("filter")
                .selected_text(r.noise_filter.label())
                .show_ui(ui, |ui| {
                    for f in NoiseFilter::ALL {
                        ui.selectable_value(&mut r.noise_filter, f, f.label());
                    }
                })
                .response
                .on_hover_text("Schpok et al.'s Table 2: how each octave's noise is shaped");
            ui.horizontal(|ui| {
                ui.label("noise");
                ui.selectable_value(&mut r.noise_basis, NoiseBasis::Perlin, "Perlin");
                ui.selectable_value(&mut r.noise_basis, NoiseBasis::Worley, "Worley (puffs)");
            });
            let [wx, wz] = &mut r.wind;
            ui.horizontal(|ui| {
                ui.label("wind");
                param(ui, wx, &limits::WIND);
            });
            ui.horizontal(|ui| {
                ui.label("wind z");
                param(ui, wz, &limits::WIND);
            });
            param(ui, &mut r.torque, &limits::TORQUE);
        });
}
