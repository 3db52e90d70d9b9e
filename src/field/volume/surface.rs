//! The field baked for one iso-surface (a mesh export): only the bricks that a cell crossing the
//! level can touch are evaluated. A brick is skipped when bounds of the field over it and one
//! texel around it (every cell with a corner in the brick lies there) keep the whole region on
//! one side of the level; its texels then get a value on that side. Marching cubes reads a
//! texel's value only in cells the level crosses, so the mesh is the full bake's, to the bit.

use glam::{UVec3, Vec3, Vec3A, Vec4};

use super::{DensityVolume, Dirty, Grid, add_groups_and_clip, volume_of};
use crate::field::{Blob, BlobRow, Clip, Field, wyvill};

/// How far (field units) a bound must clear the level before a brick is skipped: far more than
/// the rounding of a sum of thousands of kernel values, so float error never decides a side.
const MARGIN: f32 = 1e-3;
/// Side of the bricks classified (texels): a cell with a corner in one lies within a box two
/// texels wider, so small bricks hug the surface; each costs a bound per primitive reaching it.
const BRICK: u32 = 4;

/// [`super::bake_fine`]'s grid, evaluated only where the surface `value = iso` can pass: those
/// texels hold [`super::bake_fine`]'s values to the bit, the others 0 outside the level or a
/// lower bound of the field (above `iso`) inside it. Returns the volume and the share of bricks
/// evaluated.
pub fn bake_for_surface(field: &Field, resolution: u32, iso: f32) -> (DensityVolume, f32) {
    let cap = crate::limits::MAX_EXPORT_RESOLUTION;
    let Some(grid) = Grid::capped(field, resolution, cap) else {
        return (DensityVolume::default(), 0.0);
    };
    let bricks = grid.bricks_of(BRICK);
    let mut values = vec![0f32; grid.texels() as usize];
    // z-slabs of whole bricks on the machine's cores, each bounding, classifying and
    // evaluating its own bricks.
    let threads = crate::limits::cores().min(bricks.z as usize).max(1) as u32;
    let per = bricks.z.div_ceil(threads);
    let plane = (grid.dims.x * grid.dims.y) as usize;
    let mut jobs = Vec::new();
    let mut rest = values.as_mut_slice();
    for bz in (0..bricks.z).step_by(per as usize) {
        let z0 = bz * BRICK;
        let depth = (per * BRICK).min(grid.dims.z - z0);
        let slab = Grid {
            origin: grid.origin + glam::I64Vec3::new(0, 0, z0 as i64),
            dims: UVec3::new(grid.dims.x, grid.dims.y, depth),
            h: grid.h,
        };
        let (part, tail) = std::mem::take(&mut rest).split_at_mut(depth as usize * plane);
        rest = tail;
        jobs.push((slab, (z0 == 0, z0 + depth == grid.dims.z), part));
    }
    let run = |(slab, faces, part): (Grid, (bool, bool), &mut [f32])| {
        near_surface(field, &slab, faces, iso, part)
    };
    let counts: Vec<(usize, usize)> = if threads == 1 {
        // No threads (the browser): the one slab here.
        jobs.into_iter().map(run).collect()
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = jobs
                .into_iter()
                .map(|j| scope.spawn(move || run(j)))
                .collect();
            // A thread that failed leaves its bricks uncounted (the whole bake follows).
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or((0, 0)))
                .collect()
        })
    };
    let (done, all) = counts.iter().fold((0, 0), |(a, b), (c, d)| (a + c, b + d));
    if all < bricks.element_product() as usize {
        return (super::bake_fine(field, resolution), 1.0);
    }
    (volume_of(&grid, values), done as f32 / all.max(1) as f32)
}

