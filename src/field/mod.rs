//! The implicit cloud field: ellipsoids and spheres blended with Wyvill's cubic kernel,
//! hard clips from cut strokes, and the capped density grid the renderer samples.
//!
//! Kernel (Wyvill, Wyvill & McPheeters' "soft object" function, cubic in r²): for a primitive
//! of influence radius R and s = r²/R² < 1,
//! `w(s) = 1 − 4/9 s³ + 17/9 s² − 22/9 s`, else 0. The field is Σ strength·w. The visible
//! surface is the iso-level [`ISO`] = 0.5, and w(1/4) = 0.5 exactly, so an isolated primitive of
//! visible radius r gets R = 2r: its surface lies exactly at r.

pub mod billows;
mod inside;
pub mod media;
pub mod noise;
mod volume;

pub use inside::{InsideMap, PlacedInside};

pub use volume::{
    Baked, Baker, DensityVolume, MAX_RESOLUTION, bake, bake_brute_force, bake_fine, bake_fine_work,
    bake_for_surface, bake_work, density, lattice, resolution_within,
};

use glam::{Mat3, Vec2, Vec3, Vec4};

use crate::scene::Ellipsoid;

pub use crate::density::ISO;
/// Influence radius over visible radius.
pub const SUPPORT: f32 = 2.0;
/// How far (in visible radii) the field can reach the surface level once blended; grid bounds
/// use it so nothing visible is cut off while the grid stays tight.
pub const BOUNDS_MARGIN: f32 = 1.6;
pub use crate::limits::MAX_PRIMITIVES;

/// Wyvill's kernel as a function of s = r²/R².
#[inline]
pub fn wyvill(s: f32) -> f32 {
    if s >= 1.0 {
        0.0
    } else {
        let s2 = s * s;
        1.0 - (4.0 / 9.0) * s2 * s + (17.0 / 9.0) * s2 - (22.0 / 9.0) * s
    }
}

/// A blended primitive, ready for evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct Blob {
    /// Centre.
    pub center: Vec3,
    /// Maps `p − center` to a space where the influence region is the unit ball.
    pub to_unit: Mat3,
    /// Field weight.
    pub strength: f32,
    /// Half-extent (world) of the visible radius per axis.
    pub extent: Vec3,
}

impl Blob {
    /// A sphere of visible radius `radius`.
    pub fn sphere(center: Vec3, radius: f32) -> Self {
        let r = radius.max(1e-4);
        Self {
            center,
            to_unit: Mat3::from_diagonal(Vec3::splat(1.0 / (SUPPORT * r))),
            strength: 1.0,
            extent: Vec3::splat(r),
        }
    }

    /// An ellipsoid primitive of the document.
    pub fn ellipsoid(e: &Ellipsoid) -> Self {
        let radii = e.radii.max(Vec3::splat(1e-4));
        let rot = Mat3::from_quat(e.rotation.normalize());
        let to_unit = Mat3::from_diagonal(1.0 / (SUPPORT * radii)) * rot.transpose();
        // Axis-aligned half extents of the rotated ellipsoid.
        let abs = Mat3::from_cols(rot.x_axis.abs(), rot.y_axis.abs(), rot.z_axis.abs());
        Self {
            center: e.center,
            to_unit,
            strength: e.strength,
            extent: abs * radii,
        }
    }

    /// This primitive's field contribution at `p`.
    #[inline]
    pub fn value(&self, p: Vec3) -> f32 {
        self.strength * wyvill((self.to_unit * (p - self.center)).length_squared())
    }

