// The media at probe points, for tests: the slices' noisy field and soft edge (as density_at
// in volume_noise.wgsl takes them) at given world points with given field values, so the CPU's
// media (src/field/media.rs, which the exports bake) can be held against the shader's, tiers
// and all. Composed after volume_common.wgsl and volume_noise.wgsl.

// Each probe: the world point in xyz, the field's value there in w.
@group(1) @binding(0) var<storage, read> probes: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read_write> densities: array<f32>;

// 64 probes a workgroup (PROBE_WORKGROUP in src/render/probe.rs).
@compute @workgroup_size(64)
fn cs_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&probes) {
        return;
    }
    let q = probes[i];
    let v = noisy_field(q.w, q.xyz, i32(u.noise.y));
    densities[i] = smoothstep(u.media.y - u.media.z, u.media.y + u.media.z, v);
}