/// Bounds, classifies and evaluates the bricks of one slab (`faces`: whether its first and last
/// brick layers lie on the grid's faces, beyond which is the outside). Returns the bricks
/// evaluated and the bricks in all.
fn near_surface(
    field: &Field,
    slab: &Grid,
    faces: (bool, bool),
    iso: f32,
    values: &mut [f32],
) -> (usize, usize) {
    let bounds = brick_bounds(field, slab);
    let bricks = slab.bricks_of(BRICK);
    let last = bricks - 1;
    // Bricks on the grid's faces meet the outside padding: never wholly inside.
    let on_face = |b: UVec3| {
        b.x == 0
            || b.y == 0
            || b.x == last.x
            || b.y == last.y
            || (faces.0 && b.z == 0)
            || (faces.1 && b.z == last.z)
    };
    let mut mask = vec![false; bounds.len()];
    for (i, &(lo, hi)) in bounds.iter().enumerate() {
        let b = brick_at(bricks, i);
        if hi < iso - MARGIN {
            continue;
        }
        if lo > iso + MARGIN && !on_face(b) {
            fill_brick(slab, b, lo, values);
            continue;
        }
        mask[i] = true;
    }
    // The values start at 0, the primitives go in brick by brick, the rest as a bake does it.
    let centers = slab.centers();
    for blob in &field.blobs {
        add_blob_in_bricks(blob, slab, &centers, &mask, values);
    }
    add_groups_and_clip(
        field,
        slab,
        &centers,
        &Dirty::of_mask_sized(slab, &mask, BRICK),
        values,
    );
    (mask.iter().filter(|m| **m).count(), mask.len())
}

/// Adds `blob` into the texels of the flagged bricks (`mask`) within its texel box, by whole
/// brick rows: no chord to find per row, only a test that the row meets the primitive's ball of
/// influence. Texels of a row outside the ball get exactly 0 from the kernel (the chords of
/// `super::add_blob` rely on it too), so every texel gets the bits of the whole bake.
fn add_blob_in_bricks(
    blob: &Blob,
    grid: &Grid,
    [xs, ys, zs]: &[Vec<f32>; 3],
    mask: &[bool],
    values: &mut [f32],
) {
    let Some((a, b)) = grid.texel_box(blob) else {
        return;
    };
    let bricks = grid.bricks_of(BRICK);
    let (nx, ny) = (grid.dims.x as usize, grid.dims.y as usize);
    let rows = blob.rows();
    // The part of brick `i` along axis `axis` inside the texel box.
    let span = |axis: usize, i: u32| {
        let lo = (i * BRICK).max(a[axis]) as usize;
        let hi = ((i + 1) * BRICK).min(b[axis] + 1) as usize;
        lo..hi
    };
    for bz in a.z / BRICK..=b.z / BRICK {
        for by in a.y / BRICK..=b.y / BRICK {
            let brick_row = ((bz * bricks.y + by) * bricks.x) as usize;
            for bx in a.x / BRICK..=b.x / BRICK {
                if !mask[brick_row + bx as usize] {
                    continue;
                }
                let (x, y) = (span(0, bx), span(1, by));
                let whole = x.len() == BRICK as usize;
                let centres = &xs[x.clone()];
                let mut add = |j: usize, k: usize, line: BlobRow| {
                    if line.misses() {
                        return;
                    }
                    let row = &mut values[(k * ny + j) * nx..][x.clone()];
                    if whole {
                        // A fixed width: four lanes of one vector.
                        let sum = Vec4::from_slice(row) + line.value4(Vec4::from_slice(centres));
                        sum.write_to_slice(row);
                    } else {
                        for (v, &c) in row.iter_mut().zip(centres) {
                            *v += line.value(c);
                        }
                    }
                };
                for k in span(2, bz) {
                    if y.len() == BRICK as usize {
                        // The brick's four rows in this layer found at once.
                        let lines = rows.at4(Vec4::from_slice(&ys[y.clone()]), zs[k]);
                        for (j, line) in y.clone().zip(lines) {
                            add(j, k, line);
                        }
                    } else {
                        for j in y.clone() {
                            add(j, k, rows.at(ys[j], zs[k]));
                        }
                    }
                }
            }
        }
    }
}

/// Brick `i`'s coordinates (x fastest, then y, then z).
fn brick_at(bricks: UVec3, i: usize) -> UVec3 {
    let i = i as u32;
    UVec3::new(
        i % bricks.x,
        (i / bricks.x) % bricks.y,
        i / (bricks.x * bricks.y),
    )
}

/// Sets every texel of brick `b` to `value`.
fn fill_brick(grid: &Grid, b: UVec3, value: f32, values: &mut [f32]) {
    let (lo, hi) = (b * BRICK, ((b + 1) * BRICK).min(grid.dims));
    let (nx, ny) = (grid.dims.x as usize, grid.dims.y as usize);
    for z in lo.z..hi.z {
        for y in lo.y..hi.y {
            let row = (z as usize * ny + y as usize) * nx;
            values[row + lo.x as usize..row + hi.x as usize].fill(value);
        }
    }
}

