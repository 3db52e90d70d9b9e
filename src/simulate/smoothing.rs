//! The smoothing of the automaton's cloud bits: each cell's count of cloud cells in the box of
//! half-width `r` around it.
//!
//! Up to half-width 2 (the box's 125 cells fit a byte) counts are summed eight cells at a
//! time, a byte each in a `u64` (lanes that never carry into each other): a row's x-sums of
//! eight cells are one lookup of the `8 + 2r` bits around them in a table, and the y- and
//! z-sums are additions of those words, rows of them at a time (which the compiler
//! vectorises). A window of the last `2r + 1` z-planes' xy-sums is summed for each output
//! plane.
//!
//! Wider boxes are counted bit-sliced: plane `p` is a `u64` whose bit `i` is bit `p` of cell
//! `i`'s count, so adding two counts of 64 cells is a ripple of bitwise full adders, one per
//! plane. Only then is each count written out, in a byte (a byte of a plane → eight 0/1
//! lanes, one lookup per plane), halved or quartered to fit. Cells past the grid's edges count
//! as empty.

use std::mem::MaybeUninit;

use super::{Automaton, Smoothed, run_parts};

/// Adds the one-bit count `bit` into `acc` (which must hold the sum).
#[inline(always)]
fn add_bit<const N: usize>(acc: &mut [u64; N], bit: u64) {
    let mut carry = bit;
    for a in acc {
        let next = *a & carry;
        *a ^= carry;
        carry = next;
    }
}

/// Adds the bit-sliced count `x` (no more planes than `acc`) into `acc` (which must hold the
/// sum).
#[inline(always)]
fn add<const N: usize, const M: usize>(acc: &mut [u64; N], x: &[u64; M]) {
    let mut carry = 0;
    for (p, a) in acc.iter_mut().enumerate() {
        let b = if p < M { x[p] } else { 0 };
        let half = *a ^ b;
        let next = (*a & b) | (carry & half);
        *a = half ^ carry;
        carry = next;
    }
}

/// For each window of `8 + 2r` bits of a row (`N` = 2^(8 + 2r) of them), the counts of the
/// set bits at `j..=j + 2r` for j in 0..8, byte j of the entry: the x-sums of the eight cells
/// at the window's middle.
const fn x_sums<const N: usize>(r: usize) -> [u64; N] {
    assert!(N == 1 << (8 + 2 * r));
    let mut table = [0; N];
    let mut v = 0;
    while v < N {
        let mut j = 0;
        while j < 8 {
            let count = ((v >> j) & ((1 << (2 * r + 1)) - 1)).count_ones() as u64;
            table[v] |= count << (8 * j);
            j += 1;
        }
        v += 1;
    }
    table
}

/// Each byte of a plane spread into the eight bytes of a `u64`: byte j holds bit j (the
/// x-sums of half-width 0).
static SPREAD: [u64; 256] = x_sums(0);
/// The x-sums of half-width 1 (8 kB).
static X_SUMS_1: [u64; 1 << 10] = x_sums(1);
/// The x-sums of half-width 2 (32 kB).
static X_SUMS_2: [u64; 1 << 12] = x_sums(2);

/// The planes (bits) counts up to `max` need.
const fn planes_for(max: usize) -> usize {
    (usize::BITS - max.leading_zeros()) as usize
}

/// The planes below a byte's worth: dropped (after rounding) to bring counts of `planes` bits
/// into a byte.
const fn byte_shift(planes: usize) -> usize {
    planes.saturating_sub(8)
}

/// The counts of the eight cells at bits `shift..shift + 8` of the bit-sliced `planes` (at most
/// eight of them), a byte each (cell j in byte j): one lookup and add per plane for all eight.
#[inline(always)]
fn byte_counts(planes: &[u64], shift: u32) -> u64 {
    let mut v = 0u64;
    for (p, &plane) in planes.iter().enumerate() {
        // (No carries between the byte lanes: each count is below 256.)
        v += SPREAD[(plane >> shift) as u8 as usize] << p;
    }
    v
}

