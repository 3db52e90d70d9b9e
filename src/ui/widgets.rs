//! Small widgets shared by the panels.

use egui::{Slider, Ui};

use crate::limits::Param;

/// The icon glyphs the UI's labels use (undo, redo, sketch, cut, move, rotate).
pub const ICONS: &str = "⟲⟳✏✂⬌";

/// Installs the icon font, a subset of emoji-icon-font (MIT, `assets/fonts/`) holding just
/// [`ICONS`]: egui's default fonts lack them, and the browser's system-font fallback is not
/// there natively, so both targets load the same glyphs from here.
pub fn install_icon_font(ctx: &egui::Context) {
    use egui::epaint::text::{FontData, FontInsert, FontPriority, InsertFontFamily};
    ctx.add_font(FontInsert::new(
        "cloudsketch-icons",
        FontData::from_static(include_bytes!("../../assets/fonts/icons.ttf")),
        [egui::FontFamily::Proportional, egui::FontFamily::Monospace]
            .into_iter()
            .map(|family| InsertFontFamily {
                family,
                priority: FontPriority::Lowest,
            })
            .collect(),
    ));
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_icon_glyphs_are_there_only_with_the_icon_font() {
        let font = egui::FontId::proportional(14.0);
        let frame = |ctx: &egui::Context| {
            let mut out = ctx.run_ui(Default::default(), |_| {});
            out.textures_delta.clear();
        };
        let without = egui::Context::default();
        frame(&without);
        let missing = without.fonts_mut(|f| ICONS.chars().filter(|&c| !f.has_glyph(&font, c)).count());
        assert!(missing > 0, "egui's own fonts now have the icons: the icon font can go");
        let with = egui::Context::default();
        install_icon_font(&with);
        frame(&with);
        assert!(with.fonts_mut(|f| f.has_glyphs(&font, ICONS)));
    }
}
