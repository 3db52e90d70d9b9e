//! On-canvas gizmos for Move, Rotate and Scale, drawn with egui's painter (the transform-gizmo
//! crate is built for another egui): an arrow per world axis to move along it, a box per
//! ellipsoid axis to scale along it, a ring per world axis to turn about it, and a centre
//! handle (move in the view plane, scale uniformly). Where a press lands picks the handle; the
//! drag is then turned into a transform from the whole drag so far (so Ctrl's snapping sees
//! the total) by the pure functions below.

use egui::{Color32, Pos2, Rect, Stroke};
use glam::{Quat, Vec2, Vec3};

use super::picking::segment_distance;
use super::projection::project;
use super::tool::Tool;
use super::transform::Axis;
use crate::scene::OrbitCamera;

/// Length in pixels of a handle whose axis lies in the view plane.
const HANDLE_PX: f32 = 90.0;
/// Radius in pixels of the rings.
const RING_PX: f32 = 80.0;
/// How near (pixels) a press must come to a handle to take it.
const GRAB_PX: f32 = 8.0;
/// Radius in pixels of the centre handle.
const CENTER_PX: f32 = 10.0;
/// A handle shorter than this on screen (its axis points at the viewer) is not offered.
const MIN_HANDLE_PX: f32 = 14.0;

/// A part of the gizmo a drag can start on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handle {
    /// One axis: move along it, scale along it, or turn about it (the ring).
    Axis(Axis),
    /// The centre: move in the view plane, scale uniformly, or turn freely.
    Center,
}

/// One axis of a laid-out gizmo.
#[derive(Clone, Debug)]
struct AxisLayout {
    axis: Axis,
    /// World direction the handle acts along (a world axis; for Scale the ellipsoid's own).
    world: Vec3,
    /// Screen end of the handle (Move, Scale).
    end: Pos2,
    /// Screen polyline of the ring (Rotate).
    ring: Vec<Pos2>,
}

/// A gizmo laid out on the screen for one frame.
#[derive(Clone, Debug)]
pub struct Gizmo {
    tool: Tool,
    /// Screen position of the item's centre.
    pub center: Pos2,
    /// World length of a handle (so a drag along it converts to world units).
    reach: f32,
    axes: Vec<AxisLayout>,
}

/// Red, green and blue for X, Y and Z, as in Blender.
fn color(axis: Axis) -> Color32 {
    match axis {
        Axis::X => Color32::from_rgb(235, 80, 85),
        Axis::Y => Color32::from_rgb(130, 205, 70),
        Axis::Z => Color32::from_rgb(70, 140, 245),
    }
}

impl Gizmo {
    /// The gizmo of `tool` for an item at `origin` turned by `rotation` (Scale acts along the
    /// item's own axes, Move and Rotate along the world's), or `None` for a tool without one
    /// or an item behind the camera.
    pub fn layout(
        tool: Tool,
        camera: &OrbitCamera,
        rect: Rect,
        origin: Vec3,
        rotation: Quat,
    ) -> Option<Self> {
        if !matches!(tool, Tool::Move | Tool::Rotate | Tool::Scale) {
            return None;
        }
        let center = project(camera, rect, origin)?;
        let depth = (origin - camera.eye()).dot(camera.forward()).max(0.1);
        let per_px = camera.world_per_px(depth, rect.height());
        let reach = HANDLE_PX * per_px;
        let ring_radius = RING_PX * per_px;
        let axes = [Axis::X, Axis::Y, Axis::Z]
            .into_iter()
            .map(|axis| {
                let world = match tool {
                    Tool::Scale => rotation * axis.vector(),
                    _ => axis.vector(),
                };
                let end = project(camera, rect, origin + world * reach).unwrap_or(center);
                let (b, c) = perpendicular(axis.vector());
                let ring = if tool == Tool::Rotate {
                    (0..=64)
                        .filter_map(|k| {
                            let t = k as f32 / 64.0 * std::f32::consts::TAU;
                            let p = origin + (b * t.cos() + c * t.sin()) * ring_radius;
                            project(camera, rect, p)
                        })
                        .collect()
                } else {
                    Vec::new()
                };
                AxisLayout {
                    axis,
                    world,
                    end,
                    ring,
                }
            })
            .collect();
        Some(Self {
            tool,
            center,
            reach,
            axes,
        })
    }

