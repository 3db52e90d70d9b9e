//! The one tone map (pure; `shaders/tone.wgsl` is its GPU twin): the sky, the cloud and the
//! shafts of light add up as linear light with the exposure applied, then ACES's filmic curve
//! (Narkowicz's fit, the light scaled by [`TONE_SCALE`] first) maps the sum once, and sRGB
//! encodes it. Colours the user picks for what lies behind the cloud are display colours:
//! their light is the curve's inverse of them ([`light_of`]), so at exposure 0 they show as
//! picked, and exposure brightens or darkens them with the cloud.

use glam::Vec3;

/// The light is scaled by this before the curve (ACES's usual exposure bias), which keeps the
/// cloud's mid-tones near those of the `1 − exp(−x)` the renderer used before.
pub const TONE_SCALE: f32 = 0.6;

/// Linear light → display light in [0, 1] (before sRGB encoding).
pub fn tone_map(x: f32) -> f32 {
    let v = x.max(0.0) * TONE_SCALE;
    ((v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// The light [`tone_map`] maps to `y` (display light, clamped to [0, 1]).
pub fn tone_unmap(y: f32) -> f32 {
    let c = y.clamp(0.0, 1.0);
    let (a, b, d) = (2.51 - 2.43 * c, 0.03 - 0.59 * c, -0.14 * c);
    (-b + (b * b - 4.0 * a * d).sqrt()) / (2.0 * a) / TONE_SCALE
}

/// Linear → sRGB-encoded.
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        x.max(0.0) * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear light → the display's sRGB-encoded colour.
pub fn display(light: Vec3) -> [f32; 3] {
    light.to_array().map(|x| linear_to_srgb(tone_map(x)))
}

/// A display colour (sRGB-encoded, as picked) → the linear light that shows as it at exposure
/// 0.
pub fn light_of(colour: [f32; 3]) -> Vec3 {
    crate::scene::srgb_to_linear(colour)
        .to_array()
        .map(tone_unmap)
        .into()
}

/// A picked background colour as it shows at `exposure` (stops): its light scaled, mapped
/// again. The flat background's clear colour, and the composite's background where the view
/// has no sky texture.
pub fn background_display(colour: [f32; 3], exposure: f32) -> [f32; 3] {
    display(light_of(colour) * exposure.exp2())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_inverse_undoes_the_curve_and_a_picked_colour_shows_as_picked_at_exposure_0() {
        for i in 0..=100 {
            let y = i as f32 / 100.0;
            assert!((tone_map(tone_unmap(y)) - y).abs() < 1e-4, "y {y}");
        }
        for c in [[0.0, 0.5, 1.0], [0.42, 0.62, 0.86], [0.02, 0.03, 0.9]] {
            let shown = background_display(c, 0.0);
            for k in 0..3 {
                assert!((shown[k] - c[k]).abs() < 5e-4, "{c:?} shows as {shown:?}");
            }
        }
    }

    #[test]
    fn the_curve_rises_saturates_and_exposure_moves_a_background() {
        let mut last = -1.0;
        for i in 0..200 {
            let y = tone_map(i as f32 * 0.05);
            assert!(y > last || y == 1.0);
            last = y;
        }
        assert_eq!(tone_map(0.0), 0.0);
        assert!(tone_map(100.0) == 1.0);
        let sky = [0.42, 0.62, 0.86];
        let (dark, bright) = (background_display(sky, -1.0), background_display(sky, 1.0));
        for k in 0..3 {
            assert!(
                dark[k] < sky[k] - 0.05 && bright[k] > sky[k] + 0.03,
                "{dark:?} {bright:?}"
            );
        }
    }

    /// At the exposure's caps and for colours outside [0, 1] (a hand-edited document before
    /// its repair), the background is a finite display colour in [0, 1]: the inverse clamps
    /// what it is given, and a white sky at +4 EV stays white, a black one black.
    #[test]
    fn the_exposure_caps_and_odd_colours_stay_displayable() {
        let e = &crate::limits::EXPOSURE;
        for exposure in [e.min as f32, e.max as f32, 0.0] {
            for c in [
                [0.0; 3],
                [1.0; 3],
                [-0.5, 2.0, 0.5],
                [1e-7, 0.999_999, 0.04],
            ] {
                let shown = background_display(c, exposure);
                assert!(
                    shown
                        .iter()
                        .all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
                    "{c:?} at {exposure} EV shows as {shown:?}"
                );
            }
        }
        assert!(
            background_display([1.0; 3], e.max as f32)
                .iter()
                .all(|&v| v > 0.9999)
        );
        assert_eq!(background_display([0.0; 3], e.max as f32), [0.0; 3]);
        assert!(light_of([1.0; 3]).x > 11.0 && light_of([1.0; 3]).x < 13.0);
    }
}
