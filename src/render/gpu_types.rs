//! Every struct the GPU reads, `#[repr(C)]` and Pod, in one place. Each is mirrored in the
//! WGSL named on it; only 16-byte-aligned members, so WGSL's uniform layout and Rust agree,
//! and `tests/shaders.rs` compares sizes and member offsets with naga's.

use std::mem::offset_of;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

pub use crate::field::media::{Drift, Drifts};
use crate::field::media::{octave_transform, tier_octave_transform};
use crate::field::{DensityVolume, ISO};
use crate::scene::{Lighting, NoiseBasis, NoiseFilter, OrbitCamera, RenderSettings};

/// Noise octaves the slice shader can composite (`MAX_OCTAVES` in volume_common.wgsl).
pub const MAX_OCTAVES: usize = crate::limits::MAX_OCTAVES;

/// Atmospheric tiers above the base media the shader blends (`MAX_TIERS` in the WGSL).
pub const MAX_TIERS: usize = crate::limits::MAX_TIERS;

/// Uniforms of the slice shaders (`struct Volume` in `shaders/volume_common.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct VolumeUniforms {
    /// World → clip.
    pub view_proj: [[f32; 4]; 4],
    /// Camera position (xyz); w: 1 perspective, 0 orthographic.
    pub eye: [f32; 4],
    /// Unit view direction (xyz).
    pub forward: [f32; 4],
    /// Unit image-plane right (xyz).
    pub right: [f32; 4],
    /// Unit image-plane up (xyz).
    pub up: [f32; 4],
    /// Density grid minimum corner (xyz); w: depth of the farthest slice boundary along the
    /// view direction, from the bounding sphere's centre (slices run from there toward the eye).
    pub grid_min: [f32; 4],
    /// 1 / density grid size (xyz).
    pub grid_inv_size: [f32; 4],
    /// Bounding sphere of the volume: centre (xyz), radius (w; no shader reads it since each
    /// slice covers only its plane's cut through the box, not the sphere's cross-section).
    pub sphere: [f32; 4],
    /// x: total slices, y: index of the first slice of this draw (0 = farthest),
    /// z: spacing between slices in world units, w: Sharpness (the alpha cut-off as a share of
    /// a slice's opacity at full density, Table 2).
    pub slicing: [f32; 4],
    /// Linear sun colour × intensity × 2^exposure (rgb); w: Dirtiness (the exponent on the transmittance
    /// toward the sun).
    pub sun_color: [f32; 4],
    /// Linear sky colour × ambient intensity × 2^exposure (rgb); w: the multiple-scattering weight.
    pub sky_color: [f32; 4],
    /// Unit direction toward the sun (xyz); w: the phase function's asymmetry g.
    pub sun_dir: [f32; 4],
    /// x: extinction per world unit, y: iso-level, z: soft-edge half-width, w: noise amount.
    pub media: [f32; 4],
    /// x: amplitude gain per octave, y: octaves in use, z: Table 2 filter (0 stratus,
    /// 1 cumulus, 2 wispy, 3 veined), w: basis (0 Perlin, 1 Worley).
    pub noise: [f32; 4],
    /// Per-octave transform of world positions into noise-texture coordinates.
    pub octaves: [[[f32; 4]; 4]; MAX_OCTAVES],
    /// Atmospheric tiers: x, y: the floors of tiers 1 and 2, z: the blend height, w: how many.
    pub tiers: [f32; 4],
    /// x, y: Table 2 filters of tiers 1 and 2 (as `noise.z`); z: the mean of the base media's
    /// filtered noise ([`crate::field::media::NoiseMeans`]; 0.5 until the renderer sets it
    /// from its noise volume, for the light pass).
    pub tier_filters: [f32; 4],
    /// Per-octave transforms of tiers 1 and 2 (octave 0 is the base's in every tier).
    pub tier_octaves: [[[f32; 4]; 4]; MAX_OCTAVES * MAX_TIERS],
    /// Clip → world (the inverse of `view_proj`): each pixel's view ray, for the shells.
    pub inv_view_proj: [[f32; 4]; 4],
    /// Shafts of light's shells in this draw: x: the first, y: how many (0: no shafts),
    /// z: slices in this draw, w: shells in the whole image.
    pub shells: [f32; 4],
    /// x: distance of the farthest shell's outer boundary from the eye, y: the shells'
    /// spacing, z: the air's extinction per world unit, w: the shafts' intensity.
    pub shafts: [f32; 4],
    /// x: the ground's height (the air below it is hidden; very low without a ground),
    /// y: the air's phase asymmetry g, z: the shells drawn apart ([`Shells::apart`]), whose
    /// light also goes to the first target.
    pub air: [f32; 4],
    /// Aerial perspective with the physical sky: the air's extinction per world unit (xyz:
    /// what the air between the eye and a sample takes out of its light); w: 1 when on.
    pub haze: [f32; 4],
    /// The light the air adds in its place (rgb): the physical sky's toward the cloud, at this
    /// exposure; w: the scale of the light the slices accumulate (0 or 1: as it is;
    /// [`EIGHT_BIT_LIGHT_SCALE`] in an 8-bit target).
    pub haze_light: [f32; 4],
}

