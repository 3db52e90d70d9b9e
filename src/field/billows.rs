//! Billows: puffs on puffs (Bouthors & Neyret 2004, "Modeling clouds shape"). Each primitive
//! with billows shrinks to a core, and spheres a `ratio` of its size sit on the core's surface;
//! each of those shrinks to its own core under the next, smaller level, and so on. A puff's
//! outer side reaches exactly as far as what it sits on, so billows never push a primitive's
//! outline outward (a sketched outline stays within its stroke in the drawing view): between
//! puffs they scallop it inward, at every level's scale, and from any other view the puffs
//! stand out in depth. Everything is seeded by the primitive's stable id (deterministic).
//!
//! Puffs hidden inside the union of cores (the inner side of an outline's dense spheres) are
//! left out, and a puff smaller than `min_radius` (under a texel of the field grid, where it
//! would not show) gets no children.

use std::collections::HashMap;

use glam::{IVec3, Quat, Vec3};

use crate::scene::Billows;
use crate::seeded::{SplitMix, hash64};

/// How much of a puff stands out of the core it sits on, as a share of its radius, for a
/// sketched outline: the depth of the scallops between puffs. Deeper scallops read as rougher
/// billows but take more of the drawn outline's area away (at 0.5 its silhouette keeps 0.81 of
/// the stroke's by IoU, 0.72 at 1).
pub const OUTLINE_DEPTH: f32 = 0.5;
/// [`OUTLINE_DEPTH`] for an ellipsoid, which has no drawn outline to keep: its puffs stand
/// out whole, their centres on its core.
pub const ELLIPSOID_DEPTH: f32 = 1.0;

/// One puff: a sphere in its source's own coordinates, and the core it shrinks to when the
/// next level sits on it (its radius when no puff does).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Puff {
    /// Centre.
    pub center: Vec3,
    /// Visible radius of the whole puff.
    pub radius: f32,
    /// Visible radius of its core under its own puffs.
    pub core: f32,
    /// Its point farthest out: on the surface of what it sits on, before that shrank to its core.
    pub outer: Vec3,
}

impl Puff {
    /// Its radius when `last` (no level drawn over it) or not.
    pub fn drawn_radius(&self, last: bool) -> f32 {
        if last { self.radius } else { self.core }
    }
}

/// A primitive's puffs, level by level (level 1, on the primitive itself, first).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Puffs {
    /// The base primitives' core radii (per axis, in their own frame), or their whole radii
    /// where no puff sits on them.
    pub cores: Vec<Vec3>,
    /// Puffs of each level.
    pub levels: Vec<Vec<Puff>>,
}

impl Puffs {
    /// Puffs in all levels.
    pub fn count(&self) -> usize {
        self.levels.iter().map(Vec::len).sum()
    }

    /// Puffs in the first `levels` levels.
    pub fn count_within(&self, levels: usize) -> usize {
        self.levels.iter().take(levels).map(Vec::len).sum()
    }

    /// The spheres (centre, visible radius) drawn when the first `levels` levels are kept:
    /// the last kept level whole, the ones under it shrunk to their cores.
    pub fn spheres(&self, levels: usize) -> impl Iterator<Item = (Vec3, f32)> + '_ {
        let kept = levels.min(self.levels.len());
        self.levels[..kept]
            .iter()
            .enumerate()
            .flat_map(move |(k, level)| {
                level
                    .iter()
                    .map(move |p| (p.center, p.drawn_radius(k + 1 == kept)))
            })
    }

    /// The base primitive `i`'s radii when `levels` levels of puffs are kept.
    pub fn base_radii(&self, i: usize, whole: Vec3, levels: usize) -> Vec3 {
        if levels == 0 || self.levels.is_empty() {
            whole
        } else {
            self.cores.get(i).copied().unwrap_or(whole)
        }
    }
}

/// A primitive puffs grow on: an axis-aligned ellipsoid in its source's frame (a sketched
/// sphere has equal radii).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Base {
    /// Centre.
    pub center: Vec3,
    /// Semi-axes of its visible surface.
    pub radii: Vec3,
}

