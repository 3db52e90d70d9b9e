//! The Render group: quality and the cloud's media.

use egui::Ui;

use super::PartPanel;
use crate::limits;
use crate::scene::{Edit, NoiseBasis, NoiseFilter, RenderSettings, Tier};
use crate::ui::widgets::{param, param_as};

/// The Render group.
pub const RENDER: PartPanel<RenderSettings> =
    PartPanel::new("Render", |s| &s.render, Edit::SetRender, body, true);

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
    param(ui, &mut r.light_resolution, &limits::LIGHT_RESOLUTION);
    param(ui, &mut r.light_octaves, &limits::LIGHT_OCTAVES);
    egui::CollapsingHeader::new("Media: filter, basis, wind")
        .default_open(false)
        .show(ui, |ui| {
            filter_combo(ui, "filter", &mut r.noise_filter);
            ui.horizontal(|ui| {
                ui.label("noise");
                ui.selectable_value(&mut r.noise_basis, NoiseBasis::Perlin, "Perlin");
                ui.selectable_value(&mut r.noise_basis, NoiseBasis::Worley, "Worley (puffs)");
            });
            wind_and_torque(ui, &mut r.wind, &mut r.torque);
        });
    tiers(ui, r);
}

/// The wind along x and z and the torque, each slider under its own label.
fn wind_and_torque(ui: &mut Ui, wind: &mut [f32; 2], torque: &mut f32) {
    let [wx, wz] = wind;
    param_as(ui, wx, &limits::WIND, "wind x");
    param_as(ui, wz, &limits::WIND, "wind z");
    param_as(ui, torque, &limits::TORQUE, "torque");
}

fn filter_combo(ui: &mut Ui, id: &str, filter: &mut NoiseFilter) {
    egui::ComboBox::from_id_salt(id)
        .selected_text(filter.label())
        .show_ui(ui, |ui| {
            for f in NoiseFilter::ALL {
                ui.selectable_value(filter, f, f.label());
            }
        })
        .response
        .on_hover_text("Schpok et al.'s Table 2: how each octave's noise is shaped");
}

const REMOVE_TIER: &str = "remove tier";

/// The tier whose "remove" was pressed this frame, once: the caller removes it with
/// [`crate::scene::Edit::RemoveTier`], which takes its keys too.
pub fn take_removed_tier(ctx: &egui::Context) -> Option<usize> {
    ctx.data_mut(|d| d.remove_temp(egui::Id::unique(REMOVE_TIER)))
}

/// Atmospheric tiers: from each floor up, the noise has its own filter and motion; the media
/// above are the base, below the first floor (and their first octave moves everywhere).
fn tiers(ui: &mut Ui, r: &mut RenderSettings) {
    // Its id does not follow its label: adding a tier changes the count it shows, and a new
    // id would close the group under the pointer.
    let shown = egui::CollapsingHeader::new(format!("Tiers ({})", r.tiers.len()))
        .id_salt("tiers")
        .default_open(false)
        .show(ui, |ui| {
            let floors: Vec<f32> = r.tiers.iter().map(|t| t.floor).collect();
            for (k, t) in r.tiers.iter_mut().enumerate() {
                ui.horizontal(|ui| {
                    ui.label(egui::RichText::new(format!("Tier {}", k + 1)).strong());
                    let remove = ui
                        .small_button("remove")
                        .on_hover_text("Back to the media below");
                    crate::ui::widgets::mark(ui, &format!("button:remove tier {}", k + 1), remove.rect);
                    if remove.clicked() {
                        // Its own edit, which takes the tier's keys with it.
                        ui.ctx().data_mut(|d| d.insert_temp(egui::Id::unique(REMOVE_TIER), k));
                    }
                });
                param(ui, &mut t.floor, &limits::TIER_FLOOR);
                filter_combo(ui, &format!("tier {k} filter"), &mut t.filter);
                wind_and_torque(ui, &mut t.wind, &mut t.torque);
            }
            let add = (r.tiers.len() < limits::MAX_TIERS).then(|| {
                ui.button("Add a tier").on_hover_text(
                    "Higher air with its own noise: wisps above a billowing base, faster wind aloft",
                )
            });
            if let Some(add) = &add {
                crate::ui::widgets::mark(ui, "button:Add a tier", add.rect);
            }
            if add.is_some_and(|a| a.clicked()) {
                let floor = r.tiers.last().map_or(limits::TIER_FLOOR.default as f32, |t| t.floor + 4.0);
                r.tiers.push(Tier {
                    floor,
                    ..Default::default()
                });
            }
            param(ui, &mut r.tier_blend, &limits::TIER_BLEND);
            // A floor the user moves stays between its neighbours' (keys may pose them out of
            // order, which this leaves as it is).
            for (k, &was) in floors.iter().enumerate().take(r.tiers.len()) {
                if r.tiers[k].floor != was {
                    let lo = if k > 0 { r.tiers[k - 1].floor } else { f32::MIN };
                    let hi = r.tiers.get(k + 1).map_or(f32::MAX, |t| t.floor);
                    r.tiers[k].floor = r.tiers[k].floor.max(lo).min(hi.max(lo));
                }
            }
        });
    crate::ui::widgets::mark(ui, "group:Tiers", shown.header_response.rect);
}
