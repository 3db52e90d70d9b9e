//! The billows of a document's primitives ([`crate::field::billows`]), grown once per
//! primitive and cached with it: a plane's puffs live in its own coordinates, keyed on its
//! shape, so moving the plane or ticking a light slider grows nothing, and a billows slider
//! tick re-interprets no stroke.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

use glam::Vec3;

use super::planes::Shape;
use crate::field::billows::{Base, ELLIPSOID_DEPTH, OUTLINE_DEPTH, Puffs, grow};
use crate::field::{Blob, Field, Group};
use crate::limits::{MAX_PRIMITIVES, MAX_PUFFS};
use crate::scene::{Billows, Scene};
use crate::seeded::hash64;

/// The share of an outline's soft blend kept under its billows.
pub const BILLOWED_BLEND: f32 = 0.25;

/// Grown puffs by what they depend on, with the pass that last used them.
#[derive(Default)]
pub struct PuffCache {
    grown: HashMap<u64, Grown>,
    pass: u64,
    /// Primitives whose puffs were grown (for tests and benchmarks).
    pub grown_count: u64,
}

/// The seed of a primitive's puffs: its stable id alone (the document's seed moves the noise,
/// not the shape).
fn seed_of(id: u64) -> u64 {
    hash64(id ^ 0xB111_0775)
}

/// Puffs smaller than this would not show on the field grid: about 0.6 of a texel of the
/// document's grid over `field` (the field before billows, which stay inside it), rounded down
/// to a quarter octave so edits that barely change the cloud's extent keep their puffs.
pub fn min_radius(field: &Field, resolution: u32) -> f32 {
    let Some((lo, hi)) = field.bounds() else {
        return f32::MAX;
    };
    let texel = (hi - lo).max_element().max(1e-3) / resolution.max(2) as f32;
    let r = (0.6 * texel).log2();
    2f32.powf((r * 4.0).floor() / 4.0)
}

/// One source's puffs, as they are placed in the field.
enum Source {
    /// The puffs of the outline in `field.groups[group]`: `to_world` places them.
    Plane {
        group: usize,
        origin: Vec3,
        rotation: glam::Quat,
        puffs: Arc<Puffs>,
    },
    /// The puffs of the ellipsoid at `field.blobs[blob]`.
    Ellipsoid {
        blob: usize,
        center: Vec3,
        rotation: glam::Quat,
        radii: Vec3,
        strength: f32,
        puffs: Arc<Puffs>,
    },
}

/// One primitive's grown puffs in the cache.
struct Grown {
    puffs: Arc<Puffs>,
    /// The last pass that used them.
    used: u64,
    /// The outline's shape they were grown on (kept so its pointer, part of the key, stays
    /// unique while the entry lives).
    _shape: Option<Arc<Shape>>,
}

/// How one primitive's puffs grow: its billows, how deep its cores sit, its seed and the
/// smallest puff the field grid shows.
struct Growth<'a> {
    billows: &'a Billows,
    depth: f32,
    seed: u64,
    min_r: f32,
}

impl PuffCache {
    fn get(
        &mut self,
        key: u64,
        shape: Option<&Arc<Shape>>,
        bases: impl FnOnce() -> Vec<Base>,
        how: Growth<'_>,
    ) -> Arc<Puffs> {
        let pass = self.pass;
        let grown = &mut self.grown_count;
        let entry = self.grown.entry(key).or_insert_with(|| {
            *grown += 1;
            let puffs = grow(
                &bases(),
                how.billows,
                how.depth,
                how.seed,
                how.min_r,
                MAX_PUFFS,
            );
            Grown {
                puffs: Arc::new(puffs),
                used: pass,
                _shape: shape.cloned(),
            }
        });
        entry.used = pass;
        entry.puffs.clone()
    }

