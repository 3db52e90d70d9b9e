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
//! that level's table). Each word keeps member words only for the levels its cells use, so a
//! step draws once per level a word holds rather than once per level. The step and
//! [`Automaton::random_word`] (which the byte-per-cell reference in the tests calls per word)
//! both draw through one function, so the reference reproduces a run bit for bit.
//!
//! A step writes into spare buffers (no allocation), a layer of y (its rows contiguous) as one
//! run of words, and moves each row by its layer's wind while the layer is still in cache.

use crate::seeded::hash64;

/// The probability levels a cell's probabilities are rounded to (level 0 never fires).
pub const LEVELS: [f32; 8] = [0.0, 0.002, 0.01, 0.03, 0.08, 0.2, 0.45, 1.0];
/// Random words per level table.
const TABLE: usize = 1024;
// A word's used levels are a `u8` of bits, one per level.
const _: () = assert!(LEVELS.len() == 8);

/// Per level, its table of random words.
type Tables = [[u64; TABLE]; LEVELS.len()];

/// The cells of one kind at each probability level, kept only where used: per word, the
/// levels its cells use (bit `l`), and for each of them in ascending order one member word
/// (bit set: the cell is at that level), stored word after word, row after row.
#[derive(Clone, Debug, Default)]
struct Membership {
    /// Per row: the index of its first member word.
    rows: Vec<usize>,
    /// Per word: the levels its cells use.
    levels: Vec<u8>,
    /// The member words.
    words: Vec<u64>,
}

impl Membership {
    /// The used levels of the `n` words from row `row` on (which starts at word `first`), and
    /// the index of their first member word (none before any level is set).
    #[inline]
    fn words_from(&self, row: usize, first: usize, n: usize) -> (&[u8], usize) {
        match self.rows.get(row) {
            Some(&at) => (&self.levels[first..first + n], at),
            None => (&[], 0),
        }
    }

    /// The random mask of word `w` of a run of words that use `levels` (from
    /// [`Membership::words_from`]), word `i` of the grid, its member words read at `*at` on.
    #[inline(always)]
    fn draw(
        &self,
        tables: &Tables,
        keys: &[u64; LEVELS.len()],
        levels: &[u8],
        w: usize,
        at: &mut usize,
        i: usize,
    ) -> u64 {
        let used = levels.get(w).map_or(0, |&l| l);
        draw(tables, keys, used, &self.words, at, i)
    }
}

