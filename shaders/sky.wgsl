// The sky behind the cloud when the document asks for one: the physical sky
// (Lighting::physical_sky: src/atmosphere.rs's view table, the sun's disk), or a gradient
// (Lighting::sky_gradient): the background colour at the zenith, the horizon colour at eye level, and below the horizon
// a darker haze, by each pixel's view ray; and with Lighting::ground a ground plane whose
// every point is darkened by the clouds' transmittance toward the sun (the light volume where
// the sun's ray from that point enters the clouds' box: nothing shades it before); and the
// shafts of light drawn apart from the clouds' box added outside the box's rectangle. The
// picked colours are display colours: their light (tone.wgsl's `light_of`) is scaled by the
// exposure, the shafts' light added, and the sum mapped by the one tone map. `Sky` mirrors
// `SkyUniforms` in src/render/gpu_types.rs. Composed after sun_shadow.wgsl, fullscreen.wgsl
// and tone.wgsl.

struct Sky {
    // Unit view direction (xyz).
    forward: vec4<f32>,
    // Image-plane right × tan(fov/2) × aspect, and up × tan(fov/2) (xyz).
    right: vec4<f32>,
    up: vec4<f32>,
    // sRGB-encoded colours (rgb); horizon.w: 1 with the gradient, 0 for a flat sky.
    zenith: vec4<f32>,
    horizon: vec4<f32>,
    ground: vec4<f32>,
    // The eye (xyz); w: 1 with a ground plane.
    eye: vec4<f32>,
    // An orthographic view's ray origins across the image (zero in perspective).
    origin_right: vec4<f32>,
    origin_up: vec4<f32>,
    // The light volume's box: minimum (xyz; w: the ground's height), size (xyz; w: 1 when
    // there is a light volume).
    grid_min: vec4<f32>,
    grid_size: vec4<f32>,
    // Toward the sun (xyz); w: 2^exposure.
    sun_dir: vec4<f32>,
    // The ground's sRGB colour in full sun.
    ground_lit: vec4<f32>,
    // Where the shafts' light is not added (texture coordinates, v down: x0, y0, x1, y1): the
    // clouds' box, whose composite adds its own; the whole target when there are no shafts.
    keep_out: vec4<f32>,
    // The physical sky: x: the light of one unit of the view table as stored (× SKY_TABLE_SCALE
    // in src/render/gpu_types.rs); y: 1 with the physical sky; z: the cosine of the sun's
    // angular radius; w: the sun's azimuth (radians).
    atmosphere: vec4<f32>,
    // The sun disk's light (rgb).
    sun_disk: vec4<f32>,
    // The sunlight on a white ground facing the sun, and the sky's light on it (rgb).
    ground_sun: vec4<f32>,
    ground_sky: vec4<f32>,
};

@group(0) @binding(0) var<uniform> sky: Sky;
// Transmittance toward the sun, stored as T^(1/8) (light_march.wgsl).
@group(0) @binding(1) var light_tex: texture_3d<f32>;
@group(0) @binding(2) var light_smp: sampler;
// The light of the shafts' shells summed over the whole view (rgb), drawn apart from the
// clouds' box (VolumeRenderer::draw_outside_shafts).
@group(0) @binding(3) var shafts_tex: texture_2d<f32>;
// The physical sky's radiance seen from the eye (src/atmosphere.rs, SkyTables::view): u the
// azimuth from the sun over π, v the elevation (finer near the horizon); texel i at
// u = i / (w - 1).
@group(0) @binding(4) var atmosphere_tex: texture_2d<f32>;

