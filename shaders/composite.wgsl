// Composites the linear, premultiplied volume image into the output (egui's frame or the
// offscreen image): tone map, encode sRGB, premultiplied "over" blending; with shafts of
// light (fs_shafts) their light is added on top.

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var src_smp: sampler;
// The shafts of light (rgb: light added, already hidden where clouds lie in front), with
// fs_shafts only.
@group(0) @binding(2) var shafts_tex: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> Fullscreen {
    return fullscreen_vertex(vi);
}

fn linear_to_srgb(x: vec3<f32>) -> vec3<f32> {
    let lo = x * 12.92;
    let hi = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, x <= vec3<f32>(0.0031308));
}

// The cloud's premultiplied pixel: its mean light tone-mapped, then encoded.
fn cloud(p: vec4<f32>) -> vec4<f32> {
    let colour = 1.0 - exp(-p.rgb / p.a);
    return vec4<f32>(linear_to_srgb(colour) * p.a, p.a);
}

@fragment
fn fs_main(in: Fullscreen) -> @location(0) vec4<f32> {
    let p = textureSampleLevel(src, src_smp, in.uv, 0.0);
    if p.a <= 1e-4 {
        discard;
    }
    return cloud(p);
}

// The cloud as fs_main draws it with the shafts' light added on top, over the cloud and the
// sky behind it alike (alpha stays the cloud's).
fn with_shafts(uv: vec2<f32>) -> vec4<f32> {
    let p = textureSampleLevel(src, src_smp, uv, 0.0);
    let shafts = textureSampleLevel(shafts_tex, src_smp, uv, 0.0).rgb;
    var out = vec4<f32>(0.0);
    if p.a > 1e-4 {
        out = cloud(p);
    }
    // Added as is (not sRGB-encoded): about what adding that light to mid-tones does, where
    // encoding would brighten faint light five-fold.
    return vec4<f32>(out.rgb + (1.0 - exp(-shafts)), out.a);
}

@fragment
fn fs_shafts(in: Fullscreen) -> @location(0) vec4<f32> {
    return with_shafts(in.uv);
}

// The same over no background (a transparent image): light added to nothing has no alpha,
// and a straight-alpha PNG would lose it, so the shafts' light covers the pixel as much as
// its brightest channel (a glow: over a background B it gives light + (1 − a)·B).
@fragment
fn fs_shafts_transparent(in: Fullscreen) -> @location(0) vec4<f32> {
    let c = with_shafts(in.uv);
    let a = clamp(max(c.a, max(c.r, max(c.g, c.b))), 0.0, 1.0);
    return vec4<f32>(min(c.rgb, vec3<f32>(a)), a);
}
