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
//! that level's table). Each level keeps a list of the words with cells at it, so a step draws
//! once per word a level holds, in a loop without branches. The step and
//! [`Automaton::random_word`] (which the byte-per-cell reference in the tests calls per word)
//! both draw through one function, so the reference reproduces a run bit for bit.
//!
//! A step writes into spare buffers, a layer of y (its rows contiguous) at a time, in three
//! passes while the layer is in cache: the rule without its random terms (two words at a time,
//! in one SIMD register), the random terms level by level, then each row moved by its layer's
//! wind.

use super::lanes::{Lanes, Pair};
use super::run_parts;
use crate::seeded::hash64;

/// The probability levels a cell's probabilities are rounded to (level 0 never fires).
pub const LEVELS: [f32; 8] = [0.0, 0.002, 0.01, 0.03, 0.08, 0.2, 0.45, 1.0];
/// Random words per level table.
const TABLE: usize = 1024;

/// Per level, its table of random words.
type Tables = [[u64; TABLE]; LEVELS.len()];

/// The cells of one kind at one probability level: the words that have any, in ascending
/// order, each with its member word (bit set: the cell is at that level).
#[derive(Clone, Debug, Default)]
struct Level {
    /// Per word with cells at this level: its index in the grid.
    at: Vec<u32>,
    /// Per such word: its cells at this level.
    members: Vec<u64>,
    /// Per layer y, the first of its words (and one past the last layer's).
    layers: Vec<usize>,
}

/// The cells of one kind at each probability level (1..).
type Membership = [Level; LEVELS.len()];

/// The word a level draws for word `i`: picked from the level's table by its key this step
/// and `i` (a Fibonacci hash: neighbouring words draw far-apart entries).
#[inline(always)]
fn pick(table: &[u64; TABLE], key: u64, i: u64) -> u64 {
    let p = ((key ^ i).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 54) as usize;
    table[p % TABLE]
}

/// A word (or pair) moved `b` cells (0 < b < 64) toward higher x (`up`) or lower, taking the
/// bits shifted out of `from`, its neighbour on that side; `cells` keeps the row's cells.
#[inline(always)]
fn wind<B: Lanes>(up: bool, b: u32, word: B, from: B, cells: B) -> B {
    let moved = if up {
        word << b | from >> (64 - b)
    } else {
        word >> b | from << (64 - b)
    };
    moved & cells
}

/// One layer's inputs to the rule, word k of each at k (all one layer long).
struct Layer<'a> {
    hum: &'a [u64],
    cld: &'a [u64],
    /// The layer's act words from `2·words` on, between two rows of zeros each side: word
    /// k's neighbours along z (±1, ±2 rows) and along x (±1 word) all lie in it, at fixed
    /// distances from `padded[k]`.
    padded: &'a [u64],
    /// Per place in a row, twice over (so a pair may start at any place): whether the words
    /// before and after it lie in the row (all ones or zero), then which of its bits are cells
    /// (the last word's tail is not); `2·words` of each.
    edges: &'a [u64],
    /// The act words of the layers above, below and two below.
    ys: [&'a [u64]; 3],
}

