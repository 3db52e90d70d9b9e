// The field on the GPU (the bench's baseline for the CPU bake, src/render/field_gpu.rs): one
// render pass per z-slice of the 3D texture (the colour attachment's depth slice, which
// WebGL2 also has; it has no compute), each fragment a texel centre summing every primitive's
// Wyvill kernel (src/field/mod.rs), primitives read from a float texture (WebGL2 has no
// storage buffers). `FieldSlice` mirrors `FieldSliceUniforms` in src/render/gpu_types.rs.

struct FieldSlice {
    // Centre of texel (0, 0, 0) (xyz) and the texel side (w).
    first_center: vec4<f32>,
    // x: this slice's z, y: primitive count, z: rows of the primitive texture.
    slice: vec4<u32>,
};

@group(0) @binding(0) var<uniform> s: FieldSlice;
// Four texels per primitive, in column block i / rows, row i % rows: the centre and strength,
// then the rows of the matrix taking p − centre to the unit ball of its influence.
@group(0) @binding(1) var blobs: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return vec4<f32>(fullscreen_corner(vi), 0.0, 1.0);
}

fn wyvill(q: f32) -> f32 {
    let q2 = q * q;
    return 1.0 - (4.0 / 9.0) * q2 * q + (17.0 / 9.0) * q2 - (22.0 / 9.0) * q;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let texel = vec3<f32>(floor(pos.xy), f32(s.slice.x));
    let p = s.first_center.xyz + texel * s.first_center.w;
    var sum = 0.0;
    for (var i = 0u; i < s.slice.y; i = i + 1u) {
        let row = i % s.slice.z;
        let col = (i / s.slice.z) * 4u;
        let c = textureLoad(blobs, vec2<u32>(col, row), 0);
        let d = p - c.xyz;
        let u = vec3<f32>(
            dot(textureLoad(blobs, vec2<u32>(col + 1u, row), 0).xyz, d),
            dot(textureLoad(blobs, vec2<u32>(col + 2u, row), 0).xyz, d),
            dot(textureLoad(blobs, vec2<u32>(col + 3u, row), 0).xyz, d),
        );
        let q = dot(u, u);
        if q < 1.0 {
            sum = sum + c.w * wyvill(q);
        }
    }
    return vec4<f32>(sum, 0.0, 0.0, 1.0);
}