    /// What the primitive's lines parallel to x share ([`BlobRows::at`] gives each line), found
    /// once per primitive for a bake's texel rows.
    pub fn rows(&self) -> BlobRows {
        let m = &self.to_unit;
        // In unit space the line through (·, y, z) is `along·dx + across` (dx = x − center.x),
        // across = y_axis·dy + z_axis·dz. Its point nearest the centre is at dx = t, where
        // t = −(along·across)/|along|² = ty·dy + tz·dz, and its squared distance there is
        // |across + along·t|² = |py·dy + pz·dz|², with py and pz the parts of the y and z
        // columns perpendicular to `along`: the quadratic in completed-square form, from
        // perpendicular parts (not as a difference of large terms, which would cancel for
        // thin, turned ellipsoids).
        let along = m.x_axis;
        let a = along.length_squared();
        let (ty, tz) = if a > 0.0 {
            (-along.dot(m.y_axis) / a, -along.dot(m.z_axis) / a)
        } else {
            (0.0, 0.0)
        };
        BlobRows {
            center: self.center,
            a,
            ty,
            tz,
            py: m.y_axis + along * ty,
            pz: m.z_axis + along * tz,
            strength: self.strength,
        }
    }
}

/// What a primitive's lines parallel to x share ([`Blob::rows`]).
#[derive(Clone, Copy, Debug)]
pub struct BlobRows {
    center: Vec3,
    a: f32,
    ty: f32,
    tz: f32,
    py: Vec3,
    pz: Vec3,
    strength: f32,
}

impl BlobRows {
    /// The primitive along the line of points `(x, y, z)` for every x (the same values as
    /// [`Blob::value`] up to float rounding).
    #[inline]
    pub fn at(&self, y: f32, z: f32) -> BlobRow {
        let (dy, dz) = (y - self.center.y, z - self.center.z);
        BlobRow {
            center_x: self.center.x,
            t: self.ty * dy + self.tz * dz,
            a: self.a,
            c: (self.py * dy + self.pz * dz).length_squared(),
            strength: self.strength,
        }
    }
}

impl BlobRows {
    /// [`BlobRows::at`] for the four lines at `y`'s lanes and one `z`, each the same bits (the
    /// same operations in the same order), the arithmetic done on four lanes at once.
    #[inline]
    pub fn at4(&self, y: Vec4, z: f32) -> [BlobRow; 4] {
        let (dy, dz) = (y - Vec4::splat(self.center.y), z - self.center.z);
        let t = Vec4::splat(self.ty) * dy + Vec4::splat(self.tz * dz);
        let e = |py: f32, pz: f32| Vec4::splat(py) * dy + Vec4::splat(pz * dz);
        let (ex, ey, ez) = (
            e(self.py.x, self.pz.x),
            e(self.py.y, self.pz.y),
            e(self.py.z, self.pz.z),
        );
        let c = ex * ex + ey * ey + ez * ez;
        std::array::from_fn(|l| BlobRow {
            center_x: self.center.x,
            t: t[l],
            a: self.a,
            c: c[l],
            strength: self.strength,
        })
    }
}

/// A primitive along one line parallel to x ([`BlobRows::at`]): in the primitive's unit space the
/// point at `x` lies at squared distance a·(x − center_x − t)² + c from the centre, the line's
/// point nearest it at `center_x + t` (kept apart: far from the origin their rounded sum would
/// cost the precision that `x − center_x` keeps).
#[derive(Clone, Copy, Debug)]
pub struct BlobRow {
    center_x: f32,
    t: f32,
    a: f32,
    c: f32,
    strength: f32,
}

impl BlobRow {
    /// The primitive's contribution at `x`.
    #[inline]
    pub fn value(&self, x: f32) -> f32 {
        let dx = (x - self.center_x) - self.t;
        self.strength * wyvill(self.a * dx * dx + self.c)
    }

    /// [`BlobRow::value`] at four x at once, each lane the same bits (the same operations in
    /// the same order, no fused multiply-add), with no branch: one SIMD vector where glam has one.
    #[inline]
    pub fn value4(&self, x: Vec4) -> Vec4 {
        let dx = (x - Vec4::splat(self.center_x)) - Vec4::splat(self.t);
        let s = Vec4::splat(self.a) * dx * dx + Vec4::splat(self.c);
        let s2 = s * s;
        let w = Vec4::ONE - Vec4::splat(4.0 / 9.0) * s2 * s + Vec4::splat(17.0 / 9.0) * s2
            - Vec4::splat(22.0 / 9.0) * s;
        Vec4::select(s.cmpge(Vec4::ONE), Vec4::ZERO, w) * Vec4::splat(self.strength)
    }

