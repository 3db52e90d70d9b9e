// Composites the linear, premultiplied volume image into the output (egui's frame or the
// offscreen image). Over a background the view behind the cloud (its display colour D, as
// the backdrop texture or the flat background holds it) is turned back into light B, and the
// pixel's light B·(1 − alpha) + the cloud's + the shafts' is mapped once by the one tone map
// (tone.wgsl); it is blended "over" D so that over D it gives exactly that, and a guide image
// egui drew between the two still shows through the cloud's thin parts. Over no background (a
// transparent image) the cloud's mean light is mapped alone, premultiplied. Into a float
// target (the offscreen linear image an EXR holds) the `_linear` entry points lay the same
// light before any tone map. Composed after fullscreen.wgsl and tone.wgsl.

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var src_smp: sampler;
// The shafts of light (rgb: light added, already hidden where clouds lie in front), with
// fs_shafts only.
@group(0) @binding(2) var shafts_tex: texture_2d<f32>;
// With fs_shafts_beyond only: the light of the shafts' shells beyond the clouds' box, drawn
// apart over the whole view (rgb), and where this image lies in it: uv = xy + uv · zw.
@group(0) @binding(3) var beyond_tex: texture_2d<f32>;
@group(0) @binding(4) var<uniform> beyond_uv: vec4<f32>;

// What lies behind the cloud (`BehindUniforms` in src/render/gpu_types.rs).
struct Behind {
    // Where this image lies in the view behind it: uv = xy + uv · zw.
    place: vec4<f32>,
    // rgb: the flat background's display colour; w: 1 when it is that colour, not the texture.
    flat: vec4<f32>,
    // rgb: the flat background's light (`light_of(flat.rgb)`, worked out once on the CPU);
    // w: what the accumulated light is multiplied by (0: as it is; the 8-bit scale undone).
    flat_light: vec4<f32>,
};

// The cloud's accumulated pixel at `uv`, its light as the slices drew it: an 8-bit target holds
// it scaled down (VolumeUniforms' haze_light.w), which `behind.flat_light.w` undoes.
fn accumulated(uv: vec2<f32>) -> vec4<f32> {
    let p = textureSampleLevel(src, src_smp, uv, 0.0);
    let k = select(1.0, behind.flat_light.w, behind.flat_light.w > 0.0);
    return vec4<f32>(p.rgb * k, p.a);
}

// What lies behind one pixel: its display colour and its light.
struct Seen {
    shown: vec3<f32>,
    light: vec3<f32>,
};

// The view behind the cloud as drawn (display colours), and where it lies.
@group(1) @binding(0) var behind_tex: texture_2d<f32>;
@group(1) @binding(1) var<uniform> behind: Behind;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> Fullscreen {
    return fullscreen_vertex(vi);
}

// What lies behind this image's pixel `uv`: the flat background, or the backdrop's colour
// there turned back into light.
fn behind_at(uv: vec2<f32>) -> Seen {
    if behind.flat.w > 0.5 {
        return Seen(behind.flat.rgb, behind.flat_light.rgb);
    }
    let d = textureSampleLevel(behind_tex, src_smp, behind.place.xy + uv * behind.place.zw, 0.0).rgb;
    return Seen(d, light_of(d));
}

// The premultiplied pixel that, blended "over" what lies behind (`seen`: its display colour
// and light), shows the one tone map of that light behind the cloud's `alpha`, the cloud's
// premultiplied `cloud` light and the `added` light. Its alpha is the cloud's, raised where a
// channel would need less than nothing added (a dark thin cloud over a bright sky).
fn over_behind(seen: Seen, alpha: f32, cloud: vec3<f32>, added: vec3<f32>) -> vec4<f32> {
    let d = seen.shown;
    let shown = display(seen.light * (1.0 - alpha) + cloud + added);
    let ratio = select(vec3<f32>(1.0), shown / max(d, vec3<f32>(1e-6)), d > vec3<f32>(1e-6));
    let a = clamp(max(alpha, 1.0 - min(ratio.r, min(ratio.g, ratio.b))), 0.0, 1.0);
    return vec4<f32>(max(shown - (1.0 - a) * d, vec3<f32>(0.0)), a);
}