impl Layer<'_> {
    /// The rule without its random terms into `hum`, `cld` and `act`: `B::WIDTH` words at a
    /// time, then a word at a time for what is left.
    ///
    /// The common row lengths (one to four words) get their own copies of the loop: with
    /// `words` a constant, the seven act words a word needs lie at constant distances from one
    /// address and its edges' place in the row is a mask of the index, so the web build's
    /// loads take offsets from a few registers instead of spilling eighteen.
    #[inline(always)]
    fn grow<B: Lanes>(&self, words: usize, hum: &mut [u64], cld: &mut [u64], act: &mut [u64]) {
        match words {
            1 => self.grow_words::<B, 1>(hum, cld, act),
            2 => self.grow_words::<B, 2>(hum, cld, act),
            3 => self.grow_words::<B, 3>(hum, cld, act),
            4 => self.grow_words::<B, 4>(hum, cld, act),
            _ => self.grow_words::<B, 0>(hum, cld, act),
        }
    }

    /// [`Layer::grow`] for rows of `W` words (0: of any length, `edges.len() / 6`).
    #[inline(always)]
    fn grow_words<B: Lanes, const W: usize>(
        &self,
        hum: &mut [u64],
        cld: &mut [u64],
        act: &mut [u64],
    ) {
        let words = if W == 0 { self.edges.len() / 6 } else { W };
        let n = self.hum.len();
        let ins = [self.cld, self.ys[0], self.ys[1], self.ys[2], hum, cld, act];
        assert!(words > 0 && ins.iter().all(|s| s.len() >= n));
        assert!(self.padded.len() >= n + 4 * words && self.edges.len() >= 6 * words);
        let mut k = 0;
        let k = loop {
            if n - k < B::WIDTH {
                break k;
            }
            // SAFETY: k + WIDTH <= n, so every run holds the words (checked above).
            unsafe { self.grow_at::<B>(words, k, [hum, cld, act]) };
            k += B::WIDTH;
        };
        for k in k..n {
            // SAFETY: as above.
            unsafe { self.grow_at::<u64>(words, k, [hum, cld, act]) };
        }
    }

    /// The rule at words `k..k + B::WIDTH`.
    ///
    /// # Safety
    /// `k + B::WIDTH <= n`, and every run as [`Layer::grow_words`] checks it.
    #[inline(always)]
    unsafe fn grow_at<B: Lanes>(&self, words: usize, k: usize, [hum, cld, act]: [&mut [u64]; 3]) {
        let (p, e) = (self.padded, self.edges);
        let place = k % words;
        let [up, down, down2] = self.ys;
        // SAFETY: the caller's; `place + B::WIDTH <= 2·words`.
        unsafe {
            // The rule without its random terms: the new hum, cld and act from the word's
            // own, its act neighbours' (f: any of the eleven) and its cells. Each neighbour is
            // loaded as it is taken (the web build's compiler keeps that order, so few
            // registers are live at once). Bit i holds cell i+k (>>) or cell i−k (<<).
            let mut f = B::load(p, k + words);
            f = f | B::load(p, k);
            f = f | B::load(p, k + 3 * words);
            f = f | B::load(p, k + 4 * words);
            f = f | B::load(up, k);
            f = f | B::load(down, k);
            f = f | B::load(down2, k);
            let ac = B::load(p, k + 2 * words);
            let prev = B::load(p, k + 2 * words - 1) & B::load(e, place);
            let next = B::load(p, k + 2 * words + 1) & B::load(e, place + 2 * words);
            f = f
                | (ac >> 1 | next << 63)
                | (ac >> 2 | next << 62)
                | (ac << 1 | prev >> 63)
                | (ac << 2 | prev >> 62);
            let h = B::load(self.hum, k);
            let a = !ac & h & f & B::load(e, place + 4 * words);
            let c = B::load(self.cld, k) | ac;
            let h = h & !ac;
            h.store(hum, k);
            c.store(cld, k);
            a.store(act, k);
        }
    }
}

/// One layer's words moved by its wind: `here` moved `b` cells (0 < b < 64) up x or down,
/// taking the bits shifted out of `from` (the neighbour on the upwind side; `from_in`: whether
/// it lies in the row).
struct Moved<'a> {
    up: bool,
    b: u32,
    here: &'a [u64],
    from: &'a [u64],
    from_in: &'a [u64],
    cells: &'a [u64],
}

impl Moved<'_> {
    /// Writes the moved words from word `k` on into `out`, `B::WIDTH` at a time, while whole
    /// `B`s fit; returns the first word not written.
    #[inline(always)]
    fn write<B: Lanes>(&self, mut k: usize, out: &mut [u64]) -> usize {
        let n = self.here.len();
        let ins = [self.from, self.from_in, self.cells, out];
        assert!(k <= n && ins.iter().all(|s| s.len() >= n));
        while n - k >= B::WIDTH {
            // SAFETY: k + WIDTH <= n, and every run holds n words or more (checked above).
            unsafe {
                let from = B::load(self.from, k) & B::load(self.from_in, k);
                wind::<B>(
                    self.up,
                    self.b,
                    B::load(self.here, k),
                    from,
                    B::load(self.cells, k),
                )
                .store(out, k);
            }
            k += B::WIDTH;
        }
        k
    }
}