/// The puffs of `bases` (one source: an outline's spheres or one ellipsoid). At most `cap`
/// puffs: a level that would pass it is left out whole.
pub fn grow(
    bases: &[Base],
    billows: &Billows,
    depth: f32,
    seed: u64,
    min_radius: f32,
    cap: usize,
) -> Puffs {
    let mut out = Puffs {
        cores: bases.iter().map(|b| b.radii).collect(),
        levels: Vec::new(),
    };
    if billows.is_off() || bases.is_empty() {
        return out;
    }
    let ratio = billows.ratio;
    let mut rng = SplitMix::new(hash64(seed ^ 0xB111_0775));
    let mut cover = Cover::new(bases);
    // The surface the current level grows on: puffs whose outer point lies deep inside it
    // would sit under a neighbour's surface (the spheres of an outline overlap by far).
    let mut envelope = Cover::new(bases);
    for b in bases {
        envelope.add_ellipsoid(b.center, b.radii);
    }
    // Level 1: on each base's core.
    let mut level = Vec::new();
    for (i, b) in bases.iter().enumerate() {
        let r = ratio * b.radii.min_element();
        if r < min_radius {
            continue;
        }
        let core = (b.radii - Vec3::splat(depth * r)).max(Vec3::splat(1e-4));
        out.cores[i] = core;
        cover.add_ellipsoid(b.center, core);
        place(b.center, core, r, depth, billows, &mut rng, &mut level);
    }
    for _ in 0..billows.levels {
        level = spread(level, &cover, &envelope);
        if level.is_empty() || out.count() + level.len() > cap {
            break;
        }
        // The next level on each puff of this one.
        let mut next = Vec::new();
        if out.levels.len() + 1 < billows.levels as usize {
            for p in &mut level {
                let r = ratio * p.radius;
                if r < min_radius {
                    continue;
                }
                p.core = p.radius - depth * r;
                place(
                    p.center,
                    Vec3::splat(p.core),
                    r,
                    depth,
                    billows,
                    &mut rng,
                    &mut next,
                );
            }
            for p in &level {
                if p.core < p.radius {
                    cover.add_sphere(p.center, p.core);
                }
            }
        }
        envelope = Cover::with_cell(level.iter().map(|p| p.radius).fold(0.0, f32::max));
        for p in &level {
            envelope.add_sphere(p.center, p.radius);
        }
        out.levels.push(std::mem::take(&mut level));
        level = next;
    }
    // A level left out (over the cap, or all hidden) leaves the one under it whole.
    if !level.is_empty() || out.levels.is_empty() {
        match out.levels.last_mut() {
            Some(last) => last.iter_mut().for_each(|p| p.core = p.radius),
            None => out.cores = bases.iter().map(|b| b.radii).collect(),
        }
    }
    out
}

/// Puffs of radius about `r` on the surface of the core (centre `c`, semi-axes `core`): as
/// many as cover `coverage` of it twice over with their discs, spread evenly (a Fibonacci
/// lattice, turned at random and weighted by the surface's area), each a little smaller or
/// larger at random, its centre where its outer side reaches the core plus `depth`·`r` (the
/// surface the core was shrunk from).
fn place(
    c: Vec3,
    core: Vec3,
    r: f32,
    depth: f32,
    billows: &Billows,
    rng: &mut SplitMix,
    out: &mut Vec<Puff>,
) {
    let area = ellipsoid_area(core);
    let n = (billows.coverage * 2.0 * area / (std::f32::consts::PI * r * r)).round() as usize;
    let n = n.clamp(1, 4096);
    let mut u = || rng.next_f64() as f32;
    let turn = Quat::from_euler(
        glam::EulerRot::ZYX,
        u() * std::f32::consts::TAU,
        (u() * 2.0 - 1.0).acos(),
        u() * std::f32::consts::TAU,
    );
    // The area element of the map from the unit sphere onto the ellipsoid, for acceptance.
    let cof = Vec3::new(core.y * core.z, core.x * core.z, core.x * core.y);
    let most = cof.max_element();
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    for i in 0..n {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let ring = (1.0 - y * y).max(0.0).sqrt();
        let a = golden * i as f32;
        let d = turn * Vec3::new(ring * a.cos(), y, ring * a.sin());
        let accept = (cof * d).length() / most;
        let size = 0.75 + 0.5 * u();
        if u() > accept {
            continue;
        }
        let radius = r * size;
        // The point of the core's surface in direction d, then along its normal so the puff's
        // outer side lies at the core plus depth·r (for a sphere: on the whole primitive).
        let on = core * d;
        let on = on / (on / core).length().max(1e-6);
        let normal = (on / (core * core)).normalize_or_zero();
        out.push(Puff {
            center: c + on + normal * (depth * r - radius),
            radius,
            core: radius,
            outer: c + on + normal * (depth * r),
        });
    }
}

/// How deep (in its radii) a puff's outer point may lie under the surface its level grows on.
const UNDER: f32 = 0.3;