/// Each cell's count of cloud cells in the box of half-width `r` (at most 4) around it, x
/// fastest, then y, then z, in a byte: halved and rounded for r = 3, quartered for r = 4 (the
/// box's 343 or 729 cells). Slabs of z are shared out among the cores. The counts are written
/// into `reuse`'s memory where it has room (a smoothed step no longer needed: its pages are
/// already mapped, where fresh memory would be faulted in on first touch, page by page).
pub(super) fn smooth(a: &Automaton, r: usize, reuse: Vec<u8>) -> Smoothed {
    let [nx, ny, nz] = a.dims;
    let r = r.min(4);
    let plane = nx * ny;
    let cells = plane * nz;
    // Written once, by the slabs, without first being cleared (4 MB at the benchmark's size).
    let mut out = reuse;
    out.clear();
    out.reserve_exact(cells);
    let threads = crate::limits::cores()
        .min(nz)
        .min(if cells < 1 << 18 { 1 } else { 8 });
    let per = nz.div_ceil(threads) * plane;
    let slab = |i: usize, chunk: &mut [MaybeUninit<u8>]| {
        let z0 = i * per / plane;
        let zs = z0..z0 + chunk.len() / plane;
        // Up to half-width 2 in byte lanes; then bit-sliced, the planes of an x-sum, an xy-sum
        // and an xyz-sum enough for (2r + 1), (2r + 1)² and (2r + 1)³ ([`planes_for`]).
        match r {
            0 => Lanes::new(a, &SPREAD).write(zs, chunk),
            1 => Lanes::new(a, &X_SUMS_1).write(zs, chunk),
            2 => Lanes::new(a, &X_SUMS_2).write(zs, chunk),
            3 => Slab::<3, 6, 9>::new(a, r).write(zs, chunk),
            _ => Slab::<4, 7, 10>::new(a, r).write(zs, chunk),
        }
    };
    run_parts(
        threads,
        out.spare_capacity_mut()[..cells].chunks_mut(per),
        &slab,
    );
    // SAFETY: the slabs cover the first `cells` values of the spare capacity (chunks of whole
    // planes), and `Lanes::write` and `Slab::write` write every value of each of their planes,
    // so all of them are initialised.
    unsafe { out.set_len(cells) };
    Smoothed {
        counts: out,
        scale: (1u32 << byte_shift(planes_for((2 * r + 1).pow(3)))) as f32
            / ((2 * r + 1) as f32).powi(3),
    }
}

/// `dst[l]` = the sum over `rows` of `row[l]` (each row as long as `dst`; one to five rows).
#[inline(always)]
fn sum_rows(dst: &mut [u64], rows: &[&[u64]]) {
    let n = dst.len();
    let row = |k: usize| &rows[k][..n];
    match rows.len() {
        1 => dst.copy_from_slice(row(0)),
        2 => {
            for ((d, a), b) in dst.iter_mut().zip(row(0)).zip(row(1)) {
                *d = a + b;
            }
        }
        3 => {
            for (((d, a), b), c) in dst.iter_mut().zip(row(0)).zip(row(1)).zip(row(2)) {
                *d = a + b + c;
            }
        }
        _ => {
            sum_rows(dst, &rows[..3]);
            for r in &rows[3..] {
                for (d, x) in dst.iter_mut().zip(&r[..n]) {
                    *d += x;
                }
            }
        }
    }
}

/// One thread's sums for half-widths up to 2, eight cells' counts a byte each in a `u64`:
/// the x-sums of a z-plane's rows and a window of the last z-planes' xy-sums.
struct Lanes<'a, const N: usize> {
    a: &'a Automaton,
    /// The x-sums of each window of `8 + 2r` bits ([`x_sums`]; N = 2^(8 + 2r)).
    table: &'static [u64; N],
    /// Lanes of eight cells per row (eight per word).
    lanes: usize,
    /// A z-plane's x-sums: row y's lane l at `y·lanes + l`.
    xs: Vec<u64>,
    /// `2r + 1` slots of xy-sums (plane z in slot z mod 2r+1), laid out as `xs`.
    window: Vec<u64>,
    /// One output plane's sums, laid out as `xs`.
    line: Vec<u64>,
}