/// Bounds (lower, upper) of the field over each brick of `grid` grown by one texel each side.
fn brick_bounds(field: &Field, grid: &Grid) -> Vec<(f32, f32)> {
    let bricks = grid.bricks_of(BRICK);
    let h = grid.h as f64;
    // Along each axis, each brick's grown extent: from the centre of the texel before it to
    // the centre of the one after it (on the lattice, so beyond the grid too).
    let centre = |a: usize, i: i64| (((grid.origin[a] + i) as f64 + 0.5) * h) as f32;
    let extents: [Vec<(f32, f32)>; 3] = [0, 1, 2].map(|a| {
        (0..bricks[a])
            .map(|b| {
                let first = (b * BRICK) as i64 - 1;
                let end = ((b + 1) * BRICK).min(grid.dims[a]) as i64;
                (centre(a, first), centre(a, end))
            })
            .collect()
    });
    let index = |b: UVec3| ((b.z * bricks.y + b.y) * bricks.x + b.x) as usize;
    let mut bounds = vec![(0f32, 0f32); bricks.element_product() as usize];
    for blob in &field.blobs {
        blob_bounds(blob, grid, &extents, |b, lo, hi| {
            let s = &mut bounds[index(b)];
            *s = (s.0 + lo, s.1 + hi);
        });
    }
    for group in &field.groups {
        // The group's value is at least its largest sphere's or puff's (at least 0) and at most
        // that plus the smooth maximum's lift, a quarter of the blend width.
        let lift = group.blend.max(0.0) * 0.25;
        let mut own: std::collections::HashMap<usize, (f32, f32)> = Default::default();
        for blob in group.blobs.iter().chain(&group.puffs) {
            blob_bounds(blob, grid, &extents, |b, lo, hi| {
                let s = own.entry(index(b)).or_insert((0.0, 0.0));
                *s = (s.0.max(lo), s.1.max(hi));
            });
        }
        for (i, (lo, hi)) in own {
            let s = &mut bounds[i];
            *s = (s.0 + lo, s.1 + hi + lift);
        }
    }
    if !field.clips.is_empty() {
        for (i, s) in bounds.iter_mut().enumerate() {
            let b = brick_at(bricks, i);
            let lo = Vec3::new(
                extents[0][b.x as usize].0,
                extents[1][b.y as usize].0,
                extents[2][b.z as usize].0,
            );
            let hi = Vec3::new(
                extents[0][b.x as usize].1,
                extents[1][b.y as usize].1,
                extents[2][b.z as usize].1,
            );
            for clip in &field.clips {
                match clip_over(clip, lo, hi, grid.h) {
                    Cut::None => {}
                    Cut::Some => s.0 = s.0.min(0.0),
                    Cut::All => *s = (0.0, 0.0),
                }
            }
        }
    }
    bounds
}

/// Calls `sink` with bounds (lower, upper) of `blob`'s contribution over every grown brick
/// (`extents` per axis) its influence can reach. The unit-space offset `to_unit·(p − centre)`
/// is bounded per coordinate by interval arithmetic, which is a sum over the three world
/// axes, so each axis's part is found once per brick coordinate; the squared distance's bounds
/// follow, and the kernel decreases with it.
fn blob_bounds(
    blob: &Blob,
    grid: &Grid,
    extents: &[Vec<(f32, f32)>; 3],
    mut sink: impl FnMut(UVec3, f32, f32),
) {
    // The bricks whose grown box meets the influence box: those holding a texel of that box
    // widened by one texel.
    let reach = blob.extent * crate::field::SUPPORT + grid.h;
    let Some((a, b)) = grid.texels_of(blob.center - reach, blob.center + reach) else {
        return;
    };
    let (a, b) = (a / BRICK, b / BRICK);
    let m = &blob.to_unit;
    // (SIMD vectors where glam has them: this loop visits every brick a primitive reaches.)
    let axis = |j: usize, col: Vec3| -> Vec<(Vec3A, Vec3A)> {
        let col = Vec3A::from(col);
        (a[j]..=b[j])
            .map(|k| {
                let (lo, hi) = extents[j][k as usize];
                let (p, q) = (col * (lo - blob.center[j]), col * (hi - blob.center[j]));
                (p.min(q), p.max(q))
            })
            .collect()
    };
    let (xs, ys, zs) = (axis(0, m.x_axis), axis(1, m.y_axis), axis(2, m.z_axis));
    for (kz, z) in zs.iter().enumerate() {
        for (ky, y) in ys.iter().enumerate() {
            let (lo_yz, hi_yz) = (y.0 + z.0, y.1 + z.1);
            for (kx, x) in xs.iter().enumerate() {
                let (ulo, uhi) = (x.0 + lo_yz, x.1 + hi_yz);
                let (lo2, hi2) = (ulo * ulo, uhi * uhi);
                let straddles = ulo.cmple(Vec3A::ZERO) & uhi.cmpge(Vec3A::ZERO);
                // Widened a little against the rounding of the bake's own arithmetic.
                let qmin = Vec3A::select(straddles, Vec3A::ZERO, lo2.min(hi2)).element_sum()
                    * (1.0 - 1e-4);
                if qmin >= 1.0 {
                    continue;
                }
                let qmax = lo2.max(hi2).element_sum() * (1.0 + 1e-4);
                let (near, far) = (blob.strength * wyvill(qmin), blob.strength * wyvill(qmax));
                let at = UVec3::new(a.x + kx as u32, a.y + ky as u32, a.z + kz as u32);
                sink(at, near.min(far), near.max(far));
            }
        }
    }
}

