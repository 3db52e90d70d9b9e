//! Drawing planes (Wither et al. §2): each sketched stroke lives on its own plane in the scene.
//! The plane stores the stroke and its parameters; spheres are derived from them.

use glam::{DVec2, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};

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
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pressure: Vec<f32>,
    /// Hidden: kept in the document, left out of the cloud (its stroke is drawn faintly).
    pub hidden: bool,
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
        plane
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
        Ok(())
    }
}

/// Bounding box centre of plane points (used to re-centre imported strokes).
pub fn centre_of(points: &[DVec2]) -> DVec2 {
    let (lo, hi) = points.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(a, b), &q| (a.min(q), b.max(q)),
    );
    (lo + hi) * 0.5
}