/// The puffs of one level that show: those not hidden inside the cores, those whose outer point
/// lies on the surface they grow on (not under a neighbour's), and of two puffs much closer
/// than their radii (neighbouring spheres of an outline share their surface) only the first.
fn spread(level: Vec<Puff>, cover: &Cover, envelope: &Cover) -> Vec<Puff> {
    let reach = level.iter().map(|p| p.radius).fold(0.0, f32::max) * 1.2;
    let cell = reach.max(1e-6);
    let key = |p: Vec3| (p / cell).floor().as_ivec3();
    let mut kept: Vec<Puff> = Vec::with_capacity(level.len());
    let mut cells: HashMap<IVec3, Vec<u32>> = HashMap::new();
    for p in level {
        let k = key(p.center);
        let crowded = (-1..=1).any(|x| {
            (-1..=1).any(|y| {
                (-1..=1).any(|z| {
                    cells.get(&(k + IVec3::new(x, y, z))).is_some_and(|list| {
                        list.iter().any(|&i| {
                            let q = &kept[i as usize];
                            let near = 0.6 * (p.radius + q.radius);
                            (p.center - q.center).length_squared() < near * near
                        })
                    })
                })
            })
        });
        if crowded
            || envelope.deeper_than(p.outer, UNDER * p.radius)
            || cover.hides(p.center, p.radius)
        {
            continue;
        }
        cells.entry(k).or_default().push(kept.len() as u32);
        kept.push(p);
    }
    kept
}

/// Surface area of an ellipsoid (Knud Thomsen's formula, within about 1%).
fn ellipsoid_area(r: Vec3) -> f32 {
    const P: f32 = 1.6075;
    let (a, b, c) = (r.x.powf(P), r.y.powf(P), r.z.powf(P));
    4.0 * std::f32::consts::PI * ((a * b + a * c + b * c) / 3.0).powf(1.0 / P)
}

/// The union of the cores so far, to leave out puffs that would lie wholly inside it: a hash
/// grid of spheres, and the ellipsoid cores apart (one per source at most in practice).
struct Cover {
    cell: f32,
    cells: HashMap<IVec3, Vec<u32>>,
    spheres: Vec<(Vec3, f32)>,
    ellipsoids: Vec<(Vec3, Vec3)>,
}

/// Directions a puff's hiding is tested along (besides its centre).
const PROBES: [Vec3; 14] = {
    const D: f32 = 0.577_350_3;
    [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
        Vec3::new(D, D, D),
        Vec3::new(D, D, -D),
        Vec3::new(D, -D, D),
        Vec3::new(D, -D, -D),
        Vec3::new(-D, D, D),
        Vec3::new(-D, D, -D),
        Vec3::new(-D, -D, D),
        Vec3::new(-D, -D, -D),
    ]
};

impl Cover {
    fn new(bases: &[Base]) -> Self {
        let mut radii: Vec<f32> = bases.iter().map(|b| b.radii.max_element()).collect();
        radii.sort_by(f32::total_cmp);
        Self::with_cell(radii.get(radii.len() / 2).copied().unwrap_or(1.0))
    }

    fn with_cell(cell: f32) -> Self {
        Self {
            cell: cell.max(1e-4),
            cells: HashMap::new(),
            spheres: Vec::new(),
            ellipsoids: Vec::new(),
        }
    }

    /// Whether `p` lies inside one of the shapes by more than `margin`.
    fn deeper_than(&self, p: Vec3, margin: f32) -> bool {
        self.ellipsoids.iter().any(|&(c, r)| {
            let r = r - Vec3::splat(margin);
            r.min_element() > 0.0 && ((p - c) / r).length_squared() < 1.0
        }) || self.cells.get(&self.key(p)).is_some_and(|list| {
            list.iter().any(|&i| {
                let (c, r) = self.spheres[i as usize];
                r > margin && (p - c).length_squared() < (r - margin) * (r - margin)
            })
        })
    }

    fn key(&self, p: Vec3) -> IVec3 {
        (p / self.cell).floor().as_ivec3()
    }

    fn add_ellipsoid(&mut self, c: Vec3, radii: Vec3) {
        if radii.x == radii.y && radii.y == radii.z {
            self.add_sphere(c, radii.x);
        } else {
            self.ellipsoids.push((c, radii));
        }
    }