    /// Whether the line misses the unit ball of influence (a·(x − center_x − t)² + c < 1 for no
    /// x): the contribution is 0 all along it.
    #[inline]
    pub fn misses(&self) -> bool {
        self.a <= 0.0 || self.c >= 1.0
    }

    /// The open interval of x where the contribution can be non-zero (the line's chord through
    /// the unit ball of influence), if the line meets it; rounding may widen the true chord by
    /// a few ulps, so callers add slack.
    pub fn reach(&self) -> Option<(f32, f32)> {
        if self.misses() {
            return None;
        }
        let half = ((1.0 - self.c) / self.a).sqrt();
        let mid = self.center_x + self.t;
        Some((mid - half, mid + half))
    }
}

/// A cut stroke: nothing of the cloud survives below its line, within its footprint.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// Origin of the cut's plane.
    pub origin: Vec3,
    /// Plane x axis (unit).
    pub right: Vec3,
    /// Plane y axis (unit); "below" is −up.
    pub up: Vec3,
    /// The cut line in plane coordinates, sorted by x.
    pub line: Vec<Vec2>,
}

impl Clip {
    /// Whether `p` is removed by this cut.
    pub fn removes(&self, p: Vec3) -> bool {
        let d = p - self.origin;
        let (x, y) = (d.dot(self.right), d.dot(self.up));
        match line_height(&self.line, x) {
            Some(h) => y < h,
            None => false,
        }
    }
}

/// Height of a polyline (sorted by x) at `x`, or `None` outside its x-range.
fn line_height(line: &[Vec2], x: f32) -> Option<f32> {
    let (first, last) = (line.first()?, line.last()?);
    if x < first.x || x > last.x {
        return None;
    }
    let i = line.partition_point(|p| p.x < x);
    if i == 0 {
        return Some(first.y);
    }
    let (a, b) = (line[i - 1], line[i.min(line.len() - 1)]);
    let t = if b.x > a.x {
        (x - a.x) / (b.x - a.x)
    } else {
        0.0
    };
    Some(a.y + (b.y - a.y) * t)
}

/// One sketched outline's spheres. They combine by their maximum (so the outline's dense
/// spheres give their union, whose silhouette is the drawn outline), softened by a smooth
/// maximum of the two largest values where the point lies inside the outline as seen along
/// its plane's normal: creases between spheres fill in, the silhouette does not move.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Group {
    /// The spheres.
    pub blobs: Vec<Blob>,
    /// Width of the smooth maximum (field units; 0 is the plain maximum).
    pub blend: f32,
    /// Where the blend may act, and how far inside the outline it reaches full width.
    pub inside: Option<PlacedInside>,
    /// Billows' puffs over the spheres: combined by their plain maximum with the blended
    /// spheres, so the soft blend never fills the scallops between them.
    pub puffs: Vec<Blob>,
}

/// Polynomial smooth maximum of `a ≥ b` of width `k`: `a` where they differ by `k` or more,
/// up to `a + k/4` where they are equal.
#[inline]
pub fn smooth_max(a: f32, b: f32, k: f32) -> f32 {
    if k <= 0.0 {
        return a;
    }
    let h = (k - (a - b)).max(0.0) / k;
    a + h * h * k * 0.25
}

impl Group {
    /// A group of spheres combined by their plain maximum.
    pub fn hard(blobs: Vec<Blob>) -> Self {
        Self {
            blobs,
            ..Default::default()
        }
    }

    /// The blend width at `p`: full where `p` is deeper inside the outline than 4% of its
    /// size, none on or outside it.
    #[inline]
    pub fn blend_at(&self, p: Vec3) -> f32 {
        match &self.inside {
            _ if self.blend <= 0.0 => 0.0,
            None => self.blend,
            Some(inside) => {
                let t = (inside.depth(p) / (0.04 * inside.map.extent)).clamp(0.0, 1.0);
                self.blend * t * t * (3.0 - 2.0 * t)
            }
        }
    }

