//! Baking the field into a capped 3D grid: blended field value and sun transmittance.
//!
//! WebGL2 has no storage buffers or compute, so the renderer samples a 3D texture. Each texel
//! holds two bytes: the field value clamped to [0, 1] and the transmittance toward the sun.
//! Transmittance is found in O(N³) by sweeping the grid layer by layer away from the sun:
//! each texel looks one step toward the sun into the previous layer (bilinear) and attenuates.

use glam::{UVec3, Vec3};

use super::{Field, ISO};

/// Most texels along one side of the grid.
pub const MAX_RESOLUTION: u32 = 128;
/// Fewest texels along one side.
const MIN_SIDE: u32 = 4;

/// What the grid depends on besides the field itself.
#[derive(Clone, Debug, PartialEq)]
pub struct GridParams {
    /// Texels along the longest side.
    pub resolution: u32,
    /// Unit vector toward the sun.
    pub sun_dir: Vec3,
    /// Extinction per world unit of the densest cloud.
    pub extinction: f32,
    /// Half-width of the soft edge around the iso-surface (field units).
    pub softness: f32,
}

/// The baked grid, ready to upload as an `Rg8Unorm` 3D texture.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldGrid {
    /// Texels per axis (x, y, z). All zero for an empty field.
    pub dims: UVec3,
    /// World position of the grid's minimum corner.
    pub min: Vec3,
    /// World size of the grid.
    pub size: Vec3,
    /// `dims.x * dims.y * dims.z` pairs of bytes: field, transmittance; x fastest.
    pub texels: Vec<u8>,
}

impl FieldGrid {
    /// Whether there is nothing to draw.
    pub fn is_empty(&self) -> bool {
        self.texels.is_empty()
    }

    /// Bounding sphere of the grid box (centre, radius).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        (self.min + self.size * 0.5, self.size.length() * 0.5)
    }

    /// Decoded (field, transmittance) at a texel.
    pub fn texel(&self, x: u32, y: u32, z: u32) -> (f32, f32) {
        let i = 2 * (x + self.dims.x * (y + self.dims.y * z)) as usize;
        (
            self.texels[i] as f32 / 255.0,
            self.texels[i + 1] as f32 / 255.0,
        )
    }
}

/// Smooth density of a field value: 0 outside, 1 inside, soft across the surface.
#[inline]
pub fn density(field: f32, softness: f32) -> f32 {
    let t = ((field - (ISO - softness)) / (2.0 * softness)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Bakes `field` into a grid over its bounds.
pub fn bake(field: &Field, params: &GridParams) -> FieldGrid {
    let Some((lo, hi)) = field.bounds() else {
        return FieldGrid {
            dims: UVec3::ZERO,
            min: Vec3::ZERO,
            size: Vec3::ZERO,
            texels: Vec::new(),
        };
    };
    let size = (hi - lo).max(Vec3::splat(1e-3));
    let res = params.resolution.clamp(MIN_SIDE, MAX_RESOLUTION) as f32;
    let longest = size.max_element();
    let dims = (size / longest * res)
        .ceil()
        .as_uvec3()
        .max(UVec3::splat(MIN_SIDE));
    let h = size / dims.as_vec3();
    let (nx, ny, nz) = (dims.x as usize, dims.y as usize, dims.z as usize);
    let mut values = vec![0f32; nx * ny * nz];
    let center_of =
        |i: usize, j: usize, k: usize| lo + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * h;

    // Accumulate each primitive over the texels of its influence box only.
    let splat = |blob: &super::Blob, out: &mut [f32], combine: fn(f32, f32) -> f32| {
        let reach = blob.extent * super::SUPPORT;
        let a = ((blob.center - reach - lo) / h - 0.5)
            .floor()
            .max(Vec3::ZERO)
            .as_uvec3();
        let b = ((blob.center + reach - lo) / h - 0.5)
            .ceil()
            .as_ivec3()
            .min(dims.as_ivec3() - 1);
        if b.min_element() < 0 {
            return;
        }
        let b = b.as_uvec3();
        for k in a.z..=b.z {
            for j in a.y..=b.y {
                let row = (k as usize * ny + j as usize) * nx;
                for i in a.x..=b.x {
                    let v = &mut out[row + i as usize];
                    *v = combine(
                        *v,
                        blob.value(center_of(i as usize, j as usize, k as usize)),
                    );
                }
            }
        }
    };
    for blob in &field.blobs {
        splat(blob, &mut values, |a, b| a + b);
    }
    if !field.groups.is_empty() {
        let mut group_values = vec![0f32; values.len()];
        for group in &field.groups {
            group_values.iter_mut().for_each(|v| *v = 0.0);
            for blob in group {
                splat(blob, &mut group_values, f32::max);
            }
            values
                .iter_mut()
                .zip(&group_values)
                .for_each(|(v, g)| *v += g);
        }
    }
    if !field.clips.is_empty() {
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    if field.clips.iter().any(|c| c.removes(center_of(i, j, k))) {
                        values[(k * ny + j) * nx + i] = 0.0;
                    }
                }
            }
        }
    }

    let dens: Vec<f32> = values
        .iter()
        .map(|&v| density(v, params.softness))
        .collect();
    let trans = sweep_transmittance(&dens, dims, h, params.sun_dir, params.extinction);
    let mut texels = Vec::with_capacity(values.len() * 2);
    for (v, t) in values.iter().zip(&trans) {
        texels.push((v.clamp(0.0, 1.0) * 255.0).round() as u8);
        texels.push((t.clamp(0.0, 1.0) * 255.0).round() as u8);
    }
    FieldGrid {
        dims,
        min: lo,
        size,
        texels,
    }
}

