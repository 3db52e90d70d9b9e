// Slice-based volume rendering (Schpok et al. 2003, §4): view-aligned slices through the
// cloud's box (its depth along the view), drawn back to front in one instanced draw and composited with
// premultiplied "over" blending into a linear RGBA target.
//
// Density = blended implicit field (red of the volume texture) perturbed by octaves of
// periodic noise (volume_noise.wgsl); lighting = sun × transmittance toward the sun (the
// light volume, which sees the noise) × a two-lobe
// Henyey–Greenstein phase, plus octaves of multiple scattering (after Wrenninge 2013: each
// octave sees 0.3 of the extinction, 0.6 of the energy and half the asymmetry), + ambient sky.
// With shafts of light (Dobashi et al. 2000) the same draw also holds spherical shells
// centred at the eye, merged with the slices back to front; `fs_shafts` draws both.
// Composed after volume_common.wgsl (uniforms and bindings), volume_noise.wgsl and
// sun_shadow.wgsl.

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    // The shell this instance draws (−1: a slice).
    @location(1) @interpolate(flat) shell: i32,
    // A shell's points of the pixel's view ray on the near and far planes (homogeneous).
    @location(2) near: vec4<f32>,
    @location(3) far: vec4<f32>,
};

// Distance along the view from the eye to slice `j` (of the image; 0 = farthest).
fn slice_depth(j: f32) -> f32 {
    return dot(u.sphere.xyz - u.eye.xyz, u.forward.xyz) + u.grid_min.w - (j + 0.5) * u.slicing.z;
}

// How many shells lie farther from the eye than `depth` (Shells::beyond in gpu_types.rs).
fn shells_beyond(depth: f32) -> i32 {
    let n = ceil((u.shafts.x - depth) / u.shafts.y - 0.5);
    return i32(clamp(n, 0.0, u.shells.w));
}

// Where slice `j` of this draw comes among the draw's slices and shells, back to front.
fn slice_position(j: i32) -> i32 {
    let first = i32(u.shells.x);
    let beyond = clamp(shells_beyond(slice_depth(f32(j) + u.slicing.y)), first, first + i32(u.shells.y));
    return j + beyond - first;
}

