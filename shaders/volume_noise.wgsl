// The cloud's noise media, shared by the slices (volume.wgsl) and the light volume
// (light_march.wgsl): Table 2's filters, octaves through their transforms, atmospheric tiers.
// Composed after volume_common.wgsl (src/render/shaders.rs).

// Table 2's filters (Schpok et al. 2003) of one octave's noise t in [0, 1] (signed n = 2t − 1):
// stratus n, cumulus |n|, wispy 1 − |2n|, veined (1 + |10n|)⁻¹; each in [0, 1].
fn filtered(t: f32, kind: f32) -> f32 {
    let n = 2.0 * t - 1.0;
    switch i32(kind) {
        case 1: { return abs(n); }
        case 2: { return clamp(1.0 - abs(2.0 * n), 0.0, 1.0); }
        case 3: { return 1.0 / (1.0 + abs(10.0 * n)); }
        default: { return t; }
    }
}

// Sum of the first `octaves` filtered noise octaves in [0, 1] in atmospheric tier `tier` (0:
// the base media),
// each octave a look-up of the periodic noise volume (Perlin in red, Worley in green) through
// its own transform; octave 0 moves with the base in every tier (the paper's Base tier).
fn fbm(p: vec3<f32>, tier: i32, octaves: i32) -> f32 {
    let worley = u.noise.w > 0.5;
    var kind = u.noise.z;
    if tier > 0 {
        kind = u.tier_filters[tier - 1];
    }
    var amp = 1.0;
    var sum = 0.0;
    var norm = 0.0;
    for (var i = 0; i < MAX_OCTAVES; i = i + 1) {
        if i >= octaves {
            break;
        }
        var m = u.octaves[i];
        if tier > 0 && i > 0 {
            m = u.tier_octaves[(tier - 1) * MAX_OCTAVES + i];
        }
        let q = (m * vec4<f32>(p, 1.0)).xyz;
        let s = textureSampleLevel(noise_tex, repeat_smp, q, 0.0);
        sum = sum + amp * filtered(select(s.r, s.g, worley), kind);
        norm = norm + amp;
        amp = amp * u.noise.x;
    }
    return select(0.5, sum / max(norm, 1e-6), norm > 0.0);
}

// The noise (`octaves` of it) at `p` across the atmospheric tiers: each tier from its floor up, blended over
// `tiers.z` around each floor so no row of the image shows a step (only there are two
// tiers evaluated).
fn tiered_noise(p: vec3<f32>, octaves: i32) -> f32 {
    let count = i32(u.tiers.w);
    if count == 0 {
        return fbm(p, 0, octaves);
    }
    let half = max(u.tiers.z * 0.5, 1e-4);
    var total = 0.0;
    var below = 1.0;
    for (var k = 0; k <= MAX_TIERS; k = k + 1) {
        if k > count {
            break;
        }
        // How far `p` is into the tier above this one (1: wholly above its floor).
        var above = 0.0;
        if k < count {
            let floor_k = u.tiers[k];
            above = smoothstep(floor_k - half, floor_k + half, p.y);
        }
        let w = below - above;
        if w > 1e-3 {
            total = total + w * fbm(p, k, octaves);
        }
        below = above;
    }
    return total;
}

// The field perturbed by `octaves` of the noise, `field + amount · (noise − 0.5)`, with them looked
// up coarse to fine only while they can still matter: once the octaves left (each filtered
// into [0, 1]) cannot bring the value back inside the soft edge [iso − soft, iso + soft], the
// density is exactly 0 or exactly 1 whatever they hold, and the look-ups stop. Deep inside
// the cloud and in the air around it that is after none or a few of them; where the value ends
// inside the edge, every octave is summed as `fbm` sums it. (Tiers blend several sums: they
// take every octave.)
fn noisy_field(field: f32, p: vec3<f32>, octaves: i32) -> f32 {
    let amount = u.media.w;
    let lo = u.media.y - u.media.z;
    let hi = u.media.y + u.media.z;
    if amount <= 0.0 || octaves == 0 {
        return field;
    }
    if i32(u.tiers.w) > 0 {
        // Nothing noise could lift above the surface: skip the look-ups.
        if field + 0.5 * amount < lo {
            return field + 0.5 * amount;
        }
        return field + amount * (tiered_noise(p, octaves) - 0.5);
    }
    let worley = u.noise.w > 0.5;
    let kind = u.noise.z;
    let gain = u.noise.x;
    var norm = 0.0;
    var a = 1.0;
    for (var i = 0; i < MAX_OCTAVES; i = i + 1) {
        if i >= octaves {
            break;
        }
        norm = norm + a;
        a = a * gain;
    }
    let scale = amount / norm;
    var amp = 1.0;
    var sum = 0.0;
    var left = norm;
    for (var i = 0; i < MAX_OCTAVES; i = i + 1) {
        // The value if every octave left held 0 (the least) and if each held 1 (the most).
        let least = field + scale * sum - 0.5 * amount;
        let most = least + scale * left;
        if most < lo {
            return most;
        }
        if least > hi {
            return least;
        }
        if i >= octaves {
            break;
        }
        let q = (u.octaves[i] * vec4<f32>(p, 1.0)).xyz;
        let s = textureSampleLevel(noise_tex, repeat_smp, q, 0.0);
        sum = sum + amp * filtered(select(s.r, s.g, worley), kind);
        left = left - amp;
        amp = amp * gain;
    }
    return field + amount * (sum / norm - 0.5);
}

// The slices' density at world point `p` seen with `octaves` of the noise: the field, the
// noise, the iso-level and the soft edge as the slices take them.
fn density_at(p: vec3<f32>, octaves: i32) -> f32 {
    let uvw = (p - u.grid_min.xyz) * u.grid_inv_size.xyz;
    let field = textureSampleLevel(volume_tex, clamp_smp, uvw, 0.0).r;
    let v = noisy_field(field, p, octaves);
    return smoothstep(u.media.y - u.media.z, u.media.y + u.media.z, v);
}
