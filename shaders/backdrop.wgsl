// The view behind the cloud as the viewport last drew it (the sky, the ground and the shafts of
// light around the cloud's box), laid again as it is on the frames where none of it changed: on
// CPU adapters one texture read a pixel instead of the ground's shading and the shafts' lay
// (src/render/renderer.rs, VolumeRenderer::draw_backdrop). Composed after fullscreen.wgsl.

@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_smp: sampler;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> Fullscreen {
    return fullscreen_vertex(vi);
}

@fragment
fn fs_main(in: Fullscreen) -> @location(0) vec4<f32> {
    return textureSampleLevel(image, image_smp, in.uv, 0.0);
}