    /// Screen end of `axis`'s handle, when it is offered (for tests and the page state).
    pub fn handle_end(&self, axis: Axis) -> Option<Pos2> {
        let a = self.axes.iter().find(|a| a.axis == axis)?;
        (a.end.distance(self.center) >= MIN_HANDLE_PX).then_some(a.end)
    }

    /// The handle a press at `p` takes, if any.
    pub fn hit(&self, p: Pos2) -> Option<Handle> {
        let mut best: Option<(f32, Handle)> = None;
        let mut offer = |d: f32, h: Handle| {
            if d < GRAB_PX && best.is_none_or(|(b, _)| d < b) {
                best = Some((d, h));
            }
        };
        for a in &self.axes {
            match self.tool {
                Tool::Rotate => {
                    let d = a
                        .ring
                        .windows(2)
                        .map(|w| segment_distance(p, w[0], w[1]))
                        .fold(f32::INFINITY, f32::min);
                    offer(d, Handle::Axis(a.axis));
                }
                _ if self.handle_end(a.axis).is_some() && p.distance(self.center) > CENTER_PX => {
                    offer(
                        segment_distance(p, self.center, a.end),
                        Handle::Axis(a.axis),
                    );
                }
                _ => {}
            }
        }
        if self.tool != Tool::Rotate && p.distance(self.center) <= CENTER_PX {
            return Some(Handle::Center);
        }
        best.map(|(_, h)| h)
    }

    /// How far along `axis`'s handle a drag goes, in pixels along its screen direction, and the
    /// world distance that is (for Move); `None` when the axis points at the viewer.
    pub fn along(&self, axis: Axis, drag: Vec2) -> Option<(f32, Vec3)> {
        let a = self.axes.iter().find(|a| a.axis == axis)?;
        let d = Vec2::new(a.end.x - self.center.x, a.end.y - self.center.y);
        let len = d.length();
        (len >= 1.0).then(|| {
            let px = drag.dot(d) / len;
            (px, a.world * (px / len * self.reach))
        })
    }

    /// Draws the gizmo; `active` (the handle being dragged) and `hovered` are highlighted.
    pub fn draw(&self, painter: &egui::Painter, active: Option<Handle>, hovered: Option<Handle>) {
        let lit = |h: Handle, base: Color32| {
            if active == Some(h) || (active.is_none() && hovered == Some(h)) {
                Color32::from_rgb(255, 235, 120)
            } else {
                base
            }
        };
        for a in &self.axes {
            let c = lit(Handle::Axis(a.axis), color(a.axis));
            match self.tool {
                Tool::Rotate => {
                    if a.ring.len() > 2 {
                        painter.add(egui::Shape::line(a.ring.clone(), Stroke::new(2.0, c)));
                    }
                }
                _ => {
                    let Some(end) = self.handle_end(a.axis) else {
                        continue;
                    };
                    let dir = (end - self.center).normalized();
                    painter.line_segment([self.center + dir * CENTER_PX, end], Stroke::new(2.5, c));
                    if self.tool == Tool::Move {
                        let side = egui::vec2(-dir.y, dir.x) * 5.0;
                        painter.add(egui::Shape::convex_polygon(
                            vec![end + dir * 12.0, end + side, end - side],
                            c,
                            Stroke::NONE,
                        ));
                    } else {
                        painter.rect_filled(
                            Rect::from_center_size(end, egui::vec2(9.0, 9.0)),
                            1.0,
                            c,
                        );
                    }
                }
            }
        }
        if self.tool != Tool::Rotate {
            let c = lit(Handle::Center, Color32::from_white_alpha(220));
            painter.circle_stroke(self.center, CENTER_PX, Stroke::new(1.5, c));
        }
    }
}

/// Two unit vectors spanning the plane perpendicular to a world axis.
fn perpendicular(axis: Vec3) -> (Vec3, Vec3) {
    let b = if axis.x.abs() > 0.5 { Vec3::Y } else { Vec3::X };
    let b = (b - axis * b.dot(axis)).normalize();
    (b, axis.cross(b))
}

