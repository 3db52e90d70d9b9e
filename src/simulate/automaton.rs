//! Dobashi et al.'s cloud automaton (after Nagel and Raschke), bit-parallel: each of the three
//! booleans of a cell (`hum` vapour, `act` ready to condense, `cld` cloud) is one bit, 64 cells
//! of a row along x in one `u64`, so one pass of bitwise operations updates 64 cells.
//!
//! ```text
//! hum' = hum ∧ ¬act            ∨ (rnd < p_hum)
//! cld' = (cld ∨ act)           ∧ ¬(rnd < p_ext)
//! act' = ¬act ∧ hum ∧ f_act    ∨ (rnd < p_act)
//! f_act = act at x±1, x±2, z±1, z±2, y+1, y−1, y−2  (y up: two cells below, one above)
//! ```
//! then every variable moves along x with the wind of its layer, `v(y)` cells per step, the
//! fraction carried to the next step; cells blown in from outside are empty.
//!
//! The random terms come from pre-computed random words: for each of a few probability
//! levels, a table of words whose bits are 1 with that level's probability. A cell's
//! probabilities (from the parcels) are rounded to a level when the parcels change; the
//! random mask of a word is the OR over levels of (the cells at that level ∧ a word drawn from
//! that level's table). [`Automaton::random_word`] is the one source of randomness, so the
//! byte-per-cell reference in the tests reproduces a run bit for bit.

use crate::seeded::hash64;

/// The probability levels a cell's probabilities are rounded to (level 0 never fires).
pub const LEVELS: [f32; 8] = [0.0, 0.002, 0.01, 0.03, 0.08, 0.2, 0.45, 1.0];
/// Random words per level table.
const TABLE: usize = 1024;

/// The nearest level of a probability (on a log scale above the smallest).
pub fn level_of(p: f32) -> u8 {
    // (NaN and anything below half the smallest level: never.)
    if p.is_nan() || p <= LEVELS[1] * 0.5 {
        return 0;
    }
    let mut best = 1;
    for (k, &l) in LEVELS.iter().enumerate().skip(1) {
        if (p.ln() - l.ln()).abs() < (p.ln() - LEVELS[best].ln()).abs() {
            best = k;
        }
    }
    best as u8
}

/// The cells' bits, wind carry and step: what a snapshot keeps (the probability levels and
/// random tables stay with the automaton).
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    hum: Vec<u64>,
    act: Vec<u64>,
    cld: Vec<u64>,
    carry: Vec<f32>,
    /// The step it was taken at.
    pub step: u64,
}

impl State {
    /// Bytes it holds.
    pub fn bytes(&self) -> usize {
        (self.hum.len() + self.act.len() + self.cld.len()) * 8 + self.carry.len() * 4
    }
}

/// The three random terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Vapour re-supply.
    Hum = 0,
    /// Activation re-supply.
    Act = 1,
    /// Extinction.
    Ext = 2,
}

/// The automaton's state and its per-cell probability levels.
#[derive(Clone, Debug)]
pub struct Automaton {
    /// Cells along x (packed), y (up) and z.
    pub dims: [usize; 3],
    words: usize,
    /// Vapour, activation and cloud bits, row `(y·nz + z)`, word `w` at `row·words + w`.
    pub hum: Vec<u64>,
    /// See [`Automaton::hum`].
    pub act: Vec<u64>,
    /// See [`Automaton::hum`].
    pub cld: Vec<u64>,
    /// Per kind and level (1..): the cells at that level, as words.
    membership: [Vec<Vec<u64>>; 3],
    /// Per level: its random words.
    tables: Vec<Vec<u64>>,
    /// Per kind and level: this step's key, which picks each word's draw from the table.
    keys: [[u64; LEVELS.len()]; 3],
    /// Threads a step may use (`None`: every core).
    threads: Option<usize>,
    /// Wind along x per layer y, cells per step (may be negative), and its carried fraction.
    wind: Vec<f32>,
    carry: Vec<f32>,
    seed: u64,
    /// Steps taken.
    pub step: u64,
}

impl Automaton {
    /// An empty grid of `dims` cells (x, y up, z); every probability level 0, no wind.
    pub fn new(dims: [usize; 3], seed: u64) -> Self {
        let [nx, ny, nz] = dims;
        let words = nx.div_ceil(64).max(1);
        let n = words * ny * nz;
        let tables = LEVELS
            .iter()
            .enumerate()
            .map(|(k, &p)| {
                (0..TABLE)
                    .map(|i| {
                        (0..64).fold(0u64, |w, b| {
                            let h =
                                hash64(seed ^ hash64(((k as u64) << 40) ^ ((i as u64) << 8) ^ b));
                            let u = (h >> 11) as f64 / (1u64 << 53) as f64;
                            w | (((u < p as f64) as u64) << b)
                        })
                    })
                    .collect()
            })
            .collect();
        let mut automaton = Self {
            dims,
            words,
            keys: [[0; LEVELS.len()]; 3],
            threads: None,
            hum: vec![0; n],
            act: vec![0; n],
            cld: vec![0; n],
            membership: std::array::from_fn(|_| vec![Vec::new(); LEVELS.len()]),
            tables,
            wind: vec![0.0; ny],
            carry: vec![0.0; ny],
            seed,
            step: 0,
        };
        automaton.refresh_keys();
        automaton
    }

