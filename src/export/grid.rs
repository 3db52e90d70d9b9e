//! The cloud sampled for export: the field baked on a grid of the chosen resolution, turned
//! into density in [0, 1] — through the noise media as shown (the scene's time included), or
//! the plain soft iso-surface step without them.

use glam::{UVec3, Vec3};

use crate::field::media::Media;
use crate::field::{DensityVolume, bake_fine, bake_fine_work, density};
use crate::limits::{MAX_EXPORT_RESOLUTION, MAX_EXPORT_WORK};
use crate::scene::Scene;

use super::ExportError;

/// Density on a regular grid: texel `(x, y, z)` is centred at `min + (x, y, z)·h`, x fastest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DensityGrid {
    /// Texels per axis.
    pub dims: UVec3,
    /// World position of texel (0, 0, 0)'s centre.
    pub min: Vec3,
    /// Texel side in world units.
    pub h: f32,
    /// Density in [0, 1] per texel.
    pub values: Vec<f32>,
    /// The field's values (iso-surface at [`crate::field::ISO`]) on the same texels.
    pub field: Vec<f32>,
}

impl DensityGrid {
    /// The index of texel `(x, y, z)`.
    pub fn index(&self, x: u32, y: u32, z: u32) -> usize {
        ((z * self.dims.y + y) * self.dims.x + x) as usize
    }

    /// World position of texel `(x, y, z)`'s centre.
    pub fn center(&self, x: u32, y: u32, z: u32) -> Vec3 {
        self.min + UVec3::new(x, y, z).as_vec3() * self.h
    }
}

/// Samples `scene` on a grid of `resolution` texels along its longest side (at most
/// [`MAX_EXPORT_RESOLUTION`]), with or without the noise media.
pub fn sample(scene: &Scene, resolution: u32, noise: bool) -> Result<DensityGrid, ExportError> {
    let resolution = resolution.clamp(8, MAX_EXPORT_RESOLUTION);
    let field = crate::derive::field_of(scene);
    let work = bake_fine_work(&field, resolution);
    if work > MAX_EXPORT_WORK {
        return Err(ExportError::TooLarge(format!(
            "sampling this cloud at {resolution} texels would take {:.0} million field \
             evaluations (at most {:.0} million): choose a lower resolution",
            work as f64 / 1e6,
            MAX_EXPORT_WORK as f64 / 1e6
        )));
    }
    let volume = bake_fine(&field, resolution);
    if volume.is_empty() {
        return Err(ExportError::Empty);
    }
    Ok(to_density(scene, &volume, noise))
}

fn to_density(scene: &Scene, volume: &DensityVolume, noise: bool) -> DensityGrid {
    let h = volume.texel_size().x;
    let grid = DensityGrid {
        dims: volume.dims,
        min: volume.center(0, 0, 0),
        h,
        values: Vec::new(),
        field: volume.values.clone(),
    };
    let media = noise.then(|| Media::new(scene));
    let softness = scene.render.softness;
    let mut values = Vec::with_capacity(volume.values.len());
    for z in 0..grid.dims.z {
        for y in 0..grid.dims.y {
            for x in 0..grid.dims.x {
                let f = volume.values[grid.index(x, y, z)];
                values.push(match &media {
                    Some(m) => m.density(f, grid.center(x, y, z)),
                    None => density(f, softness),
                });
            }
        }
    }
    DensityGrid { values, ..grid }
}