    /// The group's value at `p` from its two largest sphere values there. The blend's width
    /// grows with the value up to the surface level, so it acts around and inside the surface
    /// and adds nothing where the spheres barely reach (no haze of k/4 around the cloud).
    #[inline]
    pub fn combine(&self, first: f32, second: f32, p: Vec3) -> f32 {
        // Values a blend's width or more apart get no lift: skip the inside look-up (most
        // texels of a dense group, in the bake's inner loop).
        if first <= 0.0 || first - second >= self.blend {
            return first.max(0.0);
        }
        smooth_max(first, second, self.blend_at(p) * (first / ISO).min(1.0))
    }

    /// The group's value at `p`.
    pub fn value(&self, p: Vec3) -> f32 {
        let (a, b) = self
            .blobs
            .iter()
            .map(|b| b.value(p))
            .fold((0.0, 0.0), top_two);
        let puffs = self.puffs.iter().map(|b| b.value(p)).fold(0.0, f32::max);
        self.combine(a, b, p).max(puffs)
    }
}

/// Folds a value into the two largest so far.
#[inline]
pub fn top_two((first, second): (f32, f32), v: f32) -> (f32, f32) {
    if v > first {
        (v, first)
    } else {
        (first, second.max(v))
    }
}

/// The whole field: blended primitives minus clips.
///
/// Ellipsoids are summed (Wyvill blending). The spheres of one sketched outline are first
/// combined into one value ([`Group`]); those per-outline fields are then summed like any other
/// primitive, so outlines and ellipsoids blend into one cloud.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Field {
    /// Positive primitives, summed.
    pub blobs: Vec<Blob>,
    /// Sphere groups (one per sketched outline), summed across.
    pub groups: Vec<Group>,
    /// Hard clips.
    pub clips: Vec<Clip>,
    /// Puffs of billows the document asked for but the cap left out (the finest levels).
    pub puffs_left_out: usize,
}

impl Field {
    /// A field of summed primitives only (no sketched outlines, no cuts).
    pub fn of_blobs(blobs: Vec<Blob>) -> Self {
        Self {
            blobs,
            ..Default::default()
        }
    }

    /// Every primitive, summed ones and grouped ones.
    pub fn all_blobs(&self) -> impl Iterator<Item = &Blob> {
        self.blobs.iter().chain(
            self.groups
                .iter()
                .flat_map(|g| g.blobs.iter().chain(&g.puffs)),
        )
    }

    /// Field value at `p`.
    pub fn value(&self, p: Vec3) -> f32 {
        if self.clips.iter().any(|c| c.removes(p)) {
            return 0.0;
        }
        let summed: f32 = self.blobs.iter().map(|b| b.value(p)).sum();
        let grouped: f32 = self.groups.iter().map(|g| g.value(p)).sum();
        summed + grouped
    }

    /// Whether `p` is inside the visible surface.
    pub fn inside(&self, p: Vec3) -> bool {
        self.value(p) >= ISO
    }

