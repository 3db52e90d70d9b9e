//! Light toward the sun through the density volume (pure CPU): transmittance at every texel,
//! found in O(N³) by sweeping the grid layer by layer away from the sun; each texel looks one
//! step toward the sun into the previous layer (bilinear) and attenuates. It depends on the
//! geometry and on the sun direction, opacity and softness only, so it is cached apart from the
//! geometry: a light slider re-runs this sweep and nothing else.

use glam::{UVec3, Vec3};

use crate::field::{DensityVolume, density};

/// What the sweep depends on besides the volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightParams {
    /// Unit vector toward the sun.
    pub sun_dir: Vec3,
    /// Extinction per world unit of the densest cloud.
    pub extinction: f32,
    /// Half-width of the soft edge around the iso-surface (field units).
    pub softness: f32,
}

/// Transmittance toward the sun on the density volume's grid.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightVolume {
    /// Texels per axis (the density volume's).
    pub dims: UVec3,
    /// Transmittance in [0, 1] per texel; same order as the density volume.
    pub values: Vec<f32>,
}

/// Sweeps `volume` for the light of `params`.
pub fn sweep(volume: &DensityVolume, params: &LightParams) -> LightVolume {
    let dens: Vec<f32> = volume
        .values
        .iter()
        .map(|&v| density(v, params.softness))
        .collect();
    let values = transmittance(
        &dens,
        volume.dims,
        volume.texel_size(),
        params.sun_dir,
        params.extinction,
    );
    LightVolume {
        dims: volume.dims,
        values,
    }
}

/// Transmittance toward the sun for every texel, sweeping layers away from the sun along the
/// sun direction's dominant axis.
fn transmittance(dens: &[f32], dims: UVec3, h: Vec3, sun: Vec3, extinction: f32) -> Vec<f32> {
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
    use super::*;
    use crate::field::{Blob, Field, bake};

    #[test]
    fn sun_side_is_brighter_than_the_far_side() {
        let f = Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, 2.0)]);
        let v = bake(&f, 32);
        for sun in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::new(0.3, 0.8, -0.5).normalize(),
        ] {
            let l = sweep(
                &v,
                &LightParams {
                    sun_dir: sun,
                    extinction: 2.0,
                    softness: 0.1,
                },
            );
            let at = |p: Vec3| {
                let t = v.texel_at(p).unwrap();
                l.values[v.index(t.x, t.y, t.z)]
            };
            // 0.5 units of cloud toward the sun at extinction 2: about e^-1 of the light left.
            let (lit, dark) = (at(sun * 1.5), at(-sun * 1.5));
            assert!(
                lit > 0.3 && dark < 0.1 && lit > dark + 0.25,
                "sun {sun}: lit {lit}, dark {dark}"
            );
        }
    }

    #[test]
    fn clear_sky_transmits_everything() {
        let f = Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, 2.0)]);
        let v = bake(&f, 16);
        let l = sweep(
            &v,
            &LightParams {
                sun_dir: Vec3::Y,
                extinction: 0.0,
                softness: 0.1,
            },
        );
        assert!(l.values.iter().all(|&t| (t - 1.0).abs() < 1e-6));
    }
}