    /// This step's key per kind and level (two hashes each, once a step).
    fn refresh_keys(&mut self) {
        let (seed, step) = (self.seed, self.step);
        self.keys = std::array::from_fn(|kind| {
            std::array::from_fn(|l| {
                hash64(seed ^ hash64((step << 24) ^ ((kind as u64) << 3) ^ l as u64))
            })
        });
    }

    /// Words per row.
    pub fn words(&self) -> usize {
        self.words
    }

    /// The index of cell `(x, y, z)`'s word and its bit.
    pub fn at(&self, x: usize, y: usize, z: usize) -> (usize, u32) {
        let [_, _, nz] = self.dims;
        ((y * nz + z) * self.words + x / 64, (x % 64) as u32)
    }

    /// Cell `(x, y, z)`'s bit of `bits`.
    pub fn get(&self, bits: &[u64], x: usize, y: usize, z: usize) -> bool {
        let (w, b) = self.at(x, y, z);
        (bits[w] >> b) & 1 == 1
    }

    /// Sets the probability levels of `kind` per cell (x fastest, then z, then y: the rows'
    /// order), from `level(x, y, z)`.
    pub fn set_levels(&mut self, kind: Kind, level: impl Fn(usize, usize, usize) -> u8) {
        let [nx, ny, nz] = self.dims;
        let n = self.words * ny * nz;
        let mut m = vec![vec![0u64; n]; LEVELS.len()];
        for y in 0..ny {
            for z in 0..nz {
                for x in 0..nx {
                    let l = level(x, y, z).min(LEVELS.len() as u8 - 1) as usize;
                    if l > 0 {
                        let (w, b) = self.at(x, y, z);
                        m[l][w] |= 1 << b;
                    }
                }
            }
        }
        // Levels no cell uses keep no words.
        for v in &mut m {
            if v.iter().all(|&w| w == 0) {
                v.clear();
            }
        }
        self.membership[kind as usize] = m;
    }

    /// The wind along x per layer: `v(y)` cells per step.
    pub fn set_wind(&mut self, v: impl Fn(usize) -> f32) {
        self.wind = (0..self.dims[1]).map(v).collect();
    }

    /// The random mask of `kind` for word `w` at the current step: bit i is 1 with the
    /// probability of cell i's level. The word drawn from a level's table is picked by the
    /// step's key for that kind and level mixed with `w` (a Fibonacci hash: neighbouring words
    /// draw far-apart entries).
    #[inline]
    pub fn random_word(&self, kind: Kind, w: usize) -> u64 {
        let mut mask = 0;
        let keys = &self.keys[kind as usize];
        for (l, members) in self.membership[kind as usize].iter().enumerate().skip(1) {
            let Some(&m) = members.get(w) else {
                continue;
            };
            if m == 0 {
                continue;
            }
            let pick = ((keys[l] ^ w as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 54) as usize;
            mask |= m & self.tables[l][pick % TABLE];
        }
        mask
    }

    /// The bits of the last word of a row that are cells (the rest stay 0).
    fn tail_mask(&self) -> u64 {
        match self.dims[0] % 64 {
            0 => u64::MAX,
            r => (1u64 << r) - 1,
        }
    }

    /// Threads a step may use: the machine's cores (1 where threads are not available, as in
    /// the browser), or what [`Automaton::set_threads`] asked for.
    fn threads(&self) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        self.threads
            .unwrap_or(cores)
            .clamp(1, cores.min(self.dims[1]))
    }

    /// Uses at most `n` threads per step (the bench's one-thread figure; `None`: every core).
    pub fn set_threads(&mut self, n: Option<usize>) {
        self.threads = n;
    }

    /// One step of growth, extinction, re-supply and wind. Layers of y are shared out among
    /// the machine's cores; each writes only its own layers, so the result is the same on any
    /// number of them.
    pub fn advance(&mut self) {
        let [_, ny, nz] = self.dims;
        let words = self.words;
        let n = self.act.len();
        let (mut hum, mut act, mut cld) = (vec![0u64; n], vec![0u64; n], vec![0u64; n]);
        // `act` with one row of zeros after it: the neighbour of every cell past an edge.
        let mut a = Vec::with_capacity(n + words);
        a.extend_from_slice(&self.act);
        a.resize(n + words, 0);
        let threads = self.threads();
        if threads <= 1 || n < (1 << 14) {
            self.step_layers(&a, 0, &mut hum, &mut act, &mut cld);
        } else {
            let layer = nz * words;
            let per = ny.div_ceil(threads) * layer;
            let this = &*self;
            let a = &a;
            std::thread::scope(|scope| {
                for (i, ((h, ac), c)) in hum
                    .chunks_mut(per)
                    .zip(act.chunks_mut(per))
                    .zip(cld.chunks_mut(per))
                    .enumerate()
                {
                    scope.spawn(move || this.step_layers(a, i * per / layer, h, ac, c));
                }
            });
        }
        (self.hum, self.act, self.cld) = (hum, act, cld);
        self.blow();
        self.step += 1;
        self.refresh_keys();
    }

