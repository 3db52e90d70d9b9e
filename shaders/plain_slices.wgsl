// Benchmark baseline only: the plain slice shader of the toolchain notes. Every slice is a
// quad over the whole viewport and every fragment takes five trilinear 3D-texture samples
// (field, light, three noise octaves), with no bounding of the slices and no empty-space skipping.
// `cloudsketch bench` reports the real renderer as a ratio against it.
// Composed after volume_common.wgsl, like volume.wgsl (same uniforms and bind group).

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
    let s = textureSampleLevel(volume_tex, clamp_smp, in.uvw, 0.0);
    let f = s.r;
    let sun = textureSampleLevel(light_tex, clamp_smp, in.uvw, 0.0).r;
    var n = 0.0;
    var scale = 1.0;
    for (var i = 0; i < 3; i = i + 1) {
        n = n + textureSampleLevel(noise_tex, repeat_smp, in.uvw * scale * 4.0, 0.0).r / scale;
        scale = scale * 2.0;
    }
    let d = clamp(f + 0.3 * (n / 1.75 - 0.5) - 0.4, 0.0, 1.0);
    let alpha = 1.0 - exp(-u.media.x * d * u.slicing.z);
    let light = u.sun_color.rgb * sun + u.sky_color.rgb;
    // At the accumulation's light scale, as the slices draw.
    return accumulated(vec4<f32>(light * alpha, alpha));
}
