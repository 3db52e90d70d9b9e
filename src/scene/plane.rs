//! Drawing planes (Wither et al. §2): each sketched stroke lives on its own plane in the scene.
//! The plane stores the stroke and its parameters; spheres are derived from them.

use glam::{DVec2, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};

use super::Billows;
use crate::limits::MAX_PLANE_POINTS;
use crate::sketch::SketchParams;

/// What a stroke means.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StrokeKind {
    /// A cloud outline: becomes spheres.
    #[default]
    Outline,
    /// A cut: nothing of the cloud survives below its line (the flat base of cumulus).
    Cut,
}

/// A plane in the scene holding one stroke.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DrawingPlane {
    /// Name shown in the plane list.
    pub name: String,
    /// Outline or cut.
    pub kind: StrokeKind,
    /// The plane's origin in the world (the stroke's points are relative to it).
    pub origin: Vec3,
    /// Orientation: the plane's x (right) and y (up) axes are this rotation of the world's
    /// x and y; its normal (toward the viewer who drew it) is the rotated z.
    pub rotation: Quat,
    /// Stroke points in plane units (world units, y up).
    #[serde(deserialize_with = "super::capped::vec::<_, _, MAX_PLANE_POINTS>")]
    pub points: Vec<Vec2>,
    /// Whether the stroke was drawn closed.
    pub closed: bool,
    /// Sketch parameters (simplification, pruning, inflation, 3D extension).
    pub sketch: SketchParams,
    /// Seed of the 3D extension's random choices.
    pub seed: u64,
    /// Pen pressure (0–1) at each point of `points`, for strokes drawn with a pen; empty for
    /// the mouse, touch and imported strokes. Kept with the stroke (for future brushes); the
    /// shape does not depend on it yet.
    #[serde(
        skip_serializing_if = "Vec::is_empty",
        deserialize_with = "super::capped::vec::<_, _, MAX_PLANE_POINTS>"
    )]
    pub pressure: Vec<f32>,
    /// Hidden: kept in the document, left out of the cloud (its stroke is drawn faintly).
    pub hidden: bool,
    /// Stable id, unique among the document's ellipsoids and planes (0: not yet given one;
    /// [`super::Scene::settle`]). Seeds the billows.
    #[serde(skip_serializing_if = "is_zero")]
    pub id: u64,
    /// Puffs on the outline's spheres.
    #[serde(skip_serializing_if = "Billows::is_unset")]
    pub billows: Billows,
}

fn is_zero(v: &u64) -> bool {
    *v == 0
}

impl Default for DrawingPlane {
    fn default() -> Self {
        Self {
            name: String::new(),
            kind: StrokeKind::Outline,
            origin: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            points: Vec::new(),
            closed: true,
            sketch: SketchParams::default(),
            seed: 1,
            pressure: Vec::new(),
            hidden: false,
            id: 0,
            billows: Billows::default(),
        }
    }
}

impl DrawingPlane {
    /// World position of a point in plane coordinates (z along the normal).
    pub fn to_world(&self, p: Vec3) -> Vec3 {
        self.origin + self.rotation * p
    }

    /// Plane x axis in the world.
    pub fn right(&self) -> Vec3 {
        self.rotation * Vec3::X
    }

    /// Plane y axis in the world.
    pub fn up(&self) -> Vec3 {
        self.rotation * Vec3::Y
    }

    /// Plane normal in the world.
    pub fn normal(&self) -> Vec3 {
        self.rotation * Vec3::Z
    }

    /// The stroke as f64 pairs for the sketch pipeline.
    pub fn stroke(&self) -> Vec<[f64; 2]> {
        self.points
            .iter()
            .map(|p| [p.x as f64, p.y as f64])
            .collect()
    }

    /// Plane coordinates of a world point projected onto the plane.
    pub fn to_plane(&self, p: Vec3) -> Vec2 {
        let d = self.rotation.inverse() * (p - self.origin);
        Vec2::new(d.x, d.y)
    }