// The rectangle, along the image's right and up from `centre` (min xy, max zw), around the
// polygon where the plane through `centre` facing the view cuts the grid's box: the crossings
// of its twelve edges. Empty (all zero) where the plane misses the box. Fragments of the
// rectangle outside the box are still discarded; most of those of the bounding sphere's
// square, which the slices covered before, are no longer drawn.
fn slice_bounds(centre: vec3<f32>) -> vec4<f32> {
    let n = u.forward.xyz;
    let lo = u.grid_min.xyz;
    let size = 1.0 / u.grid_inv_size.xyz;
    var axes = array<vec3<f32>, 3>(
        vec3<f32>(size.x, 0.0, 0.0), vec3<f32>(0.0, size.y, 0.0), vec3<f32>(0.0, 0.0, size.z),
    );
    var bounds = vec4<f32>(1e30, 1e30, -1e30, -1e30);
    for (var e = 0u; e < 12u; e = e + 1u) {
        // Edge e runs along axis e / 4 from the corner the bits of e % 4 pick on the others.
        let axis = e / 4u;
        let bits = e % 4u;
        let a = lo + f32(bits & 1u) * axes[(axis + 1u) % 3u] + f32(bits >> 1u) * axes[(axis + 2u) % 3u];
        let b = a + axes[axis];
        let da = dot(n, a - centre);
        let db = dot(n, b - centre);
        if (da <= 0.0) != (db <= 0.0) {
            let p = mix(a, b, da / (da - db)) - centre;
            let q = vec2<f32>(dot(p, u.right.xyz), dot(p, u.up.xyz));
            bounds = vec4<f32>(min(bounds.xy, q), max(bounds.zw, q));
        }
    }
    if bounds.x > bounds.z {
        return vec4<f32>(0.0);
    }
    // A margin of a thousandth of the box, so rounding loses no pixel at its rim.
    let margin = 1e-3 * length(size);
    return bounds + vec4<f32>(-margin, -margin, margin, margin);
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> VsOut {
    var out: VsOut;
    out.shell = -1;
    out.near = vec4<f32>(0.0);
    out.far = vec4<f32>(0.0);
    var slice_in_draw = i32(ii);
    if u.shells.y > 0.0 {
        // Slices and the shafts' shells merged back to front: the slices at or before this
        // instance (a binary search over their positions, which only grow) tell which it is.
        let i = i32(ii);
        var lo = 0;
        var hi = i32(u.shells.z);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if slice_position(mid) <= i {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        if lo == 0 || slice_position(lo - 1) != i {
            // A shell: one triangle over the whole image (the other three vertices collapse).
            out.shell = i32(u.shells.x) + i - lo;
            let k = vi % 6u;
            let x = select(-1.0, 3.0, k == 1u);
            let y = select(-1.0, 3.0, k == 2u);
            out.clip = vec4<f32>(x, y, 0.0, 1.0);
            out.near = u.inv_view_proj * vec4<f32>(x, y, 0.0, 1.0);
            out.far = u.inv_view_proj * vec4<f32>(x, y, 1.0, 1.0);
            out.world = vec3<f32>(0.0);
            return out;
        }
        slice_in_draw = lo - 1;
    }
    // Slice 0 is the farthest; slices span the grid box's depth along the view (from
    // grid_min.w toward the eye), and each quad is the rectangle (along the image's right and
    // up) around the polygon where the slice's plane cuts the box.
    let slice = f32(slice_in_draw) + u.slicing.y;
    let d = u.grid_min.w - (slice + 0.5) * u.slicing.z;
    let centre = u.sphere.xyz + u.forward.xyz * d;
    let bounds = slice_bounds(centre);
    var corners = array<vec2<f32>, 6>(
        bounds.xy, bounds.zy, bounds.zw,
        bounds.xy, bounds.zw, bounds.xw,
    );
    let c = corners[vi % 6u];
    let world = centre + u.right.xyz * c.x + u.up.xyz * c.y;
    out.clip = u.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    return out;
}

// Henyey–Greenstein's phase function scaled so that isotropic scattering is 1 (not 1/4π):
// the image keeps today's brightness at g = 0.
fn hg(cos_theta: f32, g: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * cos_theta;
    // d^(−3/2) from one inverse square root instead of a square root and a division.
    let r = inverseSqrt(d);
    return (1.0 - g * g) * r * r * r;
}

// Two lobes: mostly forward (g), a little backward (−g/3), so the side facing the sun keeps
// its light.
fn phase(cos_theta: f32, g: f32) -> f32 {
    return mix(hg(cos_theta, -g / 3.0), hg(cos_theta, g), 0.8);
}

// The multiple scattering's weight per unit of the Multiple scattering control: its default,
// 0.5, gives the weight that brings the slices closest to a path trace of the same cloud
// (scripts/check_exports.py light; docs/export-formats.md).
const MS_GAIN: f32 = 4.3;

// Light reaching the sample from the sun: `s` is the light volume's T^(1/8) (transmittance
// toward the sun, stored so deep shadow keeps its precision), raised to Dirtiness, through
// the phase function for the angle between the sun's light and the view ray. `diffusion` (the
// light volume's blue, doubled) scales the light scattered many times by where the sample lies
// in the cloud's thickness along the sun's rays and by how much cloud surrounds it
// (light_march.wgsl).
fn sun_light(s: f32, diffusion: f32, cos_theta: f32) -> f32 {
    let dirt = u.sun_color.w;
    let g = u.sun_dir.w;
    // T^k = exp2(k · log2 T): one logarithm for all the octaves.
    let log_t = 8.0 * dirt * log2(max(s, 1e-4));
    var light = exp2(log_t) * phase(cos_theta, g);
    // Multiple scattering (after Wrenninge 2013): octaves that see less extinction (×0.3
    // each), carry less energy (×0.6) and scatter less forward (×0.5), so light diffuses
    // into thick clouds instead of stopping at their sunny face.
    let ms = MS_GAIN * u.sky_color.w;
    if ms > 0.0 {
        var a = 0.6;
        var b = 0.3;
        var c = 0.5;
        for (var i = 0; i < 3; i = i + 1) {
            light = light + ms * a * exp2(log_t * b) * phase(cos_theta, g * c) * diffusion;
            a = a * 0.6;
            b = b * 0.3;
            c = c * 0.5;
        }
    }
    return light;
}

// One slice's light and opacity at world point `world`, premultiplied; zero where it adds
// nothing (outside the box, no density, below the alpha cut-off). The fragment shaders discard
// there; the marched slices (volume_march.wgsl) call it along each pixel's ray.
fn cloud_at(world: vec3<f32>) -> vec4<f32> {
    let uvw = (world - u.grid_min.xyz) * u.grid_inv_size.xyz;
    if any(uvw < vec3<f32>(0.0)) || any(uvw > vec3<f32>(1.0)) {
        return vec4<f32>(0.0);
    }
    let sample = textureSampleLevel(volume_tex, clamp_smp, uvw, 0.0);
    let field = sample.r;
    let iso = u.media.y;
    let soft = u.media.z;
    let amount = u.media.w;
    let v = noisy_field(field, world, i32(u.noise.y));
    let density = smoothstep(iso - soft, iso + soft, v);
    if density <= 0.0 {
        return vec4<f32>(0.0);
    }
    let view_dir = select(u.forward.xyz, normalize(world - u.eye.xyz), u.eye.w > 0.5);
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
        return vec4<f32>(0.0);
    }
    // Transmittance toward the sun from the light volume (the noise included, at the light's
    // own resolution and octaves: light_march.wgsl). Dirtiness scales the optical depth:
    // T^d = exp(−d·τ). The phase angle is between the sun's light (−sun_dir) and the light
    // going to the eye (−view_dir).
    // The sky's light comes through the cloud above (the light volume's green): bases and
    // hollows get less of it than tops and open sides.
    let lv = textureSampleLevel(light_tex, clamp_smp, uvw, 0.0);
    let sun = sun_light(lv.r, 2.0 * lv.b, dot(view_dir, u.sun_dir.xyz));
    var light = u.sun_color.rgb * sun + u.sky_color.rgb * lv.g;
    if u.haze.w > 0.5 {
        // Aerial perspective: the air between the eye and this sample takes its share of the
        // light out and adds the sky's in its place (far clouds fade into the sky's colour).
        let through = exp(-u.haze.xyz * distance(world, u.eye.xyz));
        light = light * through + u.haze_light.rgb * (1.0 - through);
    }
    return vec4<f32>(light * alpha, alpha);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let c = cloud_at(in.world);
    if c.a <= 0.0 {
        discard;
    }
    return accumulated(c);
}

// Sunlight the air scatters toward the eye over one shell's stretch of the pixel's ray
// (Dobashi et al. 2000): the sun's light through the clouds (the light volume, noise and
// all) × the air's phase × the share the stretch scatters × what the air in front lets
// through. Nothing below the ground, which hides it.
// `a` and `b` are the pixel's points on the near and far planes, `pixel` its centre on the
// target, `shell` the shell's index.
fn shaft(a: vec3<f32>, b: vec3<f32>, pixel: vec2<f32>, shell: i32) -> vec3<f32> {
    let dir = normalize(b - a);
    // The eye in perspective; the pixel's point of the eye's plane in an orthographic view.
    let origin = a - dir * dot(a - u.eye.xyz, dir);
    // A per-pixel offset within the stretch (interleaved gradient noise) turns the shells'
    // steps into fine grain.
    let jitter = fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
    let spacing = u.shafts.y;
    let r = u.shafts.x - (f32(shell) + jitter) * spacing;
    if r <= 0.0 {
        return vec3<f32>(0.0);
    }
    let p = origin + dir * r;
    if p.y < u.air.x {
        return vec3<f32>(0.0);
    }
    let sun = sun_through_clouds(
        p, u.grid_min.xyz, 1.0 / u.grid_inv_size.xyz, u.sun_dir.xyz, light_tex, clamp_smp,
    );
    let sigma = u.shafts.z;
    let scattered = (1.0 - exp(-sigma * spacing)) * exp(-sigma * r);
    return u.sun_color.rgb * (u.shafts.w * sun * scattered * hg(dot(dir, u.sun_dir.xyz), u.air.y));
}

// The slice pass with shafts of light: the cloud into target 0 as fs_main draws it; into
// target 1 the shells' light added (alpha 0) and every slice's opacity, so that clouds in
// front of a shell hide its light. The composite adds target 1 over the cloud.
struct ShaftsOut {
    @location(0) cloud: vec4<f32>,
    @location(1) shafts: vec4<f32>,
};

@fragment
fn fs_shafts(in: VsOut) -> ShaftsOut {
    var out: ShaftsOut;
    if in.shell >= 0 {
        let a = in.near.xyz / in.near.w;
        let b = in.far.xyz / in.far.w;
        let light = vec4<f32>(shaft(a, b, in.clip.xy, in.shell), 0.0);
        out.shafts = light;
        // The shells drawn apart (beyond the clouds' box, only ever drawn with no slice) also
        // into the first target, which the viewport lays under its cloud's box.
        // (Drawn into the target of the shafts apart, which the composite reads as light as
        // it is, not the accumulation: unscaled.)
        out.cloud = select(vec4<f32>(0.0), light, f32(in.shell) < u.air.z);
        return out;
    }
    let c = cloud_at(in.world);
    if c.a <= 0.0 {
        discard;
    }
    out.cloud = accumulated(c);
    out.shafts = vec4<f32>(0.0, 0.0, 0.0, c.a);
    return out;
}

// The shafts of light apart from the clouds' box (VolumeRenderer::draw_outside_shafts): every
// shell of the image summed in one pass over the view (one instance, a shell's triangle), into
// target 1, and those set apart beyond the box (the first u.air.z) into target 0 too. The same
// light as one instance per shell, for a fraction of the cost where fragments are dear (a CPU
// adapter's blending and rasterising of each shell's triangle was most of it).
@fragment
fn fs_outside_shafts(in: VsOut) -> ShaftsOut {
    let a = in.near.xyz / in.near.w;
    let b = in.far.xyz / in.far.w;
    let apart = i32(u.air.z);
    // shaft() of every shell, with what the shells of a pixel share worked out once (the ray,
    // its jitter, the phase, the share a stretch scatters): the loop keeps the part that
    // differs, the sun through the clouds and the air in front. A CPU adapter pays for each
    // shell of each pixel: this pass was most of the frame that turns shafts on.
    let dir = normalize(b - a);
    let origin = a - dir * dot(a - u.eye.xyz, dir);
    let jitter = fract(52.9829189 * fract(dot(in.clip.xy, vec2<f32>(0.06711056, 0.00583715))));
    let spacing = u.shafts.y;
    let sigma = u.shafts.z;
    let size = 1.0 / u.grid_inv_size.xyz;
    var beyond = 0.0;
    var all = 0.0;
    for (var k = 0; k < i32(u.shells.w); k = k + 1) {
        let r = u.shafts.x - (f32(k) + jitter) * spacing;
        if r <= 0.0 {
            // Nearer with every shell: the rest lie behind the eye.
            break;
        }
        let p = origin + dir * r;
        if p.y < u.air.x {
            continue;
        }
        let sun = sun_through_clouds(p, u.grid_min.xyz, size, u.sun_dir.xyz, light_tex, clamp_smp);
        let light = sun * exp(-sigma * r);
        all = all + light;
        if k < apart {
            beyond = beyond + light;
        }
    }
    let scale = u.sun_color.rgb
        * (u.shafts.w * (1.0 - exp(-sigma * spacing)) * hg(dot(dir, u.sun_dir.xyz), u.air.y));
    var out: ShaftsOut;
    // The composite reads this target as light as it is (`beyond_tex`): unscaled.
    out.cloud = vec4<f32>(scale * beyond, 0.0);
    out.shafts = vec4<f32>(scale * all, 0.0);
    return out;
}
