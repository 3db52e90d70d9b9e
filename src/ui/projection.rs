//! The view's maths between the screen and the world: a screen point's camera ray, a world
//! point's place on the screen (shared by the tools, the gizmo, picking and ellipsoids).

use egui::{Pos2, Rect};
use glam::{Vec2, Vec3};

use crate::scene::OrbitCamera;

/// The camera ray through screen point `p` of the view `rect`.
pub fn ray_at(camera: &OrbitCamera, rect: Rect, p: Pos2) -> crate::scene::Ray {
    camera.ray(ndc(rect, p), rect.aspect_ratio())
}

pub fn ndc(rect: Rect, p: Pos2) -> Vec2 {
    Vec2::new(
        (p.x - rect.left()) / rect.width() * 2.0 - 1.0,
        1.0 - (p.y - rect.top()) / rect.height() * 2.0,
    )
}

fn screen(rect: Rect, ndc: Vec2) -> Pos2 {
    Pos2::new(
        rect.left() + (ndc.x + 1.0) * 0.5 * rect.width(),
        rect.top() + (1.0 - ndc.y) * 0.5 * rect.height(),
    )
}

/// Where world point `p` appears in the view `rect`, if in front of the camera.
pub fn project(camera: &OrbitCamera, rect: Rect, p: Vec3) -> Option<Pos2> {
    camera
        .project(p, rect.aspect_ratio())
        .map(|n| screen(rect, n))
}
