//! What each drawing plane contributes, cached per plane: a new stroke interprets only its own
//! plane, a slider on one plane re-derives only that plane, and moving or turning a plane
//! re-interprets nothing (its spheres live in the plane's own coordinates).

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::Arc;

use glam::Vec2;

use crate::field::InsideMap;
use crate::scene::{DrawingPlane, StrokeKind};
use crate::sketch::{SketchError, Sphere};

/// A plane's contribution in its own coordinates (x right, y up, z along its normal).
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// An outline's final spheres, and the repairs made to its stroke in words.
    Outline {
        /// Spheres in plane coordinates.
        spheres: Vec<Sphere>,
        /// How deep each plane point lies inside the outline (where the blend may act).
        inside: Option<Arc<InsideMap>>,
        /// The pruned chordal axis, as segments in plane coordinates (for the overlay).
        skeleton: Vec<[Vec2; 2]>,
        /// Repairs made to the stroke.
        warnings: Vec<String>,
    },
    /// A cut's line, sorted by x.
    Cut(Vec<Vec2>),
    /// A stroke that cannot be used, and why.
    Unusable(SketchError),
}

/// Identifies what a plane's shape depends on: its stroke, kind and sketch parameters and seed
/// (not its placement).
fn shape_key(plane: &DrawingPlane) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (plane.kind == StrokeKind::Outline).hash(&mut h);
    plane.closed.hash(&mut h);
    plane.seed.hash(&mut h);
    let s = &plane.sketch;
    for v in [s.simplify, s.prune, s.inflate] {
        v.to_bits().hash(&mut h);
    }
    (s.extend, s.copies).hash(&mut h);
    plane.points.len().hash(&mut h);
    for p in &plane.points {
        (p.x.to_bits(), p.y.to_bits()).hash(&mut h);
    }
    h.finish()
}

fn interpret(plane: &DrawingPlane) -> Shape {
    match plane.kind {
        StrokeKind::Outline => {
            match crate::sketch::interpret(&plane.stroke(), plane.closed, &plane.sketch, plane.seed)
            {
                Ok(sketch) => Shape::Outline {
                    inside: InsideMap::new(&sketch.outline.points).map(Arc::new),
                    skeleton: sketch
                        .skeleton
                        .segments
                        .iter()
                        .map(|&[a, b]| {
                            let node = |i: usize| sketch.skeleton.nodes[i].pos.as_vec2();
                            [node(a), node(b)]
                        })
                        .collect(),
                    spheres: sketch.spheres,
                    warnings: sketch.warnings,
                },
                Err(e) => Shape::Unusable(e),
            }
        }
        StrokeKind::Cut => match crate::sketch::cut_line(&plane.stroke()) {
            Ok(line) => Shape::Cut(line.into_iter().map(|p| p.as_vec2()).collect()),
            Err(e) => Shape::Unusable(e),
        },
    }
}

/// The per-plane cache.
#[derive(Default)]
pub struct PlaneCache {
    /// Shapes by key, with the pass that last used them.
    shapes: HashMap<u64, (Arc<Shape>, u64)>,
    /// Keys of planes seen, by allocation (the `Arc` is held so its address is not reused).
    keys: HashMap<usize, (Arc<DrawingPlane>, u64)>,
    pass: u64,
    interpretations: u64,
}

impl PlaneCache {
    /// The shape of every plane, interpreting only planes whose stroke or sketch parameters
    /// are new. Shapes of the previous pass stay cached too, so undoing an edit is instant.
    pub fn shapes(&mut self, planes: &[Arc<DrawingPlane>]) -> Vec<Arc<Shape>> {
        self.pass += 1;
        let pass = self.pass;
        let mut out = Vec::with_capacity(planes.len());
        for plane in planes {
            let ptr = Arc::as_ptr(plane) as usize;
            let key = match self.keys.get(&ptr) {
                Some((_, key)) => *key,
                None => {
                    let key = shape_key(plane);
                    self.keys.insert(ptr, (plane.clone(), key));
                    key
                }
            };
            let entry = self.shapes.entry(key).or_insert_with(|| {
                self.interpretations += 1;
                (Arc::new(interpret(plane)), pass)
            });
            entry.1 = pass;
            out.push(entry.0.clone());
        }
        // Keep this pass's and the previous pass's shapes; forget planes no longer held.
        self.shapes.retain(|_, (_, used)| *used + 1 >= pass);
        let current: std::collections::HashSet<usize> =
            planes.iter().map(|p| Arc::as_ptr(p) as usize).collect();
        let shapes = &self.shapes;
        self.keys
            .retain(|ptr, (_, key)| current.contains(ptr) || shapes.contains_key(key));
        out
    }

    /// The shape of one plane, through the cache (a plane about to be added is interpreted
    /// here once, and found again when the document holding it is derived).
    pub fn shape(&mut self, plane: &DrawingPlane) -> Arc<Shape> {
        let key = shape_key(plane);
        let pass = self.pass;
        let entry = self.shapes.entry(key).or_insert_with(|| {
            self.interpretations += 1;
            (Arc::new(interpret(plane)), pass)
        });
        entry.1 = entry.1.max(pass);
        entry.0.clone()
    }

    /// The shape last derived for this plane of the document, if any (no interpretation: a
    /// lookup by the plane's allocation, cheap enough for every frame of the UI).
    pub fn derived(&self, plane: &Arc<DrawingPlane>) -> Option<Arc<Shape>> {
        let (_, key) = self.keys.get(&(Arc::as_ptr(plane) as usize))?;
        self.shapes.get(key).map(|(shape, _)| shape.clone())
    }

    /// Strokes interpreted since the cache was made (for tests and benchmarks).
    pub fn interpretations(&self) -> u64 {
        self.interpretations
    }
}
