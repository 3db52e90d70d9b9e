//! What the tools draw over the view: every plane's stroke, the selected plane's grid, the
//! ellipsoids' indicators and (K) the selected outline's skeleton and spheres.

use egui::{Color32, Pos2, Rect, Stroke};
use glam::Vec2;

use crate::derive::{Derived, Shape};
use crate::scene::{Document, DrawingPlane, OrbitCamera, StrokeKind};
use crate::ui::picking;
use crate::ui::projection::project;
use crate::ui::selection::{Item, Selection};

/// Which guides are drawn.
pub struct Shown {
    /// Every ellipsoid's indicator (a modelling tool is out), not only the selected ones'.
    pub indicators: bool,
    /// Every plane's grid, not only the selected one's.
    pub all_planes: bool,
    /// The selected outline's skeleton and spheres.
    pub skeleton: bool,
}

/// The guides: indicators, grids, the skeleton and every plane's stroke.
pub fn guides(
    painter: &egui::Painter,
    rect: Rect,
    doc: &Document,
    derived: &Derived,
    selection: &Selection,
    shown: Shown,
) {
    let scene = doc.scene();
    let camera = &scene.camera;
    // Every ellipsoid's indicator while a modelling tool is out (noise can hide a primitive),
    // the selected one bright.
    for (i, e) in scene.ellipsoids.iter().enumerate() {
        let selected = selection.contains(Item::Ellipsoid(i));
        if selected || shown.indicators || shown.all_planes {
            draw_ellipsoid(painter, camera, rect, e, selected);
        }
    }
    if shown.skeleton
        && let Some(plane) = selection.plane().and_then(|i| scene.planes.get(i))
        && let Some(shape) = derived.derived_shape(plane)
        && let Shape::Outline {
            spheres, skeleton, ..
        } = &*shape
    {
        draw_skeleton(painter, camera, rect, plane, spheres, skeleton);
    }
    for (i, plane) in scene.planes.iter().enumerate() {
        let selected = selection.contains(Item::Plane(i));
        if selected || shown.all_planes {
            draw_grid(painter, camera, rect, plane, selected);
        }
        let color = match (plane.kind, selected) {
            _ if plane.hidden && !selected => Color32::from_white_alpha(30),
            (StrokeKind::Cut, _) => Color32::from_rgb(255, 150, 60),
            (_, true) => Color32::from_rgb(255, 90, 90),
            _ => Color32::from_white_alpha(70),
        };
        let mut pts: Vec<Pos2> = plane
            .points
            .iter()
            .filter_map(|p| project(camera, rect, plane.to_world(p.extend(0.0))))
            .collect();
        if pts.len() >= 2 {
            if plane.kind == StrokeKind::Outline {
                pts.push(pts[0]);
            }
            painter.add(egui::Shape::line(
                pts,
                Stroke::new(if selected { 2.0 } else { 1.0 }, color),
            ));
        }
    }
}

/// An ellipsoid's indicator: its three principal ellipses (bright when selected, faint when
/// not, dashed-faint when hidden).
fn draw_ellipsoid(
    painter: &egui::Painter,
    camera: &OrbitCamera,
    rect: Rect,
    e: &crate::scene::Ellipsoid,
    selected: bool,
) {
    let color = match (selected, e.hidden) {
        (true, _) => Color32::from_rgb(255, 170, 60),
        (false, false) => Color32::from_rgba_unmultiplied(255, 200, 120, 70),
        (false, true) => Color32::from_white_alpha(35),
    };
    for pts in picking::indicator(camera, rect, e) {
        if pts.len() > 2 {
            painter.add(egui::Shape::line(
                pts,
                Stroke::new(if selected { 1.5 } else { 1.0 }, color),
            ));
        }
    }
}

/// Wither et al.'s Figure 4 for one plane: its spheres as circles (the 3D extension's copies
/// fainter) and its pruned skeleton as lines.
fn draw_skeleton(
    painter: &egui::Painter,
    camera: &OrbitCamera,
    rect: Rect,
    plane: &DrawingPlane,
    spheres: &[crate::sketch::Sphere],
    skeleton: &[[Vec2; 2]],
) {
    let eye = camera.eye();
    for s in spheres {
        let centre = plane.to_world(s.center.as_vec3());
        let Some(at) = project(camera, rect, centre) else {
            continue;
        };
        let depth = (centre - eye).dot(camera.forward()).max(1e-3);
        let radius = s.radius as f32 / camera.world_per_px(depth, rect.height());
        let in_plane = s.center.z.abs() < 1e-9;
        let color = if in_plane {
            Color32::from_rgba_unmultiplied(120, 200, 255, 150)
        } else {
            Color32::from_rgba_unmultiplied(120, 200, 255, 50)
        };
        painter.circle_stroke(at, radius, Stroke::new(1.0, color));
    }
    for [a, b] in skeleton {
        if let (Some(a), Some(b)) = (
            project(camera, rect, plane.to_world(a.extend(0.0))),
            project(camera, rect, plane.to_world(b.extend(0.0))),
        ) {
            painter.line_segment([a, b], Stroke::new(2.0, Color32::from_rgb(255, 220, 60)));
        }
    }
}

/// The selected plane's grid: its stroke's box, padded, with a few lines each way.
fn draw_grid(
    painter: &egui::Painter,
    camera: &OrbitCamera,
    rect: Rect,
    plane: &DrawingPlane,
    selected: bool,
) {
    if plane.points.is_empty() {
        return;
    }
    let (lo, hi) = plane
        .points
        .iter()
        .fold((Vec2::MAX, Vec2::MIN), |(a, b), &p| (a.min(p), b.max(p)));
    let pad = (hi - lo) * 0.15 + Vec2::splat(0.1);
    let (lo, hi) = (lo - pad, hi + pad);
    let color = if selected {
        Color32::from_rgba_unmultiplied(255, 80, 80, 110)
    } else {
        Color32::from_rgba_unmultiplied(255, 255, 255, 40)
    };
    let lines = 8;
    for k in 0..=lines {
        let t = k as f32 / lines as f32;
        let x = lo.x + (hi.x - lo.x) * t;
        let y = lo.y + (hi.y - lo.y) * t;
        for (a, b) in [
            (Vec2::new(x, lo.y), Vec2::new(x, hi.y)),
            (Vec2::new(lo.x, y), Vec2::new(hi.x, y)),
        ] {
            if let (Some(a), Some(b)) = (
                project(camera, rect, plane.to_world(a.extend(0.0))),
                project(camera, rect, plane.to_world(b.extend(0.0))),
            ) {
                painter.line_segment([a, b], Stroke::new(1.0, color));
            }
        }
    }
}