    /// A plane through `origin` facing the viewer of a camera with the given right/up axes,
    /// holding `world_points` (which should lie on it), re-centred on their centroid.
    pub fn facing(
        name: String,
        kind: StrokeKind,
        origin: Vec3,
        right: Vec3,
        up: Vec3,
        world_points: &[Vec3],
        seed: u64,
    ) -> Self {
        let normal = right.cross(up).normalize_or(Vec3::Z);
        let rotation = Quat::from_mat3(&glam::Mat3::from_cols(
            right.normalize_or(Vec3::X),
            normal.cross(right).normalize_or(Vec3::Y),
            normal,
        ));
        let mut plane = Self {
            name,
            kind,
            origin,
            rotation,
            points: Vec::new(),
            closed: kind == StrokeKind::Outline,
            sketch: SketchParams::default(),
            seed,
            ..Default::default()
        };
        let local: Vec<Vec2> = world_points.iter().map(|&p| plane.to_plane(p)).collect();
        let centre = if local.is_empty() {
            Vec2::ZERO
        } else {
            local.iter().copied().sum::<Vec2>() / local.len() as f32
        };
        plane.origin = plane.to_world(centre.extend(0.0));
        plane.points = local.into_iter().map(|p| p - centre).collect();
        plane.snap_to_grid();
        plane
    }

    /// Moves the stroke's points onto its grid ([`STROKE_GRID`]): done once when a stroke is
    /// made, so files and links hold it exactly.
    pub fn snap_to_grid(&mut self) {
        if self.points.iter().all(|p| p.is_finite()) {
            let e = grid_exponent(&self.points);
            self.points = grid_points(&self.points, e)
                .into_iter()
                .map(|k| grid_point(k, e))
                .collect();
        }
    }

    pub(super) fn validate(&mut self, index: usize) -> Result<(), String> {
        if self.points.len() > MAX_PLANE_POINTS {
            return Err(format!(
                "plane {index} has {} points (at most {MAX_PLANE_POINTS})",
                self.points.len()
            ));
        }
        if !(self.origin.is_finite()
            && self.rotation.is_finite()
            && self.points.iter().all(|p| p.is_finite()))
        {
            return Err(format!("plane {index} has a non-finite value"));
        }
        if let Some(r) = super::unit_rotation(self.rotation) {
            self.rotation = r;
        }
        if !self.pressure.is_empty() && self.pressure.len() != self.points.len() {
            self.pressure.clear(); // does not match its stroke: dropped (and reported)
        }
        for v in &mut self.pressure {
            *v = if v.is_nan() { 0.5 } else { v.clamp(0.0, 1.0) };
        }
        self.sketch.sanitize();
        self.billows.sanitize();
        Ok(())
    }
}

/// Steps across a stroke's larger side, at most, of the grid strokes are stored on: new
/// strokes are snapped to it ([`DrawingPlane::snap_to_grid`]), and share links store points as
/// steps of it, so a link reproduces a stroke exactly. A point moves by at most half a step:
/// under 1/880 of the stroke's larger side, under half a pixel for an outline drawn up to
/// 440 px across (pointer events report whole pixels).
pub const STROKE_GRID: f64 = 480.0;

/// Largest grid step exponent either way (eighths of an octave: steps of 2^±60).
pub const MAX_GRID_EXPONENT: i64 = 480;

/// Largest coordinate in grid steps.
pub const MAX_GRID_STEPS: i64 = 1 << 30;

/// 2^(i/8) for i in 0..8, written out so every platform computes the same steps.
const EIGHTHS: [f64; 8] = [
    1.0,
    1.090_507_732_665_257_7,
    1.189_207_115_002_721,
    1.296_839_554_651_009_7,
    std::f64::consts::SQRT_2,
    1.542_210_825_407_940_7,
    1.681_792_830_507_429,
    1.834_008_086_409_342_4,
];

