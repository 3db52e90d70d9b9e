// The light volume (Schpok's shadows, past the paper's per-vertex ones): at every texel of a
// coarse grid over the cloud's box, the transmittance toward the sun through the density the
// slices draw — the field *with its noise* (fewer octaves: `LightSlice.slice.z`) — marched in
// steps toward the sun (red), and how much of the sky's light the cloud above lets through
// (green: the transmittance toward the zenith, diffuse light seeing SKY_EXTINCTION of the
// extinction), so the sky lights tops and open sides, not bases and hollows, and (blue) the
// multiple scattering's diffusion, from the depths toward the sun and away from it through
// the cloud beyond (a second march), times the density around the texel (the field with its
// noise at its mean, `surrounding_density`). One render pass per z-slice of the 3D texture (WebGL2 can
// render into 3D texture slices; it has no compute). Composed after volume_common.wgsl and
// volume_noise.wgsl; `LightSlice` mirrors `LightSliceUniforms` in src/render/gpu_types.rs.

struct LightSlice {
    // x: this slice's z, y: march steps, z: noise octaves.
    slice: vec4<u32>,
    // Texels of the light grid per axis (xyz); w: the march's step length (world).
    dims: vec4<f32>,
};

@group(1) @binding(0) var<uniform> ls: LightSlice;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return vec4<f32>(fullscreen_corner(vi), 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let texel = vec3<f32>(floor(pos.xy), f32(ls.slice.x)) + 0.5;
    let size = 1.0 / u.grid_inv_size.xyz;
    let start = u.grid_min.xyz + texel / ls.dims.xyz * size;
    let dir = u.sun_dir.xyz;
    let h = ls.dims.w;
    let octaves = i32(ls.slice.z);
    var tau = 0.0;
    // A share of a step in, then whole steps, until the ray leaves the box. The share differs
    // from texel to texel (interleaved gradient noise over x, y and the slice): with one
    // share for all, a layer thinner than a few steps falls between a varying number of them
    // as the texels move along it, and its shadow shows bands; varied, the bands become grain
    // finer than a texel, which the slices' trilinear look-ups smooth.
    let grain = dot(floor(pos.xy) + 5.588238 * f32(ls.slice.x), vec2<f32>(0.06711056, 0.00583715));
    var p = start + dir * (fract(52.9829189 * fract(grain)) * h);
    for (var i = 0u; i < ls.slice.y; i = i + 1u) {
        let uvw = (p - u.grid_min.xyz) * u.grid_inv_size.xyz;
        if any(uvw < vec3<f32>(0.0)) || any(uvw > vec3<f32>(1.0)) {
            break;
        }
        tau = tau + density_at(p, octaves) * h;
        p = p + dir * h;
    }
    // The cloud beyond, away from the sun: how deep the light that reached here can diffuse
    // on (volume.wgsl's diffusion of the multiple scattering).
    // Steps of two: the term is smooth (it changes the light by a few percent per optical
    // depth), so half the march's cost buys it.
    var tau_away = 0.0;
    var b = start - dir * (fract(52.9829189 * fract(grain)) * 2.0 * h);
    for (var i = 0u; i < ls.slice.y; i = i + 2u) {
        let uvw = (b - u.grid_min.xyz) * u.grid_inv_size.xyz;
        if any(uvw < vec3<f32>(0.0)) || any(uvw > vec3<f32>(1.0)) {
            break;
        }
        tau_away = tau_away + density_at(b, octaves) * 2.0 * h;
        b = b - dir * (2.0 * h);
    }
    // The sky's light, from straight above: through the texels above this one, a step of two
    // texels each (the same heights in every column of a parity: no jitter, and no bands
    // between neighbouring columns either; soft light needs no finer steps), and this texel's
    // own half step.
    let step = 2.0 * size.y / ls.dims.y;
    var tau_up = 0.5 * density_at(start, octaves) * step;
    var q = start + vec3<f32>(0.0, step, 0.0);
    let top = u.grid_min.y + size.y;
    for (var i = 0u; i < u32(ls.dims.y); i = i + 2u) {
        if q.y > top {
            break;
        }
        tau_up = tau_up + density_at(q, octaves) * step;
        q.y = q.y + step;
    }
    // Diffusion through the cloud's thickness, for volume.wgsl's multiple scattering: a
    // two-stream slab lit on one side sends the light scattered many times back out near its
    // lit face (much cloud beyond to return it) and less near its far face, by
    // 2(τ_away + c) / (τ_sun + τ_away + 2c); and a cloud thin along the sun's rays scatters
    // little of its light more than once, by 1 − exp(−(τ_sun + τ_away)/THIN). In [0, 2],
    // stored halved: the ratio itself, which is smooth (8 bits of it, not of the depths).
    let t_sun = u.media.x * tau;
    let t_away = u.media.x * tau_away;
    // And light scattered many times wanders a few mean free paths every way, not only along
    // the sun's rays: where little cloud surrounds the texel (edges, fringes, thin towers) it
    // leaks out instead of coming back, so a path trace lit from the front is brightest at
    // the cloud's thick centre and dims toward every edge: × (the mean density around)^k, k
    // = ENCLOSED where the cloud is thick along the sun's rays, less where it is thin (a
    // thin sheet scatters little twice whatever surrounds it: the term before says so).
    let thick = 1.0 - exp(-(t_sun + t_away) / THIN);
    let diffusion = (t_away + DIFFUSION) / (t_sun + t_away + 2.0 * DIFFUSION) * thick
        * pow(max(surrounding_density(start), 1e-4), ENCLOSED * thick);
    // Stored as T^(1/8) = exp(−τ/8): 8 bits keep deep shadow (T far below 1/255) that
    // multiple scattering brings back (volume.wgsl raises it to 8·k for T^k).
    return vec4<f32>(
        exp(-t_sun / 8.0),
        exp(-SKY_EXTINCTION * u.media.x * tau_up),
        diffusion,
        1.0,
    );
}

