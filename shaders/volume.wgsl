// Slice-based volume rendering (Schpok et al. 2003, §4): view-aligned slices through the
// cloud's bounding sphere, drawn back to front in one instanced draw and composited with
// premultiplied "over" blending into a linear RGBA target.
//
// Density = blended implicit field (baked in a 3D texture, red) perturbed by octaves of
// periodic noise; lighting = sun × baked transmittance (green) + ambient sky.
// Mirrors `VolumeUniforms` in src/render/gpu_types.rs.

struct Volume {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    grid_min: vec4<f32>,
    grid_inv_size: vec4<f32>,
    sphere: vec4<f32>,
    slicing: vec4<f32>,
    sun_dir: vec4<f32>,
    sun_color: vec4<f32>,
    sky_color: vec4<f32>,
    media: vec4<f32>,
    noise: vec4<f32>,
    octave_offset: array<vec4<f32>, 4>,
};

@group(0) @binding(0) var<uniform> u: Volume;
@group(0) @binding(1) var field_tex: texture_3d<f32>;
@group(0) @binding(2) var field_smp: sampler;
@group(0) @binding(3) var noise_tex: texture_3d<f32>;
@group(0) @binding(4) var noise_smp: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> VsOut {
    // Slice 0 is the farthest; the quad covers the bounding sphere's cross-section.
    let slice = f32(ii) + u.slicing.y;
    let r = u.sphere.w;
    let d = r - (slice + 0.5) * u.slicing.z;
    let half = sqrt(max(r * r - d * d, 0.0));
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    let c = corners[vi % 6u] * half;
    let world = u.sphere.xyz + u.forward.xyz * d + u.right.xyz * c.x + u.up.xyz * c.y;
    var out: VsOut;
    out.clip = u.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    return out;
}

// Sum of noise octaves in [0, 1], each octave a look-up of the periodic noise volume with
// its own scale (lacunarity^i) and offset (wind).
fn fbm(p: vec3<f32>) -> f32 {
    let octaves = i32(u.noise.w);
    var freq = u.noise.x;
    var amp = 1.0;
    var sum = 0.0;
    var norm = 0.0;
    for (var i = 0; i < 4; i = i + 1) {
        if i >= octaves {
            break;
        }
        let q = p * freq + u.octave_offset[i].xyz;
        sum = sum + amp * textureSampleLevel(noise_tex, noise_smp, q, 0.0).r;
        norm = norm + amp;
        freq = freq * u.noise.y;
        amp = amp * u.noise.z;
    }
    return select(0.5, sum / max(norm, 1e-6), norm > 0.0);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let uvw = (in.world - u.grid_min.xyz) * u.grid_inv_size.xyz;
    if any(uvw < vec3<f32>(0.0)) || any(uvw > vec3<f32>(1.0)) {
        discard;
    }
    let s = textureSampleLevel(field_tex, field_smp, uvw, 0.0);
    let iso = u.media.y;
    let soft = u.media.z;
    let amount = u.media.w;
    // Nothing noise could lift above the surface: skip the noise look-ups.
    if s.r < iso - soft - 0.5 * amount {
        discard;
    }
    let v = s.r + amount * (fbm(in.world) - 0.5);
    let density = smoothstep(iso - soft, iso + soft, v);
    if density <= 0.0 {
        discard;
    }
    let view_dir = normalize(in.world - u.eye.xyz);
    let path = u.slicing.z / max(dot(view_dir, u.forward.xyz), 0.2);
    let alpha = 1.0 - exp(-u.media.x * density * path);
    let light = u.sun_color.rgb * s.g + u.sky_color.rgb;
    return vec4<f32>(light * alpha, alpha);
}