    /// Axis-aligned box holding everything visible, or `None` for an empty field.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.all_blobs().map(|b| {
            (
                b.center - b.extent * BOUNDS_MARGIN,
                b.center + b.extent * BOUNDS_MARGIN,
            )
        });
        let first = it.next()?;
        Some(it.fold(first, |(lo, hi), (a, b)| (lo.min(a), hi.max(b))))
    }

    /// Bounding sphere (centre, radius) of [`Field::bounds`].
    pub fn bounding_sphere(&self) -> Option<(Vec3, f32)> {
        self.bounds()
            .map(|(lo, hi)| ((lo + hi) * 0.5, (hi - lo).length() * 0.5))
    }

    /// Where a click's ray meets the cloud: [`Field::raycast`] in steps of 1/200 of the
    /// field's bounding radius (fine enough for picking and placing, and bounded).
    pub fn surface_under(&self, ray: &crate::scene::Ray) -> Option<Vec3> {
        let (_, radius) = self.bounding_sphere()?;
        self.raycast(ray, radius / 200.0)
    }

    /// Where a ray leaves the cloud on its far side: the last surface it crosses inside the
    /// field's box, found by marching back from the box's far side ([`Field::surface_under`]
    /// of the reversed ray). A drawing plane there lies behind the cloud.
    pub fn surface_behind(&self, ray: &crate::scene::Ray) -> Option<Vec3> {
        let (lo, hi) = self.bounds()?;
        let (_, t1) = ray_box(ray.origin, ray.dir, lo, hi)?;
        let back = crate::scene::Ray {
            origin: ray.at(t1),
            dir: -ray.dir,
        };
        let (_, radius) = self.bounding_sphere()?;
        let hit = self.raycast(&back, radius / 200.0)?;
        // The reversed ray may meet the cloud behind the viewer: only what lies ahead counts.
        ((hit - ray.origin).dot(ray.dir) > 0.0).then_some(hit)
    }

    /// First point where a ray enters the visible surface, marching in steps of `step`.
    pub fn raycast(&self, ray: &crate::scene::Ray, step: f32) -> Option<Vec3> {
        let (lo, hi) = self.bounds()?;
        let (t0, t1) = ray_box(ray.origin, ray.dir, lo, hi)?;
        let step = step.max((hi - lo).max_element() / 4096.0);
        let mut t = t0.max(0.0);
        let mut prev = t;
        while t <= t1 {
            if self.inside(ray.at(t)) {
                // Refine between the last outside sample and this one.
                let (mut a, mut b) = (prev, t);
                for _ in 0..20 {
                    let m = 0.5 * (a + b);
                    if self.inside(ray.at(m)) { b = m } else { a = m }
                }
                return Some(ray.at(b));
            }
            prev = t;
            t += step;
        }
        None
    }
}