/// What a cut does to a box.
enum Cut {
    /// Removes nothing of it.
    None,
    /// May remove part of it.
    Some,
    /// Removes all of it.
    All,
}

/// What `clip` does to the box `[lo, hi]` (`h` a texel, for the margin on whole removal).
fn clip_over(clip: &Clip, lo: Vec3, hi: Vec3, h: f32) -> Cut {
    let (Some(first), Some(last)) = (clip.line.first(), clip.line.last()) else {
        return Cut::None;
    };
    // The box's extent along the cut plane's two axes, from its eight corners.
    let (mut x, mut y) = ((f32::MAX, f32::MIN), (f32::MAX, f32::MIN));
    for c in 0..8 {
        let p = Vec3::new(
            if c & 1 == 0 { lo.x } else { hi.x },
            if c & 2 == 0 { lo.y } else { hi.y },
            if c & 4 == 0 { lo.z } else { hi.z },
        ) - clip.origin;
        let (px, py) = (p.dot(clip.right), p.dot(clip.up));
        x = (x.0.min(px), x.1.max(px));
        y = (y.0.min(py), y.1.max(py));
    }
    let (low, high) = clip
        .line
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.y), b.max(p.y)));
    let m = 0.01 * h;
    if x.1 < first.x - m || x.0 > last.x + m || y.0 > high + m {
        Cut::None
    } else if x.0 > first.x + m && x.1 < last.x - m && y.1 < low - m {
        Cut::All
    } else {
        Cut::Some
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec2};

    use super::*;
    use crate::field::{Clip, ISO, bake_fine};
    use crate::scene::{Ellipsoid, Preset, Scene};

    /// Checks `field`'s surface bake against the whole bake: every texel on the same side of
    /// the level, and the eight corners of every cell the level crosses (the padding outside
    /// the grid included) the same bits. Returns the share of bricks evaluated.
    fn check(field: &Field, resolution: u32) -> f32 {
        let whole = bake_fine(field, resolution);
        let (near, share) = bake_for_surface(field, resolution, ISO);
        assert_eq!(
            (near.dims, near.min, near.size),
            (whole.dims, whole.min, whole.size)
        );
        let inside = |v: f32| v >= ISO;
        for (i, (a, b)) in whole.values.iter().zip(&near.values).enumerate() {
            assert_eq!(
                inside(*a),
                inside(*b),
                "texel {i}: {a} baked, {b} near the surface"
            );
        }
        let d = whole.dims.as_ivec3();
        let at = |v: &DensityVolume, p: glam::IVec3| {
            (p.cmpge(glam::IVec3::ZERO).all() && p.cmplt(d).all())
                .then(|| v.value(p.x as u32, p.y as u32, p.z as u32))
        };
        let mut crossed = 0;
        for z in -1..d.z {
            for y in -1..d.y {
                for x in -1..d.x {
                    let corners = (0..8)
                        .map(|c| glam::IVec3::new(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2)));
                    let sides = corners
                        .clone()
                        .map(|p| at(&whole, p).is_some_and(inside))
                        .collect::<Vec<_>>();
                    if sides.iter().all(|s| *s) || sides.iter().all(|s| !*s) {
                        continue;
                    }
                    crossed += 1;
                    for p in corners {
                        assert_eq!(
                            at(&whole, p).map(f32::to_bits),
                            at(&near, p).map(f32::to_bits),
                            "corner {p} of a crossed cell"
                        );
                    }
                }
            }
        }
        assert!(crossed > 0, "no surface");
        share
    }

    /// A heap of spheres like the mesh benchmark's.
    fn heap(n: usize, seed: u64) -> Field {
        let mut rng = crate::seeded::SplitMix::new(seed);
        let mut u = || rng.next_f64() as f32;
        let blobs = (0..n)
            .map(|_| {
                let (a, r) = (u() * std::f32::consts::TAU, u().sqrt() * 6.0);
                let top = 3.0 * (1.0 - (r / 6.0).powi(2)).max(0.0);
                let c = Vec3::new(a.cos() * r, u() * top, a.sin() * r);
                Blob::ellipsoid(&Ellipsoid::new(c, Vec3::splat(0.6 + u() * 0.5)))
            })
            .collect();
        Field::of_blobs(blobs)
    }

    #[test]
    fn a_heap_of_spheres_is_evaluated_only_near_its_surface() {
        let share = check(&heap(400, 3), 96);
        // The heap's inside and the air around it are skipped.
        assert!(share < 0.5, "{share}");
        check(&heap(60, 4), 61);
    }

    #[test]
    fn turned_ellipsoids_far_from_the_origin_bake_as_the_whole_grid_does() {
        for offset in [Vec3::ZERO, Vec3::new(2000.0, -1500.0, 1800.0)] {
            let mut rng = crate::seeded::SplitMix::new(9);
            let mut u = || rng.next_f64() as f32;
            let blobs = (0..60)
                .map(|_| {
                    let mut e = Ellipsoid::new(
                        offset + Vec3::new(u() * 6.0, u() * 2.0, u() * 6.0),
                        Vec3::new(0.4 + u() * 2.0, 0.15 + u() * 0.4, 0.3 + u() * 1.5),
                    );
                    e.rotation =
                        Quat::from_euler(glam::EulerRot::XYZ, u() * 6.3, u() * 6.3, u() * 6.3);
                    e.strength = 0.6 + u();
                    Blob::ellipsoid(&e)
                })
                .collect();
            check(&Field::of_blobs(blobs), 80);
        }
    }

    #[test]
    fn outlines_presets_and_a_cut_bake_as_the_whole_grid_does() {
        for preset in [Preset::Cumulus, Preset::Cumulonimbus] {
            check(&crate::derive::field_of(&Scene::preset(preset)), 72);
        }
        // Two outlines' spheres, combined by their smooth maximum inside the outline.
        let mut field = heap(30, 6);
        for (k, blend) in [(0.0, 0.3), (1.5, 0.0)] {
            let outline: Vec<glam::DVec2> = (0..40)
                .map(|i| {
                    let a = i as f64 / 40.0 * std::f64::consts::TAU;
                    glam::DVec2::new(5.0 * a.cos(), 2.0 * a.sin() + 0.3 * (5.0 * a).sin())
                })
                .collect();
            let blobs = (0..24)
                .map(|i| {
                    let x = -4.5 + i as f32 * 0.4;
                    let r = 0.6 + 0.9 * (1.0 - (x / 5.0).powi(2)).max(0.0);
                    Blob::sphere(Vec3::new(x, 1.0 + k, k), r)
                })
                .collect();
            field.groups.push(crate::field::Group {
                blobs,
                puffs: Vec::new(),
                blend,
                inside: crate::field::InsideMap::new(&outline).map(|map| {
                    crate::field::PlacedInside {
                        map: std::sync::Arc::new(map),
                        origin: Vec3::new(0.0, 1.0 + k, k),
                        to_plane: Quat::IDENTITY,
                    }
                }),
            });
        }
        check(&field, 80);
        // A cut through the middle of it all, its line rising across it.
        field.clips.push(Clip {
            origin: Vec3::new(0.0, 1.0, 0.0),
            right: Vec3::X,
            up: Vec3::Y,
            line: vec![
                Vec2::new(-4.0, -0.5),
                Vec2::new(0.0, 0.5),
                Vec2::new(3.0, 1.5),
            ],
        });
        check(&field, 90);
    }
}
