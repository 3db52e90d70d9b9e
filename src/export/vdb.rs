//! An OpenVDB writer (no Rust crate writes VDB): one float fog-volume grid in file format 224,
//! uncompressed, as OpenVDB's own `io::File` lays it out — the header, the grid descriptor,
//! the grid's metadata and transform, the tree's topology (root → one 32³ internal node →
//! 16³ internal nodes → 8³ leaves, each with its masks), then the leaves' values. Only leaves
//! holding some density are written; everything else is the background, 0. See
//! docs/export-formats.md.

use glam::{IVec3, UVec3};

use super::axes::Axes;
use super::grid::DensityGrid;

/// OpenVDB's magic number (" BDV" as a little-endian int64).
const MAGIC: i64 = 0x5644_4220;
/// File format 224 (OpenVDB 7 and later write it; every reader since reads it).
const FILE_VERSION: u32 = 224;
/// "No mask compression, every value written" (`io::NO_MASK_AND_ALL_VALS`).
const ALL_VALUES: u8 = 6;
const LEAF: i32 = 8;
const LOWER: i32 = 128;
const UPPER: i32 = 4096;

struct Out(Vec<u8>);

impl Out {
    fn bytes(&mut self, b: &[u8]) {
        self.0.extend_from_slice(b);
    }
    fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    fn i32(&mut self, v: i32) {
        self.bytes(&v.to_le_bytes());
    }
    fn i64(&mut self, v: i64) {
        self.bytes(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.bytes(&v.to_le_bytes());
    }
    fn vec3d(&mut self, v: [f64; 3]) {
        for c in v {
            self.bytes(&c.to_le_bytes());
        }
    }
    fn string(&mut self, s: &str) {
        self.u32(s.len() as u32);
        self.bytes(s.as_bytes());
    }
    fn mask(&mut self, words: &[u64]) {
        for w in words {
            self.bytes(&w.to_le_bytes());
        }
    }
    /// A metadata entry: name, type name, byte count, value.
    fn meta(&mut self, name: &str, kind: &str, value: &[u8]) {
        self.string(name);
        self.string(kind);
        self.u32(value.len() as u32);
        self.bytes(value);
    }
    fn patch_i64(&mut self, at: usize, v: i64) {
        self.0[at..at + 8].copy_from_slice(&v.to_le_bytes());
    }
}

/// One 8³ leaf: its origin (index space) and values, z fastest as OpenVDB stores them.
struct Leaf {
    origin: IVec3,
    values: Vec<f32>,
    mask: [u64; 8],
}

/// Linear offset of a child in a node of `2^log2` children per side (x slowest, z fastest).
fn child_offset(p: IVec3, child_span: i32, log2: u32) -> usize {
    let n = 1 << log2;
    let c = (p / child_span) & IVec3::splat(n - 1);
    ((c.x << (2 * log2)) | (c.y << log2) | c.z) as usize
}

fn leaves(dims: UVec3, value: &dyn Fn(UVec3) -> f32) -> Vec<Leaf> {
    let count = (dims + UVec3::splat(7)) / 8;
    let mut out = Vec::new();
    for lx in 0..count.x {
        for ly in 0..count.y {
            for lz in 0..count.z {
                let origin = UVec3::new(lx, ly, lz) * 8;
                let mut values = vec![0f32; 512];
                let mut mask = [0u64; 8];
                for x in 0..8 {
                    for y in 0..8 {
                        for z in 0..8 {
                            let p = origin + UVec3::new(x, y, z);
                            if p.cmpge(dims).any() {
                                continue;
                            }
                            let v = value(p);
                            if v > 0.0 {
                                let i = ((x << 6) | (y << 3) | z) as usize;
                                values[i] = v;
                                mask[i >> 6] |= 1 << (i & 63);
                            }
                        }
                    }
                }
                if mask.iter().any(|&w| w != 0) {
                    out.push(Leaf {
                        origin: origin.as_ivec3(),
                        values,
                        mask,
                    });
                }
            }
        }
    }
    // The order OpenVDB visits leaves in: by lower node, then by offset within it.
    out.sort_by_key(|l| {
        (
            child_offset(l.origin, LOWER, 5),
            child_offset(l.origin, LEAF, 4),
        )
    });
    out
}

/// The grid as a `.vdb` file holding one float fog volume named `name`, in `axes`.
pub fn write_vdb(grid: &DensityGrid, axes: Axes, name: &str, uuid: u64) -> Vec<u8> {
    let (dims, first, order) = axes.grid(grid);
    let h = (grid.h * axes.scale) as f64;
    let at = |p: UVec3| grid.values[order[((p.z * dims.y + p.y) * dims.x + p.x) as usize]];
    let leaves = leaves(dims, &at);
    debug_assert!(dims.max_element() as i32 <= UPPER);

    let mut o = Out(Vec::new());
    // Header.
    o.i64(MAGIC);
    o.u32(FILE_VERSION);
    o.u32(10); // library version the layout follows: 10.0
    o.u32(0);
    o.bytes(&[1]); // grid offsets present
    let id = format!(
        "{:08x}-{:04x}-4{:03x}-a{:03x}-{:012x}",
        (uuid >> 32) as u32,
        (uuid >> 16) as u16,
        (uuid & 0xfff) as u16,
        (uuid >> 52) as u16 & 0xfff,
        uuid.rotate_left(17) & 0xffff_ffff_ffff
    );
    o.bytes(id.as_bytes());
    o.u32(0); // file metadata: none
    o.i32(1); // one grid

    // Grid descriptor: unique name, type, instance parent, then three stream positions.
    o.string(name);
    o.string("Tree_float_5_4_3");
    o.string("");
    let positions = o.0.len();
    o.i64(0);
    o.i64(0);
    o.i64(0);
    let grid_pos = o.0.len();
    o.u32(0); // compression: none

    // Grid metadata.
    let voxels: u64 = leaves
        .iter()
        .map(|l| l.mask.iter().map(|w| w.count_ones() as u64).sum::<u64>())
        .sum();
    let ivec =
        |v: IVec3| -> Vec<u8> { v.to_array().iter().flat_map(|c| c.to_le_bytes()).collect() };
    // The active voxels' bounding box (index space).
    let mut lo = IVec3::splat(i32::MAX);
    let mut hi = IVec3::splat(i32::MIN);
    for l in &leaves {
        for (i, w) in l.mask.iter().enumerate() {
            let mut bits = *w;
            while bits != 0 {
                let n = (i * 64 + bits.trailing_zeros() as usize) as i32;
                let p = l.origin + IVec3::new(n >> 6, (n >> 3) & 7, n & 7);
                lo = lo.min(p);
                hi = hi.max(p);
                bits &= bits - 1;
            }
        }
    }
    if leaves.is_empty() {
        (lo, hi) = (IVec3::ZERO, IVec3::ZERO);
    }
    let entries: Vec<(&str, &str, Vec<u8>)> = vec![
        ("class", "string", b"fog volume".to_vec()),
        ("creator", "string", b"cloudsketch".to_vec()),
        ("file_bbox_max", "vec3i", ivec(hi)),
        ("file_bbox_min", "vec3i", ivec(lo)),
        (
            "file_mem_bytes",
            "int64",
            ((leaves.len() * (512 * 4 + 64)) as i64)
                .to_le_bytes()
                .to_vec(),
        ),
        (
            "file_voxel_count",
            "int64",
            (voxels as i64).to_le_bytes().to_vec(),
        ),
        ("is_local_space", "bool", vec![0]),
        ("is_saved_as_half_float", "bool", vec![0]),
        ("name", "string", name.as_bytes().to_vec()),
    ];
    o.u32(entries.len() as u32);
    for (n, k, v) in &entries {
        o.meta(n, k, v);
    }

    // Transform: index (i, j, k) → first + (i, j, k)·h.
    o.string("UniformScaleTranslateMap");
    let f = first.as_dvec3().to_array();
    o.vec3d(f);
    o.vec3d([h; 3]);
    o.vec3d([h; 3]);
    o.vec3d([1.0 / h; 3]);
    o.vec3d([1.0 / (h * h); 3]);
    o.vec3d([0.5 / h; 3]);

    // Topology.
    o.i32(1); // buffer count
    o.f32(0.0); // background
    o.u32(0); // root tiles
    if leaves.is_empty() {
        o.u32(0);
    } else {
        o.u32(1); // one upper internal node, at the origin
        o.i32(0);
        o.i32(0);
        o.i32(0);
        let lowers: Vec<usize> = {
            let mut v: Vec<usize> = leaves
                .iter()
                .map(|l| child_offset(l.origin, LOWER, 5))
                .collect();
            v.dedup();
            v
        };
        // Upper node (32³ children of 128³ voxels each).
        let mut child = vec![0u64; 512];
        for &c in &lowers {
            child[c >> 6] |= 1 << (c & 63);
        }
        o.mask(&child);
        o.mask(&[0u64; 512]);
        o.bytes(&[ALL_VALUES]);
        o.bytes(&vec![0u8; 32768 * 4]);
        for &lower in &lowers {
            let mine: Vec<&Leaf> = leaves
                .iter()
                .filter(|l| child_offset(l.origin, LOWER, 5) == lower)
                .collect();
            let mut child = [0u64; 64];
            for l in &mine {
                let c = child_offset(l.origin, LEAF, 4);
                child[c >> 6] |= 1 << (c & 63);
            }
            o.mask(&child);
            o.mask(&[0u64; 64]);
            o.bytes(&[ALL_VALUES]);
            o.bytes(&vec![0u8; 4096 * 4]);
            for l in mine {
                o.mask(&l.mask);
            }
        }
    }
    let block_pos = o.0.len();
    // Leaf buffers, in the same order.
    for l in &leaves {
        o.mask(&l.mask);
        o.bytes(&[ALL_VALUES]);
        for &v in &l.values {
            o.f32(v);
        }
    }
    let end_pos = o.0.len();
    o.patch_i64(positions, grid_pos as i64);
    o.patch_i64(positions + 8, block_pos as i64);
    o.patch_i64(positions + 16, end_pos as i64);
    o.0
}