/// The stroke grid's step for an exponent in eighths of an octave: 2^(e/8).
pub fn grid_step(e: i64) -> f64 {
    2f64.powi(e.div_euclid(8) as i32) * EIGHTHS[e.rem_euclid(8) as usize]
}

/// A coordinate in steps of `step`.
fn steps(x: f32, step: f64) -> i64 {
    (x as f64 / step).round() as i64
}

/// The grid exponent for a stroke: one its points already lie on when there is one near (a
/// snapped stroke), else the finest whose steps across the larger side are at most
/// [`STROKE_GRID`] and whose coordinates fit [`MAX_GRID_STEPS`].
pub fn grid_exponent(points: &[Vec2]) -> i64 {
    let (lo, hi) = points.iter().fold(
        (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let extent = (hi - lo).max_element() as f64;
    let reach = lo.abs().max(hi.abs()).max_element() as f64;
    let mut e = if extent > 0.0 && extent.is_finite() {
        (8.0 * (extent / STROKE_GRID).log2()).floor() as i64
    } else {
        -192
    };
    e = e.clamp(-MAX_GRID_EXPONENT, MAX_GRID_EXPONENT);
    // Floating-point doubt at the boundary: step up until the side fits.
    while e < MAX_GRID_EXPONENT
        && (extent / grid_step(e) > STROKE_GRID
            || reach / grid_step(e) >= (MAX_GRID_STEPS / 2) as f64)
    {
        e += 1;
    }
    let on_grid = |e: i64| {
        let step = grid_step(e);
        points.iter().all(|p| {
            [p.x, p.y]
                .iter()
                .all(|&x| (steps(x, step) as f64 * step) as f32 == x)
        })
    };
    // Snapping can widen the stroke by a step, which may have moved it to the next grid, or
    // narrow it, which may have moved it to the one before: a stroke on either stays there.
    [e - 1, e, e + 1]
        .into_iter()
        .filter(|e| (-MAX_GRID_EXPONENT..=MAX_GRID_EXPONENT).contains(e))
        .find(|&e| on_grid(e))
        .unwrap_or(e)
}

/// A stroke's points in steps of its grid ([`grid_exponent`]).
pub fn grid_points(points: &[Vec2], e: i64) -> Vec<[i64; 2]> {
    let step = grid_step(e);
    points
        .iter()
        .map(|p| [steps(p.x, step), steps(p.y, step)])
        .collect()
}

/// The point at grid steps `k`.
pub fn grid_point(k: [i64; 2], e: i64) -> Vec2 {
    let step = grid_step(e);
    Vec2::new((k[0] as f64 * step) as f32, (k[1] as f64 * step) as f32)
}

/// Bounding box centre of plane points (used to re-centre imported strokes).
pub fn centre_of(points: &[DVec2]) -> DVec2 {
    let (lo, hi) = points.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(a, b), &q| (a.min(q), b.max(q)),
    );
    (lo + hi) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_snapped_stroke_stays_where_it_is_when_snapped_again() {
        // Snapping moves points by up to half a step, which can narrow or widen the stroke
        // across a grid boundary; a second snap (the next link's encoding) must move nothing.
        // Strokes of every size, their extents spread over many grid boundaries.
        let mut rng = crate::seeded::SplitMix::new(7);
        for case in 0..3000 {
            let scale = 10f64.powf(rng.next_f64() * 6.0 - 3.0) as f32;
            let n = 3 + (rng.next_u64() % 60) as usize;
            let points: Vec<Vec2> = (0..n)
                .map(|_| {
                    Vec2::new(rng.next_f64() as f32 - 0.5, rng.next_f64() as f32 - 0.3) * scale
                })
                .collect();
            let mut once = DrawingPlane {
                points,
                ..DrawingPlane::default()
            };
            once.snap_to_grid();
            let mut twice = once.clone();
            twice.snap_to_grid();
            assert_eq!(once.points, twice.points, "case {case}: scale {scale}");
        }
    }
}