/// The phase asymmetry of the air's scattering in the shafts: mildly forward, so shafts are
/// brightest looking toward the sun, as crepuscular rays are.
pub const AIR_ASYMMETRY: f32 = 0.3;

/// Shells the shafts of light may use in one image, at most.
pub const MAX_SHELLS: u32 = 128;

/// The shafts of light's shells of one image (Dobashi et al. 2000): spheres centred at the
/// eye (planes along the view in an orthographic one), `count` of them evenly spaced from
/// `far` toward the eye, drawn back to front and merged with the slices by their distance
/// along the view, so clouds in front of a shell hide its light and clouds behind it do not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shells {
    /// Shells in the image.
    pub count: u32,
    /// Distance of the farthest shell's outer boundary from the eye.
    pub far: f32,
    /// Distance between neighbouring shells.
    pub spacing: f32,
    /// The farthest shells, beyond the clouds' box, that a cropped view draws apart (see
    /// [`Shells::apart_beyond_the_box`]): 0 where the slices' draws hold every shell.
    pub apart: u32,
}

impl Shells {
    /// The shells of `view` over `volume` in an image of `total` slices: none without shafts
    /// or clouds. They reach from the eye to the farthest point the clouds can shade: the
    /// box's corners carried away from the sun down to the ground (or two box diagonals).
    pub fn new(view: &View, volume: &DensityVolume, total: u32) -> Option<Self> {
        if !view.light.shafts || volume.is_empty() {
            return None;
        }
        let camera = &view.camera;
        let (eye, forward) = (camera.eye(), camera.forward());
        let sun = view.light.sun_direction();
        let diagonal = volume.size.length();
        let far = (0..8)
            .flat_map(|i| {
                let corner = volume.min
                    + volume.size
                        * Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32);
                let reach = if view.light.ground && sun.y > 0.02 {
                    ((corner.y - view.light.ground_height) / sun.y).clamp(0.0, 4.0 * diagonal)
                } else {
                    2.0 * diagonal
                };
                [corner, corner - sun * reach]
            })
            .map(|p| {
                if camera.orthographic {
                    (p - eye).dot(forward)
                } else {
                    (p - eye).length()
                }
            })
            .fold(0.0f32, f32::max);
        if far.is_nan() || far <= 0.0 {
            return None;
        }
        let count = (total / 4).clamp(8, MAX_SHELLS);
        Some(Self {
            count,
            far,
            spacing: far / count as f32,
            apart: 0,
        })
    }

    /// These shells with those beyond the far side of `volume`'s box (as `view` sees it) drawn
    /// apart: no slice lies behind them, so every slice of the image hides them alike and they
    /// can be drawn once, at a fraction of the view's size, with the shafts around the box
    /// (the viewport's [`super::renderer::VolumeRenderer::draw_outside_shafts`]), instead of
    /// in the first chunk of every refinement (most of the shells when the shafts reach down
    /// to a distant ground).
    pub fn apart_beyond_the_box(self, view: &View, volume: &DensityVolume) -> Self {
        let (center, _) = volume.bounding_sphere();
        let forward = view.camera.forward();
        let (_, far) = box_depths(volume, center, forward);
        let boundary = (center - view.camera.eye()).dot(forward) + far;
        Self {
            apart: self.beyond(boundary),
            ..self
        }
    }

    /// How many shells lie farther from the eye than `depth` (the shader's `shells_beyond`).
    pub fn beyond(&self, depth: f32) -> u32 {
        ((self.far - depth) / self.spacing - 0.5)
            .ceil()
            .clamp(0.0, self.count as f32) as u32
    }
}