// The cloud's premultiplied pixel over no background: its mean light tone-mapped, encoded.
fn cloud(p: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(display(p.rgb / p.a) * p.a, p.a);
}

@fragment
fn fs_main(in: Fullscreen) -> @location(0) vec4<f32> {
    let p = accumulated(in.uv);
    if p.a <= 1e-4 {
        discard;
    }
    return over_behind(behind_at(in.uv), p.a, p.rgb, vec3<f32>(0.0));
}

@fragment
fn fs_transparent(in: Fullscreen) -> @location(0) vec4<f32> {
    let p = accumulated(in.uv);
    if p.a <= 1e-4 {
        discard;
    }
    return cloud(p);
}

// The cloud with the shafts' `light` added, over what lies behind.
fn with_light(uv: vec2<f32>, light: vec3<f32>) -> vec4<f32> {
    let p = accumulated(uv);
    let some = p.a > 1e-4;
    return over_behind(behind_at(uv), select(0.0, p.a, some), select(vec3<f32>(0.0), p.rgb, some), light);
}

// The same over no background: the cloud alone, with the display of the shafts' light added
// (what that light shows over black: mapped alone, sRGB-encoded).
fn with_light_transparent(uv: vec2<f32>, light: vec3<f32>) -> vec4<f32> {
    let p = accumulated(uv);
    var out = vec4<f32>(0.0);
    if p.a > 1e-4 {
        out = cloud(p);
    }
    return vec4<f32>(out.rgb + display(light), out.a);
}

@fragment
fn fs_shafts(in: Fullscreen) -> @location(0) vec4<f32> {
    return with_light(in.uv, textureSampleLevel(shafts_tex, src_smp, in.uv, 0.0).rgb);
}

// A cropped image's shafts (the viewport's): its own shells' light, and that of the shells
// beyond the box, drawn apart, seen through the whole cloud, as the slices would have hidden
// them had they been drawn among them.
fn beyond_light(uv: vec2<f32>) -> vec3<f32> {
    let alpha = accumulated(uv).a;
    let beyond = textureSampleLevel(beyond_tex, src_smp, beyond_uv.xy + uv * beyond_uv.zw, 0.0).rgb;
    let own = textureSampleLevel(shafts_tex, src_smp, uv, 0.0).rgb;
    return own + (1.0 - alpha) * beyond;
}

@fragment
fn fs_shafts_beyond(in: Fullscreen) -> @location(0) vec4<f32> {
    return with_light(in.uv, beyond_light(in.uv));
}

@fragment
fn fs_shafts_beyond_transparent(in: Fullscreen) -> @location(0) vec4<f32> {
    return glow(with_light_transparent(in.uv, beyond_light(in.uv)));
}

// Over no background (a transparent image): light added to nothing has no alpha, and a
// straight-alpha PNG would lose it, so the shafts' light covers the pixel as much as its
// brightest channel (a glow: over a background B it gives light + (1 − a)·B).
fn glow(c: vec4<f32>) -> vec4<f32> {
    let a = clamp(max(c.a, max(c.r, max(c.g, c.b))), 0.0, 1.0);
    return vec4<f32>(min(c.rgb, vec3<f32>(a)), a);
}

@fragment
fn fs_shafts_transparent(in: Fullscreen) -> @location(0) vec4<f32> {
    return glow(with_light_transparent(in.uv, textureSampleLevel(shafts_tex, src_smp, in.uv, 0.0).rgb));
}

// Into a float target: the cloud's premultiplied light as the slices accumulated it (exposure
// applied there), no tone map and no encoding, with `shafts` light added as is, blended over
// the linear light behind it. Premultiplied light over nothing stays light with no alpha (it
// adds to whatever lies under it), so over a transparent background it needs no glow.
fn linear_with_light(uv: vec2<f32>, shafts: vec3<f32>) -> vec4<f32> {
    let p = accumulated(uv);
    var out = vec4<f32>(0.0);
    if p.a > 1e-4 {
        out = p;
    }
    return vec4<f32>(out.rgb + shafts, out.a);
}

@fragment
fn fs_linear(in: Fullscreen) -> @location(0) vec4<f32> {
    let p = accumulated(in.uv);
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
    return linear_with_light(in.uv, beyond_light(in.uv));
}