    fn add_sphere(&mut self, c: Vec3, r: f32) {
        let i = self.spheres.len() as u32;
        self.spheres.push((c, r));
        let (lo, hi) = (self.key(c - Vec3::splat(r)), self.key(c + Vec3::splat(r)));
        // A huge sphere against tiny cells would fill too many: such spheres are rare (cells
        // are the median base's size), and are tested apart.
        if (hi - lo + IVec3::ONE).as_i64vec3().element_product() > 4096 {
            self.ellipsoids.push((c, Vec3::splat(r)));
            return;
        }
        for x in lo.x..=hi.x {
            for y in lo.y..=hi.y {
                for z in lo.z..=hi.z {
                    self.cells.entry(IVec3::new(x, y, z)).or_default().push(i);
                }
            }
        }
    }

    fn covers(&self, p: Vec3) -> bool {
        self.ellipsoids
            .iter()
            .any(|&(c, r)| ((p - c) / r).length_squared() < 1.0)
            || self.cells.get(&self.key(p)).is_some_and(|list| {
                list.iter().any(|&i| {
                    let (c, r) = self.spheres[i as usize];
                    (p - c).length_squared() < r * r
                })
            })
    }

    /// Whether the ball (`c`, `r`) lies inside the cores (its centre and 14 points of its
    /// surface do).
    fn hides(&self, c: Vec3, r: f32) -> bool {
        self.covers(c) && PROBES.iter().all(|d| self.covers(c + *d * r))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn on() -> Billows {
        Billows::NEW
    }

    /// Every puff, at every level, lies within its base: billows never push an outline outward.
    #[test]
    fn puffs_never_reach_beyond_what_they_sit_on() {
        for radii in [Vec3::splat(1.0), Vec3::new(3.0, 0.7, 2.0)] {
            let base = Base {
                center: Vec3::new(1.0, 2.0, -1.0),
                radii,
            };
            let puffs = grow(&[base], &on(), 1.0, 7, 0.01, 100_000);
            assert_eq!(puffs.levels.len(), 3, "{radii}");
            for level in 1..=puffs.levels.len() {
                for (c, r) in puffs.spheres(level) {
                    // The sphere's farthest point from the base's centre, in the base's
                    // ellipsoidal measure (a sphere base: exact; an ellipsoid: within 5%, where the
                    // parallel surface of its core bulges).
                    let d = c - base.center;
                    let far = d + d.normalize_or_zero() * r;
                    let reach = (far / radii).length();
                    let slack = if radii.x == radii.y { 1e-4 } else { 0.05 };
                    assert!(
                        reach <= 1.0 + slack,
                        "{radii}: level {level} reaches {reach}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_same_id_grows_the_same_puffs_and_another_id_others() {
        let base = [Base {
            center: Vec3::ZERO,
            radii: Vec3::splat(2.0),
        }];
        let a = grow(&base, &on(), 1.0, 3, 0.02, 100_000);
        assert_eq!(a, grow(&base, &on(), 1.0, 3, 0.02, 100_000));
        assert_ne!(a, grow(&base, &on(), 1.0, 4, 0.02, 100_000));
        assert!(a.count() > 100, "{}", a.count());
        let off = Billows::default();
        assert_eq!(grow(&base, &off, 1.0, 3, 0.02, 100_000).count(), 0);
    }

    #[test]
    fn levels_stop_at_the_smallest_radius_and_at_the_cap() {
        let base = [Base {
            center: Vec3::ZERO,
            radii: Vec3::splat(1.0),
        }];
        // Level 1's puffs are 0.45 across, level 2's 0.15 to 0.25, level 3's at most 0.14:
        // two levels over 0.15.
        let two = grow(&base, &on(), 1.0, 1, 0.15, 100_000);
        assert_eq!(two.levels.len(), 2);
        assert!(two.levels[1].iter().all(|p| p.core == p.radius));
        let all = grow(&base, &on(), 1.0, 1, 0.01, 100_000);
        let capped = grow(&base, &on(), 1.0, 1, 0.01, all.count() - 1);
        assert_eq!(capped.levels.len(), 2, "the third level passes the cap");
        assert!(capped.levels[1].iter().all(|p| p.core == p.radius));
    }

    /// The inner spheres of a dense row (an outline's body) get no puffs of their own inside
    /// the others.
    #[test]
    fn puffs_hidden_inside_the_cores_are_left_out() {
        let row: Vec<Base> = (0..40)
            .map(|i| Base {
                center: Vec3::new(i as f32 * 0.1, 0.0, 0.0),
                radii: Vec3::splat(1.0),
            })
            .collect();
        let one = grow(&row[..1], &on(), 1.0, 1, 0.05, 100_000);
        let all = grow(&row, &on(), 1.0, 1, 0.05, 100_000);
        assert!(
            all.count() < one.count() * 8,
            "40 overlapping spheres: {} puffs, one alone {}",
            all.count(),
            one.count()
        );
    }
}