/// Transmittance toward the sun for every texel, sweeping layers away from the sun along the
/// sun direction's dominant axis.
fn sweep_transmittance(dens: &[f32], dims: UVec3, h: Vec3, sun: Vec3, extinction: f32) -> Vec<f32> {
    let sun = sun.normalize_or(Vec3::Y);
    let n = [dims.x as usize, dims.y as usize, dims.z as usize];
    let a = sun.abs().max_position();
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let step = h[a] / sun[a].abs(); // world length between layers along the sun ray
    let off_b = sun[b] * step / h[b]; // texel offset of the sun-ward neighbour in the other axes
    let off_c = sun[c] * step / h[c];
    let toward_sun: isize = if sun[a] > 0.0 { 1 } else { -1 };
    let index = |ia: usize, ib: usize, ic: usize| {
        let mut idx = [0usize; 3];
        idx[a] = ia;
        idx[b] = ib;
        idx[c] = ic;
        (idx[2] * n[1] + idx[1]) * n[0] + idx[0]
    };
    let mut trans = vec![1f32; dens.len()];
    let layers: Box<dyn Iterator<Item = usize>> = if toward_sun > 0 {
        Box::new((0..n[a]).rev())
    } else {
        Box::new(0..n[a])
    };
    let mut first = true;
    for ia in layers {
        let prev_a = ia as isize + toward_sun;
        for ic in 0..n[c] {
            for ib in 0..n[b] {
                let i = index(ia, ib, ic);
                let d = dens[i];
                if first || prev_a < 0 || prev_a >= n[a] as isize {
                    trans[i] = (-extinction * d * step * 0.5).exp();
                    continue;
                }
                // Bilinear sample of (transmittance, density) in the previous layer.
                let (fb, fc) = (ib as f32 + off_b, ic as f32 + off_c);
                let (mut t_prev, mut d_prev) = (0.0, 0.0);
                let (b0, c0) = (fb.floor(), fc.floor());
                let (wb, wc) = (fb - b0, fc - c0);
                for (db, w1) in [(0, 1.0 - wb), (1, wb)] {
                    for (dc, w2) in [(0, 1.0 - wc), (1, wc)] {
                        let (sb, sc) = (b0 as isize + db, c0 as isize + dc);
                        let w = w1 * w2;
                        if sb < 0 || sc < 0 || sb >= n[b] as isize || sc >= n[c] as isize {
                            t_prev += w; // outside the grid: clear sky
                        } else {
                            let j = index(prev_a as usize, sb as usize, sc as usize);
                            t_prev += w * trans[j];
                            d_prev += w * dens[j];
                        }
                    }
                }
                trans[i] = t_prev * (-extinction * 0.5 * (d + d_prev) * step).exp();
            }
        }
        first = false;
    }
    trans
}

#[cfg(test)]
mod tests {
    use super::super::Blob;
    use super::*;

    fn params(sun: Vec3) -> GridParams {
        GridParams {
            resolution: 32,
            sun_dir: sun,
            extinction: 2.0,
            softness: 0.1,
        }
    }

    #[test]
    fn empty_field_bakes_empty_grid() {
        assert!(bake(&Field::default(), &params(Vec3::Y)).is_empty());
    }

    #[test]
    fn grid_is_capped_and_matches_the_field() {
        let f = Field {
            blobs: vec![Blob::sphere(Vec3::ZERO, 2.0)],
            ..Default::default()
        };
        let g = bake(
            &f,
            &GridParams {
                resolution: 100_000,
                ..params(Vec3::Y)
            },
        );
        assert!(g.dims.max_element() <= MAX_RESOLUTION);
        let g = bake(&f, &params(Vec3::Y));
        assert_eq!(
            g.texels.len(),
            (g.dims.x * g.dims.y * g.dims.z * 2) as usize
        );
        let c = g.dims / 2;
        assert!(g.texel(c.x, c.y, c.z).0 > 0.9);
        assert!(g.texel(0, 0, 0).0 < 0.05);
    }

    #[test]
    fn sun_side_is_brighter_than_the_far_side() {
        let f = Field {
            blobs: vec![Blob::sphere(Vec3::ZERO, 2.0)],
            ..Default::default()
        };
        for sun in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::new(0.3, 0.8, -0.5).normalize(),
        ] {
            let g = bake(&f, &params(sun));
            let texel_at = |p: Vec3| {
                let idx = ((p - g.min) / g.size * g.dims.as_vec3())
                    .as_uvec3()
                    .min(g.dims - 1);
                g.texel(idx.x, idx.y, idx.z).1
            };
            // 0.5 units of cloud toward the sun at extinction 2: about e^-1 of the light left.
            let lit = texel_at(sun * 1.5);
            let dark = texel_at(-sun * 1.5);
            assert!(
                lit > 0.3 && dark < 0.1 && lit > dark + 0.25,
                "sun {sun}: lit {lit}, dark {dark}"
            );
        }
    }

    #[test]
    fn density_is_half_at_the_surface() {
        assert!((density(ISO, 0.1) - 0.5).abs() < 1e-6);
        assert_eq!(density(0.0, 0.1), 0.0);
        assert_eq!(density(1.0, 0.1), 1.0);
    }
}
