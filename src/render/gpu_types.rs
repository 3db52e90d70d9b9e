//! Every struct the GPU reads, `#[repr(C)]` and Pod, in one place. Each is mirrored field by
//! field in the WGSL named on it; only vec4-sized members, so std140 and Rust agree.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::field::{FieldGrid, ISO};
use crate::scene::{OrbitCamera, Scene};

/// Octave transforms passed to the slice shader (the noise octaves the renderer supports).
pub const MAX_OCTAVES: usize = 4;

/// Uniforms of `shaders/volume.wgsl` (`struct Volume`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct VolumeUniforms {
    /// World → clip.
    pub view_proj: [[f32; 4]; 4],
    /// Camera position (xyz).
    pub eye: [f32; 4],
    /// Unit view direction (xyz).
    pub forward: [f32; 4],
    /// Unit image-plane right (xyz).
    pub right: [f32; 4],
    /// Unit image-plane up (xyz).
    pub up: [f32; 4],
    /// Field grid minimum corner (xyz).
    pub grid_min: [f32; 4],
    /// 1 / field grid size (xyz).
    pub grid_inv_size: [f32; 4],
    /// Bounding sphere of the volume: centre (xyz), radius (w).
    pub sphere: [f32; 4],
    /// x: total slices, y: index of the first slice of this draw (0 = farthest),
    /// z: spacing between slices in world units, w: unused.
    pub slicing: [f32; 4],
    /// Unit vector toward the sun (xyz).
    pub sun_dir: [f32; 4],
    /// Linear sun colour × intensity (rgb).
    pub sun_color: [f32; 4],
    /// Linear sky colour × ambient intensity (rgb).
    pub sky_color: [f32; 4],
    /// x: extinction per world unit, y: iso-level, z: soft-edge half-width, w: noise amount.
    pub media: [f32; 4],
    /// x: base noise frequency (per world unit), y: lacunarity, z: gain per octave, w: octaves.
    pub noise: [f32; 4],
    /// Per-octave offset of the noise texture coordinates (xyz), for wind animation.
    pub octave_offset: [[f32; 4]; MAX_OCTAVES],
}

/// The volume draw's slice layout: how many slices and where they lie.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slicing {
    /// Total slices through the bounding sphere.
    pub total: u32,
}

impl VolumeUniforms {
    /// Uniforms for drawing `scene`'s field grid from `camera` at image aspect `aspect`.
    pub fn new(
        scene: &Scene,
        camera: &OrbitCamera,
        grid: &FieldGrid,
        aspect: f32,
        slicing: Slicing,
    ) -> Self {
        let (center, radius) = grid.bounding_sphere();
        let total = slicing.total.max(1);
        let light = &scene.light;
        let r = &scene.render;
        let sun = light.sun_direction();
        let sun_color = srgb_to_linear(light.sun_color) * light.sun_intensity;
        let sky_color = srgb_to_linear(light.sky_color) * light.ambient;
        let inv_size = Vec3::ONE / grid.size.max(Vec3::splat(1e-6));
        Self {
            view_proj: camera.view_projection(aspect).to_cols_array_2d(),
            eye: camera.eye().extend(1.0).to_array(),
            forward: camera.forward().extend(0.0).to_array(),
            right: camera.right().extend(0.0).to_array(),
            up: camera.up().extend(0.0).to_array(),
            grid_min: grid.min.extend(0.0).to_array(),
            grid_inv_size: inv_size.extend(0.0).to_array(),
            sphere: center.extend(radius).to_array(),
            slicing: [total as f32, 0.0, 2.0 * radius / total as f32, 0.0],
            sun_dir: sun.extend(0.0).to_array(),
            sun_color: sun_color.extend(1.0).to_array(),
            sky_color: sky_color.extend(1.0).to_array(),
            media: [
                r.opacity,
                ISO,
                r.softness,
                if r.noise_octaves == 0 {
                    0.0
                } else {
                    r.noise_amount
                },
            ],
            noise: [
                1.0 / r.noise_scale.max(1e-3),
                r.detail,
                0.5,
                r.noise_octaves.min(MAX_OCTAVES as u32) as f32,
            ],
            octave_offset: [[0.0; 4]; MAX_OCTAVES],
        }
    }

    /// The same uniforms for a draw that starts at slice `first`.
    pub fn starting_at(mut self, first: u32) -> Self {
        self.slicing[1] = first as f32;
        self
    }
}

/// Uniforms of `shaders/composite.wgsl` (`struct Composite`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct CompositeUniforms {
    /// x: exposure, yzw: unused.
    pub params: [f32; 4],
}

/// sRGB-encoded colour → linear.
pub fn srgb_to_linear(c: [f32; 3]) -> Vec3 {
    let f = |v: f32| {
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    Vec3::new(f(c[0]), f(c[1]), f(c[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_multiples_of_16_bytes() {
        assert_eq!(std::mem::size_of::<VolumeUniforms>() % 16, 0);
        assert_eq!(std::mem::size_of::<CompositeUniforms>(), 16);
    }

    #[test]
    fn uniforms_cover_the_grid() {
        let scene = Scene::default();
        let grid = crate::field::bake(
            &crate::field::Field::from_scene(&scene),
            &crate::field::GridParams {
                resolution: 16,
                sun_dir: Vec3::Y,
                extinction: 1.0,
                softness: 0.1,
            },
        );
        let u = VolumeUniforms::new(&scene, &scene.camera, &grid, 1.5, Slicing { total: 64 });
        let center = Vec3::from_slice(&u.sphere[..3]);
        assert!(center.abs_diff_eq(grid.min + grid.size * 0.5, 1e-4));
        assert!((u.slicing[2] * 64.0 - 2.0 * u.sphere[3]).abs() < 1e-4);
        assert_eq!(
            glam::Mat4::from_cols_array_2d(&u.view_proj),
            scene.camera.view_projection(1.5)
        );
        assert_eq!(u.starting_at(10).slicing[1], 10.0);
    }

    #[test]
    fn srgb_conversion_endpoints() {
        assert_eq!(srgb_to_linear([0.0, 1.0, 0.5]).x, 0.0);
        assert!((srgb_to_linear([0.0, 1.0, 0.5]).y - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear([0.0, 1.0, 0.5]).z - 0.214).abs() < 1e-3);
    }
}
