// Slice-based volume rendering (Schpok et al. 2003, §4): view-aligned slices through the
// cloud's box (its depth along the view), drawn back to front in one instanced draw and composited with
// premultiplied "over" blending into a linear RGBA target.
//
// Density = blended implicit field (red of the volume texture) perturbed by octaves of
// periodic noise; lighting = sun × transmittance toward the sun (green) × a two-lobe
// Henyey–Greenstein phase, plus octaves of multiple scattering (Wrenninge 2013: each octave
// sees a half of the extinction, half the energy and half the asymmetry), + ambient sky.
// Composed after volume_common.wgsl (uniforms and bindings).

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> VsOut {
    // Slice 0 is the farthest; slices span the grid box's depth along the view (from
    // grid_min.w toward the eye), and each quad covers the bounding sphere's cross-section.
    let slice = f32(ii) + u.slicing.y;
    let r = u.sphere.w;
    let d = u.grid_min.w - (slice + 0.5) * u.slicing.z;
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

// Sum of filtered noise octaves in [0, 1] in atmospheric tier `tier` (0: the base media),
// each octave a look-up of the periodic noise volume (Perlin in red, Worley in green) through
// its own transform; octave 0 moves with the base in every tier (the paper's Base tier).
fn fbm(p: vec3<f32>, tier: i32) -> f32 {
    let octaves = i32(u.noise.y);
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

// The noise at `p` across the atmospheric tiers: each tier from its floor up, blended over
// `tiers.z` around each floor so no row of the image shows a step (only there are two
// tiers evaluated).
fn tiered_noise(p: vec3<f32>) -> f32 {
    let count = i32(u.tiers.w);
    if count == 0 {
        return fbm(p, 0);
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
            total = total + w * fbm(p, k);
        }
        below = above;
    }
    return total;
}

// Henyey–Greenstein's phase function scaled so that isotropic scattering is 1 (not 1/4π):
// the image keeps today's brightness at g = 0.
fn hg(cos_theta: f32, g: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (d * sqrt(d));
}

// Two lobes: mostly forward (g), a little backward (−g/3), so the side facing the sun keeps
// its light.
fn phase(cos_theta: f32, g: f32) -> f32 {
    return mix(hg(cos_theta, -g / 3.0), hg(cos_theta, g), 0.8);
}

// Light reaching the sample from the sun: transmittance `t` (raised to Dirtiness), through
// the phase function for the angle between the sun's light and the view ray.
fn sun_light(t: f32, cos_theta: f32) -> f32 {
    let dirt = u.sun_color.w;
    let g = u.sun_dir.w;
    var light = pow(max(t, 1e-6), dirt) * phase(cos_theta, g);
    // Multiple scattering: octaves with extinction ×½, energy ×½, asymmetry ×½ each.
    let ms = u.sky_color.w;
    if ms > 0.0 {
        var a = 0.5;
        var b = 0.5;
        var c = 0.5;
        for (var i = 0; i < 2; i = i + 1) {
            light = light + ms * a * pow(max(t, 1e-6), dirt * b) * phase(cos_theta, g * c);
            a = a * 0.5;
            b = b * 0.5;
            c = c * 0.5;
        }
    }
    return light;
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let uvw = (in.world - u.grid_min.xyz) * u.grid_inv_size.xyz;
    if any(uvw < vec3<f32>(0.0)) || any(uvw > vec3<f32>(1.0)) {
        discard;
    }
    let sample = textureSampleLevel(volume_tex, clamp_smp, uvw, 0.0);
    let field = sample.r;
    let iso = u.media.y;
    let soft = u.media.z;
    let amount = u.media.w;
    // Nothing noise could lift above the surface: skip the noise look-ups.
    if field < iso - soft - 0.5 * amount {
        discard;
    }
    let v = field + amount * (tiered_noise(in.world) - 0.5);
    let density = smoothstep(iso - soft, iso + soft, v);
    if density <= 0.0 {
        discard;
    }
    let view_dir = select(u.forward.xyz, normalize(in.world - u.eye.xyz), u.eye.w > 0.5);
    let path = u.slicing.z / max(dot(view_dir, u.forward.xyz), 0.2);
    // Sharpness (Table 2): the alpha cut-off is Sharpness × this slice's opacity at full
    // density, and what is above it is stretched back to that opacity: the faint fringe goes,
    // the core keeps its opacity, and the edge's ramp steepens.
    var alpha = 1.0 - exp(-u.media.x * density * path);
    if u.slicing.w > 0.0 {
        let full = 1.0 - exp(-u.media.x * path);
        let cut = u.slicing.w * full;
        alpha = full * max(alpha - cut, 0.0) / max(full - cut, 1e-6);
    }
    if alpha <= 0.0 {
        discard;
    }
    // Dirtiness scales the optical depth toward the sun: T^d = exp(−d·τ). The phase angle is
    // between the sun's light (−sun_dir) and the light going to the eye (−view_dir).
    let sun = sun_light(sample.g, dot(view_dir, u.sun_dir.xyz));
    let light = u.sun_color.rgb * sun + u.sky_color.rgb;
    return vec4<f32>(light * alpha, alpha);
}
