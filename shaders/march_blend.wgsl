// Lays a draw of marched slices (volume_march.wgsl: premultiplied, one texel a pixel) over the
// accumulation target with the slices' "over" blending, as the rasterised slices of the same
// draw would have been blended; fs_shafts also lays the shafts' light and opacity over the
// shafts' target. Composed after fullscreen.wgsl.

@group(0) @binding(0) var marched: texture_2d<f32>;
@group(0) @binding(1) var marched_shafts: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> Fullscreen {
    return fullscreen_vertex(vi);
}

@fragment
fn fs_main(in: Fullscreen) -> @location(0) vec4<f32> {
    let c = textureLoad(marched, vec2<i32>(in.clip.xy), 0);
    if c.a <= 0.0 {
        discard;
    }
    return c;
}

struct Both {
    @location(0) cloud: vec4<f32>,
    @location(1) shafts: vec4<f32>,
};

@fragment
fn fs_shafts(in: Fullscreen) -> Both {
    var out: Both;
    out.cloud = textureLoad(marched, vec2<i32>(in.clip.xy), 0);
    out.shafts = textureLoad(marched_shafts, vec2<i32>(in.clip.xy), 0);
    return out;
}