impl<const N: usize> Window for Lanes<'_, N> {
    fn automaton(&self) -> &Automaton {
        self.a
    }

    fn half_width(&self) -> usize {
        Self::R
    }

    fn make(&mut self, z: usize) {
        let a = self.a;
        let [_, ny, nz] = a.dims;
        let (r, words, lanes) = (Self::R, a.words(), self.lanes);
        for (y, sums) in self.xs.chunks_exact_mut(lanes).enumerate() {
            let row = &a.cld[(y * nz + z) * words..][..words];
            for (w, eight) in sums.as_chunks_mut::<8>().0.iter_mut().enumerate() {
                let prev = if w > 0 { row[w - 1] } else { 0 };
                let next = if w + 1 < words { row[w + 1] } else { 0 };
                // Bit k of `low` is cell 64w − r + k (cells past the row's ends are 0 bits):
                // the windows of the first seven bytes, each 8 + 2r ≤ 12 bits from bit 8b.
                // The last byte's window runs into the next word: `high` from bit 56 on. (In
                // 64-bit words: the web build makes each shift of a u128 a call.)
                let (low, high) = if r == 0 {
                    (row[w], row[w] >> 56)
                } else {
                    (
                        row[w] << r | prev >> (64 - r),
                        row[w] >> (56 - r) | next << (8 + r),
                    )
                };
                // (An index loop: the web build makes the iterator's adaptors calls, 1.5× the
                // smoothing's time there.)
                #[allow(clippy::needless_range_loop)]
                for b in 0..7 {
                    eight[b] = self.table[(low >> (8 * b)) as usize & (N - 1)];
                }
                eight[7] = self.table[high as usize & (N - 1)];
            }
        }
        let layer = ny * lanes;
        let slot = &mut self.window[(z % (2 * r + 1)) * layer..][..layer];
        // Rows with all 2r + 1 neighbours in the plane: summed as one run, each of the 2r + 1
        // rows of sums a run of x-sums `lanes` further on; the rows at the edges one by one.
        let inner = r..ny.saturating_sub(r).max(r);
        if !inner.is_empty() {
            let mut rows: [&[u64]; 5] = [&[]; 5];
            for (k, row) in rows.iter_mut().enumerate().take(2 * r + 1) {
                *row = &self.xs[k * lanes..];
            }
            sum_rows(
                &mut slot[inner.start * lanes..inner.end * lanes],
                &rows[..2 * r + 1],
            );
        }
        for (y, sums) in slot.chunks_exact_mut(lanes).enumerate() {
            if inner.contains(&y) {
                continue;
            }
            let mut rows: [&[u64]; 5] = [&[]; 5];
            let near = y.saturating_sub(r)..(y + r + 1).min(ny);
            let n = near.len();
            for (row, k) in rows.iter_mut().zip(near) {
                *row = &self.xs[k * lanes..][..lanes];
            }
            sum_rows(sums, &rows[..n]);
        }
    }
}

impl<'a, const N: usize> Lanes<'a, N> {
    /// The half-width (a constant, so the row's bits shift by constants).
    const R: usize = (N.trailing_zeros() as usize - 8) / 2;

    fn new(a: &'a Automaton, table: &'static [u64; N]) -> Self {
        let r = Self::R;
        debug_assert!(r <= 2 && N == 1 << (8 + 2 * r));
        let [_, ny, _] = a.dims;
        let lanes = 8 * a.words();
        Self {
            a,
            table,
            lanes,
            xs: vec![0; ny * lanes],
            window: vec![0; (2 * r + 1) * ny * lanes],
            line: vec![0; ny * lanes],
        }
    }