/// Uniforms of the sky pass: the physical sky, the gradient or the flat colour, and the ground
/// (`struct Sky` in `shaders/sky.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SkyUniforms {
    /// Unit view direction (xyz).
    pub forward: [f32; 4],
    /// Image-plane right × tan(fov/2) × aspect (xyz).
    pub right: [f32; 4],
    /// Image-plane up × tan(fov/2) (xyz).
    pub up: [f32; 4],
    /// sRGB-encoded zenith colour (the background's).
    pub zenith: [f32; 4],
    /// sRGB-encoded horizon colour; w: 1 with the gradient, 0 for a flat sky.
    pub horizon: [f32; 4],
    /// sRGB-encoded colour below the horizon.
    pub ground: [f32; 4],
    /// The eye (xyz); w: 1 with a ground plane.
    pub eye: [f32; 4],
    /// Where a pixel's ray starts across the image plane: right and up half-extents of an
    /// orthographic view (xyz; zero in perspective, where every ray starts at the eye).
    pub origin_right: [f32; 4],
    /// See `origin_right`.
    pub origin_up: [f32; 4],
    /// The light volume's box: minimum corner (xyz); w: the ground's height.
    pub grid_min: [f32; 4],
    /// Its size (xyz); w: 1 when there is a light volume to shade the ground with.
    pub grid_size: [f32; 4],
    /// Unit vector toward the sun (xyz); w: 2^exposure, which scales the picked colours'
    /// light (`tone::light_of`).
    pub sun_dir: [f32; 4],
    /// The ground's sRGB colour in full sun (rgb).
    pub ground_lit: [f32; 4],
    /// Where the shafts drawn apart from the clouds' box are not added (texture coordinates,
    /// v down: x0, y0, x1, y1): the box's rectangle; the whole target without shafts.
    pub keep_out: [f32; 4],
    /// The physical sky (`crate::atmosphere`): x: the light of one unit of its view table
    /// at this exposure; y: 1 with the physical sky; z: the cosine of the sun's angular
    /// radius; w: the sun's azimuth (radians, from +x toward +z).
    pub atmosphere: [f32; 4],
    /// The sun disk's light at this exposure (rgb), with the physical sky.
    pub sun_disk: [f32; 4],
    /// With the physical sky: the sunlight on the ground at this exposure, as a white
    /// surface's light facing the sun (rgb)...
    pub ground_sun: [f32; 4],
    /// ...and the sky's light on it (rgb).
    pub ground_sky: [f32; 4],
}