// The clouds' transmittance toward the sun from ground point `p` (sun_shadow.wgsl).
fn ground_sun(p: vec3<f32>) -> f32 {
    if sky.grid_size.w < 0.5 {
        return 1.0;
    }
    return sun_through_clouds(
        p, sky.grid_min.xyz, sky.grid_size.xyz, sky.sun_dir.xyz, light_tex, light_smp,
    );
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> Fullscreen {
    return fullscreen_vertex(vi);
}

@fragment
fn fs_main(in: Fullscreen) -> @location(0) vec4<f32> {
    return vec4<f32>(display(sky_light(in)) + dither(in.clip.xy), 1.0);
}

// An offset below half a level of 8 bits, the same for each channel, spread over the pixels
// (Jimenez's interleaved gradient noise of the pixel's place on the target): a slow gradient
// rounds to one level here and the next there instead of to bands of each with a contour line
// between them, and a colour on a level (a picked one) stays on it.
fn dither(pixel: vec2<f32>) -> f32 {
    let n = fract(52.9829189 * fract(dot(floor(pixel), vec2<f32>(0.06711056, 0.00583715))));
    return (n - 0.5) * (0.9 / 255.0);
}

// Into a float target (the offscreen linear image an EXR holds): the same light before the
// tone map.
@fragment
fn fs_linear(in: Fullscreen) -> @location(0) vec4<f32> {
    return vec4<f32>(sky_light(in), 1.0);
}

// This pixel's linear light: the physical sky's, or the picked colours' at this exposure,
// and the shafts' outside the clouds' box.
fn sky_light(in: Fullscreen) -> vec3<f32> {
    var light: vec3<f32>;
    if sky.atmosphere.y > 0.5 {
        light = physical_sky(in);
    } else {
        light = light_of(sky_colour(in)) * sky.sun_dir.w;
    }
    let k = sky.keep_out;
    if any(in.uv < k.xy) || any(in.uv >= k.zw) {
        light = light + textureSampleLevel(shafts_tex, light_smp, in.uv, 0.0).rgb;
    }
    return light;
}

// This pixel's display colour (sRGB-encoded, as picked at exposure 0): the gradient or the flat background, the ground over it.
fn sky_colour(in: Fullscreen) -> vec3<f32> {
    let d = normalize(sky.forward.xyz + in.ndc.x * sky.right.xyz + in.ndc.y * sky.up.xyz);
    let e = d.y;
    var colour: vec3<f32>;
    if e >= 0.0 {
        colour = mix(sky.horizon.rgb, sky.zenith.rgb, sqrt(min(e / 0.7, 1.0)));
    } else {
        colour = mix(sky.horizon.rgb, sky.ground.rgb, smoothstep(0.0, 0.12, -e));
    }
    if sky.horizon.w < 0.5 {
        // No gradient: the flat background, the ground alone drawn over it.
        colour = sky.zenith.rgb;
    }
    let ground = ground_at(in, d);
    if ground.w > 0.0 {
        // Sunlight on the ground (by the sun's height) through the clouds, plus the sky's.
        let sun = max(sky.sun_dir.y, 0.0) * ground_sun(ground.xyz);
        let lit = sky.ground_lit.rgb * (0.35 + 0.65 * sun);
        colour = mix(colour, lit, ground.w);
    }
    return colour;
}

// Where this pixel's ray (`d` in perspective) meets the ground plane y = height (xyz), and how
// much the ground shows there (w: 0 where there is no ground or the ray misses it, rising as
// the ray looks down: far ground fades into the horizon's haze).
fn ground_at(in: Fullscreen, d: vec3<f32>) -> vec4<f32> {
    if sky.eye.w < 0.5 {
        return vec4<f32>(0.0);
    }
    let ortho = dot(sky.origin_right.xyz, sky.origin_right.xyz) > 0.0;
    let dir = select(d, sky.forward.xyz, ortho);
    let origin = sky.eye.xyz + in.ndc.x * sky.origin_right.xyz + in.ndc.y * sky.origin_up.xyz;
    let t = (sky.grid_min.w - origin.y) / dir.y;
    if dir.y >= 0.0 || t <= 0.0 {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(origin + dir * t, smoothstep(0.0, 0.25, -dir.y));
}

// The physical sky along this pixel's ray (the view table's light, the sun's disk), and the
// ground plane's light where the ray meets it, fading into the sky with distance.
fn physical_sky(in: Fullscreen) -> vec3<f32> {
    let d = normalize(sky.forward.xyz + in.ndc.x * sky.right.xyz + in.ndc.y * sky.up.xyz);
    let size = vec2<f32>(textureDimensions(atmosphere_tex));
    let across = length(d.xz);
    let sun_across = vec2<f32>(cos(sky.atmosphere.w), sin(sky.atmosphere.w));
    var cos_azimuth = 1.0;
    if across > 1e-5 {
        cos_azimuth = dot(d.xz / across, sun_across);
    }
    let pi = 3.14159265;
    let u = acos(clamp(cos_azimuth, -1.0, 1.0)) / pi;
    let l = clamp(asin(clamp(d.y, -1.0, 1.0)) / (0.5 * pi), -1.0, 1.0);
    let v = 0.5 + 0.5 * sign(l) * sqrt(abs(l));
    let uv = (vec2<f32>(u, v) * (size - 1.0) + 0.5) / size;
    var light = textureSampleLevel(atmosphere_tex, light_smp, uv, 0.0).rgb * sky.atmosphere.x;
    // The sun's disk, its edge softened over a tenth of its radius.
    let c = dot(d, sky.sun_dir.xyz);
    let edge = 1.0 - sky.atmosphere.z;
    let disk = smoothstep(sky.atmosphere.z - 0.1 * edge, sky.atmosphere.z + 0.1 * edge, c);
    light = light + sky.sun_disk.rgb * disk;
    let ground = ground_at(in, d);
    if ground.w > 0.0 {
        // A Lambertian ground of the picked colour (its albedo), lit by the sun through the
        // clouds and by the sky.
        let sun = max(sky.sun_dir.y, 0.0) * ground_sun(ground.xyz);
        let albedo = srgb_to_linear(sky.ground_lit.rgb);
        let lit = albedo * (sky.ground_sun.rgb * sun + sky.ground_sky.rgb);
        light = mix(light, lit, ground.w);
    }
    return light;
}