    /// The growth, extinction and re-supply of the layers from `y0` on that `hum`, `act` and
    /// `cld` (whole layers) hold, reading `a`: this step's activation with a row of zeros after.
    fn step_layers(&self, a: &[u64], y0: usize, hum: &mut [u64], act: &mut [u64], cld: &mut [u64]) {
        let [_, ny, nz] = self.dims;
        let words = self.words;
        let n = self.act.len();
        let tail = self.tail_mask();
        let layers = hum.len() / (nz * words);
        for y in y0..y0 + layers {
            for z in 0..nz {
                let r = (y * nz + z) * words;
                let row = |dy: isize, dz: isize| {
                    let (y, z) = (y as isize + dy, z as isize + dz);
                    if y >= 0 && z >= 0 && (y as usize) < ny && (z as usize) < nz {
                        (y as usize * nz + z as usize) * words
                    } else {
                        n
                    }
                };
                let near = [
                    row(0, 1),
                    row(0, -1),
                    row(0, 2),
                    row(0, -2),
                    row(1, 0),
                    row(-1, 0),
                    row(-2, 0),
                ];
                let out = r - y0 * nz * words;
                for w in 0..words {
                    let i = r + w;
                    let prev = if w > 0 { a[i - 1] } else { 0 };
                    let next = if w + 1 < words { a[i + 1] } else { 0 };
                    // Bit i holds cell i+k (>>) or cell i−k (<<).
                    let mut f = (a[i] >> 1 | next << 63)
                        | (a[i] >> 2 | next << 62)
                        | (a[i] << 1 | prev >> 63)
                        | (a[i] << 2 | prev >> 62);
                    for o in near {
                        f |= a[o + w];
                    }
                    let (h, ac, c) = (self.hum[i], a[i], self.cld[i]);
                    let keep = if w + 1 == words { tail } else { u64::MAX };
                    hum[out + w] = ((h & !ac) | self.random_word(Kind::Hum, i)) & keep;
                    cld[out + w] = ((c | ac) & !self.random_word(Kind::Ext, i)) & keep;
                    act[out + w] = ((!ac & h & f) | self.random_word(Kind::Act, i)) & keep;
                }
            }
        }
    }

    /// Moves every layer along x by its wind, carrying the fraction.
    fn blow(&mut self) {
        let [_, ny, nz] = self.dims;
        for y in 0..ny {
            let total = self.carry[y] + self.wind[y];
            let cells = total.trunc();
            self.carry[y] = total - cells;
            let s = cells as i64;
            if s == 0 {
                continue;
            }
            for z in 0..nz {
                let r = (y * nz + z) * self.words;
                for bits in [&mut self.hum, &mut self.act, &mut self.cld] {
                    shift_row(&mut bits[r..r + self.words], s);
                }
            }
        }
        let tail = self.tail_mask();
        let words = self.words;
        for bits in [&mut self.hum, &mut self.act, &mut self.cld] {
            for row in bits.chunks_mut(words) {
                row[words - 1] &= tail;
            }
        }
    }

    /// A snapshot of the state.
    pub fn state(&self) -> State {
        State {
            hum: self.hum.clone(),
            act: self.act.clone(),
            cld: self.cld.clone(),
            carry: self.carry.clone(),
            step: self.step,
        }
    }

    /// Goes back (or forward) to a snapshot of this automaton.
    pub fn restore(&mut self, s: &State) {
        self.hum.clone_from(&s.hum);
        self.act.clone_from(&s.act);
        self.cld.clone_from(&s.cld);
        self.carry.clone_from(&s.carry);
        self.step = s.step;
        self.refresh_keys();
    }

    /// Cells with cloud.
    pub fn cloud_cells(&self) -> u64 {
        self.cld.iter().map(|w| w.count_ones() as u64).sum()
    }
}

/// Moves a row's cells `s` places toward higher x (lower when negative); cells shifted in are 0.
pub fn shift_row(row: &mut [u64], s: i64) {
    let n = row.len() as i64;
    let (words, bits) = (s.unsigned_abs() / 64, (s.unsigned_abs() % 64) as u32);
    let words = words as i64;
    let old = row.to_vec();
    let get = |i: i64| {
        if (0..n).contains(&i) {
            old[i as usize]
        } else {
            0
        }
    };
    for i in 0..n {
        row[i as usize] = if s > 0 {
            let lo = get(i - words);
            let below = get(i - words - 1);
            if bits == 0 {
                lo
            } else {
                (lo << bits) | (below >> (64 - bits))
            }
        } else {
            let hi = get(i + words);
            let above = get(i + words + 1);
            if bits == 0 {
                hi
            } else {
                (hi >> bits) | (above << (64 - bits))
            }
        };
    }
}
