//! The automaton written plainly, one byte per cell and one cell at a time: the reference the
//! bit-parallel step is tested against (bit for bit, with the same random words) and the
//! baseline `bench` times it against.

use super::{Automaton, Kind};

/// The byte-per-cell reference: the same rules written plainly, one cell at a time, drawing
/// each cell's random terms from the automaton's own random words (so runs compare bit for
/// bit).
pub struct Reference {
    dims: [usize; 3],
    hum: Vec<u8>,
    act: Vec<u8>,
    cld: Vec<u8>,
    carry: Vec<f32>,
}

impl Reference {
    /// The automaton's state, one byte per cell.
    pub fn of(a: &Automaton) -> Self {
        let [nx, ny, nz] = a.dims;
        let read = |bits: &[u64]| {
            let mut v = vec![0u8; nx * ny * nz];
            for y in 0..ny {
                for z in 0..nz {
                    for x in 0..nx {
                        v[(y * nz + z) * nx + x] = a.get(bits, x, y, z) as u8;
                    }
                }
            }
            v
        };
        Self {
            dims: a.dims,
            hum: read(&a.hum),
            act: read(&a.act),
            cld: read(&a.cld),
            carry: vec![0.0; ny],
        }
    }

    /// One step, with `a` (not yet advanced) supplying the random bits and the wind.
    pub fn step(&mut self, a: &Automaton, wind: &dyn Fn(usize) -> f32) {
        let [nx, ny, nz] = self.dims;
        let i = |x: usize, y: usize, z: usize| (y * nz + z) * nx + x;
        let act_at = |x: isize, y: isize, z: isize| -> u8 {
            if x < 0 || y < 0 || z < 0 || x >= nx as isize || y >= ny as isize || z >= nz as isize {
                0
            } else {
                self.act[i(x as usize, y as usize, z as usize)]
            }
        };
        let (mut hum, mut act, mut cld) = (self.hum.clone(), self.act.clone(), self.cld.clone());
        // The step's random words, drawn once per word as the bit-parallel step draws them.
        let words = a.hum.len();
        let masks: Vec<[u64; 3]> = (0..words)
            .map(|w| [Kind::Hum, Kind::Act, Kind::Ext].map(|k| a.random_word(k, w)))
            .collect();
        for y in 0..ny {
            for z in 0..nz {
                for x in 0..nx {
                    let (xi, yi, zi) = (x as isize, y as isize, z as isize);
                    let f = [
                        (1, 0, 0),
                        (-1, 0, 0),
                        (2, 0, 0),
                        (-2, 0, 0),
                        (0, 0, 1),
                        (0, 0, -1),
                        (0, 0, 2),
                        (0, 0, -2),
                        (0, 1, 0),
                        (0, -1, 0),
                        (0, -2, 0),
                    ]
                    .iter()
                    .any(|&(dx, dy, dz)| act_at(xi + dx, yi + dy, zi + dz) == 1);
                    let (w, b) = a.at(x, y, z);
                    let rnd = |k: Kind| (masks[w][k as usize] >> b) & 1 == 1;
                    let c = i(x, y, z);
                    let (h0, a0, c0) = (self.hum[c] == 1, self.act[c] == 1, self.cld[c] == 1);
                    hum[c] = ((h0 && !a0) || rnd(Kind::Hum)) as u8;
                    cld[c] = ((c0 || a0) && !rnd(Kind::Ext)) as u8;
                    act[c] = ((!a0 && h0 && f) || rnd(Kind::Act)) as u8;
                }
            }
        }
        for y in 0..ny {
            let total = self.carry[y] + wind(y);
            let s = total.trunc();
            self.carry[y] = total - s;
            let s = s as isize;
            for v in [&mut hum, &mut act, &mut cld] {
                for z in 0..nz {
                    let row: Vec<u8> = (0..nx).map(|x| v[i(x, y, z)]).collect();
                    for x in 0..nx {
                        let from = x as isize - s;
                        v[i(x, y, z)] = if (0..nx as isize).contains(&from) {
                            row[from as usize]
                        } else {
                            0
                        };
                    }
                }
            }
        }
        (self.hum, self.act, self.cld) = (hum, act, cld);
    }

    /// Whether it holds the automaton's state.
    pub fn same_as(&self, a: &Automaton) -> bool {
        *self.hum == Reference::of(a).hum
            && *self.act == Reference::of(a).act
            && *self.cld == Reference::of(a).cld
    }
}
