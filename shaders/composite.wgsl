// Composites the linear, premultiplied volume image into the output (egui's frame or the
// offscreen image): tone map, encode sRGB, premultiplied "over" blending; with shafts of
// light (fs_shafts) their light is added on top. Into a float target (the offscreen linear
// image an EXR holds) the `_linear` entry points lay the same light before any tone map.

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var src_smp: sampler;
// The shafts of light (rgb: light added, already hidden where clouds lie in front), with
// fs_shafts only.
@group(0) @binding(2) var shafts_tex: texture_2d<f32>;
// With fs_shafts_beyond only: the light of the shafts' shells beyond the clouds' box, drawn
// apart over the whole view (rgb), and where this image lies in it: uv = xy + uv · zw.
@group(0) @binding(3) var beyond_tex: texture_2d<f32>;
@group(0) @binding(4) var<uniform> beyond_uv: vec4<f32>;

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
    return with_light(uv, textureSampleLevel(shafts_tex, src_smp, uv, 0.0).rgb);
}

// The cloud with `shafts` light added on top.
fn with_light(uv: vec2<f32>, shafts: vec3<f32>) -> vec4<f32> {
    let p = textureSampleLevel(src, src_smp, uv, 0.0);
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

// A cropped image's shafts (the viewport's): its own shells' light, and that of the shells
// beyond the box, drawn apart, seen through the whole cloud, as the slices would have hidden
// them had they been drawn among them.
fn with_beyond(uv: vec2<f32>) -> vec4<f32> {
    let alpha = textureSampleLevel(src, src_smp, uv, 0.0).a;
    let beyond = textureSampleLevel(beyond_tex, src_smp, beyond_uv.xy + uv * beyond_uv.zw, 0.0).rgb;
    let own = textureSampleLevel(shafts_tex, src_smp, uv, 0.0).rgb;
    return with_light(uv, own + (1.0 - alpha) * beyond);
}

@fragment
fn fs_shafts_beyond(in: Fullscreen) -> @location(0) vec4<f32> {
    return with_beyond(in.uv);
}

@fragment
fn fs_shafts_beyond_transparent(in: Fullscreen) -> @location(0) vec4<f32> {
    return glow(with_beyond(in.uv));
}

// The same over no background (a transparent image): light added to nothing has no alpha,
// and a straight-alpha PNG would lose it, so the shafts' light covers the pixel as much as
// its brightest channel (a glow: over a background B it gives light + (1 − a)·B).
fn glow(c: vec4<f32>) -> vec4<f32> {
    let a = clamp(max(c.a, max(c.r, max(c.g, c.b))), 0.0, 1.0);
    return vec4<f32>(min(c.rgb, vec3<f32>(a)), a);
}

@fragment
fn fs_shafts_transparent(in: Fullscreen) -> @location(0) vec4<f32> {
    return glow(with_shafts(in.uv));
}

// Into a float target: the cloud's premultiplied light as the slices accumulated it (exposure
// applied there), no tone map and no encoding, with `shafts` light added as is. Premultiplied
// light over nothing stays light with no alpha (it adds to whatever lies under it), so over a
// transparent background it needs no glow.
fn linear_with_light(uv: vec2<f32>, shafts: vec3<f32>) -> vec4<f32> {
    let p = textureSampleLevel(src, src_smp, uv, 0.0);
    var out = vec4<f32>(0.0);
    if p.a > 1e-4 {
        out = p;
    }
    return vec4<f32>(out.rgb + shafts, out.a);
}

@fragment
fn fs_linear(in: Fullscreen) -> @location(0) vec4<f32> {
    let p = textureSampleLevel(src, src_smp, in.uv, 0.0);
    if p.a <= 1e-4 {
        discard;
    }
    return p;
}

@fragment
fn fs_shafts_linear(in: Fullscreen) -> @location(0) vec4<f32> {
    return linear_with_light(in.uv, textureSampleLevel(shafts_tex, src_smp, in.uv, 0.0).rgb);
}

@fragment
fn fs_shafts_beyond_linear(in: Fullscreen) -> @location(0) vec4<f32> {
    let alpha = textureSampleLevel(src, src_smp, in.uv, 0.0).a;
    let beyond = textureSampleLevel(beyond_tex, src_smp, beyond_uv.xy + in.uv * beyond_uv.zw, 0.0).rgb;
    let own = textureSampleLevel(shafts_tex, src_smp, in.uv, 0.0).rgb;
    return linear_with_light(in.uv, own + (1.0 - alpha) * beyond);
}
