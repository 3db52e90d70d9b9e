//! Transform maths of the tools: the world axes a drag can be locked to, what a Move, Rotate
//! or Scale drag of so many pixels does, and the axes a new drawing plane takes from the view.
//! Shared by the tools' drags and the gizmo (pure: glam only).

use glam::{Quat, Vec2, Vec3};

use crate::scene::OrbitCamera;

/// A world axis the Rotate tool can be locked to (for Scale: the ellipsoid's own axis).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// World X (right in the front view).
    X,
    /// World Y (up).
    Y,
    /// World Z (toward the front view's camera).
    Z,
}

impl Axis {
    /// The world unit vector.
    pub fn vector(self) -> Vec3 {
        match self {
            Axis::X => Vec3::X,
            Axis::Y => Vec3::Y,
            Axis::Z => Vec3::Z,
        }
    }

    /// The axis's letter.
    pub fn name(self) -> &'static str {
        match self {
            Axis::X => "X",
            Axis::Y => "Y",
            Axis::Z => "Z",
        }
    }
}

/// Turn per pixel of drag: about 1° per 5 px (a 150 px drag turns 30°), as the gizmos will.
const TURN_PER_PX: f32 = 0.2 * std::f32::consts::PI / 180.0;
/// The step Ctrl snaps turns to.
pub const SNAP_STEP: f32 = 15.0 * std::f32::consts::PI / 180.0;

/// Scale per pixel of drag: a 140 px drag doubles.
const SCALE_PER_PX: f32 = std::f32::consts::LN_2 / 140.0;

/// The factor per axis a Scale drag of `drag` pixels gives: right or up grows, left or down
/// shrinks; locked, only that axis changes; `snap` rounds the factor to tenths.
pub fn drag_scale(drag: Vec2, lock: Option<Axis>, snap: bool) -> Vec3 {
    let mut f = ((drag.x - drag.y) * SCALE_PER_PX).exp();
    if snap {
        f = ((f * 10.0).round() / 10.0).max(0.1);
    }
    match lock {
        Some(axis) => Vec3::ONE + axis.vector() * (f - 1.0),
        None => Vec3::splat(f),
    }
}

/// The turn a Rotate drag of `drag` pixels (screen x right, y down) gives. Locked to an axis,
/// a drag right or up turns positively about it; free, sideways turns about the vertical and
/// up/down tilts about the view's right axis. `snap` rounds each angle to 15°.
pub fn drag_turn(drag: Vec2, lock: Option<Axis>, snap: bool, view_right: Vec3) -> Quat {
    let angle = |px: f32| {
        let a = px * TURN_PER_PX;
        if snap {
            (a / SNAP_STEP).round() * SNAP_STEP
        } else {
            a
        }
    };
    match lock {
        Some(axis) => Quat::from_axis_angle(axis.vector(), angle(drag.x - drag.y)),
        None => {
            Quat::from_axis_angle(Vec3::Y, angle(drag.x))
                * Quat::from_axis_angle(view_right, angle(drag.y))
        }
    }
}

/// Within this many degrees of level, a view draws on vertical planes: the default view looks
/// 8° down, and a plane facing it exactly leaned every outline back.
pub const LEVEL_PITCH_DEG: f32 = 10.0;

/// The axes a new drawing plane takes from `camera`: its right, up and normal (toward the
/// viewer). Facing the view, except that a view within [`LEVEL_PITCH_DEG`] of level gives a
/// vertical plane (up is the world's).
pub fn drawing_axes(camera: &OrbitCamera) -> (Vec3, Vec3, Vec3) {
    let right = camera.right();
    if camera.pitch_deg.abs() <= LEVEL_PITCH_DEG {
        let normal = right.cross(Vec3::Y).normalize_or(-camera.forward());
        (right, Vec3::Y, normal)
    } else {
        (right, camera.up(), -camera.forward())
    }
}

/// How far a Move drag of `drag` pixels (`per_px` world units a pixel) moves an item: in the
/// view's plane, or with `toward` (Shift) along the view: dragging up moves it away from the
/// viewer, down toward them, as Blender's depth drags do.
pub fn view_move(camera: &OrbitCamera, drag: Vec2, per_px: f32, toward: bool) -> Vec3 {
    if toward {
        camera.forward() * (-drag.y * per_px)
    } else {
        camera.right() * (drag.x * per_px) - camera.up() * (drag.y * per_px)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis_angle(q: Quat) -> (Vec3, f32) {
        let (axis, angle) = q.to_axis_angle();
        (axis, angle.to_degrees())
    }

    #[test]
    fn a_scale_drag_grows_rightward_per_axis_and_snaps() {
        let grow = drag_scale(Vec2::new(140.0, 0.0), None, false);
        assert!(grow.abs_diff_eq(Vec3::splat(2.0), 1e-4), "{grow}");
        let shrink = drag_scale(Vec2::new(0.0, 140.0), None, false);
        assert!(shrink.abs_diff_eq(Vec3::splat(0.5), 1e-4), "{shrink}");
        let y = drag_scale(Vec2::new(100.0, 0.0), Some(Axis::Y), true);
        assert_eq!(y, Vec3::new(1.0, 1.6, 1.0));
    }

    #[test]
    fn a_150_px_drag_turns_30_degrees_about_the_vertical() {
        let (axis, deg) = axis_angle(drag_turn(Vec2::new(150.0, 0.0), None, false, Vec3::X));
        assert!(axis.abs_diff_eq(Vec3::Y, 1e-5), "{axis}");
        assert!((deg - 30.0).abs() < 1e-3, "{deg}");
    }

    #[test]
    fn a_locked_axis_takes_the_whole_drag_and_ctrl_snaps_to_15_degrees() {
        // Right 160 and up 60: 220 px, 44° about Z; snapped, 45°.
        let drag = Vec2::new(160.0, -60.0);
        let (axis, deg) = axis_angle(drag_turn(drag, Some(Axis::Z), false, Vec3::X));
        assert!(
            axis.abs_diff_eq(Vec3::Z, 1e-5) && (deg - 44.0).abs() < 1e-3,
            "{axis} {deg}"
        );
        let (axis, deg) = axis_angle(drag_turn(drag, Some(Axis::Z), true, Vec3::X));
        assert!(
            axis.abs_diff_eq(Vec3::Z, 1e-5) && (deg - 45.0).abs() < 1e-3,
            "{axis} {deg}"
        );
        // Free, the same drag turns about two axes, each snapped on its own.
        let free = drag_turn(drag, None, true, Vec3::X);
        let expected =
            Quat::from_rotation_y(30f32.to_radians()) * Quat::from_rotation_x(-15f32.to_radians());
        assert!(free.abs_diff_eq(expected, 1e-5), "{free} {expected}");
    }

    #[test]
    fn a_shift_drag_up_moves_away_from_the_viewer() {
        let camera = crate::scene::Scene::default().camera;
        let up = view_move(&camera, Vec2::new(0.0, -50.0), 0.01, true);
        assert!(up.dot(camera.forward()) > 0.49, "{up}");
        let down = view_move(&camera, Vec2::new(0.0, 50.0), 0.01, true);
        assert!(down.dot(camera.forward()) < -0.49, "{down}");
        // Without Shift, up is up on the screen.
        let plain = view_move(&camera, Vec2::new(0.0, -50.0), 0.01, false);
        assert!(plain.dot(camera.up()) > 0.49, "{plain}");
    }
}
