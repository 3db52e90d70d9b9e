// One triangle over the whole target: its corner `vi` (0 to 2) in clip space, (−1, −1),
// (3, −1) and (−1, 3). Composed into the shaders that draw over a whole target
// (src/render/shaders.rs).
fn fullscreen_corner(vi: u32) -> vec2<f32> {
    return vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u)) * 2.0 - 1.0;
}


// What a full-screen vertex hands on: its place on the target as clip-space x, y (`ndc`) and
// as texture coordinates, v down (`uv`), both interpolated across the target.
struct Fullscreen {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
    @location(1) uv: vec2<f32>,
};

// The full-screen triangle's vertex `vi` with its place on the target.
fn fullscreen_vertex(vi: u32) -> Fullscreen {
    let c = fullscreen_corner(vi);
    var out: Fullscreen;
    out.clip = vec4<f32>(c, 0.0, 1.0);
    out.ndc = c;
    out.uv = vec2<f32>(c.x * 0.5 + 0.5, 0.5 - c.y * 0.5);
    return out;
}
