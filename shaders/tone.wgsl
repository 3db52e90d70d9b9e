// The one tone map (src/render/tone.rs mirrors it): the sky, the cloud and the shafts of light
// are added as linear light (exposure applied), then mapped once by ACES's filmic curve
// (Narkowicz's fit, the light scaled by 0.6 first) and sRGB-encoded. A colour the user picks
// (the background, the sky gradient's, the ground's) is display-encoded: its light is the
// curve's inverse of it, so at exposure 0 it shows as picked. Composed into the sky and
// composite shaders.

const TONE_SCALE: f32 = 0.6;

// Linear light → display light in [0, 1] (before sRGB encoding).
fn tone_map(x: vec3<f32>) -> vec3<f32> {
    let v = max(x, vec3<f32>(0.0)) * TONE_SCALE;
    return clamp((v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

// The light `tone_map` maps to `y` (display light in [0, 1]): the quadratic's positive root.
fn tone_unmap(y: vec3<f32>) -> vec3<f32> {
    let c = clamp(y, vec3<f32>(0.0), vec3<f32>(1.0));
    let a = 2.51 - 2.43 * c;
    let b = 0.03 - 0.59 * c;
    let d = -0.14 * c;
    return (-b + sqrt(b * b - 4.0 * a * d)) / (2.0 * a) / TONE_SCALE;
}

fn linear_to_srgb(x: vec3<f32>) -> vec3<f32> {
    let lo = x * 12.92;
    let hi = 1.055 * pow(max(x, vec3<f32>(0.0)), vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, x <= vec3<f32>(0.0031308));
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((max(c, vec3<f32>(0.0)) + 0.055) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

// Linear light → the display's sRGB-encoded colour.
fn display(x: vec3<f32>) -> vec3<f32> {
    return linear_to_srgb(tone_map(x));
}

// A display colour (sRGB-encoded, as picked or as a display target holds it) → the linear
// light that shows as it at exposure 0.
fn light_of(c: vec3<f32>) -> vec3<f32> {
    return tone_unmap(srgb_to_linear(c));
}