    /// Writes the counts of z-planes `zs` into `out` (their planes, in order).
    fn write(self, zs: std::ops::Range<usize>, out: &mut [MaybeUninit<u8>]) {
        let [nx, ny, _] = self.a.dims;
        let lanes = self.lanes;
        let (span, layer) = (2 * Self::R + 1, ny * lanes);
        self.slide(zs, out, |this, near, values| {
            // The plane's sums at once: the xy-sums of its near planes added lane by lane.
            let mut rows: [&[u64]; 5] = [&[]; 5];
            let n = near.len();
            for (row, k) in rows.iter_mut().zip(near) {
                *row = &this.window[(k % span) * layer..][..layer];
            }
            let plane = &mut this.line;
            sum_rows(plane, &rows[..n]);
            // Byte j of lane l is cell 8l + j, in memory order once little-endian: a row's
            // counts are its lanes' first nx bytes, copied at once (the page's size-optimised
            // build would otherwise store them lane by lane, or byte by byte).
            if cfg!(target_endian = "big") {
                plane.iter_mut().for_each(|l| *l = l.to_le());
            }
            // (Rows without spare bytes, as where nx is a multiple of 64: the plane at once.)
            let (per, row) = if 8 * lanes == nx {
                (layer, nx * ny)
            } else {
                (lanes, nx)
            };
            for (sums, cells) in plane.chunks_exact(per).zip(values.chunks_exact_mut(row)) {
                debug_assert!(8 * sums.len() >= cells.len());
                // SAFETY: `sums` holds at least as many bytes as `cells`, which is writable
                // (`MaybeUninit<u8>` is laid out as `u8`), and the two do not overlap.
                unsafe {
                    std::ptr::copy_nonoverlapping(
                        sums.as_ptr().cast::<u8>(),
                        cells.as_mut_ptr().cast::<u8>(),
                        cells.len(),
                    );
                }
            }
        });
    }
}

/// A thread's sums over a window of z-planes: what [`Window::slide`] walks.
trait Window: Sized {
    /// The automaton summed.
    fn automaton(&self) -> &Automaton;
    /// The window's half-width.
    fn half_width(&self) -> usize;
    /// Sums plane z into its slot of the window.
    fn make(&mut self, z: usize);

    /// Walks z-planes `zs`: [`Window::make`] once for every plane the window needs, in order,
    /// each before the first `emit(self, near, values)` whose planes `near` hold it, which
    /// writes plane z's `values` (`out` holds the planes of `zs` in order).
    fn slide(
        mut self,
        zs: std::ops::Range<usize>,
        out: &mut [MaybeUninit<u8>],
        mut emit: impl FnMut(&mut Self, std::ops::Range<usize>, &mut [MaybeUninit<u8>]),
    ) {
        let ([nx, ny, nz], r) = (self.automaton().dims, self.half_width());
        for z in zs.start.saturating_sub(r)..(zs.start + r).min(nz) {
            self.make(z);
        }
        for (z, values) in zs.zip(out.chunks_exact_mut(nx * ny)) {
            if z + r < nz {
                self.make(z + r);
            }
            emit(&mut self, z.saturating_sub(r)..(z + r + 1).min(nz), values);
        }
    }
}

/// One thread's sums, bit-sliced in `PX`, `PY` and `PZ` planes: the x-sums of a z-plane's
/// rows and a window of the last z-planes' xy-sums.
struct Slab<'a, const PX: usize, const PY: usize, const PZ: usize> {
    a: &'a Automaton,
    r: usize,
    /// A z-plane's x-sums: row y's word w at `y·words + w`.
    xs: Vec<[u64; PX]>,
    /// `2r + 1` slots of xy-sums (plane z in slot z mod 2r+1), laid out as `xs`.
    window: Vec<[u64; PY]>,
}