/// The signed turn (radians) about world `axis` that takes the pointer from `from` to `to`
/// around the screen point `center`: counter-clockwise on screen is a positive turn about an
/// axis pointing at the viewer (`toward_viewer` > 0).
pub fn ring_turn(center: Pos2, from: Pos2, to: Pos2, axis_toward_viewer: f32) -> f32 {
    // Screen y points down: flip it so counter-clockwise is positive.
    let a = Vec2::new(from.x - center.x, center.y - from.y);
    let b = Vec2::new(to.x - center.x, center.y - to.y);
    if a.length() < 1.0 || b.length() < 1.0 {
        return 0.0;
    }
    let angle = a.perp_dot(b).atan2(a.dot(b));
    if axis_toward_viewer >= 0.0 {
        angle
    } else {
        -angle
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    use crate::ui::test_view as view;

    #[test]
    fn a_drag_along_the_x_arrow_moves_along_x_by_what_the_pointer_covers() {
        let camera = Scene::default().camera;
        let origin = camera.target;
        let g = Gizmo::layout(Tool::Move, &camera, view(), origin, Quat::IDENTITY).unwrap();
        let end = g
            .handle_end(Axis::X)
            .expect("x handle offered in the default view");
        // A press on the arrow takes it; one on the centre takes the centre; far away, none.
        let on_arrow = g.center + (end - g.center) * 0.6;
        assert_eq!(g.hit(on_arrow), Some(Handle::Axis(Axis::X)));
        assert_eq!(g.hit(g.center), Some(Handle::Center));
        assert_eq!(g.hit(g.center + egui::vec2(300.0, 300.0)), None);
        // Dragging along the arrow by its own length moves by the handle's world length, along
        // x only, whatever the drag's sideways part.
        let d = end - g.center;
        let (_, moved) = g
            .along(Axis::X, Vec2::new(d.x, d.y) + Vec2::new(-d.y, d.x) * 0.5)
            .unwrap();
        assert!(moved.y.abs() < 1e-6 && moved.z.abs() < 1e-6, "{moved}");
        let tip = project(&camera, view(), origin + moved).unwrap();
        assert!(tip.distance(end) < 0.5, "{tip:?} vs {end:?}");
    }

    #[test]
    fn rings_turn_the_way_the_pointer_goes_round() {
        let camera = Scene::default().camera;
        let g =
            Gizmo::layout(Tool::Rotate, &camera, view(), camera.target, Quat::IDENTITY).unwrap();
        // The Z ring (facing a front view) is a circle round the centre: a press on it, away
        // from the X and Y rings (seen nearly edge-on), takes it.
        let on_ring = g.center + egui::vec2(1.0, -1.0).normalized() * RING_PX;
        assert_eq!(g.hit(on_ring), Some(Handle::Axis(Axis::Z)));
        // A quarter turn counter-clockwise on screen about an axis toward the viewer is +90°.
        let c = Pos2::new(100.0, 100.0);
        let t = ring_turn(
            c,
            c + egui::vec2(50.0, 0.0),
            c + egui::vec2(0.0, -50.0),
            1.0,
        );
        assert!((t - std::f32::consts::FRAC_PI_2).abs() < 1e-5, "{t}");
        assert!(
            (ring_turn(
                c,
                c + egui::vec2(50.0, 0.0),
                c + egui::vec2(0.0, -50.0),
                -1.0
            ) + t)
                .abs()
                < 1e-6
        );
    }

    #[test]
    fn scale_handles_follow_the_ellipsoid_s_own_axes() {
        let camera = Scene::default().camera;
        let turn = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let g = Gizmo::layout(Tool::Scale, &camera, view(), camera.target, turn).unwrap();
        // Its x axis now points up the screen.
        let end = g.handle_end(Axis::X).unwrap();
        assert!(
            end.y < g.center.y - 40.0 && (end.x - g.center.x).abs() < 5.0,
            "{end:?}"
        );
        let (px, world) = g.along(Axis::X, Vec2::new(0.0, -30.0)).unwrap();
        assert!(
            px > 29.0 && world.normalize().abs_diff_eq(Vec3::Y, 1e-4),
            "{px} {world}"
        );
    }
}