/// The nearest level of a probability (on a log scale above the smallest).
pub fn level_of(p: f32) -> u8 {
    // (NaN and anything below half the smallest level: never.)
    if p.is_nan() || p <= LEVELS[1] * 0.5 {
        return 0;
    }
    // The nearest level in log space: above the geometric mean of two neighbours, the higher
    // (no logarithm or root per cell: a simulation's parcels set these at every interval).
    static BETWEEN: std::sync::OnceLock<[f32; LEVELS.len() - 2]> = std::sync::OnceLock::new();
    let between =
        BETWEEN.get_or_init(|| std::array::from_fn(|i| (LEVELS[i + 1] * LEVELS[i + 2]).sqrt()));
    let mut k = 1;
    while k + 1 < LEVELS.len() && p > between[k - 1] {
        k += 1;
    }
    k as u8
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

    /// Its step, then its cells and carry, little-endian (a checkpoint file's body).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(8 + self.bytes());
        out.extend_from_slice(&self.step.to_le_bytes());
        for words in [&self.hum, &self.act, &self.cld] {
            out.extend(words.iter().flat_map(|w| w.to_le_bytes()));
        }
        out.extend(self.carry.iter().flat_map(|c| c.to_le_bytes()));
        out
    }

    /// A state of the same automaton as `like` read back from [`State::to_bytes`], or why
    /// not (another size: another automaton).
    pub fn from_bytes(bytes: &[u8], like: &State) -> Result<State, String> {
        if bytes.len() != 8 + like.bytes() {
            return Err(format!(
                "{} bytes where this run's state has {}",
                bytes.len(),
                8 + like.bytes()
            ));
        }
        let (step, mut rest) = bytes.split_at(8);
        let mut words = |n: usize| {
            let (these, after) = rest.split_at(n * 8);
            rest = after;
            these
                .chunks_exact(8)
                .map(|c| u64::from_le_bytes(c.try_into().unwrap_or_default()))
                .collect::<Vec<u64>>()
        };
        let hum = words(like.hum.len());
        let act = words(like.act.len());
        let cld = words(like.cld.len());
        let carry = rest
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap_or_default()))
            .collect::<Vec<f32>>();
        if carry.iter().any(|c| !c.is_finite()) {
            return Err("a wind carry that is not a number".into());
        }
        Ok(State {
            hum,
            act,
            cld,
            carry,
            step: u64::from_le_bytes(step.try_into().unwrap_or_default()),
        })
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
    /// Per word of a layer: whether the words before and after it in its row lie in the row
    /// (all ones or zero), and which of its bits are cells (the last word's tail is not).
    edges: [Vec<u64>; 3],
    /// The same per place in a row, twice over ([`Layer::edges`]).
    row_edges: Vec<u64>,
    /// Whether the rule runs on pairs of words (as it does unless a test or the page's
    /// benchmark asks for a word at a time).
    paired: bool,
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
            edges: {
                let tail = match nx % 64 {
                    0 => u64::MAX,
                    r => (1u64 << r) - 1,
                };
                let per_word =
                    |f: &dyn Fn(usize) -> u64| (0..words * nz).map(|k| f(k % words)).collect();
                [
                    per_word(&|w| if w > 0 { u64::MAX } else { 0 }),
                    per_word(&|w| if w + 1 < words { u64::MAX } else { 0 }),
                    per_word(&|w| if w + 1 < words { u64::MAX } else { tail }),
                ]
            },
            row_edges: Vec::new(),
            paired: true,
            wind: vec![0.0; ny],
            carry: vec![0.0; ny],
            seed,
            step: 0,
        };
        automaton.row_edges = automaton
            .edges
            .iter()
            .flat_map(|e| (0..2 * words).map(|k| e[k % words]))
            .collect();
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
        let nx = self.dims[0];
        self.set_levels_in_spans(kind, 0, |_, _| Some((0, nx)), level);
    }

    /// [`Automaton::set_levels`] where only the cells `span(y, z)` (a range of x, or none) of
    /// each row ask `level`, and every other cell is at `outside`: the same levels, in a time
    /// that grows with the spans' cells (a parcel's steering reaches only the cells its box
    /// holds).
    pub fn set_levels_in_spans(
        &mut self,
        kind: Kind,
        outside: u8,
        span: impl Fn(usize, usize) -> Option<(usize, usize)>,
        level: impl Fn(usize, usize, usize) -> u8,
    ) {
        let [nx, ny, nz] = self.dims;
        let words = self.words;
        let top = LEVELS.len() as u8 - 1;
        let outside = outside.min(top) as usize;
        let mut m = Membership::default();
        let mut row = vec![[0u64; LEVELS.len()]; words];
        // Every bit of a row's word that holds a cell.
        let full = |w: usize| {
            let bits = (nx - 64 * w).min(64);
            if bits == 64 {
                u64::MAX
            } else {
                (1u64 << bits) - 1
            }
        };
        for y in 0..ny {
            for l in &mut m {
                l.layers.push(l.at.len());
            }
            for z in 0..nz {
                row.iter_mut().enumerate().for_each(|(w, bits)| {
                    *bits = [0; LEVELS.len()];
                    bits[outside] = full(w);
                });
                if let Some((from, to)) = span(y, z) {
                    for x in from..to.min(nx) {
                        let bit = 1u64 << (x % 64);
                        let bits = &mut row[x / 64];
                        bits[outside] &= !bit;
                        bits[level(x, y, z).min(top) as usize] |= bit;
                    }
                }
                let first = (y * nz + z) * words;
                for (w, bits) in row.iter().enumerate() {
                    // (Level 0 is never drawn: its cells are in no list.)
                    for (l, &b) in m.iter_mut().zip(bits).skip(1).filter(|(_, b)| **b != 0) {
                        l.at.push((first + w) as u32);
                        l.members.push(b);
                    }
                }
            }
        }
        for l in &mut m {
            l.layers.push(l.at.len());
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
    pub fn random_word(&self, kind: Kind, w: usize) -> u64 {
        let keys = &self.keys[kind as usize];
        let mut mask = 0;
        for (l, level) in self.membership[kind as usize].iter().enumerate() {
            if let Ok(k) = level.at.binary_search(&(w as u32)) {
                mask |= level.members[k] & pick(&self.tables[l], keys[l], w as u64);
            }
        }
        mask
    }

    /// The bits of the last word of a row that are cells (the rest stay 0).
    fn tail_mask(&self) -> u64 {
        self.edges[2][self.words - 1]
    }

    /// Runs the rule on pairs of words or one word at a time (the tests compare the two; both
    /// give the same bits).
    pub fn set_paired(&mut self, paired: bool) {
        self.paired = paired;
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
            let parts = hum
                .chunks_mut(per)
                .zip(act.chunks_mut(per))
                .zip(cld.chunks_mut(per));
            run_parts(threads, parts, &|i, ((h, ac), c)| {
                self.step_layers(&shifts, i * per / layer, h, ac, c)
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
        let n = nz * words;
        let a = &self.act[..];
        let [prev_in, next_in, cells] = self.edges.each_ref().map(|e| &e[..n]);
        // A layer's act words between two rows of zeros each side: word k's neighbours along
        // z (±1, ±2 rows) and along x (±1 word) all lie within it. The wind pass reuses it.
        let mut padded = vec![0u64; n + 4 * words];
        let layers = hum.len() / n;
        let outputs = hum
            .chunks_exact_mut(n)
            .zip(act.chunks_exact_mut(n))
            .zip(cld.chunks_exact_mut(n));
        for ((y, &s), ((ho, ao), co)) in shifts.iter().enumerate().skip(y0).zip(outputs) {
            debug_assert!(y < y0 + layers);
            let base = y * n;
            let near = |dy: isize| -> &[u64] {
                let y = y as isize + dy;
                if (0..ny as isize).contains(&y) {
                    &a[y as usize * n..][..n]
                } else {
                    &self.zeros[..n]
                }
            };
            padded[2 * words..2 * words + n].copy_from_slice(&a[base..][..n]);
            let layer = Layer {
                hum: &self.hum[base..][..n],
                cld: &self.cld[base..][..n],
                padded: &padded,
                edges: &self.row_edges,
                ys: [near(1), near(-1), near(-2)],
            };
            let (ho, co, ao) = (&mut ho[..n], &mut co[..n], &mut ao[..n]);
            if self.paired {
                layer.grow::<Pair>(words, ho, co, ao);
            } else {
                layer.grow::<u64>(words, ho, co, ao);
            }
            // The random terms, level by level: one draw per word with cells at the level.
            for (kind, out) in [
                (Kind::Hum, &mut *ho),
                (Kind::Ext, &mut *co),
                (Kind::Act, &mut *ao),
            ] {
                let keys = &self.keys[kind as usize];
                for (l, level) in self.membership[kind as usize].iter().enumerate() {
                    let Some(&[from, to]) =
                        level.layers.get(y..y + 2).and_then(|r| r.first_chunk())
                    else {
                        continue;
                    };
                    let (at, members) = (&level.at[from..to], &level.members[from..to]);
                    // (The level's key and table, and the loops per kind, are written out:
                    // the web build's size-optimised code reloads and re-checks them for
                    // every word otherwise.)
                    let (key, table) = (keys[l], &self.tables[l]);
                    if kind == Kind::Ext {
                        for j in 0..at.len().min(members.len()) {
                            let draw = members[j] & pick(table, key, at[j] as u64);
                            out[at[j] as usize - base] &= !draw;
                        }
                    } else {
                        for j in 0..at.len().min(members.len()) {
                            let draw = members[j] & pick(table, key, at[j] as u64);
                            out[at[j] as usize - base] |= draw;
                        }
                    }
                }
            }
            if s != 0 && s.unsigned_abs() < 64 {
                // Within a word: each word takes the bits shifted out of its neighbour on the
                // wind's upwind side in the row (none past the row's ends).
                let b = s.unsigned_abs() as u32;
                let (d, from_in) = if s > 0 {
                    (2 * words - 1, prev_in)
                } else {
                    (2 * words + 1, next_in)
                };
                for bits in [ho, ao, co] {
                    padded[2 * words..2 * words + n].copy_from_slice(bits);
                    let moved = Moved {
                        up: s > 0,
                        b,
                        here: &padded[2 * words..][..n],
                        from: &padded[d..][..n],
                        from_in,
                        cells,
                    };
                    let k = if self.paired {
                        moved.write::<Pair>(0, bits)
                    } else {
                        0
                    };
                    moved.write::<u64>(k, bits);
                }
            } else if s != 0 {
                let tail = self.tail_mask();
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
