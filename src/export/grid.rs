//! The cloud sampled for export: the field baked on a grid of the chosen resolution, turned
//! into density in [0, 1] — through the noise media as shown (the scene's time included), or
//! the plain soft iso-surface step without them. A mesh of the plain field needs neither the
//! density nor the field away from its surface, so for it only the bricks the surface can
//! cross are evaluated ([`bake_for_surface`]).

use std::sync::Arc;

use glam::{UVec3, Vec3};

use crate::field::media::Media;
use crate::field::{DensityVolume, ISO, bake_fine, bake_fine_work, bake_for_surface, density};
use crate::limits::{MAX_EXPORT_RESOLUTION, MAX_EXPORT_WORK};
use crate::scene::Scene;

use super::{ExportError, Format, Options};

/// Density on a regular grid: texel `(x, y, z)` is centred at `min + (x, y, z)·h`, x fastest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DensityGrid {
    /// Texels per axis.
    pub dims: UVec3,
    /// World position of texel (0, 0, 0)'s centre.
    pub min: Vec3,
    /// Texel side in world units.
    pub h: f32,
    /// Density in [0, 1] per texel (empty where the export reads only the surface).
    pub values: Vec<f32>,
    /// The field's values (iso-surface at [`crate::field::ISO`]) on the same texels; where the
    /// export reads only the surface, exact at the corners of the cells it crosses and
    /// elsewhere only on the right side of the level.
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

/// A sampling under way: the field baked (the first step), then the density filled slab by
/// slab, so an app can spread the work over frames and show progress.
pub struct Sampling {
    volume: DensityVolume,
    grid: DensityGrid,
    media: Option<Media>,
    softness: f32,
    next_z: u32,
}

impl Sampling {
    /// Bakes `scene`'s field for `format` on a grid of `options.resolution` texels along its
    /// longest side (at most [`MAX_EXPORT_RESOLUTION`]); the density follows with
    /// [`Sampling::step`] (none for a mesh of the plain field, which reads only its surface).
    pub fn start(scene: &Scene, format: Format, options: &Options) -> Result<Self, ExportError> {
        Self::start_in(
            &mut crate::derive::Derived::default(),
            scene,
            format,
            options,
            false,
        )
    }

    /// [`Sampling::start`] through `derived`, whose simulation run a simulated scene steps on
    /// from (a sequence's frames cost the steps between them, not a replay each). With
    /// `clear_ok`, a grid holding no cloud yet (a simulation's first frames) is sampled as it
    /// is for a volume format (a sequence's frame); a mesh of it is still refused.
    pub fn start_in(
        derived: &mut crate::derive::Derived,
        scene: &Scene,
        format: Format,
        options: &Options,
        clear_ok: bool,
    ) -> Result<Self, ExportError> {
        let (resolution, noise) = (options.resolution, options.noise);
        let surface_only = format.is_mesh() && !noise && scene.simulation.is_none();
        let volume = match &scene.simulation {
            // A simulated cloud: the run's smoothed cloud at the scene's time, on its own grid
            // (with the outlines sketched in it, on one grid over both), as the app shows it.
            Some(_) => Arc::unwrap_or_clone(derived.density_afresh(scene)),
            None => {
                let resolution = resolution.clamp(8, MAX_EXPORT_RESOLUTION);
                let field = crate::derive::field_of(scene);
                let work = bake_fine_work(&field, resolution);
                if work > MAX_EXPORT_WORK {
                    return Err(ExportError::TooLarge(format!(
                        "sampling this cloud at {resolution} texels would take {:.0} million \
                         field evaluations (at most {:.0} million): choose a lower resolution",
                        work as f64 / 1e6,
                        MAX_EXPORT_WORK as f64 / 1e6
                    )));
                }
                if surface_only {
                    bake_for_surface(&field, resolution, ISO).0
                } else {
                    bake_fine(&field, resolution)
                }
            }
        };
        // A sequence's frame with nothing to bake (every primitive hidden, say): one clear
        // texel at the origin, so the sequence stays whole.
        let volume = if volume.is_empty() && clear_ok && !format.is_mesh() {
            DensityVolume {
                dims: UVec3::ONE,
                min: Vec3::ZERO,
                size: Vec3::ONE,
                values: vec![0.0],
            }
        } else {
            volume
        };
        let clear = volume.values.iter().all(|&v| v <= 0.0);
        if volume.is_empty() || (clear && (!clear_ok || format.is_mesh())) {
            return Err(ExportError::Empty);
        }
        let grid = DensityGrid {
            dims: volume.dims,
            min: volume.center(0, 0, 0),
            h: volume.texel_size().x,
            values: Vec::with_capacity(if surface_only { 0 } else { volume.values.len() }),
            field: Vec::new(),
        };
        Ok(Self {
            next_z: if surface_only { grid.dims.z } else { 0 },
            volume,
            grid,
            media: noise.then(|| Media::new(scene)),
            softness: scene.render.softness,
        })
    }

    /// Fills the density of up to `slabs` more z-slabs; returns whether all are done.
    pub fn step(&mut self, slabs: u32) -> bool {
        let end = self.next_z.saturating_add(slabs).min(self.grid.dims.z);
        let g = &mut self.grid;
        for z in self.next_z..end {
            for y in 0..g.dims.y {
                for x in 0..g.dims.x {
                    let f = self.volume.values[((z * g.dims.y + y) * g.dims.x + x) as usize];
                    let p = g.min + UVec3::new(x, y, z).as_vec3() * g.h;
                    g.values.push(match &self.media {
                        Some(m) => m.density(f, p),
                        None => density(f, self.softness),
                    });
                }
            }
        }
        self.next_z = end;
        self.next_z >= self.grid.dims.z
    }

    /// The share of the density filled, in [0, 1].
    pub fn progress(&self) -> f32 {
        self.next_z as f32 / self.grid.dims.z.max(1) as f32
    }

    /// The finished grid (fills what is left first).
    pub fn finish(mut self) -> DensityGrid {
        while !self.step(u32::MAX) {}
        DensityGrid {
            field: self.volume.values,
            ..self.grid
        }
    }
}

/// Samples `scene` for `format` as `options` say ([`Sampling::start`]), in one go.
pub fn sample(
    scene: &Scene,
    format: Format,
    options: &Options,
) -> Result<DensityGrid, ExportError> {
    Ok(Sampling::start(scene, format, options)?.finish())
}
