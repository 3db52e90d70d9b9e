// One triangle over the whole target: its corner `vi` (0 to 2) in clip space, (−1, −1),
// (3, −1) and (−1, 3). Composed into the shaders that draw over a whole target
// (src/render/shaders.rs).
fn fullscreen_corner(vi: u32) -> vec2<f32> {
    return vec2<f32>(f32((vi << 1u) & 2u), f32(vi & 2u)) * 2.0 - 1.0;
}

