//! The neutral density volume: a field (or, later, a simulation) sampled on a capped regular
//! grid. The renderer uploads it as a 3D texture (WebGL2 has no storage buffers or compute),
//! and the exporters write it.
//!
//! Texels are cubes of side `h` on a lattice anchored at the world origin (texel centres at
//! `(n + ½)·h`), so two grids of one texel size share their texels wherever they overlap: an
//! update copies what it can from the last volume and re-evaluates only the bricks (8³ texels)
//! that an edited primitive reaches ([`Baker`]).

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

use glam::{I64Vec3, UVec3, Vec3};

use super::{Blob, BlobRow, Field, ISO, SUPPORT};

mod surface;
pub use surface::bake_for_surface;

pub use crate::density::DensityVolume;
pub use crate::limits::MAX_GRID_RESOLUTION as MAX_RESOLUTION;
/// Fewest texels along one side.
const MIN_SIDE: u32 = 4;
/// Side of a brick, the unit of partial updates (texels).
const BRICK: u32 = 8;

/// Smooth density of a field value: 0 outside, 1 inside, soft across the surface.
#[inline]
pub fn density(field: f32, softness: f32) -> f32 {
    let t = ((field - (ISO - softness)) / (2.0 * softness)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A box of texels on the lattice of texel size `h`: texel `i` of the box is lattice cell
/// `origin + i`, centred at `(origin + i + ½)·h`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Lattice index of the first texel.
    origin: I64Vec3,
    /// Texels per axis.
    dims: UVec3,
    /// Texel side (world units).
    h: f32,
}

impl Grid {
    /// The texel side that puts `resolution` texels along the longest side of `field`'s box.
    fn texel_for(field: &Field, resolution: u32, cap: u32) -> Option<f32> {
        let (lo, hi) = field.bounds()?;
        let extent = (hi - lo).max_element().max(1e-3);
        // One texel of slack: the lattice's floor and ceiling add at most one.
        let res = resolution.clamp(MIN_SIDE, cap);
        Some(extent / (res - 1) as f32)
    }

    /// The grid of texel side `h` over `field`'s box, if that stays within the cap per side.
    fn over(field: &Field, h: f32, cap: u32) -> Option<Self> {
        let (lo, hi) = field.bounds()?;
        let h64 = h as f64;
        let first = (lo.as_dvec3() / h64).floor().as_i64vec3();
        let end = (hi.as_dvec3() / h64).ceil().as_i64vec3();
        let dims = (end - first).max(I64Vec3::splat(MIN_SIDE as i64));
        (dims.max_element() <= cap as i64).then(|| Self {
            origin: first,
            dims: dims.as_uvec3(),
            h,
        })
    }

    /// The grid the renderer bakes `field` on: [`Grid::of`]'s texel rounded to the nearest
    /// step of 2^(1/4), so it is a function of the field alone that stays put while the
    /// cloud's extent changes a little (edits then update the texels they reach and copy the
    /// others). About 0.92–1.09 of `resolution` texels along the longest side (within the cap:
    /// past it, the next coarser step).
    fn stepped(field: &Field, resolution: u32) -> Option<Self> {
        let h = Self::texel_for(field, resolution, MAX_RESOLUTION)?;
        let step = (h.log2() * 4.0).round();
        Self::over(field, (step / 4.0).exp2(), MAX_RESOLUTION)
            .or_else(|| Self::over(field, ((step + 1.0) / 4.0).exp2(), MAX_RESOLUTION))
            .or_else(|| Self::of(field, resolution))
    }

    /// The grid with `resolution` texels along the longest side of `field`'s box.
    pub fn of(field: &Field, resolution: u32) -> Option<Self> {
        Self::capped(field, resolution, MAX_RESOLUTION)
    }

    /// [`Grid::of`] with another cap per side (exports go finer than the renderer's grid).
    fn capped(field: &Field, resolution: u32, cap: u32) -> Option<Self> {
        let h = Self::texel_for(field, resolution, cap)?;
        // Rounding can push a side one past the cap: widen the texel a hair.
        Self::over(field, h, cap).or_else(|| Self::over(field, h * 1.02, cap))
    }

    /// World coordinates of the texel centres along each axis. They depend on the lattice
    /// index alone, so a texel has the same centre (to the bit) in every grid that holds it.
    fn centers(&self) -> [Vec<f32>; 3] {
        let h = self.h as f64;
        [0, 1, 2].map(|a| {
            (0..self.dims[a] as i64)
                .map(|i| (((self.origin[a] + i) as f64 + 0.5) * h) as f32)
                .collect()
        })
    }

    fn texels(&self) -> u64 {
        self.dims.as_u64vec3().element_product()
    }

    fn min(&self) -> Vec3 {
        (self.origin.as_dvec3() * self.h as f64).as_vec3()
    }

    /// The texels a world box reaches (inclusive), clamped to the grid, if any.
    fn texels_of(&self, lo: Vec3, hi: Vec3) -> Option<(UVec3, UVec3)> {
        let h = self.h as f64;
        let o = self.origin.as_dvec3();
        let a = ((lo.as_dvec3() / h - o - 0.5).floor())
            .max(glam::DVec3::ZERO)
            .as_uvec3();
        let b = ((hi.as_dvec3() / h - o - 0.5).ceil())
            .as_i64vec3()
            .min(self.dims.as_i64vec3() - 1);
        (b.min_element() >= 0 && a.cmple(b.as_uvec3()).all()).then(|| (a, b.as_uvec3()))
    }

    /// The texels a primitive's influence reaches (inclusive), clamped to the grid, if any.
    fn texel_box(&self, blob: &Blob) -> Option<(UVec3, UVec3)> {
        let reach = blob.extent * SUPPORT;
        self.texels_of(blob.center - reach, blob.center + reach)
    }

    fn bricks(&self) -> UVec3 {
        self.bricks_of(BRICK)
    }

    /// Bricks of `size`³ texels per axis.
    fn bricks_of(&self, size: u32) -> UVec3 {
        (self.dims + size - 1) / size
    }
}

/// The bricks of a grid that an update re-evaluates, as runs of texels along x per brick row.
struct Dirty {
    /// Brick side (texels): [`BRICK`] for updates.
    size: u32,
    bricks: UVec3,
    /// Per brick row (`by + bricks.y · bz`): merged texel ranges along x.
    runs: Vec<Vec<std::ops::Range<u32>>>,
    /// The texel box (inclusive) holding every dirty texel, if any: a primitive whose box
    /// misses it is skipped without visiting its rows.
    bounds: Option<(UVec3, UVec3)>,
}

impl Dirty {
    /// Every texel of `grid`.
    fn all(grid: &Grid) -> Self {
        let bricks = grid.bricks();
        Self {
            size: BRICK,
            bricks,
            runs: vec![vec![0..grid.dims.x]; (bricks.y * bricks.z) as usize],
            bounds: Some((UVec3::ZERO, grid.dims - 1)),
        }
    }

    /// The bricks flagged in `mask` (x fastest, then y, then z).
    fn of_mask(grid: &Grid, mask: &[bool]) -> Self {
        Self::of_mask_sized(grid, mask, BRICK)
    }

    /// [`Dirty::of_mask`] for bricks of `size`³ texels.
    fn of_mask_sized(grid: &Grid, mask: &[bool], size: u32) -> Self {
        let bricks = grid.bricks_of(size);
        let runs = (0..(bricks.y * bricks.z) as usize)
            .map(|row| {
                let flags = &mask[row * bricks.x as usize..][..bricks.x as usize];
                let mut runs: Vec<std::ops::Range<u32>> = Vec::new();
                for (bx, _) in flags.iter().enumerate().filter(|(_, f)| **f) {
                    let (a, b) = (bx as u32 * size, ((bx as u32 + 1) * size).min(grid.dims.x));
                    match runs.last_mut() {
                        Some(r) if r.end == a => r.end = b,
                        _ => runs.push(a..b),
                    }
                }
                runs
            })
            .collect();
        let mut bounds: Option<(UVec3, UVec3)> = None;
        for (i, _) in mask.iter().enumerate().filter(|(_, f)| **f) {
            let b = UVec3::new(
                i as u32 % bricks.x,
                (i as u32 / bricks.x) % bricks.y,
                i as u32 / (bricks.x * bricks.y),
            );
            let (lo, hi) = (b * size, ((b + 1) * size).min(grid.dims) - 1);
            bounds = Some(bounds.map_or((lo, hi), |(a, c)| (a.min(lo), c.max(hi))));
        }
        Self {
            size,
            bricks,
            runs,
            bounds,
        }
    }

    /// Calls `f` with the dirty part of each texel row of box `(a, b)` (inclusive); plain
    /// loops, as a bake calls it for every row of every primitive.
    #[inline]
    fn each_row(&self, dims: UVec3, (a, b): (UVec3, UVec3), mut f: impl FnMut(Row)) {
        let (nx, ny) = (dims.x as usize, dims.y as usize);
        // Only the part of the box inside the dirty bounds has dirty rows (none without them).
        let Some((lo, hi)) = self.bounds else {
            return;
        };
        let (a, b) = (a.max(lo), b.min(hi));
        if a.cmpgt(b).any() {
            return;
        }
        for k in a.z..=b.z {
            for j in a.y..=b.y {
                let brick_row = (j / self.size + self.bricks.y * (k / self.size)) as usize;
                let at = (k as usize * ny + j as usize) * nx;
                for r in &self.runs[brick_row] {
                    let (lo, hi) = (r.start.max(a.x), r.end.min(b.x + 1));
                    if lo < hi {
                        f(Row {
                            at,
                            j: j as usize,
                            k: k as usize,
                            xs: lo as usize..hi as usize,
                        });
                    }
                }
            }
        }
    }
}

/// A dirty run of one texel row.
struct Row {
    /// The index of the row's first texel (x = 0).
    at: usize,
    /// The row's y and z texel indices.
    j: usize,
    k: usize,
    /// The dirty x range.
    xs: std::ops::Range<usize>,
}

/// Calls `sink` with the index and centre of every dirty texel of box `bx`, counting them.
#[inline]
fn splat(
    dirty: &Dirty,
    dims: UVec3,
    [xs_c, ys_c, zs_c]: &[Vec<f32>; 3],
    bx: (UVec3, UVec3),
    work: &mut u64,
    mut sink: impl FnMut(usize, Vec3),
) {
    dirty.each_row(dims, bx, |Row { at: row, j, k, xs }| {
        *work += xs.len() as u64;
        let (y, z) = (ys_c[j], zs_c[k]);
        for i in xs {
            sink(row + i, Vec3::new(xs_c[i], y, z));
        }
    });
}

/// Adds `blob` into the dirty texels of box `bx`, row by row, visiting only the texels of each
/// row within the primitive's chord (a texel of slack each side; beyond it the kernel is 0, so
/// the sums are the same bits as visiting every texel), counting them.
fn add_blob(
    dirty: &Dirty,
    grid: &Grid,
    [xs_c, ys_c, zs_c]: &[Vec<f32>; 3],
    bx: (UVec3, UVec3),
    work: &mut u64,
    blob: &Blob,
    values: &mut [f32],
) {
    // A world x's texel index, from the lattice in f64 (not from the spacing of two rounded
    // centres, which is off by several texels far from the origin).
    let (inv_h, offset) = (1.0 / grid.h as f64, grid.origin.x as f64 + 0.5);
    let index = |x: f32| x as f64 * inv_h - offset;
    // The row's chord (texel indices with slack, unclamped), found once per row and kept for
    // the row's further dirty runs.
    let rows = blob.rows();
    let chord = |j: usize, k: usize| {
        let line = rows.at(ys_c[j], zs_c[k]);
        let (lo, hi) = line.reach()?;
        // Truncation is within a texel of floor and ceil: one more texel of slack each side
        // (and no call to floor on targets without SSE4.1). The casts saturate.
        Some((
            line,
            (index(lo) as i64).saturating_sub(2),
            (index(hi) as i64).saturating_add(3),
        ))
    };
    let mut last: Option<(usize, Option<(BlobRow, i64, i64)>)> = None;
    dirty.each_row(grid.dims, bx, |Row { at: row, j, k, xs }| {
        let found = match last {
            Some((at, found)) if at == row => found,
            _ => last.insert((row, chord(j, k))).1,
        };
        let Some((line, first, end)) = found else {
            return;
        };
        let first = first.max(xs.start as i64);
        let end = end.min(xs.end as i64);
        if first >= end {
            return;
        }
        let (first, end) = (first as usize, end as usize);
        *work += (end - first) as u64;
        let texels = &mut values[row + first..row + end];
        for (v, &x) in texels.iter_mut().zip(&xs_c[first..end]) {
            *v += line.value(x);
        }
    });
}

/// Evaluates `field` at the dirty texels of `values` (laid out on `grid`): clears them, sums the
/// primitives, adds each group's maximum and applies the clips. Every texel is computed by the
/// same operations in the same order whichever bricks are dirty, so a partial update equals a
/// full bake bit for bit. Returns the kernel evaluations and clip tests done.
fn evaluate(field: &Field, grid: &Grid, dirty: &Dirty, values: &mut [f32]) -> u64 {
    let dims = grid.dims;
    let whole = (UVec3::ZERO, dims - 1);
    dirty.each_row(dims, whole, |Row { at: row, xs, .. }| {
        values[row + xs.start..row + xs.end].fill(0.0)
    });
    let mut work = 0u64;
    // The dirty texels' world box (a texel of slack): a primitive that misses it is skipped
    // before any texel arithmetic.
    let Some((da, db)) = dirty.bounds else {
        return 0;
    };
    let (wlo, whi) = (
        grid.min() + (da.as_vec3() - 1.0) * grid.h,
        grid.min() + (db.as_vec3() + 2.0) * grid.h,
    );
    let misses = |b: &Blob| {
        let r = b.extent * SUPPORT;
        (b.center + r).cmplt(wlo).any() || (b.center - r).cmpgt(whi).any()
    };
    let reach = |blob: &Blob| (!misses(blob)).then(|| grid.texel_box(blob)).flatten();
    let centers = grid.centers();
    for blob in &field.blobs {
        if let Some(bx) = reach(blob) {
            add_blob(dirty, grid, &centers, bx, &mut work, blob, values);
        }
    }
    work + add_groups_and_clip(field, grid, &centers, dirty, values)
}

/// The rest of [`evaluate`] once the primitives are summed into the dirty texels: adds each
/// group's maximum and applies the clips. Returns the kernel evaluations and clip tests done.
fn add_groups_and_clip(
    field: &Field,
    grid: &Grid,
    centers: &[Vec<f32>; 3],
    dirty: &Dirty,
    values: &mut [f32],
) -> u64 {
    let dims = grid.dims;
    let [xs, ys, zs] = centers;
    let center = |i: usize, j: usize, k: usize| Vec3::new(xs[i], ys[j], zs[k]);
    let whole = (UVec3::ZERO, dims - 1);
    let reach = |blob: &Blob| grid.texel_box(blob);
    let mut work = 0u64;
    if !field.groups.is_empty() {
        // Scratch grids of each group's two largest values; each group clears and adds back
        // only the box it reaches.
        let mut first = vec![0f32; values.len()];
        let mut second = vec![0f32; values.len()];
        // Each group's puffs' maximum (billows), where it has puffs.
        let mut puffs = if field.groups.iter().any(|g| !g.puffs.is_empty()) {
            vec![0f32; values.len()]
        } else {
            Vec::new()
        };
        for group in &field.groups {
            let Some(bx) = group
                .blobs
                .iter()
                .chain(&group.puffs)
                .filter_map(|b| grid.texel_box(b))
                .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
            else {
                continue;
            };
            let puffed = !group.puffs.is_empty();
            dirty.each_row(dims, bx, |Row { at: row, xs, .. }| {
                first[row + xs.start..row + xs.end].fill(0.0);
                second[row + xs.start..row + xs.end].fill(0.0);
                if puffed {
                    puffs[row + xs.start..row + xs.end].fill(0.0);
                }
            });
            for blob in &group.blobs {
                if let Some(bx) = reach(blob) {
                    splat(dirty, dims, centers, bx, &mut work, |at, p| {
                        (first[at], second[at]) =
                            super::top_two((first[at], second[at]), blob.value(p));
                    });
                }
            }
            for blob in &group.puffs {
                if let Some(bx) = reach(blob) {
                    splat(dirty, dims, centers, bx, &mut work, |at, p| {
                        puffs[at] = puffs[at].max(blob.value(p));
                    });
                }
            }
            splat(dirty, dims, centers, bx, &mut work, |at, p| {
                let blended = group.combine(first[at], second[at], p);
                values[at] += if puffed {
                    blended.max(puffs[at])
                } else {
                    blended
                }
            });
        }
    }
    if !field.clips.is_empty() {
        dirty.each_row(dims, whole, |Row { at: row, j, k, xs }| {
            for i in xs {
                let v = &mut values[row + i];
                // Empty texels need no clip test.
                if *v != 0.0 {
                    work += field.clips.len() as u64;
                    if field.clips.iter().any(|c| c.removes(center(i, j, k))) {
                        *v = 0.0;
                    }
                }
            }
        });
    }
    work
}

/// The most work a full bake of `field` on `grid` does: kernel evaluations (each primitive over
/// the box of texels its influence reaches; the bake visits only the chords of its rows, fewer)
/// plus clip tests (each cut over every texel, at most).
fn work_on(field: &Field, grid: &Grid) -> u64 {
    let kernel: u64 = field
        .all_blobs()
        .filter_map(|b| grid.texel_box(b))
        .map(|(a, b)| (b - a + UVec3::ONE).as_u64vec3().element_product())
        .sum();
    kernel + field.clips.len() as u64 * grid.texels()
}

/// The most work [`bake`] does for `field` at `resolution` (see `work_on`). Cheap to compute
/// (one box per primitive), so callers check it before baking.
pub fn bake_work(field: &Field, resolution: u32) -> u64 {
    Grid::of(field, resolution).map_or(0, |grid| work_on(field, &grid))
}

/// The largest resolution up to `wanted` whose [`bake_work`] fits `budget` (the grid's floor
/// when none does), with its work.
pub fn resolution_within(field: &Field, wanted: u32, budget: u64) -> (u32, u64) {
    let mut res = wanted.clamp(MIN_SIDE, MAX_RESOLUTION);
    let mut work = bake_work(field, res);
    while res > MIN_SIDE && work > budget {
        res = (res * 4 / 5).max(MIN_SIDE);
        work = bake_work(field, res);
    }
    (res, work)
}

fn volume_of(grid: &Grid, values: Vec<f32>) -> DensityVolume {
    DensityVolume {
        dims: grid.dims,
        min: grid.min(),
        size: grid.dims.as_vec3() * grid.h,
        values,
    }
}

/// The grid [`bake`] samples `field` on: the centre of its first texel, texels per axis and
/// the texel side (texel `i` is centred at `first + i·h`, to float rounding).
pub fn lattice(field: &Field, resolution: u32) -> Option<(Vec3, UVec3, f32)> {
    let grid = Grid::of(field, resolution)?;
    let [xs, ys, zs] = grid.centers();
    Some((Vec3::new(xs[0], ys[0], zs[0]), grid.dims, grid.h))
}

/// Samples `field` on a grid over its bounds, `resolution` texels along the longest side.
pub fn bake(field: &Field, resolution: u32) -> DensityVolume {
    let Some(grid) = Grid::of(field, resolution) else {
        return DensityVolume::default();
    };
    bake_on(field, &grid)
}

/// [`bake`] at up to [`crate::limits::MAX_EXPORT_RESOLUTION`] texels along the longest side
/// (exports; the renderer's grid stops at [`MAX_RESOLUTION`]).
/// The grid is cut into z-slabs baked on the machine's cores (one where threads are not
/// available, as in the browser); texels sit on the lattice, so each slab's texels are the
/// whole grid's to the bit.
pub fn bake_fine(field: &Field, resolution: u32) -> DensityVolume {
    let cap = crate::limits::MAX_EXPORT_RESOLUTION;
    let Some(grid) = Grid::capped(field, resolution, cap) else {
        return DensityVolume::default();
    };
    let threads = crate::limits::cores().min(grid.dims.z as usize / 8).max(1);
    if threads == 1 {
        return bake_on(field, &grid);
    }
    let per = grid.dims.z.div_ceil(threads as u32);
    let slabs: Vec<Grid> = (0..grid.dims.z)
        .step_by(per as usize)
        .map(|z0| Grid {
            origin: grid.origin + I64Vec3::new(0, 0, z0 as i64),
            dims: UVec3::new(grid.dims.x, grid.dims.y, per.min(grid.dims.z - z0)),
            h: grid.h,
        })
        .collect();
    let parts: Option<Vec<Vec<f32>>> = std::thread::scope(|scope| {
        let handles: Vec<_> = slabs
            .iter()
            .map(|slab| scope.spawn(move || bake_on(field, slab).values))
            .collect();
        handles.into_iter().map(|h| h.join().ok()).collect()
    });
    match parts {
        Some(parts) => volume_of(&grid, parts.concat()),
        None => bake_on(field, &grid),
    }
}

/// [`bake_work`] of [`bake_fine`].
pub fn bake_fine_work(field: &Field, resolution: u32) -> u64 {
    let cap = crate::limits::MAX_EXPORT_RESOLUTION;
    Grid::capped(field, resolution, cap).map_or(0, |grid| work_on(field, &grid))
}

/// Samples `field` at every texel of `grid`.
fn bake_on(field: &Field, grid: &Grid) -> DensityVolume {
    let mut values = vec![0f32; grid.texels() as usize];
    evaluate(field, grid, &Dirty::all(grid), &mut values);
    volume_of(grid, values)
}

/// Every primitive evaluated at every texel of `resolution`'s grid, with no box culling: the
/// reference the culled and partial bakes are tested and benchmarked against.
pub fn bake_brute_force(field: &Field, resolution: u32) -> DensityVolume {
    let Some(grid) = Grid::of(field, resolution) else {
        return DensityVolume::default();
    };
    let mut values = Vec::with_capacity(grid.texels() as usize);
    let [xs, ys, zs] = grid.centers();
    for &z in &zs {
        for &y in &ys {
            for &x in &xs {
                values.push(field.value(Vec3::new(x, y, z)));
            }
        }
    }
    volume_of(&grid, values)
}

/// Bit pattern of a primitive, for finding the ones an edit changed.
fn blob_key(b: &Blob) -> [u32; 16] {
    let mut k = [0u32; 16];
    let floats = b
        .center
        .to_array()
        .into_iter()
        .chain(b.to_unit.to_cols_array());
    let floats = floats.chain([b.strength]).chain(b.extent.to_array());
    for (slot, f) in k.iter_mut().zip(floats) {
        *slot = f.to_bits();
    }
    k
}

fn group_key(group: &super::Group) -> u64 {
    let mut hasher = std::hash::DefaultHasher::new();
    for b in &group.blobs {
        blob_key(b).hash(&mut hasher);
    }
    group.puffs.len().hash(&mut hasher);
    for b in &group.puffs {
        blob_key(b).hash(&mut hasher);
    }
    group.blend.to_bits().hash(&mut hasher);
    if let Some(inside) = &group.inside {
        for f in inside
            .origin
            .to_array()
            .into_iter()
            .chain(inside.to_plane.to_array())
        {
            f.to_bits().hash(&mut hasher);
        }
    }
    hasher.finish()
}

/// World boxes reached by the primitives (and sphere groups) of `old` and `new` that are not in
/// both, or `None` when everything must be re-evaluated (the cuts changed).
fn changed_boxes(old: &Field, new: &Field) -> Option<Vec<(Vec3, Vec3)>> {
    if old.clips != new.clips {
        return None;
    }
    let reach = |b: &Blob| (b.center - b.extent * SUPPORT, b.center + b.extent * SUPPORT);
    let mut boxes = Vec::new();
    if old.blobs.len() == new.blobs.len() {
        // The same count (a drag, a slider): compare in place.
        for (a, b) in old.blobs.iter().zip(&new.blobs) {
            if a != b {
                boxes.extend([reach(a), reach(b)]);
            }
        }
    } else {
        // Present in one field and not the other: counts that do not cancel.
        let mut count: HashMap<[u32; 16], i32> = HashMap::new();
        for b in &old.blobs {
            *count.entry(blob_key(b)).or_default() += 1;
        }
        for b in &new.blobs {
            *count.entry(blob_key(b)).or_default() -= 1;
        }
        let changed = |b: &&Blob| count[&blob_key(b)] != 0;
        boxes.extend(
            old.blobs
                .iter()
                .chain(&new.blobs)
                .filter(changed)
                .map(reach),
        );
    }
    let group_box = |g: &super::Group| {
        g.blobs
            .iter()
            .map(reach)
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
    };
    if old.groups.len() == new.groups.len() {
        for (a, b) in old.groups.iter().zip(&new.groups) {
            if a != b {
                boxes.extend(group_box(a).into_iter().chain(group_box(b)));
            }
        }
    } else {
        let mut count: HashMap<u64, i32> = HashMap::new();
        for g in &old.groups {
            *count.entry(group_key(g)).or_default() += 1;
        }
        for g in &new.groups {
            *count.entry(group_key(g)).or_default() -= 1;
        }
        for g in old.groups.iter().chain(&new.groups) {
            if count[&group_key(g)] != 0 {
                boxes.extend(group_box(g));
            }
        }
    }
    Some(boxes)
}

/// The last bake a [`Baker`] made.
struct LastBake {
    field: Arc<Field>,
    grid: Grid,
    volume: Arc<DensityVolume>,
}

/// What one [`Baker::update`] produced.
pub struct Baked {
    /// The field sampled on the grid.
    pub volume: Arc<DensityVolume>,
    /// Kernel evaluations and clip tests done.
    pub work: u64,
    /// Texels re-evaluated (the rest were copied from the last volume).
    pub texels: u64,
}

/// Bakes a field after each edit, re-evaluating only what changed.
///
/// The grid is the one a fresh bake of the field takes (from the field, the resolution and the
/// budget alone, never from what was baked before), so a frame is the same wherever it is
/// made. When the texel size is the last bake's, the new grid is the field's box on the same
/// lattice: texels the old grid had are copied unless a changed primitive reaches their brick
/// (its old place or its new one), and only the other bricks are evaluated. The result equals
/// [`bake`] on the same grid bit for bit.
#[derive(Default)]
pub struct Baker {
    last: Option<LastBake>,
}

impl Baker {
    /// Bakes `field` with about `resolution` texels along its longest side, within `budget`
    /// kernel evaluations for a full bake (coarser otherwise).
    pub fn update(&mut self, field: &Arc<Field>, resolution: u32, budget: u64) -> Baked {
        if field.bounds().is_none() {
            self.last = None;
            return Baked {
                volume: Arc::new(DensityVolume::default()),
                work: 0,
                texels: 0,
            };
        }
        // The grid is the document's alone (what a fresh bake of this field takes), never
        // the one baked before: a frame is the same wherever and after whatever it is made.
        let (res, _) = resolution_within(field, resolution, budget);
        // The step may be a little finer than the resolution the budget allows: then coarser.
        let grid = Grid::stepped(field, res).map(|g| {
            let mut g = g;
            for _ in 0..2 {
                if work_on(field, &g) <= budget {
                    break;
                }
                match Grid::over(field, g.h * 2f32.powf(0.25), MAX_RESOLUTION) {
                    Some(coarser) => g = coarser,
                    None => break,
                }
            }
            g
        });
        let Some(grid) = grid else {
            // Bounds no grid within the caps can hold (not a validated document).
            self.last = None;
            return Baked {
                volume: Arc::new(DensityVolume::default()),
                work: 0,
                texels: 0,
            };
        };
        // On the same grid, a partial update when only primitives changed: it copies what it
        // can and re-evaluates the bricks the changes reach. Texels sit on one lattice per
        // texel size, so a copied texel is the one a full bake computes.
        let partial = self
            .last
            .as_ref()
            .filter(|last| last.grid.h.to_bits() == grid.h.to_bits())
            .map(|last| {
                let mut values = vec![0f32; grid.texels() as usize];
                let dirty = changed_boxes(&last.field, field)
                    .map(|boxes| copy_unchanged(&grid, last, &boxes, &mut values))
                    .unwrap_or_else(|| Dirty::all(&grid));
                (values, dirty)
            });
        let (mut values, dirty) =
            partial.unwrap_or_else(|| (vec![0f32; grid.texels() as usize], Dirty::all(&grid)));
        let mut texels = 0;
        dirty.each_row(grid.dims, (UVec3::ZERO, grid.dims - 1), |row| {
            texels += row.xs.len() as u64
        });
        let work = evaluate(field, &grid, &dirty, &mut values);
        let volume = Arc::new(volume_of(&grid, values));
        self.last = Some(LastBake {
            field: field.clone(),
            grid,
            volume: volume.clone(),
        });
        Baked {
            volume,
            work,
            texels,
        }
    }
}

/// Copies into `values` (on `grid`) every texel `last` holds, and returns the bricks to
/// re-evaluate: those not wholly inside the last grid and those the changed `boxes` reach.
fn copy_unchanged(
    grid: &Grid,
    last: &LastBake,
    boxes: &[(Vec3, Vec3)],
    values: &mut [f32],
) -> Dirty {
    let bricks = grid.bricks();
    let brick_index = |b: UVec3| (b.x + bricks.x * (b.y + bricks.y * b.z)) as usize;
    let mut mask = vec![false; (bricks.x * bricks.y * bricks.z) as usize];
    // The overlap of the two grids, in the new grid's texels.
    let offset = last.grid.origin - grid.origin;
    let from = offset.max(I64Vec3::ZERO);
    let to = (offset + last.grid.dims.as_i64vec3()).min(grid.dims.as_i64vec3());
    if from.cmplt(to).all() {
        let (from, to) = (from.as_uvec3(), to.as_uvec3());
        let (nx, ny) = (grid.dims.x as usize, grid.dims.y as usize);
        let (ox, oy) = (last.grid.dims.x as usize, last.grid.dims.y as usize);
        let old = &last.volume.values;
        for k in from.z..to.z {
            for j in from.y..to.y {
                let (ok, oj) = (
                    (k as i64 - offset.z) as usize,
                    (j as i64 - offset.y) as usize,
                );
                let oi = (from.x as i64 - offset.x) as usize;
                let len = (to.x - from.x) as usize;
                let dst = (k as usize * ny + j as usize) * nx + from.x as usize;
                let src = (ok * oy + oj) * ox + oi;
                values[dst..dst + len].copy_from_slice(&old[src..src + len]);
            }
        }
        // Bricks the copy does not fill wholly.
        for bz in 0..bricks.z {
            for by in 0..bricks.y {
                for bx in 0..bricks.x {
                    let a = UVec3::new(bx, by, bz) * BRICK;
                    let b = (a + BRICK).min(grid.dims);
                    if !(a.cmpge(from).all() && b.cmple(to).all()) {
                        mask[brick_index(UVec3::new(bx, by, bz))] = true;
                    }
                }
            }
        }
    } else {
        mask.fill(true);
    }
    for (a, b) in boxes.iter().filter_map(|&(lo, hi)| grid.texels_of(lo, hi)) {
        for bz in a.z / BRICK..=b.z / BRICK {
            for by in a.y / BRICK..=b.y / BRICK {
                for bx in a.x / BRICK..=b.x / BRICK {
                    mask[brick_index(UVec3::new(bx, by, bz))] = true;
                }
            }
        }
    }
    Dirty::of_mask(grid, &mask)
}

#[cfg(test)]
mod tests {
    use super::super::Blob;
    use super::*;
    use std::sync::Arc;

    /// Sampling returns a texel's value at its centre and blends between centres; the union of
    /// two clouds far apart holds each where it was (a brute-force check against the field).
    #[test]
    fn sampling_and_the_union_of_two_volumes_keep_each_cloud() {
        let a = bake(&Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, 2.0)]), 32);
        let b = bake(
            &Field::of_blobs(vec![Blob::sphere(Vec3::new(9.0, 1.0, 0.0), 1.0)]),
            32,
        );
        let at = |x, y, z| a.value(x, y, z).clamp(0.0, 1.0);
        for (x, y, z) in [(0, 0, 0), (5, 9, 13), (16, 16, 16)] {
            assert!((a.sample(a.center(x, y, z)) - at(x, y, z)).abs() < 1e-5);
        }
        let mid = (a.center(3, 4, 5) + a.center(4, 4, 5)) * 0.5;
        let want = (at(3, 4, 5) + at(4, 4, 5)) * 0.5;
        assert!((a.sample(mid) - want).abs() < 1e-5);
        assert_eq!(a.sample(Vec3::splat(100.0)), 0.0, "nothing outside the box");

        let u = a.union(&b, 128);
        assert!(u.dims.max_element() <= 128);
        let fa = Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, 2.0)]);
        let fb = Field::of_blobs(vec![Blob::sphere(Vec3::new(9.0, 1.0, 0.0), 1.0)]);
        let mut inside = [0, 0];
        for z in 0..u.dims.z {
            for y in 0..u.dims.y {
                for x in 0..u.dims.x {
                    let p = u.center(x, y, z);
                    let (va, vb) = (fa.value(p), fb.value(p));
                    let want = va.max(vb).clamp(0.0, 1.0);
                    // Within a texel's interpolation of the fields, where they are inside
                    // their own grids.
                    if a.texel_at(p).is_some() || b.texel_at(p).is_some() {
                        assert!(
                            (u.value(x, y, z) - want).abs() < 0.15,
                            "{p}: {} vs {want}",
                            u.value(x, y, z)
                        );
                    }
                    if u.value(x, y, z) > ISO {
                        inside[usize::from(vb > va)] += 1;
                    }
                }
            }
        }
        assert!(inside[0] > 0 && inside[1] > 0, "both clouds: {inside:?}");
        assert_eq!(a.union(&DensityVolume::default(), 128), a);
    }

    #[test]
    fn empty_field_bakes_empty_volume() {
        assert!(bake(&Field::default(), 32).is_empty());
    }

    #[test]
    fn volume_is_capped_and_matches_the_field() {
        let f = Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, 2.0)]);
        let v = bake(&f, 100_000);
        assert!(v.dims.max_element() <= MAX_RESOLUTION);
        let v = bake(&f, 32);
        assert_eq!(v.values.len(), (v.dims.x * v.dims.y * v.dims.z) as usize);
        let c = v.texel_at(Vec3::ZERO).unwrap();
        assert!(v.value(c.x, c.y, c.z) > 0.9);
        assert!(v.value(0, 0, 0) < 0.05);
        // Brute force: every texel equals the field at its centre.
        let h = v.texel_size();
        for (z, y, x) in [(3, 5, 7), (16, 16, 16), (0, 31, 2)] {
            let p = v.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * h;
            assert!((v.value(x, y, z) - f.value(p)).abs() < 1e-5);
        }
    }

    #[test]
    fn every_texel_equals_the_field_at_its_centre() {
        // Summed blobs, two max-combined groups (one reaching the grid's edge) and a clip,
        // against the field evaluated at every texel (brute force).
        let group = |c: Vec3| -> Vec<Blob> {
            (0..6)
                .map(|i| {
                    Blob::sphere(
                        c + Vec3::new(i as f32 * 0.4, 0.0, 0.0),
                        0.5 + 0.1 * i as f32,
                    )
                })
                .collect()
        };
        let f = Field {
            blobs: vec![Blob::sphere(Vec3::new(0.0, 1.0, 0.0), 1.2)],
            groups: vec![
                // One softened everywhere, one a plain maximum.
                super::super::Group {
                    blobs: group(Vec3::new(-2.0, 0.0, 0.0)),
                    blend: 0.15,
                    inside: None,
                    // Billows' puffs, combined by their maximum over the blended spheres.
                    puffs: group(Vec3::new(-1.6, 0.4, 0.2))
                        .into_iter()
                        .map(|b| Blob::sphere(b.center, b.extent.x * 0.5))
                        .collect(),
                },
                super::super::Group::hard(group(Vec3::new(1.0, -1.0, 0.5))),
            ],
            clips: vec![super::super::Clip {
                origin: Vec3::ZERO,
                right: Vec3::X,
                up: Vec3::Y,
                line: vec![glam::Vec2::new(-1.0, -1.2), glam::Vec2::new(1.0, -1.2)],
            }],
            ..Default::default()
        };
        let v = bake(&f, 24);
        let h = v.texel_size();
        for z in 0..v.dims.z {
            for y in 0..v.dims.y {
                for x in 0..v.dims.x {
                    let p = v.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * h;
                    let want = f.value(p);
                    assert!((v.value(x, y, z) - want).abs() < 1e-5, "({x},{y},{z})");
                }
            }
        }
    }

    #[test]
    fn density_is_half_at_the_surface() {
        assert!((density(ISO, 0.1) - 0.5).abs() < 1e-6);
        assert_eq!(density(0.0, 0.1), 0.0);
        assert_eq!(density(1.0, 0.1), 1.0);
    }

    /// A scatter of `n` ellipsoid-like blobs (seeded), the kind of field the bench uses.
    fn scatter(n: usize, seed: u64) -> Vec<Blob> {
        let mut rng = crate::seeded::SplitMix::new(seed);
        (0..n)
            .map(|_| {
                let c = Vec3::new(
                    (rng.next_f64() as f32) * 10.0,
                    (rng.next_f64() as f32) * 3.0,
                    (rng.next_f64() as f32) * 10.0,
                );
                Blob::sphere(c, 0.3 + (rng.next_f64() as f32) * 0.5)
            })
            .collect()
    }

    /// Fails with the number of differing texels (volumes are too large to print).
    fn assert_same(got: &DensityVolume, want: &DensityVolume, what: &str) {
        assert_eq!(
            (got.dims, got.min, got.size),
            (want.dims, want.min, want.size),
            "{what}"
        );
        let diff = got
            .values
            .iter()
            .zip(&want.values)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            diff,
            0,
            "{what}: {diff} of {} texels differ",
            got.values.len()
        );
    }

    fn full_on_same_grid(baker: &Baker, field: &Field) -> DensityVolume {
        bake_on(field, &baker.last.as_ref().unwrap().grid)
    }

    #[test]
    fn partial_updates_equal_a_full_bake_on_the_same_grid() {
        let mut blobs = scatter(200, 7);
        let group: Vec<Blob> = (0..8)
            .map(|i| Blob::sphere(Vec3::new(i as f32 * 0.5, 1.0, 0.0), 0.6))
            .collect();
        let clip = super::super::Clip {
            origin: Vec3::ZERO,
            right: Vec3::X,
            up: Vec3::Y,
            line: vec![glam::Vec2::new(-20.0, -1.5), glam::Vec2::new(20.0, -1.5)],
        };
        let mut field = Field {
            blobs: blobs.clone(),
            groups: vec![super::super::Group {
                blobs: group.clone(),
                blend: 0.15,
                inside: None,
                puffs: Vec::new(),
            }],
            clips: vec![clip],
            ..Default::default()
        };
        let mut baker = Baker::default();
        let first = baker.update(&Arc::new(field.clone()), 64, u64::MAX);
        let total = first.volume.values.len() as u64;
        assert_eq!(first.texels, total, "the first bake evaluates everything");
        let mut rng = crate::seeded::SplitMix::new(3);
        for step in 0..24 {
            let i = (rng.next_u64() % blobs.len() as u64) as usize;
            match step % 6 {
                0 => blobs[i].center += Vec3::new(0.7, -0.3, 0.2),
                1 => blobs[i] = Blob::sphere(blobs[i].center, 1.1),
                2 => blobs.push(Blob::sphere(
                    Vec3::new((rng.next_f64() as f32) * 9.0, 0.5, -1.0),
                    0.5,
                )),
                3 => {
                    blobs.remove(i);
                }
                4 => field.groups[0].blobs[3].center.y += 0.4,
                // Past the box: the grid grows on the same lattice.
                _ => blobs[i].center.x = 11.0 + step as f32 * 0.1,
            }
            field.blobs = blobs.clone();
            let arc = Arc::new(field.clone());
            let h = baker.last.as_ref().unwrap().grid.h;
            let baked = baker.update(&arc, 64, u64::MAX);
            let want = full_on_same_grid(&baker, &field);
            assert_same(&baked.volume, &want, &format!("step {step}"));
            // A change of the cloud's extent past a texel step bakes it afresh.
            let same_texel = baker.last.as_ref().unwrap().grid.h == h;
            assert!(
                !same_texel || baked.texels < want.values.len() as u64 / 2,
                "step {step}: {} of {} texels re-evaluated",
                baked.texels,
                want.values.len()
            );
        }
        // And the grid agrees with the field itself (every primitive at every texel).
        let v = baker.last.as_ref().unwrap().volume.clone();
        for z in 0..v.dims.z {
            for y in 0..v.dims.y {
                for x in 0..v.dims.x {
                    let want = field.value(v.center(x, y, z));
                    assert!(
                        (v.value(x, y, z) - want).abs() < 1.0 / 255.0,
                        "({x},{y},{z})"
                    );
                }
            }
        }
    }

    #[test]
    fn a_changed_cut_re_evaluates_everything() {
        let mut field = Field::of_blobs(scatter(50, 1));
        let mut baker = Baker::default();
        baker.update(&Arc::new(field.clone()), 32, u64::MAX);
        field.clips.push(super::super::Clip {
            origin: Vec3::ZERO,
            right: Vec3::X,
            up: Vec3::Y,
            line: vec![glam::Vec2::new(-20.0, 0.0), glam::Vec2::new(20.0, 0.0)],
        });
        let baked = baker.update(&Arc::new(field.clone()), 32, u64::MAX);
        assert_eq!(baked.texels, baked.volume.values.len() as u64);
        assert_same(&baked.volume, &full_on_same_grid(&baker, &field), "cut");
    }

    #[test]
    fn the_texel_size_is_the_fields_alone_in_steps() {
        let at = |r: f32| Arc::new(Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, r)]));
        let h = |b: &Baker| b.last.as_ref().unwrap().grid.h;
        let fresh = |r: f32| {
            let mut b = Baker::default();
            b.update(&at(r), 32, u64::MAX);
            h(&b)
        };
        // Whatever was baked before, a field gets the texel a fresh bake gives it.
        let mut baker = Baker::default();
        for r in [1.0, 1.8, 0.6, 0.4, 1.05, 1.0] {
            baker.update(&at(r), 32, u64::MAX);
            assert_eq!(h(&baker), fresh(r), "radius {r}");
        }
        // A few per cent of growth keeps the texel (a step is 2^(1/4)), and the grid keeps
        // near the resolution asked.
        let mut hs: Vec<f32> = (0..=15).map(|i| fresh(1.0 + i as f32 * 0.01)).collect();
        hs.dedup();
        assert!(
            hs.len() <= 2,
            "15% of growth crosses at most one step: {hs:?}"
        );
        assert!(fresh(1.5) > fresh(1.0));
        let v = baker.update(&at(1.0), 32, u64::MAX).volume;
        assert!((29..=35).contains(&v.dims.x), "{}", v.dims.x);
        // Past the cap per side: coarser.
        let big = baker.update(&at(1.9), 140, u64::MAX);
        assert!(big.volume.dims.max_element() <= MAX_RESOLUTION);
    }

    #[test]
    fn edits_change_the_field_where_expected_and_nowhere_else() {
        use crate::scene::Ellipsoid;
        let base: Vec<Ellipsoid> = (0..6)
            .map(|i| {
                Ellipsoid::new(
                    Vec3::new(i as f32 * 3.0, 0.0, 0.0),
                    Vec3::new(1.2, 0.8, 1.0),
                )
            })
            .collect();
        let field_of = |es: &[Ellipsoid]| Field::of_blobs(es.iter().map(Blob::ellipsoid).collect());
        let mut baker = Baker::default();
        let before = baker
            .update(&Arc::new(field_of(&base)), 64, u64::MAX)
            .volume;
        let reach = |e: &Ellipsoid| {
            let b = Blob::ellipsoid(e);
            (b.center - b.extent * SUPPORT, b.center + b.extent * SUPPORT)
        };
        let inside = |p: Vec3, (lo, hi): (Vec3, Vec3)| p.cmpge(lo).all() && p.cmple(hi).all();
        let mut moved = base.clone();
        moved[2].center.y += 0.8;
        let mut scaled = base.clone();
        scaled[4].radii *= 1.3;
        let mut turned = base.clone();
        turned[1].rotation = glam::Quat::from_rotation_z(0.9);
        let mut removed = base.clone();
        removed.remove(3);
        let mut added = base.clone();
        added.push(Ellipsoid::new(Vec3::new(7.5, 1.0, 0.0), Vec3::splat(0.7)));
        let cases: [(&str, &[Ellipsoid], Vec<(Vec3, Vec3)>); 5] = [
            ("move", &moved, vec![reach(&base[2]), reach(&moved[2])]),
            ("scale", &scaled, vec![reach(&base[4]), reach(&scaled[4])]),
            ("rotate", &turned, vec![reach(&base[1]), reach(&turned[1])]),
            ("delete", &removed, vec![reach(&base[3])]),
            ("add", &added, vec![reach(&added[6])]),
        ];
        for (name, scene, regions) in cases {
            let mut baker = Baker::default();
            baker.update(&Arc::new(field_of(&base)), 64, u64::MAX);
            let after = baker
                .update(&Arc::new(field_of(scene)), 64, u64::MAX)
                .volume;
            assert_eq!(
                after.texel_size(),
                before.texel_size(),
                "{name}: the same lattice"
            );
            // Texels both grids hold (same lattice: the same centres).
            let (mut changed, mut outside) = (0, 0);
            for z in 0..after.dims.z {
                for y in 0..after.dims.y {
                    for x in 0..after.dims.x {
                        let p = after.center(x, y, z);
                        let Some(t) = before.texel_at(p) else {
                            continue;
                        };
                        if after.value(x, y, z) != before.value(t.x, t.y, t.z) {
                            changed += 1;
                            if !regions.iter().any(|r| inside(p, *r)) {
                                outside += 1;
                            }
                        }
                    }
                }
            }
            assert!(changed > 100, "{name}: {changed} texels changed");
            assert_eq!(
                outside, 0,
                "{name}: changes outside the edited primitive's reach"
            );
        }
    }

    #[test]
    fn strength_zero_adds_nothing_and_negative_strength_carves() {
        use crate::scene::Ellipsoid;
        let body = Ellipsoid::new(Vec3::ZERO, Vec3::new(3.0, 2.0, 2.0));
        let mut ghost = Ellipsoid::new(Vec3::new(2.0, 0.0, 0.0), Vec3::splat(1.5));
        ghost.strength = 0.0;
        let alone = Field::of_blobs(vec![Blob::ellipsoid(&body)]);
        let with = Field::of_blobs(vec![Blob::ellipsoid(&body), Blob::ellipsoid(&ghost)]);
        assert_eq!(bake(&alone, 48), bake(&with, 48));
        let mut carver = ghost.clone();
        carver.strength = -1.0;
        let carved = Field::of_blobs(vec![Blob::ellipsoid(&body), Blob::ellipsoid(&carver)]);
        let (a, c) = (bake(&alone, 48), bake(&carved, 48));
        let inside = |v: &DensityVolume| v.values.iter().filter(|&&x| x >= ISO).count();
        assert!(
            inside(&c) < inside(&a) * 9 / 10,
            "{} vs {}",
            inside(&c),
            inside(&a)
        );
        assert!(!carved.inside(Vec3::new(2.0, 0.0, 0.0)));
        assert!(alone.inside(Vec3::new(2.0, 0.0, 0.0)));
    }

    #[test]
    fn the_culled_bake_equals_brute_force() {
        let f = Field {
            blobs: scatter(60, 11),
            groups: vec![
                super::super::Group::hard(scatter(20, 12)),
                super::super::Group {
                    blobs: scatter(15, 13),
                    blend: 0.2,
                    inside: None,
                    puffs: Vec::new(),
                },
            ],
            clips: vec![],
            ..Default::default()
        };
        let (worst, _) = bake_error(&f, 40);
        assert!(worst < 1e-5, "{worst}");
    }

    /// The largest difference between the bake of `f` and the brute-force one, and the
    /// brute force's largest value.
    fn bake_error(f: &Field, resolution: u32) -> (f32, f32) {
        let (culled, brute) = (bake(f, resolution), bake_brute_force(f, resolution));
        assert_eq!(culled.dims, brute.dims);
        let worst = culled
            .values
            .iter()
            .zip(&brute.values)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        (worst, brute.values.iter().copied().fold(0.0, f32::max))
    }

    /// Thin ellipsoids turned about every axis (the row quadratic's cross term is large and
    /// the chords are short), near the origin and 2,000 and 20,000 units from it, against
    /// `Blob::value` at every texel.
    #[test]
    fn turned_thin_ellipsoids_bake_as_brute_force_does() {
        for offset in [
            Vec3::ZERO,
            Vec3::new(2000.0, -1500.0, 1800.0),
            Vec3::new(2e4, 0.0, 0.0),
        ] {
            let mut rng = crate::seeded::SplitMix::new(5);
            let mut u = || rng.next_f64() as f32;
            let blobs = (0..40)
                .map(|_| {
                    let mut e = crate::scene::Ellipsoid::new(
                        offset + Vec3::new(u() * 8.0, u() * 3.0, u() * 8.0),
                        Vec3::new(0.3 + u() * 2.5, 0.02 + u() * 0.1, 0.2 + u() * 1.5),
                    );
                    e.rotation = glam::Quat::from_euler(
                        glam::EulerRot::XYZ,
                        u() * 6.3,
                        u() * 6.3,
                        u() * 6.3,
                    );
                    Blob::ellipsoid(&e)
                })
                .collect();
            let f = Field {
                blobs,
                groups: vec![],
                clips: vec![],
                ..Default::default()
            };
            let (worst, peak) = bake_error(&f, 96);
            assert!(peak > 0.5, "nothing baked");
            // (The row quadratic as a·dx² + 2b·dx + c, its terms cancelling, was off by 7e-5
            // here; a texel of the chord skipped would be off by up to the kernel's peak.)
            assert!(worst < 1e-5, "{offset}: {worst}");
        }
    }

    #[test]
    fn the_export_bake_in_slabs_equals_the_whole_grid_bake() {
        let field = crate::derive::field_of(&crate::scene::Scene::default());
        let fine = bake_fine(&field, 100);
        let whole = bake(&field, 100);
        assert_eq!(
            (fine.dims, fine.min, fine.size),
            (whole.dims, whole.min, whole.size)
        );
        assert!(
            fine.values == whole.values,
            "slab texels differ from the whole grid's"
        );
    }
}
