//! How deep a point lies inside a sketched outline, seen along its drawing plane's normal: a
//! small raster of the outline's inside distance, made once per outline. The blend between an
//! outline's spheres softens only where this depth is positive, so the silhouette from the
//! drawing view stays the drawn outline while creases inside it are smoothed.

use glam::{DVec2, Quat, Vec2, Vec3};

use crate::sketch::outline::{boundary_distance, contains};

/// Cells along the raster's longer side.
const CELLS: u32 = 64;

/// Inside distance of an outline on a raster in its plane's coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct InsideMap {
    /// Plane coordinates of cell (0, 0)'s centre.
    lo: Vec2,
    /// Cell side (plane units).
    cell: f32,
    /// Cells per axis.
    size: [u32; 2],
    /// Distance to the outline inside it (plane units), 0 outside; x fastest.
    depth: Vec<f32>,
    /// The outline's longer side (plane units).
    pub extent: f32,
}

impl InsideMap {
    /// The map of a simple polygon in plane coordinates (`None` for fewer than 3 points).
    pub fn new(outline: &[DVec2]) -> Option<Self> {
        if outline.len() < 3 {
            return None;
        }
        let (lo, hi) = outline
            .iter()
            .fold((DVec2::MAX, DVec2::MIN), |(a, b), &p| (a.min(p), b.max(p)));
        let extent = (hi - lo).max_element().max(1e-6);
        let cell = extent / (CELLS - 1) as f64;
        let size = [
            (((hi.x - lo.x) / cell).ceil() as u32 + 1).max(2),
            (((hi.y - lo.y) / cell).ceil() as u32 + 1).max(2),
        ];
        let mut depth = Vec::with_capacity((size[0] * size[1]) as usize);
        for j in 0..size[1] {
            for i in 0..size[0] {
                let q = lo + DVec2::new(i as f64, j as f64) * cell;
                let d = if contains(outline, q) {
                    boundary_distance(q, outline)
                } else {
                    0.0
                };
                depth.push(d as f32);
            }
        }
        Some(Self {
            lo: lo.as_vec2(),
            cell: cell as f32,
            size,
            depth,
            extent: extent as f32,
        })
    }

    /// Inside distance at plane point `q` (bilinear; 0 off the raster).
    pub fn depth_at(&self, q: Vec2) -> f32 {
        let t = (q - self.lo) / self.cell;
        let [w, h] = self.size;
        if t.x < 0.0 || t.y < 0.0 || t.x > (w - 1) as f32 || t.y > (h - 1) as f32 {
            return 0.0;
        }
        let (i, j) = ((t.x as u32).min(w - 2), (t.y as u32).min(h - 2));
        let (fx, fy) = (t.x - i as f32, t.y - j as f32);
        let at = |i: u32, j: u32| self.depth[(j * w + i) as usize];
        let bottom = at(i, j) * (1.0 - fx) + at(i + 1, j) * fx;
        let top = at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx;
        bottom * (1.0 - fy) + top * fy
    }
}

/// An outline's inside map placed in the world by its drawing plane.
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedInside {
    /// The map.
    pub map: std::sync::Arc<InsideMap>,
    /// The plane's origin.
    pub origin: Vec3,
    /// World → plane turn (the plane's rotation inverted).
    pub to_plane: Quat,
}

impl PlacedInside {
    /// Inside distance of world point `p`'s projection along the plane's normal.
    pub fn depth(&self, p: Vec3) -> f32 {
        self.map
            .depth_at((self.to_plane * (p - self.origin)).truncate())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_is_the_distance_inside_and_zero_outside() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(0.0, 4.0),
        ];
        let m = InsideMap::new(&square).unwrap();
        assert!((m.depth_at(Vec2::new(2.0, 2.0)) - 2.0).abs() < 0.05);
        assert!((m.depth_at(Vec2::new(1.0, 2.0)) - 1.0).abs() < 0.05);
        assert!(m.depth_at(Vec2::new(0.01, 2.0)) < 0.07);
        assert_eq!(m.depth_at(Vec2::new(-1.0, 2.0)), 0.0);
        assert_eq!(m.depth_at(Vec2::new(9.0, 9.0)), 0.0);
        // Placed on a plane turned a quarter about y, through (10, 0, 0).
        let placed = PlacedInside {
            map: std::sync::Arc::new(m),
            origin: Vec3::new(10.0, 0.0, 0.0),
            to_plane: Quat::from_rotation_y(std::f32::consts::FRAC_PI_2).inverse(),
        };
        // Plane x is world −z there; the point's offset along the normal does not matter.
        let p = Vec3::new(10.0 + 7.0, 2.0, -2.0);
        assert!((placed.depth(p) - 2.0).abs() < 0.05, "{}", placed.depth(p));
    }
}