// The mean density around `p`: the point itself and two shells of 14 points (the axes and the
// diagonals) at SURROUND_RADIUS and twice it, in optical depths at full density. Outside the
// box counts as clear air. A blur of the cloud over a couple of mean free paths, of the field
// with the noise at its mean (`mean_density_at`): the noise's cells are far finer than the
// blur, and their look-ups would cost more than the marches (a render of the default cloud
// 1.6× as long on lavapipe with 2 octaves, 1.1× without).
fn surrounding_density(p: vec3<f32>) -> f32 {
    var around = array<vec3<f32>, 14>(
        vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(-1.0, 0.0, 0.0),
        vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, -1.0, 0.0),
        vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0, 0.0, -1.0),
        vec3<f32>(0.57735, 0.57735, 0.57735), vec3<f32>(-0.57735, 0.57735, 0.57735),
        vec3<f32>(0.57735, -0.57735, 0.57735), vec3<f32>(-0.57735, -0.57735, 0.57735),
        vec3<f32>(0.57735, 0.57735, -0.57735), vec3<f32>(-0.57735, 0.57735, -0.57735),
        vec3<f32>(0.57735, -0.57735, -0.57735), vec3<f32>(-0.57735, -0.57735, -0.57735),
    );
    let r = SURROUND_RADIUS / max(u.media.x, 1e-3);
    var sum = mean_density_at(p);
    for (var shell = 1; shell <= 2; shell = shell + 1) {
        for (var i = 0; i < 14; i = i + 1) {
            let q = p + around[i] * (r * f32(shell));
            let uvw = (q - u.grid_min.xyz) * u.grid_inv_size.xyz;
            if all(uvw >= vec3<f32>(0.0)) && all(uvw <= vec3<f32>(1.0)) {
                sum = sum + mean_density_at(q);
            }
        }
    }
    return sum / 29.0;
}

// The density at `p` with the noise at its mean: the field shifted by what the filtered noise
// adds on average, `amount · (mean − 0.5)` (`tier_filters.z`, the base media's; tiers above
// take it too). |n| averages a quarter: the cloud it leaves is thinner than its field.
fn mean_density_at(p: vec3<f32>) -> f32 {
    let uvw = (p - u.grid_min.xyz) * u.grid_inv_size.xyz;
    let field = textureSampleLevel(volume_tex, clamp_smp, uvw, 0.0).r;
    let v = field + u.media.w * (u.tier_filters.z - 0.5);
    return smoothstep(u.media.y - u.media.z, u.media.y + u.media.z, v);
}

// The inner shell's radius of `surrounding_density`, in optical depths at full density: about
// how far light scattered many times wanders (calibrated with the outer shell at twice it
// against Mitsuba's path trace, scripts/check_exports.py light).
const SURROUND_RADIUS: f32 = 1.25;
// How strongly the density around scales the multiple scattering in thick cloud (calibrated
// as above).
const ENCLOSED: f32 = 0.8;

// The diffusion length of the multiple scattering's thickness term, in optical depths: the
// depth over which light scattered many times forgets which face it entered by.
const DIFFUSION: f32 = 4.0;
// The optical depth along the sun's rays over which a cloud goes from scattering its light once
// to scattering it many times.
const THIN: f32 = 4.0;

// The share of the extinction the sky's diffuse light sees on its way down: it comes from the
// whole upper hemisphere and much of it is scattered forward on through, so it reaches deeper
// than the sun's direct beam.
const SKY_EXTINCTION: f32 = 0.35;