impl SkyUniforms {
    /// Names and byte offsets of the members, in order (checked against the WGSL struct).
    pub const LAYOUT: [(&'static str, usize); 19] = [
        ("forward", offset_of!(Self, forward)),
        ("right", offset_of!(Self, right)),
        ("up", offset_of!(Self, up)),
        ("zenith", offset_of!(Self, zenith)),
        ("horizon", offset_of!(Self, horizon)),
        ("ground", offset_of!(Self, ground)),
        ("eye", offset_of!(Self, eye)),
        ("origin_right", offset_of!(Self, origin_right)),
        ("origin_up", offset_of!(Self, origin_up)),
        ("grid_min", offset_of!(Self, grid_min)),
        ("grid_size", offset_of!(Self, grid_size)),
        ("sun_dir", offset_of!(Self, sun_dir)),
        ("ground_lit", offset_of!(Self, ground_lit)),
        ("keep_out", offset_of!(Self, keep_out)),
        ("atmosphere", offset_of!(Self, atmosphere)),
        ("sun_disk", offset_of!(Self, sun_disk)),
        ("ground_sun", offset_of!(Self, ground_sun)),
        ("ground_sky", offset_of!(Self, ground_sky)),
        ("", std::mem::size_of::<Self>()),
    ];

    /// The sky of `camera` and `light` in a view of `aspect` (width / height), with the
    /// ground shaded through the light volume over `grid` (its box), if any.
    pub fn new(
        camera: &OrbitCamera,
        light: &Lighting,
        aspect: f32,
        grid: Option<(Vec3, Vec3)>,
    ) -> Self {
        let t = (camera.fov_y_deg.to_radians() * 0.5).tan();
        let [hr, hg, hb] = light.horizon_color;
        let half = camera.distance * t;
        let (origin_right, origin_up) = if camera.orthographic {
            (camera.right() * half * aspect, camera.up() * half)
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        let (min, size) = grid.unwrap_or((Vec3::ZERO, Vec3::ZERO));
        let ground = light.ground as u8 as f32;
        Self {
            eye: camera.eye().extend(ground).to_array(),
            origin_right: origin_right.extend(0.0).to_array(),
            origin_up: origin_up.extend(0.0).to_array(),
            grid_min: min.extend(light.ground_height).to_array(),
            grid_size: size.extend(grid.is_some() as u8 as f32).to_array(),
            sun_dir: light
                .sun_direction()
                .extend(light.exposure.exp2())
                .to_array(),
            ground_lit: Vec3::from(light.ground_color).extend(1.0).to_array(),
            forward: camera.forward().extend(0.0).to_array(),
            right: (camera.right() * t * aspect).extend(0.0).to_array(),
            up: (camera.up() * t).extend(0.0).to_array(),
            zenith: Vec3::from(light.background).extend(1.0).to_array(),
            // w: 1 for the gradient, 0 for one flat colour (the ground alone asked for the pass).
            horizon: [hr, hg, hb, light.sky_gradient as u8 as f32],
            // A darker, slightly warmer haze below the horizon.
            ground: [hr * 0.62, hg * 0.6, hb * 0.56, 1.0],
            keep_out: SkyUniforms::NO_SHAFTS,
            ..Self::atmosphere(light)
        }
    }

    /// The physical sky's members of `light` (all zero without it).
    fn atmosphere(light: &Lighting) -> Self {
        if !light.physical_sky {
            return Self::default();
        }
        let exposure = light.exposure.exp2();
        let scale = light.physical_scale() * exposure;
        let sky = crate::atmosphere::sky(light.sun_elevation_deg);
        // The disk's radiance: the sun's irradiance spread over its solid angle, capped
        // within half floats (it maps to white whatever its colour's share).
        let solid_angle = std::f32::consts::TAU * (1.0 - crate::atmosphere::SUN_RADIUS.cos());
        let disk = (sky.sun_at_eye * (scale / solid_angle)).min(Vec3::splat(3.0e4));
        Self {
            atmosphere: [
                scale / SKY_TABLE_SCALE,
                1.0,
                crate::atmosphere::SUN_RADIUS.cos(),
                light.sun_azimuth_deg.to_radians(),
            ],
            sun_disk: disk.extend(0.0).to_array(),
            // A white surface facing the sun: 1/π of the sun's irradiance (4π × its light).
            ground_sun: (sky.sun_at_eye * (4.0 * light.sun_intensity * exposure))
                .extend(0.0)
                .to_array(),
            ground_sky: (sky.sky_on_ground * scale).extend(0.0).to_array(),
            ..Self::default()
        }
    }
}

/// The physical sky's table is stored times this (half floats: a twilight sky's radiance per
/// unit of the sun's, a millionth, would fall among their coarse subnormals); the sky pass's
/// scale (`SkyUniforms::atmosphere`'s x) divides it out.
pub const SKY_TABLE_SCALE: f32 = 1024.0;

impl SkyUniforms {
    /// A `keep_out` over the whole target: no shafts' light added anywhere.
    pub const NO_SHAFTS: [f32; 4] = [-1.0, -1.0, 2.0, 2.0];
}

/// What lies behind the cloud for the composite (`struct Behind` in
/// `shaders/composite.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BehindUniforms {
    /// Where the composited image lies in the view behind it: uv = xy + uv · zw.
    pub place: [f32; 4],
    /// The flat background's display colour (rgb); w: 1 when there is no texture behind.
    pub flat: [f32; 4],
    /// The flat background's light (rgb): `tone::light_of` of its display colour; w: what the
    /// cloud's accumulated light is multiplied by before the tone map (0 or 1: as it is; 8-bit
    /// accumulation stores it scaled by [`EIGHT_BIT_LIGHT_SCALE`]).
    pub flat_light: [f32; 4],
}

/// The scale of the light the slices accumulate in an 8-bit target (plain WebGL2, no float
/// targets): a sunlit cloud's light is over 1, which 8 bits would clip; scaled, it fits up to
/// 1 / this, 2.5 times the default sun (0.8); the presets' light fits, the sunset's included.
/// The composite scales it back. (A quarter, chosen for a sun of 1.6, spent a bit on light no
/// preset reaches: the stratus seen from below was a level off the float path's.)
pub const EIGHT_BIT_LIGHT_SCALE: f32 = 0.5;

impl BehindUniforms {
    /// Names and byte offsets of the members, in order (checked against the WGSL struct).
    pub const LAYOUT: [(&'static str, usize); 4] = [
        ("place", offset_of!(Self, place)),
        ("flat", offset_of!(Self, flat)),
        ("flat_light", offset_of!(Self, flat_light)),
        ("", std::mem::size_of::<Self>()),
    ];

    /// Over the flat background of display colour `shown`, the image lying at `place`.
    pub fn flat(place: [f32; 4], [r, g, b]: [f32; 3]) -> Self {
        let [lr, lg, lb] = super::tone::light_of([r, g, b]).to_array();
        Self {
            place,
            flat: [r, g, b, 1.0],
            flat_light: [lr, lg, lb, 0.0],
        }
    }

    /// Over a backdrop texture, the image lying at `place` in it.
    pub fn backdrop(place: [f32; 4]) -> Self {
        Self {
            place,
            ..Self::default()
        }
    }

    /// The same, for a cloud accumulated with its light scaled by `scale`
    /// (`resources::accumulation_light_scale`).
    pub fn accumulated_at(mut self, scale: f32) -> Self {
        self.flat_light[3] = 1.0 / scale;
        self
    }
}

/// Uniforms of one slice of the light volume pass (`struct LightSlice` in
/// `shaders/light_march.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LightSliceUniforms {
    /// x: this slice's z, y: march steps, z: noise octaves, w: unused.
    pub slice: [u32; 4],
    /// Texels of the light grid per axis (xyz); w: the march's step length (world).
    pub dims: [f32; 4],
}

impl LightSliceUniforms {
    /// Names and byte offsets of the members, in order (checked against the WGSL struct).
    pub const LAYOUT: [(&'static str, usize); 3] = [
        ("slice", offset_of!(Self, slice)),
        ("dims", offset_of!(Self, dims)),
        ("", std::mem::size_of::<Self>()),
    ];
}

/// Uniforms of one slice of the GPU field evaluation (`struct FieldSlice` in
/// `shaders/field_eval.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FieldSliceUniforms {
    /// Centre of texel (0, 0, 0) (xyz) and the texel side (w).
    pub first_center: [f32; 4],
    /// x: this slice's z, y: primitive count, z: rows of the primitive texture, w: unused.
    pub slice: [u32; 4],
}

impl FieldSliceUniforms {
    /// Names and byte offsets of the members, in order (checked against the WGSL struct).
    pub const LAYOUT: [(&'static str, usize); 3] = [
        ("first_center", offset_of!(Self, first_center)),
        ("slice", offset_of!(Self, slice)),
        ("", std::mem::size_of::<Self>()),
    ];
}

/// What one image of the volume shows: a plain, `Send + Sync` copy of the document's view,
/// light and render settings (the renderer turns it into uniforms).
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    /// The camera.
    pub camera: OrbitCamera,
    /// Sun and sky.
    pub light: Lighting,
    /// Media and quality.
    pub render: RenderSettings,
    /// How far the wind and torque of the base media and of each tier (keyed ones
    /// integrated) have carried the noise by the scene's time ([`Drifts::of`]).
    pub drift: Drifts,
    /// Width / height of the whole view.
    pub aspect: f32,
    /// The part of the view this image covers, in normalised device coordinates
    /// (x0, y0, x1, y1; y up): the image is drawn only where the cloud can be. [`FULL_VIEW`]
    /// covers it all.
    pub crop: [f32; 4],
}

/// A [`View::crop`] covering the whole view.
pub const FULL_VIEW: [f32; 4] = [-1.0, -1.0, 1.0, 1.0];

/// Maps the crop rectangle of normalised device coordinates onto the whole image.
pub fn crop_matrix(crop: [f32; 4]) -> Mat4 {
    let [x0, y0, x1, y1] = crop;
    let (w, h) = ((x1 - x0).max(1e-6), (y1 - y0).max(1e-6));
    Mat4::from_cols_array(&[
        2.0 / w,
        0.0,
        0.0,
        0.0,
        0.0,
        2.0 / h,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        0.0,
        -(x1 + x0) / w,
        -(y1 + y0) / h,
        0.0,
        1.0,
    ])
}

impl VolumeUniforms {
    /// Names and byte offsets of the members, in order (checked against the WGSL struct).
    pub const LAYOUT: [(&'static str, usize); 25] = [
        ("view_proj", offset_of!(Self, view_proj)),
        ("eye", offset_of!(Self, eye)),
        ("forward", offset_of!(Self, forward)),
        ("right", offset_of!(Self, right)),
        ("up", offset_of!(Self, up)),
        ("grid_min", offset_of!(Self, grid_min)),
        ("grid_inv_size", offset_of!(Self, grid_inv_size)),
        ("sphere", offset_of!(Self, sphere)),
        ("slicing", offset_of!(Self, slicing)),
        ("sun_color", offset_of!(Self, sun_color)),
        ("sky_color", offset_of!(Self, sky_color)),
        ("sun_dir", offset_of!(Self, sun_dir)),
        ("media", offset_of!(Self, media)),
        ("noise", offset_of!(Self, noise)),
        ("octaves", offset_of!(Self, octaves)),
        ("tiers", offset_of!(Self, tiers)),
        ("tier_filters", offset_of!(Self, tier_filters)),
        ("tier_octaves", offset_of!(Self, tier_octaves)),
        ("inv_view_proj", offset_of!(Self, inv_view_proj)),
        ("shells", offset_of!(Self, shells)),
        ("shafts", offset_of!(Self, shafts)),
        ("air", offset_of!(Self, air)),
        ("haze", offset_of!(Self, haze)),
        ("haze_light", offset_of!(Self, haze_light)),
        ("", std::mem::size_of::<Self>()),
    ];

    /// Uniforms for drawing slices `range` of `total` of `volume` as `view` shows it, with the
    /// shafts of light's `shells` that lie among them (see [`VolumeUniforms::shells_of`]).
    pub fn new(
        view: &View,
        volume: &DensityVolume,
        total: u32,
        range: std::ops::Range<u32>,
        shells: Option<&Shells>,
    ) -> Self {
        let first = range.start;
        let (center, radius) = volume.bounding_sphere();
        let total = total.max(1);
        let (camera, light, r) = (&view.camera, &view.light, &view.render);
        let exposure = light.exposure.exp2();
        let sun_color = light.sun_light() * exposure;
        let sky_color = light.sky_light() * exposure;
        let inv_size = Vec3::ONE / volume.size.max(Vec3::splat(1e-6));
        let octaves = r.noise_octaves.min(MAX_OCTAVES as u32);
        // Slices span only the depth the grid's box takes along the view (a flat layer seen
        // edge-on takes far less than its bounding sphere's diameter), farthest first.
        let forward = camera.forward();
        let (near, far) = box_depths(volume, center, forward);
        let spacing = (far - near).max(1e-6) / total as f32;
        let filter_code = |f: NoiseFilter| match f {
            NoiseFilter::Stratus => 0.0,
            NoiseFilter::Cumulus => 1.0,
            NoiseFilter::Wispy => 2.0,
            NoiseFilter::Veined => 3.0,
        };
        let filter = filter_code(r.noise_filter);
        let view_proj = crop_matrix(view.crop) * camera.view_projection(view.aspect);
        let eye = camera.eye();
        // The shells among slices `range`: those beyond the far boundary of its first slice
        // (all of them when it is the image's first) and not beyond the far boundary of the
        // slice after its last (all the rest when it is the image's last).
        let (shell_range, shafts) = match shells {
            Some(s) => {
                let boundary = |j: u32| (center - eye).dot(forward) + far - j as f32 * spacing;
                // The shells drawn apart are in no draw of slices.
                let k0 = if first == 0 {
                    s.apart
                } else {
                    s.beyond(boundary(first)).max(s.apart)
                };
                let k1 = if range.end >= total {
                    s.count
                } else {
                    s.beyond(boundary(range.end)).max(k0)
                };
                (
                    [k0 as f32, k1.saturating_sub(k0) as f32, s.count as f32],
                    [s.far, s.spacing, light.shaft_density, light.shaft_intensity],
                )
            }
            None => ([0.0; 3], [1.0, 1.0, 0.0, 0.0]),
        };
        let ground = if light.ground {
            light.ground_height
        } else {
            -1.0e30
        };
        let tiers = &r.tiers[..r.tiers.len().min(MAX_TIERS)];
        let floors = r.tier_floors();
        let floor = |k: usize| floors.get(k).copied().unwrap_or(f32::MAX);
        let tier_filter = |k: usize| tiers.get(k).map_or(filter, |t| filter_code(t.filter));
        let basis = match r.noise_basis {
            NoiseBasis::Perlin => 0.0,
            NoiseBasis::Worley => 1.0,
        };
        Self {
            view_proj: view_proj.to_cols_array_2d(),
            // w: 1 perspective, 0 orthographic (every view ray is `forward`).
            eye: eye
                .extend(if camera.orthographic { 0.0 } else { 1.0 })
                .to_array(),
            forward: camera.forward().extend(0.0).to_array(),
            right: camera.right().extend(0.0).to_array(),
            up: camera.up().extend(0.0).to_array(),
            grid_min: volume.min.extend(far).to_array(),
            grid_inv_size: inv_size.extend(0.0).to_array(),
            sphere: center.extend(radius).to_array(),
            slicing: [total as f32, first as f32, spacing, r.sharpness],
            sun_color: sun_color.extend(r.dirtiness).to_array(),
            sky_color: sky_color.extend(light.multiple_scattering).to_array(),
            sun_dir: light
                .sun_direction()
                .extend(light.forward_scattering)
                .to_array(),
            media: [
                r.opacity,
                ISO,
                r.softness,
                if octaves == 0 { 0.0 } else { r.noise_amount },
            ],
            noise: [0.5, octaves as f32, filter, basis],
            octaves: std::array::from_fn(|i| {
                octave_transform(r, i, view.drift.base).to_cols_array_2d()
            }),
            tiers: [floor(0), floor(1), r.tier_blend, tiers.len() as f32],
            tier_filters: [tier_filter(0), tier_filter(1), 0.5, 0.0],
            tier_octaves: std::array::from_fn(|j| {
                tier_octave_transform(r, 1 + j / MAX_OCTAVES, j % MAX_OCTAVES, &view.drift)
                    .to_cols_array_2d()
            }),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            shells: [
                shell_range[0],
                shell_range[1],
                range.end.saturating_sub(first) as f32,
                shell_range[2],
            ],
            shafts,
            air: [
                ground,
                AIR_ASYMMETRY,
                shells.map_or(0.0, |s| s.apart as f32),
                0.0,
            ],
            ..Self::haze(light, center - eye, exposure)
        }
    }

    /// The aerial perspective of `light`'s physical sky (none without it), the cloud's centre
    /// `toward` from the eye.
    fn haze(light: &Lighting, toward: Vec3, exposure: f32) -> Self {
        if !light.physical_sky {
            return Self::zeroed();
        }
        let sky = crate::atmosphere::sky(light.sun_elevation_deg);
        // The air's own light over a few kilometres is near the sky's at the horizon (a long
        // path through the same low air), looking down as well: the table below the horizon
        // holds the ground beyond, not the air.
        let level = Vec3::new(toward.x, toward.y.max(0.0), toward.z);
        let seen = sky.radiance(
            level.normalize_or(Vec3::NEG_Z),
            light.sun_azimuth_deg.to_radians(),
        ) * (light.physical_scale() * exposure);
        Self {
            haze: (crate::atmosphere::air_extinction() * crate::atmosphere::KM_PER_UNIT)
                .extend(1.0)
                .to_array(),
            haze_light: seen.extend(0.0).to_array(),
            ..Self::zeroed()
        }
    }
}

/// Nearest and farthest depth of the grid box's corners along `forward`, from `center`.
pub fn box_depths(volume: &DensityVolume, center: Vec3, forward: Vec3) -> (f32, f32) {
    (0..8)
        .map(|i| {
            let corner = volume.min
                + volume.size * Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32);
            (corner - center).dot(forward)
        })
        .fold((f32::MAX, f32::MIN), |(a, b), d| (a.min(d), b.max(d)))
}

pub use crate::scene::srgb_to_linear;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    /// The whole view of `scene` at aspect 1.5, and its field baked coarsely.
    fn view_and_volume(scene: &Scene) -> (View, DensityVolume) {
        let volume = crate::field::bake(&crate::derive::field_of(scene), 16);
        let view = View {
            camera: scene.camera.clone(),
            light: scene.light.clone(),
            render: scene.render.clone(),
            drift: Drifts::default(),
            aspect: 1.5,
            crop: FULL_VIEW,
        };
        (view, volume)
    }