    /// Adds the billows of `scene`'s primitives to `field` (assembled without them, its
    /// outlines in the order of the scene's visible outline planes): each billowed outline's
    /// spheres shrink to their cores under their puffs, and each billowed ellipsoid becomes a
    /// group of its core and its puffs. Over [`MAX_PUFFS`] in all, the finest levels are left
    /// out (`field.puffs_left_out` counts them).
    pub fn add(&mut self, scene: &Scene, shapes: &[Arc<Shape>], field: &mut Field) {
        self.pass += 1;
        let min_r = min_radius(field, scene.render.field_resolution);
        let mut sources = Vec::new();
        let mut group = 0;
        for (plane, shape) in scene.planes.iter().zip(shapes) {
            if plane.hidden {
                continue;
            }
            let Shape::Outline { spheres, .. } = &**shape else {
                continue;
            };
            let g = group;
            group += 1;
            if plane.billows.is_off() || field.groups.get(g).is_none() {
                continue;
            }
            let key = {
                let mut h = std::collections::hash_map::DefaultHasher::new();
                (0u8, Arc::as_ptr(shape) as usize, plane.billows.key()).hash(&mut h);
                (seed_of(plane.id), min_r.to_bits()).hash(&mut h);
                h.finish()
            };
            let bases = || {
                spheres
                    .iter()
                    .map(|s| Base {
                        center: s.center.as_vec3(),
                        radii: Vec3::splat(s.radius as f32),
                    })
                    .collect()
            };
            let seed = seed_of(plane.id);
            sources.push(Source::Plane {
                group: g,
                origin: plane.origin,
                rotation: plane.rotation,
                puffs: self.get(
                    key,
                    Some(shape),
                    bases,
                    Growth {
                        billows: &plane.billows,
                        depth: OUTLINE_DEPTH,
                        seed,
                        min_r,
                    },
                ),
            });
        }
        for (blob, e) in scene.ellipsoids.iter().filter(|e| !e.hidden).enumerate() {
            if e.billows.is_off() || e.strength <= 0.0 || blob >= field.blobs.len() {
                continue;
            }
            let seed = seed_of(e.id);
            let key = {
                let mut h = std::collections::hash_map::DefaultHasher::new();
                (1u8, e.radii.to_array().map(f32::to_bits), e.billows.key()).hash(&mut h);
                (seed, min_r.to_bits()).hash(&mut h);
                h.finish()
            };
            let radii = e.radii.max(Vec3::splat(1e-4));
            // An ellipsoid has no drawn outline to keep: its first puffs are centred on its
            // surface (Bouthors & Neyret), so the body keeps its size, the puffs half out.
            let out = 0.5 * e.billows.ratio * radii.min_element();
            let bases = || {
                vec![Base {
                    center: Vec3::ZERO,
                    radii: radii + Vec3::splat(out),
                }]
            };
            sources.push(Source::Ellipsoid {
                blob,
                center: e.center,
                rotation: e.rotation.normalize(),
                radii,
                strength: e.strength,
                puffs: self.get(
                    key,
                    None,
                    bases,
                    Growth {
                        billows: &e.billows,
                        depth: ELLIPSOID_DEPTH,
                        seed,
                        min_r,
                    },
                ),
            });
        }
        // Keep this pass's and the previous pass's puffs (undo is instant).
        let pass = self.pass;
        self.grown.retain(|_, g| g.used + 1 >= pass);
        if sources.is_empty() {
            return;
        }
        // The most levels that fit the caps, the same for every source.
        let puffs_of = |s: &Source| match s {
            Source::Plane { puffs, .. } | Source::Ellipsoid { puffs, .. } => puffs.clone(),
        };
        let deepest = sources
            .iter()
            .map(|s| puffs_of(s).levels.len())
            .max()
            .unwrap_or(0);
        let room = MAX_PUFFS.min(MAX_PRIMITIVES.saturating_sub(field.all_blobs().count()));
        let within = |levels: usize| -> usize {
            sources
                .iter()
                .map(|s| puffs_of(s).count_within(levels))
                .sum()
        };
        let levels = (0..=deepest)
            .rev()
            .find(|&l| within(l) <= room)
            .unwrap_or(0);
        field.puffs_left_out = within(deepest) - within(levels);
        // Ellipsoids leave the summed primitives from the last, so indices stay valid.
        let mut groups = Vec::new();
        for source in sources.iter().rev() {
            match source {
                Source::Plane {
                    group,
                    origin,
                    rotation,
                    puffs,
                } => {
                    let g = &mut field.groups[*group];
                    if levels > 0 {
                        // The soft blend lifts the cores between their spheres back out to
                        // where the puffs reach, filling the scallops: under billows it acts at
                        // a quarter of its width, smoothing creases between cores only.
                        g.blend *= BILLOWED_BLEND;
                    }
                    let place = |c: Vec3| *origin + *rotation * c;
                    for (i, blob) in g.blobs.iter_mut().enumerate() {
                        let whole = Vec3::splat(blob.extent.x);
                        let r = puffs.base_radii(i, whole, levels).x;
                        *blob = Blob::sphere(blob.center, r);
                    }
                    g.puffs = puffs
                        .spheres(levels)
                        .map(|(c, r)| Blob::sphere(place(c), r))
                        .collect();
                }
                Source::Ellipsoid {
                    blob,
                    center,
                    rotation,
                    radii,
                    strength,
                    puffs,
                } => {
                    field.blobs.remove(*blob);
                    let core = crate::scene::Ellipsoid {
                        center: *center,
                        radii: puffs.base_radii(0, *radii, levels),
                        rotation: *rotation,
                        strength: *strength,
                        ..Default::default()
                    };
                    groups.push(Group {
                        puffs: puffs
                            .spheres(levels)
                            .map(|(c, r)| Blob {
                                strength: *strength,
                                ..Blob::sphere(*center + *rotation * c, r)
                            })
                            .collect(),
                        ..Group::hard(vec![Blob::ellipsoid(&core)])
                    });
                }
            }
        }
        groups.reverse();
        field.groups.extend(groups);
    }
}
