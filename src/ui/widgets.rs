//! Small widgets shared by the panels.

use egui::{Slider, Ui};

use crate::limits::Param;

/// A slider over a parameter's one range (see [`crate::limits`]). Returns whether it changed.
pub fn param_f32(ui: &mut Ui, value: &mut f32, param: &Param, label: &str, tip: &str) -> bool {
    ui.add(
        Slider::new(value, param.range_f32())
            .logarithmic(param.logarithmic)
            .text(label),
    )
    .on_hover_text(tip)
    .changed()
}

/// [`param_f32`] for `f64` values.
pub fn param_f64(ui: &mut Ui, value: &mut f64, param: &Param, label: &str, tip: &str) -> bool {
    ui.add(
        Slider::new(value, param.min..=param.max)
            .logarithmic(param.logarithmic)
            .text(label),
    )
    .on_hover_text(tip)
    .changed()
}

/// [`param_f32`] for integer values.
pub fn param_u32(ui: &mut Ui, value: &mut u32, param: &Param, label: &str, tip: &str) -> bool {
    ui.add(
        Slider::new(value, param.range_u32())
            .logarithmic(param.logarithmic)
            .text(label),
    )
    .on_hover_text(tip)
    .changed()
}

/// A colour button for an sRGB colour in [0, 1]. Returns whether it changed.
pub fn srgb_button(ui: &mut Ui, label: &str, color: &mut [f32; 3]) -> bool {
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
