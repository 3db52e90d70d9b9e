//! Cloud simulation by cellular automaton (Dobashi et al. 2000; pure): the bit-parallel
//! automaton, steered by ellipsoid parcels, its wind by height, and the smoothing of its cloud
//! bits into a density volume the renderer and the exporters take like any other.
//!
//! - `automaton`: the state, the growth rules, the random masks, the wind;
//! - `reference`: the same rules one byte per cell (the tests' reference, the bench's baseline);
//! - here: [`Settings`] → [`Simulation`] (parcels → per-cell probability levels), stepping,
//!   and [`Simulation::density`] (a box kernel over the cloud bits, interpolated between steps).

mod automaton;
pub mod reference;

pub use automaton::{Automaton, Kind, LEVELS, level_of, shift_row};

use glam::{Quat, UVec3, Vec3};

use crate::field::DensityVolume;

/// An air parcel: inside it vapour and activation are re-supplied and cloud persists; outside,
/// clouds dissolve. Its influence falls off toward its surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parcel {
    /// World centre.
    pub center: Vec3,
    /// Semi-axes.
    pub radii: Vec3,
    /// Orientation.
    pub rotation: Quat,
}

impl Parcel {
    /// 1 at the centre, 0 at and beyond the surface (smoothly).
    pub fn weight(&self, p: Vec3) -> f32 {
        let local = self.rotation.inverse() * (p - self.center) / self.radii.max(Vec3::splat(1e-4));
        let s = (1.0 - local.length_squared()).clamp(0.0, 1.0);
        s * s * (3.0 - 2.0 * s)
    }
}

/// What a simulation depends on (a part of the scene document).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Settings {
    /// Cells along x, y (up) and z.
    pub cells: [u32; 3],
    /// World position of the grid's minimum corner.
    pub origin: [f32; 3],
    /// Cell side in world units.
    pub cell_size: f32,
    /// Vapour re-supply probability at a parcel's centre.
    pub p_hum: f32,
    /// Activation re-supply probability at a parcel's centre.
    pub p_act: f32,
    /// Extinction probability at a parcel's centre.
    pub p_ext_inside: f32,
    /// Extinction probability outside every parcel.
    pub p_ext_outside: f32,
    /// Wind along x at the bottom and top layers, cells per step (linear in between).
    pub wind: [f32; 2],
    /// Steps per second of scene time.
    pub rate: f32,
    /// Half-width in cells of the smoothing kernel.
    pub smoothing: u32,
    /// Seed of the random masks.
    pub seed: u64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            cells: [128, 32, 128],
            origin: [-16.0, -1.0, -16.0],
            cell_size: 0.25,
            p_hum: 0.1,
            p_act: 0.002,
            p_ext_inside: 0.002,
            p_ext_outside: 0.2,
            wind: [0.0, 0.5],
            rate: 10.0,
            smoothing: 1,
            seed: 1,
        }
    }
}

/// Most cells a simulation may have (each of x, y, z at most 256).
pub const MAX_CELLS: u64 = 1 << 22;

impl Settings {
    /// The grid's cells, capped: each side 4 to 256, at most [`MAX_CELLS`] in all.
    pub fn dims(&self) -> [usize; 3] {
        let mut d = self.cells.map(|c| c.clamp(4, 256) as usize);
        while (d[0] * d[1] * d[2]) as u64 > MAX_CELLS {
            let i = (0..3).max_by_key(|&i| d[i]).unwrap_or(0);
            d[i] /= 2;
        }
        d
    }

    /// World centre of cell `(x, y, z)`.
    pub fn center(&self, x: usize, y: usize, z: usize) -> Vec3 {
        Vec3::from(self.origin)
            + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * self.cell_size.max(1e-3)
    }
}

/// A simulation run: the automaton at its current step and the density of the step before.
#[derive(Clone, Debug)]
pub struct Simulation {
    settings: Settings,
    automaton: Automaton,
}

