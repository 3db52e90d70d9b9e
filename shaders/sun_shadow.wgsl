// The clouds' transmittance toward the sun from any point `p` of the scene, from the light
// volume over the clouds' box (`lo`, `size`): the light volume at `p` inside the box, where
// the sun's ray from `p` enters the box outside it, and full sun when that ray misses the box.
// `light` stores T^(1/8) (light_march.wgsl). Shared by the ground (sky.wgsl) and the shafts of
// light (volume.wgsl); WGSL has no include, so src/render/shaders.rs composes it into both.
fn sun_through_clouds(
    p: vec3<f32>,
    lo: vec3<f32>,
    size: vec3<f32>,
    sun: vec3<f32>,
    light: texture_3d<f32>,
    smp: sampler,
) -> f32 {
    let hi = lo + size;
    let inv = 1.0 / select(sun, vec3<f32>(1e-6), abs(sun) < vec3<f32>(1e-6));
    let t0 = (lo - p) * inv;
    let t1 = (hi - p) * inv;
    let enter = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z));
    let leave = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    if leave < max(enter, 0.0) {
        return 1.0;
    }
    let q = p + sun * max(enter, 0.0);
    let uvw = clamp((q - lo) / size, vec3<f32>(0.0), vec3<f32>(1.0));
    let t = textureSampleLevel(light, smp, uvw, 0.0).r;
    let t2 = t * t;
    let t4 = t2 * t2;
    return t4 * t4;
}
