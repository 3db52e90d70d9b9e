//! The Light group: sun, sky, scattering and background.

use egui::Ui;

use super::PartPanel;
use crate::limits;
use crate::scene::{Edit, Lighting};
use crate::ui::widgets::{mark, param, srgb_button};

/// The Light group.
pub const LIGHT: PartPanel<Lighting> =
    PartPanel::new("Light", |s| &s.light, Edit::SetLight, body, false);

fn body(ui: &mut Ui, l: &mut Lighting) {
    param(ui, &mut l.sun_azimuth_deg, &limits::SUN_AZIMUTH);
    param(ui, &mut l.sun_elevation_deg, &limits::SUN_ELEVATION);
    param(ui, &mut l.sun_intensity, &limits::SUN_INTENSITY);
    param(ui, &mut l.ambient, &limits::AMBIENT);
    param(ui, &mut l.exposure, &limits::EXPOSURE);
    param(ui, &mut l.forward_scattering, &limits::FORWARD_SCATTERING);
    param(ui, &mut l.multiple_scattering, &limits::MULTIPLE_SCATTERING);
    ui.horizontal(|ui| {
        ui.label("sky");
        let (physical, gradient) = (l.physical_sky, l.sky_gradient);
        if ui
            .radio(!physical && !gradient, "flat")
            .on_hover_text("One flat background colour")
            .clicked()
        {
            (l.physical_sky, l.sky_gradient) = (false, false);
        }
        if ui
            .radio(!physical && gradient, "gradient")
            .on_hover_text("The background at the top of the sky, fading to the horizon colour at eye level")
            .clicked()
        {
            (l.physical_sky, l.sky_gradient) = (false, true);
        }
        let r = ui
            .radio(physical, "physical")
            .on_hover_text("The sky of a real atmosphere (Hillaire 2020) with the sun's disk: its colours, the sun's and the sky light's all follow the sun's elevation, a sunset without picking colours");
        mark(ui, "light:physical", r.rect);
        if r.clicked() {
            l.physical_sky = true;
        }
    });
    ui.add_enabled_ui(!l.physical_sky, |ui| {
        srgb_button(ui, "lit colour (sun)", &mut l.sun_color);
        srgb_button(ui, "shadow colour (sky)", &mut l.sky_color);
        srgb_button(ui, "background", &mut l.background);
        if l.sky_gradient {
            srgb_button(ui, "horizon", &mut l.horizon_color);
        }
    })
    .response
    .on_disabled_hover_text("The physical sky sets these from the sun's elevation");
    ui.checkbox(&mut l.ground, "ground")
        .on_hover_text("A ground plane under the sky; the clouds' shadows fall on it");
    if l.ground {
        param(ui, &mut l.ground_height, &limits::GROUND_HEIGHT);
        srgb_button(ui, "ground colour", &mut l.ground_color);
    }
    let r = ui.checkbox(&mut l.shafts, "shafts of light")
        .on_hover_text("Sunlight scattered by the air, dark in the clouds' shadows: shafts of light through the gaps between clouds, brightest looking toward the sun");
    mark(ui, "light:shafts", r.rect);
    if l.shafts {
        param(ui, &mut l.shaft_intensity, &limits::SHAFT_INTENSITY);
        param(ui, &mut l.shaft_density, &limits::SHAFT_DENSITY);
    }
}