impl Simulation {
    /// A fresh run of `settings` steered by `parcels`: empty sky, vapour and activation then
    /// re-supplied inside the parcels each step.
    pub fn new(settings: &Settings, parcels: &[Parcel]) -> Self {
        let dims = settings.dims();
        let mut automaton = Automaton::new(dims, settings.seed);
        let weight = |x, y, z| {
            let p = settings.center(x, y, z);
            parcels.iter().map(|q| q.weight(p)).fold(0.0f32, f32::max)
        };
        let weights: Vec<f32> = (0..dims[1])
            .flat_map(|y| (0..dims[2]).flat_map(move |z| (0..dims[0]).map(move |x| (x, y, z))))
            .map(|(x, y, z)| weight(x, y, z))
            .collect();
        let at = |x: usize, y: usize, z: usize| weights[(y * dims[2] + z) * dims[0] + x];
        let s = settings;
        automaton.set_levels(Kind::Hum, |x, y, z| level_of(s.p_hum * at(x, y, z)));
        automaton.set_levels(Kind::Act, |x, y, z| level_of(s.p_act * at(x, y, z)));
        automaton.set_levels(Kind::Ext, |x, y, z| {
            let w = at(x, y, z);
            level_of(s.p_ext_inside * w + s.p_ext_outside * (1.0 - w))
        });
        let ny = dims[1].max(2);
        let [bottom, top] = s.wind;
        automaton.set_wind(|y| bottom + (top - bottom) * y as f32 / (ny - 1) as f32);
        Self {
            settings: settings.clone(),
            automaton,
        }
    }

    /// The automaton.
    pub fn automaton(&self) -> &Automaton {
        &self.automaton
    }

    /// Steps taken.
    pub fn step(&self) -> u64 {
        self.automaton.step
    }

    /// Advances `n` steps.
    pub fn advance(&mut self, n: u64) {
        for _ in 0..n {
            self.automaton.advance();
        }
    }

    /// The cloud bits smoothed by a box kernel of half-width `smoothing` cells: each cell's
    /// share of cloud around it, in [0, 1], in a density volume's order (x fastest, then y,
    /// then z).
    pub fn smoothed(&self) -> Vec<f32> {
        let a = &self.automaton;
        let [nx, ny, nz] = a.dims;
        let r = self.settings.smoothing.min(4) as usize;
        let mut v = vec![0f32; nx * ny * nz];
        let words = a.words();
        for y in 0..ny {
            for z in 0..nz {
                let row = &a.cld[(y * nz + z) * words..][..words];
                let line = &mut v[(z * ny + y) * nx..][..nx];
                for (w, &bits) in row.iter().enumerate() {
                    let mut b = bits;
                    while b != 0 {
                        line[w * 64 + b.trailing_zeros() as usize] = 1.0;
                        b &= b - 1;
                    }
                }
            }
        }
        // Separable running box sums along x, y, z (cells past the edge count as empty).
        let mut out = vec![0f32; v.len()];
        let plane = nx * ny;
        let passes: [(usize, usize, Vec<usize>); 3] = [
            (nx, 1, (0..ny * nz).map(|l| l * nx).collect()),
            (
                ny,
                nx,
                (0..nz)
                    .flat_map(|z| (0..nx).map(move |x| z * plane + x))
                    .collect(),
            ),
            (nz, plane, (0..plane).collect()),
        ];
        let scale = 1.0 / (2 * r + 1) as f32;
        for (n, stride, starts) in passes {
            for start in starts {
                let at = |i: usize| start + i * stride;
                let mut sum: f32 = (0..r.min(n)).map(|i| v[at(i)]).sum();
                for i in 0..n {
                    if i + r < n {
                        sum += v[at(i + r)];
                    }
                    out[at(i)] = (sum * scale).clamp(0.0, 1.0);
                    if i >= r {
                        sum -= v[at(i - r)];
                    }
                }
            }
            std::mem::swap(&mut v, &mut out);
        }
        v
    }

    /// The density volume of the current step (`previous`: the last step's smoothed values,
    /// blended with weight `1 − t`, so playback between steps is smooth).
    pub fn density(&self, previous: Option<&[f32]>, t: f32) -> DensityVolume {
        let now = self.smoothed();
        let values = match previous {
            Some(p) if p.len() == now.len() => p
                .iter()
                .zip(&now)
                .map(|(a, b)| a + (b - a) * t.clamp(0.0, 1.0))
                .collect(),
            _ => now,
        };
        let [nx, ny, nz] = self.automaton.dims;
        let h = self.settings.cell_size.max(1e-3);
        DensityVolume {
            dims: UVec3::new(nx as u32, ny as u32, nz as u32),
            min: Vec3::from(self.settings.origin),
            size: Vec3::new(nx as f32, ny as f32, nz as f32) * h,
            values,
        }
    }
}

#[cfg(test)]
mod tests;
