// Benchmark baseline only: the plain slice shader of the toolchain notes. Every slice is a
// quad over the whole viewport and every fragment takes four trilinear 3D-texture samples
// (field + three noise octaves), with no bounding of the slices and no empty-space skipping.
// `cloudsketch bench` reports the real renderer as a ratio against it.
// Shares the bind group layout and `Volume` uniforms of volume.wgsl.

struct Volume {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    grid_min: vec4<f32>,
    grid_inv_size: vec4<f32>,
    sphere: vec4<f32>,
    slicing: vec4<f32>,
    sun_dir: vec4<f32>,
    sun_color: vec4<f32>,
    sky_color: vec4<f32>,
    media: vec4<f32>,
    noise: vec4<f32>,
    octave_offset: array<vec4<f32>, 4>,
};

@group(0) @binding(0) var<uniform> u: Volume;
@group(0) @binding(1) var field_tex: texture_3d<f32>;
@group(0) @binding(2) var field_smp: sampler;
@group(0) @binding(3) var noise_tex: texture_3d<f32>;
@group(0) @binding(4) var noise_smp: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uvw: vec3<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> VsOut {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    let c = corners[vi % 6u];
    let w = 1.0 - (f32(ii) + u.slicing.y + 0.5) / u.slicing.x;
    var out: VsOut;
    out.clip = vec4<f32>(c, 0.5, 1.0);
    out.uvw = vec3<f32>(c * 0.5 + 0.5, w);
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let f = textureSampleLevel(field_tex, field_smp, in.uvw, 0.0);
    var n = 0.0;
    var scale = 1.0;
    for (var i = 0; i < 3; i = i + 1) {
        n = n + textureSampleLevel(noise_tex, noise_smp, in.uvw * scale * 4.0, 0.0).r / scale;
        scale = scale * 2.0;
    }
    let d = clamp(f.r + 0.3 * (n / 1.75 - 0.5) - 0.4, 0.0, 1.0);
    let alpha = 1.0 - exp(-u.media.x * d * u.slicing.z);
    let light = u.sun_color.rgb * f.g + u.sky_color.rgb;
    return vec4<f32>(light * alpha, alpha);
}