    #[test]
    fn uniforms_cover_the_volume() {
        let scene = Scene::default();
        let (view, volume) = view_and_volume(&scene);
        let u = VolumeUniforms::new(&view, &volume, 64, 10..20, None);
        let center = Vec3::from_slice(&u.sphere[..3]);
        assert!(center.abs_diff_eq(volume.min + volume.size * 0.5, 1e-4));
        // The slices span the box's depth along the view, inside the bounding sphere.
        let (near, far) = box_depths(&volume, center, scene.camera.forward());
        assert!((u.slicing[2] * 64.0 - (far - near)).abs() < 1e-4);
        assert!(far - near <= 2.0 * u.sphere[3] + 1e-4 && u.grid_min[3] == far);
        assert_eq!(
            Mat4::from_cols_array_2d(&u.view_proj),
            scene.camera.view_projection(1.5)
        );
        assert_eq!(u.slicing[1], 10.0);
    }

    #[test]
    fn refinement_chunks_share_out_the_shells_once_each_among_their_slices() {
        let mut scene = Scene::default();
        scene.light.shafts = true;
        let (view, volume) = view_and_volume(&scene);
        let total = 100;
        let shells = Shells::new(&view, &volume, total).expect("shells with shafts on");
        assert_eq!(shells.count, 25);
        // The shells reach past the cloud's far side.
        let (center, _) = volume.bounding_sphere();
        let eye = scene.camera.eye();
        let forward = scene.camera.forward();
        let (_, far) = box_depths(&volume, center, forward);
        assert!(shells.far >= (center - eye).dot(forward) + far);
        let mut next = 0;
        for range in [0..7, 7..40, 40..41, 41..100] {
            let u = VolumeUniforms::new(&view, &volume, total, range.clone(), Some(&shells));
            let (k0, m) = (u.shells[0] as u32, u.shells[1] as u32);
            assert_eq!(k0, next, "chunk {range:?} starts at shell {k0}");
            assert_eq!(u.shells[2] as u32, range.len() as u32);
            next = k0 + m;
            // Each shell lies between the chunk's first slice's far boundary and the next
            // chunk's.
            let boundary = |j: u32| (center - eye).dot(forward) + far - j as f32 * u.slicing[2];
            for k in k0..k0 + m {
                let r = shells.far - (k as f32 + 0.5) * shells.spacing;
                assert!(range.start == 0 || r <= boundary(range.start) + 1e-4);
                assert!(range.end == total || r > boundary(range.end) - 1e-4);
            }
        }
        assert_eq!(next, shells.count);
        // Without shafts or without a cloud there are none.
        let off = View {
            light: Lighting::default(),
            ..view.clone()
        };
        assert!(Shells::new(&off, &volume, total).is_none());
        assert!(Shells::new(&view, &DensityVolume::default(), total).is_none());
    }

