// Shared by the slice shaders (volume.wgsl, plain_slices.wgsl) and the light pass
// (light_march.wgsl): the `Volume` uniforms and the bind group. WGSL has no include, so src/render/shaders.rs prepends this file to each of them
// and the tests validate the composed modules; `Volume` mirrors `VolumeUniforms` in
// src/render/gpu_types.rs, and a test compares their sizes and member offsets.

const MAX_OCTAVES: i32 = 8;
const MAX_TIERS: i32 = 2;

struct Volume {
    // World → clip.
    view_proj: mat4x4<f32>,
    // Camera position (xyz); w: 1 perspective, 0 orthographic.
    eye: vec4<f32>,
    // Unit view direction, image-plane right and up (xyz).
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // Density grid: minimum corner and 1 / size (xyz); grid_min.w: depth of the farthest slice
    // boundary along the view from the bounding sphere's centre.
    grid_min: vec4<f32>,
    grid_inv_size: vec4<f32>,
    // Bounding sphere: centre (xyz), radius (w; unread: the slices cover their cut through the
    // box, not the sphere's cross-section).
    sphere: vec4<f32>,
    // x: total slices, y: first slice of this draw (0 = farthest), z: slice spacing (world),
    // w: Sharpness (the alpha cut-off as a share of the slice's full opacity).
    slicing: vec4<f32>,
    // Linear sun colour × intensity, sky colour × ambient (rgb); sun_color.w: Dirtiness;
    // sky_color.w: the multiple-scattering weight.
    sun_color: vec4<f32>,
    sky_color: vec4<f32>,
    // Unit direction toward the sun (xyz); w: the phase function's asymmetry g.
    sun_dir: vec4<f32>,
    // x: extinction per world unit, y: iso-level, z: soft-edge half-width, w: noise amount.
    media: vec4<f32>,
    // x: amplitude gain per octave, y: octaves, z: Table 2 filter (0 stratus, 1 cumulus,
    // 2 wispy, 3 veined), w: basis (0 Perlin, 1 Worley).
    noise: vec4<f32>,
    // Per-octave transform of world positions into noise-texture coordinates
    // (scale × rotation × translation; the scale grows by the lacunarity per octave).
    octaves: array<mat4x4<f32>, MAX_OCTAVES>,
    // Atmospheric tiers: x, y: floors of tiers 1 and 2, z: blend height, w: how many.
    tiers: vec4<f32>,
    // x, y: Table 2 filters of tiers 1 and 2; z: the mean of the base media's filtered noise.
    tier_filters: vec4<f32>,
    // Per-octave transforms of tiers 1 and 2 (octave 0 is the base's in every tier).
    tier_octaves: array<mat4x4<f32>, 16>,
    // Clip → world: each pixel's view ray, for the shells of the shafts of light.
    inv_view_proj: mat4x4<f32>,
    // Shells in this draw: x: the first, y: how many (0: no shafts), z: slices in this draw,
    // w: shells in the whole image.
    shells: vec4<f32>,
    // x: distance of the farthest shell's outer boundary from the eye, y: the shells'
    // spacing, z: the air's extinction per world unit, w: the shafts' intensity.
    shafts: vec4<f32>,
    // x: the ground's height (the air below it is hidden), y: the air's phase asymmetry g,
    // z: the shells drawn apart (Shells::apart), whose light also goes to the first target.
    air: vec4<f32>,
    // Aerial perspective with the physical sky: the air's extinction per world unit (xyz);
    // w: 1 when on. haze_light: the light the air adds in its place (rgb).
    haze: vec4<f32>,
    haze_light: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Volume;
// The field value (red; green: the CPU's transmittance sweep, which the light volume replaced).
@group(0) @binding(1) var volume_tex: texture_3d<f32>;
@group(0) @binding(2) var clamp_smp: sampler;
@group(0) @binding(3) var noise_tex: texture_3d<f32>;
@group(0) @binding(4) var repeat_smp: sampler;
// Transmittance toward the sun (red), computed on the GPU with the noise (light_march.wgsl);
// the slices read it, the light pass writes it (and so binds no texture 5).
@group(0) @binding(5) var light_tex: texture_3d<f32>;

// `c` (premultiplied light and alpha) at the scale of the light accumulated in the slices'
// target: 1 in floats, less in 8 bits (plain WebGL2), which would clip a sunlit cloud's light
// at 1 (`VolumeUniforms::haze_light.w`; 0 means 1); the composite scales it back.
fn accumulated(c: vec4<f32>) -> vec4<f32> {
    let k = select(1.0, u.haze_light.w, u.haze_light.w > 0.0);
    return vec4<f32>(c.rgb * k, c.a);
}
