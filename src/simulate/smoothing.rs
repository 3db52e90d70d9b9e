//! The smoothing of the automaton's cloud bits: each cell's count of cloud cells in the box of
//! half-width `r` around it, counted 64 cells at a time.
//!
//! A count is kept bit-sliced while it is summed: plane `p` is a `u64` whose bit `i` is bit `p`
//! of cell `i`'s count, so adding two counts of 64 cells is a ripple of bitwise full adders,
//! one per plane, instead of 64 additions. A z-plane of the grid is summed across x (the row's
//! bits shifted by −r..r) and then across y (neighbouring rows' x-sums); a window of the last
//! `2r + 1` such planes is summed across z for each output plane. Only then is each count
//! written out, in a byte, eight cells per lookup and plane (a byte of a plane → eight 0/1
//! lanes). Cells past the grid's edges count as empty.

use std::mem::MaybeUninit;

use super::{Automaton, Smoothed};

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

/// Each byte of a plane spread into the eight bytes of a `u64`: byte j holds bit j.
const SPREAD: [u64; 256] = {
    let mut table = [0; 256];
    let mut b = 0;
    while b < 256 {
        let mut j = 0;
        while j < 8 {
            table[b] |= ((b as u64 >> j) & 1) << (8 * j);
            j += 1;
        }
        b += 1;
    }
    table
};

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
/// box's 343 or 729 cells). Slabs of z are shared out among the cores.
pub(super) fn smooth(a: &Automaton, r: usize) -> Smoothed {
    let [nx, ny, nz] = a.dims;
    let r = r.min(4);
    let plane = nx * ny;
    let cells = plane * nz;
    // Written once, by the slabs, without first being cleared (4 MB at the benchmark's size).
    let mut out: Vec<u8> = Vec::with_capacity(cells);
    let threads = crate::limits::cores()
        .min(nz)
        .min(if cells < 1 << 18 { 1 } else { 8 });
    let per = nz.div_ceil(threads) * plane;
    let slab = |i: usize, chunk: &mut [MaybeUninit<u8>]| {
        let z0 = i * per / plane;
        let zs = z0..z0 + chunk.len() / plane;
        // The planes of an x-sum, an xy-sum and an xyz-sum: enough for (2r + 1), (2r + 1)² and
        // (2r + 1)³ ([`planes_for`]).
        match r {
            0 => Slab::<1, 1, 1>::new(a, r).write(zs, chunk),
            1 => Slab::<2, 4, 5>::new(a, r).write(zs, chunk),
            2 => Slab::<3, 5, 7>::new(a, r).write(zs, chunk),
            3 => Slab::<3, 6, 9>::new(a, r).write(zs, chunk),
            _ => Slab::<4, 7, 10>::new(a, r).write(zs, chunk),
        }
    };
    run_parts(
        threads,
        out.spare_capacity_mut()[..cells].chunks_mut(per).collect(),
        &slab,
    );
    // SAFETY: the slabs cover the first `cells` values of the spare capacity (chunks of whole
    // planes), and `Slab::write` writes every value of each of its planes, so all of them are
    // initialised.
    unsafe { out.set_len(cells) };
    Smoothed {
        counts: out,
        scale: (1u32 << byte_shift(planes_for((2 * r + 1).pow(3)))) as f32
            / ((2 * r + 1) as f32).powi(3),
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

    /// The xy-sums of z-plane `z` into its slot of the window.
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

    /// Writes the counts of z-planes `zs` into `out` (their planes, in order).
    fn write(mut self, zs: std::ops::Range<usize>, out: &mut [MaybeUninit<u8>]) {
        let [nx, ny, nz] = self.a.dims;
        let (r, words) = (self.r, self.a.words());
        let span = 2 * r + 1;
        let layer = ny * words;
        for z in zs.start.saturating_sub(r)..(zs.start + r).min(nz) {
            self.make(z);
        }
        for (z, values) in zs.zip(out.chunks_exact_mut(nx * ny)) {
            if z + r < nz {
                self.make(z + r);
            }
            // The window's slots of the planes around z.
            let mut slots = [0; 9];
            let near = z.saturating_sub(r)..(z + r + 1).min(nz);
            let slots = &mut slots[..near.len()];
            for (slot, k) in slots.iter_mut().zip(near) {
                *slot = (k % span) * layer;
            }
            for (y, line) in values.chunks_exact_mut(nx).enumerate() {
                for (w, cells) in line.chunks_mut(64).enumerate() {
                    let mut acc = [0u64; PZ];
                    for &slot in &*slots {
                        add(&mut acc, &self.window[slot + y * words + w]);
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
        }
    }
}

/// Runs `work(i, part)` for every part, on up to `threads` scoped threads (inline for one).
fn run_parts<T: Send>(threads: usize, parts: Vec<T>, work: &(dyn Fn(usize, T) + Sync)) {
    if threads <= 1 {
        parts.into_iter().enumerate().for_each(|(i, p)| work(i, p));
        return;
    }
    std::thread::scope(|scope| {
        for (i, p) in parts.into_iter().enumerate() {
            scope.spawn(move || work(i, p));
        }
    });
}