    #[test]
    fn shells_drawn_apart_are_those_beyond_the_box_and_no_chunk_draws_them() {
        // The default view with the ground far below: most shells lie beyond the cloud's box
        // (the shafts reach down to the ground), and the first chunk used to draw them all.
        let mut scene = Scene::default();
        scene.light.shafts = true;
        scene.light.ground = true;
        scene.light.ground_height = -20.0;
        let (view, volume) = view_and_volume(&scene);
        let total = 128;
        let shells = Shells::new(&view, &volume, total)
            .expect("shells")
            .apart_beyond_the_box(&view, &volume);
        let (center, _) = volume.bounding_sphere();
        let forward = scene.camera.forward();
        let (_, far) = box_depths(&volume, center, forward);
        let back = (center - scene.camera.eye()).dot(forward) + far;
        assert!(
            shells.apart > 0 && shells.apart < shells.count,
            "{shells:?}"
        );
        for k in 0..shells.count {
            let r = shells.far - (k as f32 + 0.5) * shells.spacing;
            assert_eq!(
                k < shells.apart,
                r > back,
                "shell {k} at {r} (box's back {back})"
            );
        }
        // The chunks share out the rest once each; the outside pass is told which to set apart.
        let mut next = shells.apart;
        for range in [0..1, 1..60, 60..128] {
            let u = VolumeUniforms::new(&view, &volume, total, range.clone(), Some(&shells));
            assert_eq!(u.shells[0] as u32, next, "chunk {range:?}");
            next += u.shells[1] as u32;
            assert_eq!(u.air[2] as u32, shells.apart);
        }
        assert_eq!(next, shells.count);
    }