/// The random mask of word `i`: the OR over its used `levels` of (its member word ∧ the word
/// drawn from that level's table by `keys` and `i`), its member words read from `members` at
/// `*at` on (which moves past them).
#[inline(always)]
fn draw(
    tables: &Tables,
    keys: &[u64; LEVELS.len()],
    levels: u8,
    members: &[u64],
    at: &mut usize,
    i: usize,
) -> u64 {
    let (mut mask, mut left) = (0, levels);
    while left != 0 {
        let l = left.trailing_zeros() as usize & (LEVELS.len() - 1);
        left &= left - 1;
        let pick = ((keys[l] ^ i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 54) as usize;
        mask |= members[*at] & tables[l][pick % TABLE];
        *at += 1;
    }
    mask
}

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
    /// Per kind: the cells at each level (1..) its words use.
    membership: [Membership; 3],
    /// Per level: its random words.
    tables: Box<Tables>,
    /// The buffers a step writes (hum, act, cld), swapped with the state after it.
    spare: [Vec<u64>; 3],
    /// One layer of zeros: the neighbour layer of every cell past the bottom or top.
    zeros: Vec<u64>,
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
        let mut tables = Box::new([[0u64; TABLE]; LEVELS.len()]);
        for (k, (table, &p)) in tables.iter_mut().zip(&LEVELS).enumerate() {
            for (i, word) in table.iter_mut().enumerate() {
                *word = (0..64).fold(0u64, |w, b| {
                    let h = hash64(seed ^ hash64(((k as u64) << 40) ^ ((i as u64) << 8) ^ b));
                    let u = (h >> 11) as f64 / (1u64 << 53) as f64;
                    w | (((u < p as f64) as u64) << b)
                });
            }
        }
        let mut automaton = Self {
            dims,
            words,
            keys: [[0; LEVELS.len()]; 3],
            threads: None,
            hum: vec![0; n],
            act: vec![0; n],
            cld: vec![0; n],
            membership: Default::default(),
            tables,
            spare: Default::default(),
            zeros: vec![0; words * nz],
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
        let words = self.words;
        let mut m = Membership {
            rows: Vec::with_capacity(ny * nz),
            levels: Vec::with_capacity(ny * nz * words),
            words: Vec::new(),
        };
        let mut row = vec![[0u64; LEVELS.len()]; words];
        for y in 0..ny {
            for z in 0..nz {
                row.iter_mut().for_each(|w| *w = [0; LEVELS.len()]);
                for x in 0..nx {
                    let l = level(x, y, z).min(LEVELS.len() as u8 - 1) as usize;
                    if l > 0 {
                        row[x / 64][l] |= 1 << (x % 64);
                    }
                }
                m.rows.push(m.words.len());
                for w in &row {
                    // Only the levels some cell of the word uses keep a member word.
                    let mut used = 0u8;
                    for l in (1..LEVELS.len()).filter(|&l| w[l] != 0) {
                        used |= 1 << l;
                        m.words.push(w[l]);
                    }
                    m.levels.push(used);
                }
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
        let m = &self.membership[kind as usize];
        let Some(&levels) = m.levels.get(w) else {
            return 0;
        };
        let first = w - w % self.words;
        let mut at = m.rows[w / self.words]
            + m.levels[first..w]
                .iter()
                .map(|l| l.count_ones() as usize)
                .sum::<usize>();
        let keys = &self.keys[kind as usize];
        draw(&self.tables, keys, levels, &m.words, &mut at, w)
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
        let cores = crate::limits::cores();
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
        // Each layer's whole cells of wind this step; the fraction is carried.
        let shifts: Vec<i64> = (0..ny)
            .map(|y| {
                let total = self.carry[y] + self.wind[y];
                let cells = total.trunc();
                self.carry[y] = total - cells;
                cells as i64
            })
            .collect();
        let mut out = std::mem::take(&mut self.spare);
        out.iter_mut().for_each(|v| v.resize(n, 0));
        let threads = self.threads();
        let [hum, act, cld] = &mut out;
        if threads <= 1 || n < (1 << 14) {
            self.step_layers(&shifts, 0, hum, act, cld);
        } else {
            let layer = nz * words;
            let per = ny.div_ceil(threads) * layer;
            let (this, shifts) = (&*self, &shifts);
            std::thread::scope(|scope| {
                for (i, ((h, ac), c)) in hum
                    .chunks_mut(per)
                    .zip(act.chunks_mut(per))
                    .zip(cld.chunks_mut(per))
                    .enumerate()
                {
                    scope.spawn(move || this.step_layers(shifts, i * per / layer, h, ac, c));
                }
            });
        }
        std::mem::swap(&mut self.hum, &mut out[0]);
        std::mem::swap(&mut self.act, &mut out[1]);
        std::mem::swap(&mut self.cld, &mut out[2]);
        self.spare = out;
        self.step += 1;
        self.refresh_keys();
    }

    /// The growth, extinction, re-supply and wind of the layers from `y0` on that `hum`, `act`
    /// and `cld` (whole layers) hold; `shifts` is every layer's wind this step, in cells.
    ///
    /// A layer's rows are contiguous, so each layer is one run of words: the neighbours along z
    /// are `words` and `2·words` away in it (none past its ends: past the grid's edge), the
    /// layers above and below at the same place in theirs.
    fn step_layers(
        &self,
        shifts: &[i64],
        y0: usize,
        hum: &mut [u64],
        act: &mut [u64],
        cld: &mut [u64],
    ) {
        let [_, ny, nz] = self.dims;
        let words = self.words;
        let layer = nz * words;
        let tail = self.tail_mask();
        let a = &self.act[..];
        let zeros = &self.zeros[..layer];
        let [key_h, key_a, key_e] = &self.keys;
        let [mem_h, mem_a, mem_e] = &self.membership;
        let tables = &self.tables;
        let layers = hum.len() / layer;
        // A layer's act words between two rows of zeros each side: word k's neighbours along
        // z (±1, ±2 rows) and along x (±1 word) all lie within it.
        let mut padded = vec![0u64; layer + 4 * words];
        let outputs = hum
            .chunks_exact_mut(layer)
            .zip(act.chunks_exact_mut(layer))
            .zip(cld.chunks_exact_mut(layer));
        for ((y, &s), ((ho, ao), co)) in shifts.iter().enumerate().skip(y0).zip(outputs) {
            debug_assert!(y < y0 + layers);
            let base = y * layer;
            let near = |dy: isize| -> &[u64] {
                let y = y as isize + dy;
                if (0..ny as isize).contains(&y) {
                    &a[y as usize * layer..][..layer]
                } else {
                    zeros
                }
            };
            let (above, below, below2) = (near(1), near(-1), near(-2));
            // Per kind: the layer's words' used levels and where its member words start.
            let ((lh, mut at_h), (la, mut at_a), (le, mut at_e)) = (
                mem_h.words_from(y * nz, base, layer),
                mem_a.words_from(y * nz, base, layer),
                mem_e.words_from(y * nz, base, layer),
            );
            let (ha, aa, ca) = (
                &self.hum[base..base + layer],
                &a[base..base + layer],
                &self.cld[base..base + layer],
            );
            padded[2 * words..2 * words + layer].copy_from_slice(aa);
            let shifted = |d: usize| &padded[d..d + layer];
            // Zipped, not indexed: no bounds test per word where the page's size-optimised
            // build would keep one.
            let words_in = ha
                .iter()
                .zip(aa)
                .zip(ca)
                .zip(above.iter().zip(below).zip(below2));
            let z_near = shifted(0)
                .iter()
                .zip(shifted(words))
                .zip(shifted(3 * words).iter().zip(shifted(4 * words)));
            let x_near = shifted(2 * words - 1).iter().zip(shifted(2 * words + 1));
            let words_out = ho.iter_mut().zip(ao.iter_mut()).zip(co.iter_mut());
            // The word's place in its row.
            let mut w = 0;
            for (
                k,
                (
                    (
                        (((&h, &ac), &c), ((&up, &down), &down2)),
                        (((&z2, &z1), (&z3, &z4)), (&prev, &next)),
                    ),
                    ((ho, ao), co),
                ),
            ) in words_in.zip(z_near.zip(x_near)).zip(words_out).enumerate()
            {
                let i = base + k;
                // The words before and after in the row (none past its ends).
                let prev = if w > 0 { prev } else { 0 };
                let next = if w + 1 < words { next } else { 0 };
                // Bit i holds cell i+k (>>) or cell i−k (<<).
                let f = (ac >> 1 | next << 63)
                    | (ac >> 2 | next << 62)
                    | (ac << 1 | prev >> 63)
                    | (ac << 2 | prev >> 62)
                    | z1
                    | z2
                    | z3
                    | z4
                    | up
                    | down
                    | down2;
                let keep = if w + 1 == words { tail } else { u64::MAX };
                let r_h = mem_h.draw(tables, key_h, lh, k, &mut at_h, i);
                let r_e = mem_e.draw(tables, key_e, le, k, &mut at_e, i);
                let r_a = mem_a.draw(tables, key_a, la, k, &mut at_a, i);
                *ho = ((h & !ac) | r_h) & keep;
                *co = ((c | ac) & !r_e) & keep;
                *ao = ((!ac & h & f) | r_a) & keep;
                w += 1;
                if w == words {
                    w = 0;
                }
            }
            if s != 0 {
                for bits in [ho, ao, co] {
                    for row in bits.chunks_exact_mut(words) {
                        shift_row(row, s);
                        row[words - 1] &= tail;
                    }
                }
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
/// In place: words are rewritten in the order that reads each source before it is overwritten.
pub fn shift_row(row: &mut [u64], s: i64) {
    let n = row.len();
    // Whole words capped at the row's length before the cast (which would wrap on 32-bit
    // targets).
    let words = (s.unsigned_abs() / 64).min(n as u64) as usize;
    let bits = (s.unsigned_abs() % 64) as u32;
    if words >= n {
        row.fill(0);
        return;
    }
    if s > 0 {
        for i in (0..n).rev() {
            let lo = if i >= words { row[i - words] } else { 0 };
            let below = if i > words { row[i - words - 1] } else { 0 };
            row[i] = if bits == 0 {
                lo
            } else {
                (lo << bits) | (below >> (64 - bits))
            };
        }
    } else {
        for i in 0..n {
            let hi = if i + words < n { row[i + words] } else { 0 };
            let above = if i + words + 1 < n {
                row[i + words + 1]
            } else {
                0
            };
            row[i] = if bits == 0 {
                hi
            } else {
                (hi >> bits) | (above << (64 - bits))
            };
        }
    }
}
