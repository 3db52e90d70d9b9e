//! The Render group: quality and the cloud's media.

use egui::Ui;

use super::PartPanel;
use crate::limits;
use crate::scene::{Edit, RenderSettings};
use crate::ui::widgets::param;

/// The Render group.
pub const RENDER: PartPanel<RenderSettings> =
    PartPanel::new("Render", |s| &s.render, Edit::SetRender, body);

fn body(ui: &mut Ui, r: &mut RenderSettings) {
    param(ui, &mut r.slices, &limits::SLICES);
    param(ui, &mut r.opacity, &limits::OPACITY);
    param(ui, &mut r.softness, &limits::SOFTNESS);
    param(ui, &mut r.noise_amount, &limits::NOISE_AMOUNT);
    param(ui, &mut r.noise_scale, &limits::NOISE_SCALE);
    param(ui, &mut r.noise_octaves, &limits::OCTAVES);
    param(ui, &mut r.detail, &limits::DETAIL);
    param(ui, &mut r.field_resolution, &limits::FIELD_RESOLUTION);
}