    #[test]
    fn a_crop_maps_its_rectangle_onto_the_image() {
        let crop = [-0.5, 0.0, 0.25, 1.0];
        let m = crop_matrix(crop);
        let at = |x: f32, y: f32| {
            let c = m * glam::Vec4::new(x * 3.0, y * 3.0, 0.4, 3.0);
            (c.x / c.w, c.y / c.w)
        };
        assert_eq!(at(-0.5, 0.0), (-1.0, -1.0));
        assert_eq!(at(0.25, 1.0), (1.0, 1.0));
        assert_eq!(crop_matrix(FULL_VIEW), Mat4::IDENTITY);
    }

    #[test]
    fn wind_carries_the_noise_and_finer_octaves_move_faster() {
        let r = RenderSettings {
            wind: [2.0, 0.0],
            ..Default::default()
        };
        let p = Vec3::new(1.0, 2.0, 3.0);
        // After t seconds, the noise seen at p + wind·t·speed is what was at p at time 0.
        for i in [0, 3] {
            let speed = 1.0 + 0.5 * i as f32;
            let before =
                octave_transform(&r, i, Drift::steady(r.wind, r.torque, 0.0)).transform_point3(p);
            let moved = p + Vec3::new(2.0, 0.0, 0.0) * 1.5 * speed;
            let after = octave_transform(&r, i, Drift::steady(r.wind, r.torque, 1.5))
                .transform_point3(moved);
            assert!(
                before.abs_diff_eq(after, 1e-4),
                "octave {i}: {before} vs {after}"
            );
        }
        // Without wind or torque, time changes nothing.
        let calm = RenderSettings::default();
        assert_eq!(
            octave_transform(&calm, 2, Drift::steady(calm.wind, calm.torque, 0.0)),
            octave_transform(&calm, 2, Drift::steady(calm.wind, calm.torque, 9.0))
        );
    }

    #[test]
    fn octave_frequency_grows_by_the_lacunarity() {
        let r = RenderSettings::default();
        let p = Vec3::new(1.0, 0.0, 0.0);
        let len = |i| {
            let m = octave_transform(&r, i, Drift::steady(r.wind, r.torque, 0.0));
            (m.transform_point3(p) - m.transform_point3(Vec3::ZERO)).length()
        };
        assert!((len(0) - 1.0 / r.noise_scale).abs() < 1e-5);
        for i in 1..MAX_OCTAVES {
            assert!((len(i) / len(i - 1) - r.detail).abs() < 1e-3);
        }
    }

    #[test]
    fn srgb_conversion_endpoints() {
        assert_eq!(srgb_to_linear([0.0, 1.0, 0.5]).x, 0.0);
        assert!((srgb_to_linear([0.0, 1.0, 0.5]).y - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear([0.0, 1.0, 0.5]).z - 0.214).abs() < 1e-3);
    }
}
