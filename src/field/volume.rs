//! The neutral density volume: a field (or, later, a simulation) sampled on a capped regular
//! grid. The renderer uploads it as a 3D texture (WebGL2 has no storage buffers or compute),
//! the light sweep reads it, and exporters will write it.

use glam::{UVec3, Vec3};

use super::{Field, ISO};

pub use crate::limits::MAX_GRID_RESOLUTION as MAX_RESOLUTION;
/// Fewest texels along one side.
const MIN_SIDE: u32 = 4;

/// Field values on a regular grid over a box.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DensityVolume {
    /// Texels per axis (x, y, z). All zero for an empty volume.
    pub dims: UVec3,
    /// World position of the grid's minimum corner.
    pub min: Vec3,
    /// World size of the grid.
    pub size: Vec3,
    /// Field value at each texel centre (iso-surface at [`ISO`]); x fastest, then y, then z.
    pub values: Vec<f32>,
}

impl DensityVolume {
    /// Whether there is nothing to draw.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Bounding sphere of the grid box (centre, radius).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        (self.min + self.size * 0.5, self.size.length() * 0.5)
    }

    /// World size of one texel.
    pub fn texel_size(&self) -> Vec3 {
        self.size / self.dims.max(UVec3::ONE).as_vec3()
    }

    /// Index of texel (x, y, z) in [`DensityVolume::values`].
    pub fn index(&self, x: u32, y: u32, z: u32) -> usize {
        (x + self.dims.x * (y + self.dims.y * z)) as usize
    }

    /// Field value at a texel.
    pub fn value(&self, x: u32, y: u32, z: u32) -> f32 {
        self.values[self.index(x, y, z)]
    }

    /// The texel holding world point `p`, if inside the grid.
    pub fn texel_at(&self, p: Vec3) -> Option<UVec3> {
        let t = (p - self.min) / self.size;
        (!self.is_empty() && t.cmpge(Vec3::ZERO).all() && t.cmplt(Vec3::ONE).all())
            .then(|| (t * self.dims.as_vec3()).as_uvec3().min(self.dims - 1))
    }
}

