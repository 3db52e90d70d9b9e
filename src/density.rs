//! The neutral density volume: values on a regular grid over a box, below both the implicit
//! field that bakes sketched planes and ellipsoids into one (`field`) and the cloud automaton
//! that smooths its cells into one (`simulate`). A simulated scene's outlines and its
//! simulated cloud meet here ([`DensityVolume::union`]); the renderer and every exporter take
//! it. Pure: glam only.

use glam::{UVec3, Vec3};

/// Iso-level of the visible surface, in a volume's values as in the field's.
pub const ISO: f32 = 0.5;

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

    /// World position of texel (x, y, z)'s centre.
    pub fn center(&self, x: u32, y: u32, z: u32) -> Vec3 {
        self.min + (UVec3::new(x, y, z).as_vec3() + 0.5) * self.texel_size()
    }

    /// The texel holding world point `p`, if inside the grid.
    pub fn texel_at(&self, p: Vec3) -> Option<UVec3> {
        let t = (p - self.min) / self.size;
        (!self.is_empty() && t.cmpge(Vec3::ZERO).all() && t.cmplt(Vec3::ONE).all())
            .then(|| (t * self.dims.as_vec3()).as_uvec3().min(self.dims - 1))
    }

    /// The value at world point `p` as the GPU samples the grid: each texel clamped to
    /// [0, 1] as the texture stores it (8-bit unorm), trilinear between texel centres, clamped
    /// to the edge texels within the box; 0 (no cloud) outside it.
    pub fn sample(&self, p: Vec3) -> f32 {
        let t = (p - self.min) / self.size;
        if self.is_empty() || t.cmplt(Vec3::ZERO).any() || t.cmpgt(Vec3::ONE).any() {
            return 0.0;
        }
        let top = (self.dims - 1).as_vec3();
        let g = (t * self.dims.as_vec3() - 0.5).clamp(Vec3::ZERO, top);
        let i = g.floor().as_uvec3().min(self.dims - 1);
        let j = (i + 1).min(self.dims - 1);
        let f = g - i.as_vec3();
        let v = |x: u32, y: u32, z: u32| self.value(x, y, z).clamp(0.0, 1.0);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let x00 = lerp(v(i.x, i.y, i.z), v(j.x, i.y, i.z), f.x);
        let x10 = lerp(v(i.x, j.y, i.z), v(j.x, j.y, i.z), f.x);
        let x01 = lerp(v(i.x, i.y, j.z), v(j.x, i.y, j.z), f.x);
        let x11 = lerp(v(i.x, j.y, j.z), v(j.x, j.y, j.z), f.x);
        lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z)
    }

    /// Both volumes on one grid, each texel the larger of their [`DensityVolume::sample`]s
    /// (the union of their clouds): over both boxes ([`DensityVolume::union_grid`]).
    pub fn union(&self, other: &DensityVolume, max_side: u32) -> DensityVolume {
        match (self.is_empty(), other.is_empty()) {
            (true, _) => return other.clone(),
            (_, true) => return self.clone(),
            _ => {}
        }
        let grid = self.union_grid(other, max_side);
        let theirs = other.resampled_onto(&grid);
        self.union_with(&grid, &theirs)
    }

    /// The grid [`DensityVolume::union`] lays both volumes on (its values empty): over both
    /// boxes, at the finer texel size, with at most `max_side` texels along the longest side
    /// (coarser where the boxes lie far apart), texels cubic (the exporters take one texel
    /// size). Neither volume may be empty.
    pub fn union_grid(&self, other: &DensityVolume, max_side: u32) -> DensityVolume {
        let min = self.min.min(other.min);
        let need = (self.min + self.size).max(other.min + other.size) - min;
        let finest = self
            .texel_size()
            .min_element()
            .min(other.texel_size().min_element())
            .max(need.max_element() / max_side.max(1) as f32);
        let dims = (need / finest)
            .ceil()
            .as_uvec3()
            .clamp(UVec3::ONE, UVec3::splat(max_side.max(1)));
        DensityVolume {
            dims,
            min,
            size: dims.as_vec3() * finest,
            values: Vec::new(),
        }
    }

    /// This volume's [`DensityVolume::sample`] at every texel centre of `grid` (a grid's
    /// shape; its values are not read): on this volume's own grid, its texels as the GPU
    /// holds them.
    pub fn resampled_onto(&self, grid: &DensityVolume) -> Vec<f32> {
        if grid.dims == self.dims && grid.min == self.min && grid.size == self.size {
            return self.values.iter().map(|v| v.clamp(0.0, 1.0)).collect();
        }
        let mut out = Vec::with_capacity(grid.len());
        for z in 0..grid.dims.z {
            for y in 0..grid.dims.y {
                for x in 0..grid.dims.x {
                    out.push(self.sample(grid.center(x, y, z)));
                }
            }
        }
        out
    }

    /// Texels of the grid.
    fn len(&self) -> usize {
        self.dims.x as usize * self.dims.y as usize * self.dims.z as usize
    }

    /// The union of this volume and another already resampled onto `grid` (`theirs`, from
    /// [`DensityVolume::resampled_onto`]; a simulated scene's outlines keep theirs while the
    /// simulation steps).
    pub fn union_with(&self, grid: &DensityVolume, theirs: &[f32]) -> DensityVolume {
        let mut values = self.resampled_onto(grid);
        for (v, t) in values.iter_mut().zip(theirs) {
            *v = v.max(*t);
        }
        DensityVolume {
            values,
            ..grid.clone()
        }
    }
}
