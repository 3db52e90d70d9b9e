// A flat colour over a paint callback's rectangle (the side panel's background). The colour is
// the render pass's blend constant (the pipeline blends Constant × 1 over nothing), so the pass
// binds nothing. On CPU adapters it costs a fraction of egui's own fill, whose every pixel
// samples a texture and converts gamma (on SwiftShader the panel's fill took 17 ms a frame).
// Composed after fullscreen.wgsl.

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return vec4<f32>(fullscreen_corner(vi), 0.0, 1.0);
}

@fragment
fn fs_main() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0);
}