/// Slab test: entry and exit parameters of a ray through a box.
pub fn ray_box(origin: Vec3, dir: Vec3, lo: Vec3, hi: Vec3) -> Option<(f32, f32)> {
    let inv = dir.recip();
    let (a, b) = ((lo - origin) * inv, (hi - origin) * inv);
    let (tmin, tmax) = (a.min(b), a.max(b));
    let (t0, t1) = (tmin.max_element(), tmax.min_element());
    (t1 >= t0.max(0.0)).then_some((t0, t1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Ray;
    use glam::Quat;

    /// The four-lane forms give each lane the scalar form's bits, for turned, thin, strong and
    /// carving ellipsoids near and far from the origin (a lane off by one ulp would make the
    /// mesh export's bake differ from the whole bake).
    #[test]
    fn four_lanes_give_the_scalar_bits() {
        let mut rng = crate::seeded::SplitMix::new(44);
        let mut u = || rng.next_f64() as f32;
        let mut inside = 0;
        for n in 0..400 {
            let offset = [Vec3::ZERO, Vec3::new(2000.0, -1500.0, 1800.0)][n % 2];
            let mut e = Ellipsoid::new(
                offset + Vec3::new(u(), u(), u()) * 4.0,
                Vec3::new(0.05 + u() * 2.0, 0.02 + u() * 0.5, 0.1 + u()),
            );
            e.rotation = Quat::from_euler(glam::EulerRot::XYZ, u() * 6.3, u() * 6.3, u() * 6.3);
            e.strength = u() * 3.0 - 1.0;
            let rows = Blob::ellipsoid(&e).rows();
            // Within ±1.5 of the centre: most lanes inside the influence, some beyond it.
            let near = |v: f32| v * 3.0 - 1.5;
            let c = e.center;
            let y = Vec4::new(u(), u(), u(), u()).map(near) + c.y;
            let z = near(u()) + c.z;
            let x = Vec4::new(u(), u(), u(), u()).map(near) + c.x;
            for (l, line) in rows.at4(y, z).into_iter().enumerate() {
                let one = rows.at(y[l], z);
                assert_eq!(
                    (line.t.to_bits(), line.c.to_bits()),
                    (one.t.to_bits(), one.c.to_bits())
                );
                let four = line.value4(x);
                for k in 0..4 {
                    assert_eq!(
                        four[k].to_bits(),
                        one.value(x[k]).to_bits(),
                        "{n}: lane {k}"
                    );
                    inside += (four[k] != 0.0) as u32;
                }
            }
        }
        assert!(inside > 500, "only {inside} lanes inside an influence");
    }

    #[test]
    fn kernel_is_calibrated_to_the_visible_radius() {
        assert_eq!(wyvill(0.0), 1.0);
        assert!((wyvill(0.25) - ISO).abs() < 1e-6);
        assert_eq!(wyvill(1.0), 0.0);
        // Monotone decreasing.
        let mut prev = 2.0;
        for i in 0..=100 {
            let v = wyvill(i as f32 / 100.0);
            assert!(v <= prev);
            prev = v;
        }
        let b = Blob::sphere(Vec3::new(1.0, 2.0, 3.0), 1.7);
        for dir in [Vec3::X, Vec3::NEG_Y, Vec3::new(1.0, 1.0, 1.0).normalize()] {
            assert!((b.value(b.center + dir * 1.7) - ISO).abs() < 1e-5);
        }
    }

    #[test]
    fn ellipsoid_surface_lies_on_its_radii_even_rotated() {
        let e = Ellipsoid {
            center: Vec3::new(0.5, 1.0, -2.0),
            radii: Vec3::new(3.0, 1.0, 2.0),
            rotation: Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.3),
            ..Default::default()
        };
        let b = Blob::ellipsoid(&e);
        for (axis, r) in [(Vec3::X, 3.0), (Vec3::Y, 1.0), (Vec3::Z, 2.0)] {
            let p = e.center + e.rotation * axis * r;
            assert!((b.value(p) - ISO).abs() < 1e-4, "{axis}");
        }
        let f = Field::of_blobs(vec![b]);
        let (lo, hi) = f.bounds().unwrap();
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let p = e.center + e.rotation * axis * [3.0, 1.0, 2.0][axis.abs().max_position()];
            assert!(p.cmpge(lo).all() && p.cmple(hi).all());
        }
    }

    #[test]
    fn blending_grows_the_union() {
        let a = Blob::sphere(Vec3::ZERO, 1.0);
        let b = Blob::sphere(Vec3::new(2.2, 0.0, 0.0), 1.0);
        let f = Field::of_blobs(vec![a, b]);
        // The midpoint is outside both spheres alone but the blend bridges them.
        assert!(f.inside(Vec3::new(1.1, 0.0, 0.0)));
    }

    #[test]
    fn clip_removes_below_its_line_within_its_footprint() {
        let clip = Clip {
            origin: Vec3::ZERO,
            right: Vec3::X,
            up: Vec3::Y,
            line: vec![Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.5)],
        };
        assert!(clip.removes(Vec3::new(0.0, 0.2, 5.0)));
        assert!(!clip.removes(Vec3::new(0.0, 0.3, 0.0)));
        assert!(
            !clip.removes(Vec3::new(2.0, -10.0, 0.0)),
            "outside the footprint"
        );
        let f = Field {
            blobs: vec![Blob::sphere(Vec3::ZERO, 1.0)],
            groups: vec![],
            clips: vec![clip],
            ..Default::default()
        };
        assert!(!f.inside(Vec3::new(0.0, -0.5, 0.0)));
        assert!(f.inside(Vec3::new(0.0, 0.5, 0.0)));
    }

    #[test]
    fn raycast_finds_the_surface() {
        let f = Field::of_blobs(vec![Blob::sphere(Vec3::ZERO, 2.0)]);
        let ray = Ray {
            origin: Vec3::new(0.0, 0.0, 10.0),
            dir: Vec3::NEG_Z,
        };
        let hit = f.raycast(&ray, 0.05).unwrap();
        assert!((hit.z - 2.0).abs() < 1e-3, "{hit}");
        let miss = Ray {
            origin: Vec3::new(5.0, 0.0, 10.0),
            dir: Vec3::NEG_Z,
        };
        assert!(f.raycast(&miss, 0.05).is_none());
        assert!(Field::default().raycast(&ray, 0.05).is_none());
    }
}
