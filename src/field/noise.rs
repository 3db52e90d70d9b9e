//! The periodic noise volume the slice shader samples for its octaves (pure CPU code).
//!
//! Two bases on lattices that wrap, so the texture tiles seamlessly with a repeating sampler:
//! gradient (Perlin) noise in the red channel and cellular (Worley) noise — one minus the
//! distance to the nearest of one feature point per cell — in the green. Each is rescaled to
//! fill [0, 1]. Deterministic for a given seed.

/// Texels along each side of the noise volume.
pub const NOISE_SIZE: u32 = 32;
/// Lattice cells along each side (the noise's period inside the texture).
const LATTICE: u32 = 8;

use crate::seeded::hash64;

fn gradient(seed: u64, x: u32, y: u32, z: u32) -> [f32; 3] {
    let h = hash64(seed ^ hash64(((x as u64) << 42) | ((y as u64) << 21) | z as u64));
    // A uniformly distributed unit vector from two hashed angles.
    let u = (h & 0xFFFF_FFFF) as f32 / u32::MAX as f32;
    let v = (h >> 32) as f32 / u32::MAX as f32;
    let z = 2.0 * u - 1.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * v;
    [r * phi.cos(), r * phi.sin(), z]
}

fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Tileable gradient noise at a lattice-space point.
fn perlin(seed: u64, p: [f32; 3]) -> f32 {
    let cell = p.map(|v| v.floor());
    let f = [p[0] - cell[0], p[1] - cell[1], p[2] - cell[2]];
    let c = cell.map(|v| v as i64);
    let mut sum = 0.0;
    for corner in 0..8u32 {
        let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
        let l = |i: usize| (c[i] + o[i] as i64).rem_euclid(LATTICE as i64) as u32;
        let g = gradient(seed, l(0), l(1), l(2));
        let d = [f[0] - o[0] as f32, f[1] - o[1] as f32, f[2] - o[2] as f32];
        let w = (0..3)
            .map(|i| {
                if o[i] == 1 {
                    fade(f[i])
                } else {
                    1.0 - fade(f[i])
                }
            })
            .product::<f32>();
        sum += w * (g[0] * d[0] + g[1] * d[1] + g[2] * d[2]);
    }
    sum
}

/// The feature point of lattice cell `c` (wrapped), in cell units.
fn feature(seed: u64, c: [i64; 3]) -> [f32; 3] {
    let l = c.map(|v| v.rem_euclid(LATTICE as i64) as u64);
    let h = hash64(seed ^ 0xC311 ^ hash64((l[0] << 42) | (l[1] << 21) | l[2]));
    [0, 21, 42].map(|shift| ((h >> shift) & 0x1F_FFFF) as f32 / 0x1F_FFFF as f32)
}

/// Tileable cellular noise at a lattice-space point: the distance to the nearest feature point.
fn worley(seed: u64, p: [f32; 3]) -> f32 {
    let cell = p.map(|v| v.floor() as i64);
    let mut best = f32::MAX;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let c = [cell[0] + dx, cell[1] + dy, cell[2] + dz];
                let f = feature(seed, c);
                let d2: f32 = (0..3)
                    .map(|i| {
                        let d = c[i] as f32 + f[i] - p[i];
                        d * d
                    })
                    .sum();
                best = best.min(d2);
            }
        }
    }
    best.sqrt()
}

/// Rescales values to fill [0, 255].
fn to_bytes(values: &[f32]) -> Vec<u8> {
    let (lo, hi) = values
        .iter()
        .fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let span = (hi - lo).max(1e-6);
    values
        .iter()
        .map(|v| ((v - lo) / span * 255.0).round() as u8)
        .collect()
}

/// `NOISE_SIZE³` texels of tileable noise as `Rg8Unorm` bytes: Perlin in red, Worley in green,
/// x fastest.
pub fn noise_volume(seed: u64) -> Vec<u8> {
    let n = NOISE_SIZE;
    let scale = LATTICE as f32 / n as f32;
    let points = (0..n).flat_map(|z| {
        (0..n).flat_map(move |y| {
            (0..n).map(move |x| [x as f32 * scale, y as f32 * scale, z as f32 * scale])
        })
    });
    let (gradient, cellular): (Vec<f32>, Vec<f32>) =
        points.map(|p| (perlin(seed, p), -worley(seed, p))).unzip();
    let (r, g) = (to_bytes(&gradient), to_bytes(&cellular));
    r.into_iter().zip(g).flat_map(|(a, b)| [a, b]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deterministic_full_range_and_seed_dependent() {
        let a = noise_volume(7);
        assert_eq!(a, noise_volume(7));
        assert_ne!(a, noise_volume(8));
        assert_eq!(a.len(), 2 * (NOISE_SIZE * NOISE_SIZE * NOISE_SIZE) as usize);
        for channel in 0..2 {
            let c: Vec<u8> = a.iter().skip(channel).step_by(2).copied().collect();
            assert_eq!(*c.iter().min().unwrap(), 0);
            assert_eq!(*c.iter().max().unwrap(), 255);
            let mean = c.iter().map(|&v| v as f64).sum::<f64>() / c.len() as f64;
            assert!((mean - 127.5).abs() < 60.0, "channel {channel}: {mean}");
        }
        // The two bases are different noises.
        let same = a.chunks(2).filter(|p| p[0].abs_diff(p[1]) < 8).count();
        assert!(same < a.len() / 2 / 4, "{same}");
    }

    #[test]
    fn worley_is_zero_at_feature_points_and_tiles() {
        let f = feature(3, [2, 5, 1]);
        let at = [2.0 + f[0], 5.0 + f[1], 1.0 + f[2]];
        assert!(worley(3, at) < 1e-5);
        let q = at.map(|v| v + LATTICE as f32);
        assert!((worley(3, [0.3, 1.7, 2.2]) - worley(3, [0.3 + 8.0, 1.7, 2.2 - 8.0])).abs() < 1e-5);
        assert!(worley(3, q) < 1e-4);
    }

    #[test]
    fn tiles_seamlessly() {
        // The lattice wraps: noise at p and p + LATTICE agree.
        for p in [[0.3, 1.7, 2.2], [7.9, 0.1, 5.5]] {
            let q = p.map(|v| v + LATTICE as f32);
            assert!((perlin(3, p) - perlin(3, q)).abs() < 1e-5);
        }
    }
}
