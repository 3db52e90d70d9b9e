//! The settings of a cloud simulation (Dobashi et al. 2000), the part of the document the
//! automaton (`simulate`) runs: held by the scene, so the document does not depend on the
//! simulation that reads it.

use glam::Vec3;

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
    /// Brings every value into its range (a loaded document's; the panel's sliders keep to
    /// the same ranges).
    pub fn sanitize(&mut self) {
        let fix =
            |v: f32, lo: f32, hi: f32, d: f32| if v.is_finite() { v.clamp(lo, hi) } else { d };
        let d = Settings::default();
        self.cells = self.cells.map(|c| c.clamp(4, 256));
        for (o, od) in self.origin.iter_mut().zip(d.origin) {
            *o = fix(*o, -1.0e4, 1.0e4, od);
        }
        self.cell_size = fix(self.cell_size, 0.01, 100.0, d.cell_size);
        self.p_hum = fix(self.p_hum, 0.0, 1.0, d.p_hum);
        self.p_act = fix(self.p_act, 0.0, 1.0, d.p_act);
        self.p_ext_inside = fix(self.p_ext_inside, 0.0, 1.0, d.p_ext_inside);
        self.p_ext_outside = fix(self.p_ext_outside, 0.0, 1.0, d.p_ext_outside);
        for (w, wd) in self.wind.iter_mut().zip(d.wind) {
            *w = fix(*w, -8.0, 8.0, wd);
        }
        self.rate = fix(self.rate, 0.5, 60.0, d.rate);
        self.smoothing = self.smoothing.min(4);
    }

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