impl<const PX: usize, const PY: usize, const PZ: usize> Window for Slab<'_, PX, PY, PZ> {
    fn automaton(&self) -> &Automaton {
        self.a
    }

    fn half_width(&self) -> usize {
        self.r
    }

    fn make(&mut self, z: usize) {
        let a = self.a;
        let [_, ny, nz] = a.dims;
        let (r, words) = (self.r, a.words());
        for (y, sums) in self.xs.chunks_exact_mut(words).enumerate() {
            let row = &a.cld[(y * nz + z) * words..][..words];
            for (w, acc) in sums.iter_mut().enumerate() {
                let cur = row[w];
                let prev = if w > 0 { row[w - 1] } else { 0 };
                let next = if w + 1 < words { row[w + 1] } else { 0 };
                *acc = [0; PX];
                add_bit(acc, cur);
                // Bit i of the shifted words holds cell i + d and cell i − d (r < 64).
                for d in 1..=r as u32 {
                    add_bit(acc, cur >> d | next << (64 - d));
                    add_bit(acc, cur << d | prev >> (64 - d));
                }
            }
        }
        let layer = ny * words;
        let slot = &mut self.window[(z % (2 * r + 1)) * layer..][..layer];
        for (y, sums) in slot.chunks_exact_mut(words).enumerate() {
            let rows = y.saturating_sub(r)..(y + r + 1).min(ny);
            for (w, acc) in sums.iter_mut().enumerate() {
                *acc = [0; PY];
                for y in rows.clone() {
                    add(acc, &self.xs[y * words + w]);
                }
            }
        }
    }
}

impl<'a, const PX: usize, const PY: usize, const PZ: usize> Slab<'a, PX, PY, PZ> {
    fn new(a: &'a Automaton, r: usize) -> Self {
        let [_, ny, _] = a.dims;
        let layer = ny * a.words();
        let span = 2 * r + 1;
        debug_assert_eq!(
            [PX, PY, PZ],
            [span, span * span, span.pow(3)].map(planes_for)
        );
        Self {
            a,
            r,
            xs: vec![[0; PX]; layer],
            window: vec![[0; PY]; (2 * r + 1) * layer],
        }
    }

    /// Writes the counts of z-planes `zs` into `out` (their planes, in order).
    fn write(self, zs: std::ops::Range<usize>, out: &mut [MaybeUninit<u8>]) {
        let [nx, ny, _] = self.a.dims;
        let words = self.a.words();
        let (span, layer) = (2 * self.r + 1, ny * words);
        self.slide(zs, out, |this, near, values| {
            // The window's slots of the planes around z.
            let mut slots = [0; 9];
            let slots = &mut slots[..near.len()];
            for (slot, k) in slots.iter_mut().zip(near) {
                *slot = (k % span) * layer;
            }
            for (y, line) in values.chunks_exact_mut(nx).enumerate() {
                for (w, cells) in line.chunks_mut(64).enumerate() {
                    let mut acc = [0u64; PZ];
                    for &slot in &*slots {
                        add(&mut acc, &this.window[slot + y * words + w]);
                    }
                    // Counts over a byte (r = 3, 4) are rounded: half of the lowest kept
                    // plane added, the planes below dropped.
                    let down = byte_shift(PZ);
                    if down > 0 {
                        let mut carry = u64::MAX;
                        for a in &mut acc[down - 1..] {
                            let next = *a & carry;
                            *a ^= carry;
                            carry = next;
                        }
                    }
                    let acc = &acc[down..];
                    let whole = (cells.len() / 8 * 8) as u32;
                    let (eights, rest) = cells.as_chunks_mut::<8>();
                    for (b, eight) in (0..).zip(eights) {
                        let counts = byte_counts(acc, 8 * b).to_le();
                        // SAFETY: `eight` is 8 writable bytes, which an unaligned write of a
                        // u64 fills (one store, where the page's build would otherwise make
                        // eight).
                        unsafe { eight.as_mut_ptr().cast::<u64>().write_unaligned(counts) };
                    }
                    // A last word's cells past a whole byte.
                    if !rest.is_empty() {
                        let counts = byte_counts(acc, whole).to_le_bytes();
                        for (o, c) in rest.iter_mut().zip(counts) {
                            o.write(c);
                        }
                    }
                }
            }
        });
    }
}