/// Smooth density of a field value: 0 outside, 1 inside, soft across the surface.
#[inline]
pub fn density(field: f32, softness: f32) -> f32 {
    let t = ((field - (ISO - softness)) / (2.0 * softness)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The grid `bake` samples a field on: its box and texel counts.
#[derive(Clone, Copy)]
struct Grid {
    lo: Vec3,
    size: Vec3,
    dims: UVec3,
    /// Texel size.
    h: Vec3,
}

impl Grid {
    fn of(field: &Field, resolution: u32) -> Option<Self> {
        let (lo, hi) = field.bounds()?;
        let size = (hi - lo).max(Vec3::splat(1e-3));
        let res = resolution.clamp(MIN_SIDE, MAX_RESOLUTION) as f32;
        let dims = (size / size.max_element() * res)
            .ceil()
            .as_uvec3()
            .max(UVec3::splat(MIN_SIDE));
        Some(Self {
            lo,
            size,
            dims,
            h: size / dims.as_vec3(),
        })
    }

    fn texels(&self) -> u64 {
        self.dims.as_u64vec3().element_product()
    }

    /// The texels a primitive's influence reaches (inclusive), clamped to the grid, if any.
    fn texel_box(&self, blob: &super::Blob) -> Option<(UVec3, UVec3)> {
        let reach = blob.extent * super::SUPPORT;
        let a = ((blob.center - reach - self.lo) / self.h - 0.5)
            .floor()
            .max(Vec3::ZERO)
            .as_uvec3();
        let b = ((blob.center + reach - self.lo) / self.h - 0.5)
            .ceil()
            .as_ivec3()
            .min(self.dims.as_ivec3() - 1);
        (b.min_element() >= 0 && a.cmple(b.as_uvec3()).all()).then(|| (a, b.as_uvec3()))
    }
}

/// The work [`bake`] does for `field` at `resolution`: kernel evaluations (each primitive over
/// the texels its influence reaches) plus clip tests (each cut over every texel, at most).
/// Cheap to compute (one box per primitive), so callers check it before baking.
pub fn bake_work(field: &Field, resolution: u32) -> u64 {
    let Some(grid) = Grid::of(field, resolution) else {
        return 0;
    };
    let kernel: u64 = field
        .all_blobs()
        .filter_map(|b| grid.texel_box(b))
        .map(|(a, b)| (b - a + UVec3::ONE).as_u64vec3().element_product())
        .sum();
    kernel + field.clips.len() as u64 * grid.texels()
}

/// The largest resolution up to `wanted` whose [`bake_work`] fits `budget` (the grid's floor
/// when none does), with its work.
pub fn resolution_within(field: &Field, wanted: u32, budget: u64) -> (u32, u64) {
    let mut res = wanted.clamp(MIN_SIDE, MAX_RESOLUTION);
    let mut work = bake_work(field, res);
    while res > MIN_SIDE && work > budget {
        res = (res * 4 / 5).max(MIN_SIDE);
        work = bake_work(field, res);
    }
    (res, work)
}

/// Samples `field` on a grid over its bounds, `resolution` texels along the longest side.
pub fn bake(field: &Field, resolution: u32) -> DensityVolume {
    let Some(grid) = Grid::of(field, resolution) else {
        return DensityVolume::default();
    };
    let Grid { lo, size, dims, h } = grid;
    let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
    let mut values = vec![0f32; nx * ny * nz];
    let center_of =
        |i: usize, j: usize, k: usize| lo + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * h;
    let texel_box = |blob: &super::Blob| grid.texel_box(blob);
    // Every texel row of a box: (row start index, x range).
    let rows = move |(a, b): (UVec3, UVec3)| {
        (a.z..=b.z).flat_map(move |k| {
            (a.y..=b.y).map(move |j| {
                (
                    (k as usize * ny + j as usize) * nx,
                    a.x as usize..=b.x as usize,
                )
            })
        })
    };
    // Accumulate each primitive over the texels of its influence box only.
    let splat = |blob: &super::Blob, out: &mut [f32], combine: fn(f32, f32) -> f32| {
        let Some(bx) = texel_box(blob) else { return };
        for (row, xs) in rows(bx) {
            let (j, k) = ((row / nx) % ny, row / (nx * ny));
            for i in xs {
                let v = &mut out[row + i];
                *v = combine(*v, blob.value(center_of(i, j, k)));
            }
        }
    };
    for blob in &field.blobs {
        splat(blob, &mut values, |a, b| a + b);
    }
    if !field.groups.is_empty() {
        // One scratch grid; each group clears and adds back only the box it reaches.
        let mut group_values = vec![0f32; values.len()];
        for group in &field.groups {
            let Some(bx) = group
                .iter()
                .filter_map(texel_box)
                .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
            else {
                continue;
            };
            for (row, xs) in rows(bx) {
                group_values[row + xs.start()..=row + xs.end()].fill(0.0);
            }
            for blob in group {
                splat(blob, &mut group_values, f32::max);
            }
            for (row, xs) in rows(bx) {
                let span = row + xs.start()..=row + xs.end();
                for (v, g) in values[span.clone()].iter_mut().zip(&group_values[span]) {
                    *v += g;
                }
            }
        }
    }
    if !field.clips.is_empty() {
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let v = &mut values[(k * ny + j) * nx + i];
                    // Empty texels need no clip test.
                    if *v != 0.0 && field.clips.iter().any(|c| c.removes(center_of(i, j, k))) {
                        *v = 0.0;
                    }
                }
            }
        }
    }

    DensityVolume {
        dims,
        min: lo,
        size,
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::super::Blob;
    use super::*;

    #[test]
    fn empty_field_bakes_empty_volume() {
        assert!(bake(&Field::default(), 32).is_empty());
    }

    #[test]
    fn volume_is_capped_and_matches_the_field() {
        let f = Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, 2.0)]);
        let v = bake(&f, 100_000);
        assert!(v.dims.max_element() <= MAX_RESOLUTION);
        let v = bake(&f, 32);
        assert_eq!(v.values.len(), (v.dims.x * v.dims.y * v.dims.z) as usize);
        let c = v.texel_at(Vec3::ZERO).unwrap();
        assert!(v.value(c.x, c.y, c.z) > 0.9);
        assert!(v.value(0, 0, 0) < 0.05);
        // Brute force: every texel equals the field at its centre.
        let h = v.texel_size();
        for (z, y, x) in [(3, 5, 7), (16, 16, 16), (0, 31, 2)] {
            let p = v.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * h;
            assert!((v.value(x, y, z) - f.value(p)).abs() < 1e-5);
        }
    }

    #[test]
    fn every_texel_equals_the_field_at_its_centre() {
        // Summed blobs, two max-combined groups (one reaching the grid's edge) and a clip,
        // against the field evaluated at every texel (brute force).
        let group = |c: Vec3| -> Vec<Blob> {
            (0..6)
                .map(|i| {
                    Blob::sphere(
                        c + Vec3::new(i as f32 * 0.4, 0.0, 0.0),
                        0.5 + 0.1 * i as f32,
                    )
                })
                .collect()
        };
        let f = Field {
            blobs: vec![Blob::sphere(Vec3::new(0.0, 1.0, 0.0), 1.2)],
            groups: vec![
                group(Vec3::new(-2.0, 0.0, 0.0)),
                group(Vec3::new(1.0, -1.0, 0.5)),
            ],
            clips: vec![super::super::Clip {
                origin: Vec3::ZERO,
                right: Vec3::X,
                up: Vec3::Y,
                line: vec![glam::Vec2::new(-1.0, -1.2), glam::Vec2::new(1.0, -1.2)],
            }],
        };
        let v = bake(&f, 24);
        let h = v.texel_size();
        for z in 0..v.dims.z {
            for y in 0..v.dims.y {
                for x in 0..v.dims.x {
                    let p = v.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * h;
                    let want = f.value(p);
                    assert!((v.value(x, y, z) - want).abs() < 1e-5, "({x},{y},{z})");
                }
            }
        }
    }

    #[test]
    fn density_is_half_at_the_surface() {
        assert!((density(ISO, 0.1) - 0.5).abs() < 1e-6);
        assert_eq!(density(0.0, 0.1), 0.0);
        assert_eq!(density(1.0, 0.1), 1.0);
    }
}
