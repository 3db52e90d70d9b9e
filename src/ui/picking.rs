//! What is under the pointer or inside a dragged box: drawing planes by their strokes,
//! ellipsoids by their indicators or by the cloud they shape. Used by clicks (Shift adds to
//! the selection) and box selection.

use egui::{Pos2, Rect};
use glam::Vec3;

use super::ellipsoids;
use super::projection::project;
use super::selection::Item;
use crate::derive::Derived;
use crate::scene::{Document, Ellipsoid, OrbitCamera, StrokeKind};
use crate::sketch::outline;

/// How near (pixels) a click must come to an indicator's line to pick its ellipsoid.
const INDICATOR_PX: f32 = 6.0;

/// An ellipsoid's indicator on screen: its three principal ellipses as polylines.
pub fn indicator(camera: &OrbitCamera, rect: Rect, e: &Ellipsoid) -> [Vec<Pos2>; 3] {
    const N: usize = 48;
    [(Vec3::X, Vec3::Y), (Vec3::Y, Vec3::Z), (Vec3::Z, Vec3::X)].map(|(a, b)| {
        (0..=N)
            .filter_map(|k| {
                let t = k as f32 / N as f32 * std::f32::consts::TAU;
                let local = (a * t.cos() + b * t.sin()) * e.radii;
                project(camera, rect, e.center + e.rotation * local)
            })
            .collect()
    })
}

/// Distance from screen point `p` to segment `ab`.
pub fn segment_distance(p: Pos2, a: Pos2, b: Pos2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_sq().max(1e-6)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// The ellipsoid whose indicator passes nearest `p` (within a few pixels).
pub fn indicator_at(doc: &Document, rect: Rect, p: Pos2) -> Option<usize> {
    let camera = &doc.scene().camera;
    doc.scene()
        .ellipsoids
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let d = indicator(camera, rect, e)
                .iter()
                .flat_map(|line| line.windows(2).map(|w| segment_distance(p, w[0], w[1])))
                .fold(f32::INFINITY, f32::min);
            (d < INDICATOR_PX).then_some((d, i))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, i)| i)
}

/// The item a click at `p` picks: a drawing plane whose stroke is under it, an ellipsoid whose
/// indicator it touches (when indicators are shown: noise can hide a primitive), else the
/// ellipsoid that shapes the cloud there.
pub fn item_at(
    doc: &Document,
    derived: &mut Derived,
    rect: Rect,
    p: Pos2,
    indicators: bool,
) -> Option<Item> {
    if let Some(i) = plane_at(doc, rect, p) {
        return Some(Item::Plane(i));
    }
    if indicators && let Some(i) = indicator_at(doc, rect, p) {
        return Some(Item::Ellipsoid(i));
    }
    ellipsoids::pick(doc, derived, rect, p).map(Item::Ellipsoid)
}

/// Every item whose centre appears inside `area` (an ellipsoid's centre, the centre of a
/// plane's stroke), in document order.
pub fn items_in(doc: &Document, rect: Rect, area: Rect) -> Vec<Item> {
    let scene = doc.scene();
    let camera = &scene.camera;
    let inside = |p: Vec3| project(camera, rect, p).is_some_and(|q| area.contains(q));
    let planes = scene.planes.iter().enumerate().filter_map(|(i, plane)| {
        let n = plane.points.len().max(1) as f32;
        let centre = plane.points.iter().fold(glam::Vec2::ZERO, |a, &p| a + p) / n;
        inside(plane.to_world(centre.extend(0.0))).then_some(Item::Plane(i))
    });
    let ellipsoids = (scene.ellipsoids.iter().enumerate())
        .filter_map(|(i, e)| inside(e.center).then_some(Item::Ellipsoid(i)));
    planes.chain(ellipsoids).collect()
}

/// The drawing plane whose stroke encloses screen point `p` (outlines by their inside, cuts
/// within a few pixels of their line), the nearest to the camera when several do.
pub fn plane_at(doc: &Document, rect: Rect, p: Pos2) -> Option<usize> {
    let camera = &doc.scene().camera;
    let eye = camera.eye();
    let mut best: Option<(f32, usize)> = None;
    for (i, plane) in doc.scene().planes.iter().enumerate() {
        // Screen points in f64, for the sketch core's polygon helpers.
        let pts: Vec<glam::DVec2> = plane
            .points
            .iter()
            .filter_map(|q| project(camera, rect, plane.to_world(q.extend(0.0))))
            .map(|q| glam::DVec2::new(q.x as f64, q.y as f64))
            .collect();
        if pts.len() < 2 {
            continue;
        }
        let at = glam::DVec2::new(p.x as f64, p.y as f64);
        let hit = match plane.kind {
            StrokeKind::Outline => outline::contains(&pts, at),
            StrokeKind::Cut => pts
                .windows(2)
                .any(|w| outline::segment_distance(at, w[0], w[1]) < 6.0),
        };
        let depth = plane.origin.distance(eye);
        if hit && best.is_none_or(|(d, _)| depth < d) {
            best = Some((depth, i));
        }
    }
    best.map(|(_, i)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Preset, Scene};

    use crate::ui::test_view as view;

    #[test]
    fn an_indicator_line_picks_its_ellipsoid_and_a_box_takes_what_it_holds() {
        let doc = Document::new(Scene::preset(Preset::Cumulus));
        let camera = &doc.scene().camera;
        let e = &doc.scene().ellipsoids[2];
        // A point on its horizontal ellipse, at the end of its x radius.
        let on_line = project(camera, view(), e.center + e.rotation * Vec3::X * e.radii.x).unwrap();
        assert_eq!(indicator_at(&doc, view(), on_line), Some(2));
        assert_eq!(indicator_at(&doc, view(), Pos2::new(5.0, 5.0)), None);
        // A box round that ellipsoid's centre only.
        let c = project(camera, view(), e.center).unwrap();
        let area = Rect::from_center_size(c, egui::vec2(4.0, 4.0));
        assert_eq!(items_in(&doc, view(), area), vec![Item::Ellipsoid(2)]);
        // The whole view holds every ellipsoid.
        assert_eq!(
            items_in(&doc, view(), view()).len(),
            doc.scene().ellipsoids.len()
        );
    }
}
