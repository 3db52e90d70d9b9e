// Composites the linear, premultiplied volume image into the output (egui's frame or the
// offscreen image): tone map, encode sRGB, premultiplied "over" blending.

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var src_smp: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    // One triangle covering the viewport.
    let x = f32(i32(vi & 1u) * 4 - 1);
    let y = f32(i32(vi >> 1u) * 4 - 1);
    var out: VsOut;
    out.clip = vec4<f32>(x, y, 0.0, 1.0);
    out.uv = vec2<f32>(x * 0.5 + 0.5, 0.5 - y * 0.5);
    return out;
}

fn linear_to_srgb(x: vec3<f32>) -> vec3<f32> {
    let lo = x * 12.92;
    let hi = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, x <= vec3<f32>(0.0031308));
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let p = textureSampleLevel(src, src_smp, in.uv, 0.0);
    if p.a <= 1e-4 {
        discard;
    }
    let colour = 1.0 - exp(-p.rgb / p.a);
    return vec4<f32>(linear_to_srgb(colour) * p.a, p.a);
}
