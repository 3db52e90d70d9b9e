//! Sketch modelling (Wither, Bouthors & Cani 2008): a drawn outline becomes spheres.
//!
//! Pure core, no GPU or UI types. Pipeline: [`outline::clean`] (repair, simplify, resample) →
//! [`skeleton::chordal_axis`] (constrained Delaunay triangulation, chordal axis, pruning) →
//! [`spheres::sample`] (maximal balls along the skeleton) → [`spheres::inflate`] (r_f and the
//! inflation slider) → [`spheres::extend`] (automatic 3D extension). Coordinates are the
//! stroke's own 2D units; the spheres' z axis points toward the viewer.

pub mod outline;
pub mod skeleton;
pub mod spheres;

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::limits;

pub use outline::Outline;
pub use skeleton::Skeleton;
pub use spheres::Sphere;

/// The smallest extent (the bounding box's larger side) a stroke may have, in its own units.
pub const MIN_EXTENT: f64 = 1e-9;
/// The largest extent a stroke may have.
pub const MAX_EXTENT: f64 = 1e12;

/// Why a stroke cannot become a cloud.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SketchError {
    /// Fewer than three usable points.
    #[error("the stroke needs at least 3 distinct points to outline a cloud (it has {0})")]
    TooFewPoints(usize),
    /// A line, a dot or a scribble with no inside.
    #[error("the stroke encloses no area: draw a closed outline around the cloud")]
    NoArea,
    /// So many self-crossings that the repair ran out of its budget before finding any loop.
    #[error("the stroke crosses itself too often to find its outline: draw it with fewer loops")]
    TooTangled,
    /// Too large or too small to draw with: its extent is outside [`MIN_EXTENT`, `MAX_EXTENT`].
    #[error("the stroke spans {0:e} units: a stroke spans {MIN_EXTENT:e} to {MAX_EXTENT:e}")]
    OutOfRange(f64),
    /// The triangulation refused the outline (should not happen after cleaning).
    #[error("could not triangulate the outline: {0}")]
    Triangulation(String),
}

/// The user's parameters of one sketched outline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SketchParams {
    /// Simplification tolerance as a fraction of the outline's size (0 keeps every wiggle).
    pub simplify: f64,
    /// Branches covering less than this fraction of the outline's area are pruned.
    pub prune: f64,
    /// Inflation slider t in [0, 1]: 0 keeps the maximal balls, 1 shrinks big ones to r_f.
    pub inflate: f64,
    /// Automatic 3D extension on or off.
    pub extend: bool,
    /// Copies of each terminal branch placed around the trunk by the extension.
    pub copies: u32,
    /// Width of the smooth maximum between the spheres inside the outline (the field's
    /// [`crate::field::Group`]; it does not change the spheres).
    pub blend: f64,
}

impl Default for SketchParams {
    fn default() -> Self {
        Self {
            simplify: limits::SIMPLIFY.default,
            prune: limits::PRUNE.default,
            inflate: limits::INFLATE.default,
            extend: true,
            copies: limits::COPIES.default as u32,
            blend: limits::BLEND.default,
        }
    }
}

impl SketchParams {
    /// Clamps every value into its range (documents and links may carry anything).
    pub fn sanitize(&mut self) {
        self.simplify = limits::SIMPLIFY.fix(self.simplify);
        self.prune = limits::PRUNE.fix(self.prune);
        self.inflate = limits::INFLATE.fix(self.inflate);
        self.copies = limits::COPIES.fix_u32(self.copies);
        self.blend = limits::BLEND.fix(self.blend);
    }
}

/// Everything derived from one outline.
#[derive(Clone, Debug)]
pub struct Sketch {
    /// The cleaned outline.
    pub outline: Outline,
    /// Its pruned chordal axis.
    pub skeleton: Skeleton,
    /// The minimal feature radius r_f.
    pub feature_radius: f64,
    /// Final spheres (after inflation and, when on, the 3D extension).
    pub spheres: Vec<Sphere>,
    /// Repairs made to the input, in words.
    pub warnings: Vec<String>,
}

/// Interprets a stroke (points in any 2D units) as a cloud outline.
pub fn interpret(
    points: &[[f64; 2]],
    closed: bool,
    params: &SketchParams,
    seed: u64,
) -> Result<Sketch, SketchError> {
    let mut params = params.clone();
    params.sanitize();
    // Work around the stroke's centre so far-off coordinates keep their precision.
    let centre = points
        .iter()
        .map(|&[x, y]| DVec2::new(x, y))
        .filter(|p| p.is_finite())
        .fold((DVec2::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
    let centre = if centre.1 > 0 {
        centre.0 / centre.1 as f64
    } else {
        DVec2::ZERO
    };
    let local: Vec<[f64; 2]> = points
        .iter()
        .map(|&[x, y]| [x - centre.x, y - centre.y])
        .collect();

    let mut outline = outline::clean(&local, closed, params.simplify)?;
    let skeleton = skeleton::chordal_axis(&outline, params.prune)?;
    let mut spheres = spheres::sample(&outline, &skeleton);
    if spheres.is_empty() {
        return Err(SketchError::NoArea);
    }
    let feature_radius = spheres::feature_radius(&spheres);
    spheres::inflate(
        &outline.boundary,
        &mut spheres,
        feature_radius,
        params.inflate,
    );
    if params.extend {
        spheres = spheres::extend(&outline, &skeleton, &spheres, seed, params.copies as usize);
    }
    let warnings = std::mem::take(&mut outline.warnings);
    // Back to the caller's coordinates.
    let shift = centre.extend(0.0);
    outline.translate(centre);
    let mut skeleton = skeleton;
    for n in &mut skeleton.nodes {
        n.pos += centre;
    }
    for s in &mut spheres {
        s.center += shift;
    }
    Ok(Sketch {
        outline,
        skeleton,
        feature_radius,
        spheres,
        warnings,
    })
}

/// A cut stroke's line: the drawn points made x-monotone (sorted by x, one height per x), so
/// "below the line" is well defined. Needs two points spanning some width.
pub fn cut_line(points: &[[f64; 2]]) -> Result<Vec<DVec2>, SketchError> {
    let mut pts: Vec<DVec2> = points
        .iter()
        .map(|&[x, y]| DVec2::new(x, y))
        .filter(|p| p.is_finite())
        .collect();
    if pts.len() > outline::MAX_STROKE_POINTS {
        let step = pts.len() / outline::MAX_STROKE_POINTS + 1;
        pts = pts.into_iter().step_by(step).collect();
    }
    if pts.len() < 2 {
        return Err(SketchError::TooFewPoints(pts.len()));
    }
    pts.sort_by(|a, b| a.x.total_cmp(&b.x));
    let width = pts[pts.len() - 1].x - pts[0].x;
    if width.is_nan() || width <= 0.0 {
        return Err(SketchError::NoArea);
    }
    // Average runs of (almost) equal x into one point.
    let eps = width * 1e-4;
    let mut out: Vec<(DVec2, f64)> = Vec::new();
    for p in pts {
        match out.last_mut() {
            Some((q, n)) if (p.x - q.x / *n).abs() <= eps => {
                *q += p;
                *n += 1.0;
            }
            _ => out.push((p, 1.0)),
        }
    }
    Ok(out.into_iter().map(|(q, n)| q / n).collect())
}

#[cfg(test)]
mod tests;
