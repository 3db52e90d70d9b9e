// The sky behind the cloud when the document asks for a gradient (Lighting::sky_gradient):
// the background colour at the zenith, the horizon colour at eye level, and below the horizon
// a darker haze, by each pixel's view ray. Colours are sRGB-encoded, as the flat background
// (the clear colour) is. `Sky` mirrors `SkyUniforms` in src/render/gpu_types.rs.

struct Sky {
    // Unit view direction (xyz).
    forward: vec4<f32>,
    // Image-plane right × tan(fov/2) × aspect, and up × tan(fov/2) (xyz).
    right: vec4<f32>,
    up: vec4<f32>,
    // sRGB-encoded colours (rgb).
    zenith: vec4<f32>,
    horizon: vec4<f32>,
    ground: vec4<f32>,
};

@group(0) @binding(0) var<uniform> sky: Sky;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    // One triangle covering the viewport.
    let x = f32(i32(vi & 1u) * 4 - 1);
    let y = f32(i32(vi >> 1u) * 4 - 1);
    var out: VsOut;
    out.clip = vec4<f32>(x, y, 0.0, 1.0);
    out.ndc = vec2<f32>(x, y);
    return out;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let d = normalize(sky.forward.xyz + in.ndc.x * sky.right.xyz + in.ndc.y * sky.up.xyz);
    let e = d.y;
    var colour: vec3<f32>;
    if e >= 0.0 {
        colour = mix(sky.horizon.rgb, sky.zenith.rgb, sqrt(min(e / 0.7, 1.0)));
    } else {
        colour = mix(sky.horizon.rgb, sky.ground.rgb, smoothstep(0.0, 0.12, -e));
    }
    return vec4<f32>(colour, 1.0);
}
