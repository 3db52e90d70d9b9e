//! The orbit camera (Blender-like: orbit around a target, pan, zoom, frame).

use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};
use serde::{Deserialize, Serialize};

use super::finite_or;

/// A camera orbiting a target point, stored in the document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OrbitCamera {
    /// The point the camera looks at and orbits around.
    pub target: Vec3,
    /// Rotation around the world's up axis in degrees; 0 looks along −z.
    pub yaw_deg: f32,
    /// Angle above the horizon in degrees.
    pub pitch_deg: f32,
    /// Distance from the target.
    pub distance: f32,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// Orthographic projection (5 toggles it): the view is as tall as the perspective view
    /// is at the target's distance, and parallel lines stay parallel (how outlines are drawn).
    pub orthographic: bool,
}

/// The standard views (numpad 1, 3, 7 and Ctrl for the opposite side, as in Blender).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StandardView {
    /// Looking along −z.
    Front,
    /// Looking along +z.
    Back,
    /// Looking along −x (from the right).
    Right,
    /// Looking along +x.
    Left,
    /// Looking down.
    Top,
    /// Looking up.
    Bottom,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::new(0.0, 3.0, 0.0),
            yaw_deg: 0.0,
            pitch_deg: 8.0,
            distance: 19.0,
            fov_y_deg: 45.0,
            orthographic: false,
        }
    }
}

/// A ray in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

impl Ray {
    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// Intersection parameter with the plane through `point` with normal `normal`, if in front.
    pub fn hit_plane(&self, point: Vec3, normal: Vec3) -> Option<f32> {
        let denom = self.dir.dot(normal);
        if denom.abs() < 1e-6 {
            return None;
        }
        let t = (point - self.origin).dot(normal) / denom;
        (t > 0.0).then_some(t)
    }
}

/// Pitch is kept just short of the poles so "up" stays defined.
const PITCH_LIMIT: f32 = 89.0;
/// Zoom range.
const DISTANCE_RANGE: (f32, f32) = (0.05, 1.0e4);

impl OrbitCamera {
    /// Camera position.
    pub fn eye(&self) -> Vec3 {
        self.target + self.back() * self.distance
    }

    /// Unit vector from the target toward the eye.
    fn back(&self) -> Vec3 {
        let (yaw, pitch) = (self.yaw_deg.to_radians(), self.pitch_deg.to_radians());
        Vec3::new(
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            pitch.cos() * yaw.cos(),
        )
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        -self.back()
    }

    /// Unit right vector of the image plane.
    pub fn right(&self) -> Vec3 {
        self.forward().cross(Vec3::Y).normalize_or(Vec3::X)
    }

    /// Unit up vector of the image plane.
    pub fn up(&self) -> Vec3 {
        self.right().cross(self.forward())
    }

    /// Near and far clip distances.
    pub fn clip_range(&self) -> (f32, f32) {
        (self.distance * 0.01, self.distance * 20.0 + 100.0)
    }

    /// World → view matrix.
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye(), self.target, Vec3::Y)
    }

    /// Half the view's height in world units at the target (the orthographic view's size).
    fn half_height(&self) -> f32 {
        self.distance * (self.fov_y_deg.to_radians() * 0.5).tan()
    }

    /// View → clip matrix (wgpu depth range 0..1).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        let (near, far) = self.clip_range();
        let aspect = aspect.max(1e-3);
        if self.orthographic {
            let h = self.half_height();
            Mat4::orthographic_rh(-h * aspect, h * aspect, -h, h, near, far)
        } else {
            Mat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, near, far)
        }
    }

    /// Turns the camera to a standard view, keeping its target and distance.
    pub fn set_view(&mut self, view: StandardView) {
        let (yaw, pitch) = match view {
            StandardView::Front => (0.0, 0.0),
            StandardView::Back => (180.0, 0.0),
            StandardView::Right => (90.0, 0.0),
            StandardView::Left => (270.0, 0.0),
            StandardView::Top => (0.0, PITCH_LIMIT),
            StandardView::Bottom => (0.0, -PITCH_LIMIT),
        };
        self.yaw_deg = yaw;
        self.pitch_deg = pitch;
    }

    /// World → clip matrix.
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }

    /// The ray through a point of the image given in normalised device coordinates
    /// (x right, y up, both in −1..1).
    pub fn ray(&self, ndc: Vec2, aspect: f32) -> Ray {
        let aspect = aspect.max(1e-3);
        if self.orthographic {
            let h = self.half_height();
            return Ray {
                origin: self.eye() + self.right() * (ndc.x * h * aspect) + self.up() * (ndc.y * h),
                dir: self.forward(),
            };
        }
        let tan = (self.fov_y_deg.to_radians() * 0.5).tan();
        let dir =
            self.forward() + self.right() * (ndc.x * tan * aspect) + self.up() * (ndc.y * tan);
        Ray {
            origin: self.eye(),
            dir: dir.normalize(),
        }
    }

    /// Projects a world point to normalised device coordinates; `None` behind the camera.
    pub fn project(&self, point: Vec3, aspect: f32) -> Option<Vec2> {
        let clip = self.view_projection(aspect) * point.extend(1.0);
        (clip.w > 1e-6).then(|| clip.xy() / clip.w)
    }

    /// The rectangle of normalised device coordinates (x0, y0, x1, y1) a box covers on screen,
    /// clamped to the view; the whole view when part of the box is behind the camera, `None`
    /// when it is entirely outside the view.
    pub fn ndc_bounds(&self, lo: Vec3, hi: Vec3, aspect: f32) -> Option<[f32; 4]> {
        let m = self.view_projection(aspect);
        let (near, _) = self.clip_range();
        let (eye, forward) = (self.eye(), self.forward());
        let (mut a, mut b) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
        let mut behind = 0;
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let clip = m * p.extend(1.0);
            if (p - eye).dot(forward) <= near {
                behind += 1;
                continue;
            }
            let q = clip.xy() / clip.w;
            a = a.min(q);
            b = b.max(q);
        }
        match behind {
            0 => {
                let (a, b) = (a.max(Vec2::NEG_ONE), b.min(Vec2::ONE));
                (a.x < b.x && a.y < b.y).then_some([a.x, a.y, b.x, b.y])
            }
            8 => None,
            _ => Some([-1.0, -1.0, 1.0, 1.0]),
        }
    }

    /// Orbits by a pointer movement in pixels (drag right turns the view right).
    pub fn orbit(&mut self, delta_px: Vec2) {
        const DEG_PER_PX: f32 = 0.35;
        self.yaw_deg = (self.yaw_deg - delta_px.x * DEG_PER_PX).rem_euclid(360.0);
        self.pitch_deg =
            (self.pitch_deg + delta_px.y * DEG_PER_PX).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// World units per pixel at `depth` along the view direction, in a viewport
    /// `viewport_height_px` pixels tall.
    pub fn world_per_px(&self, depth: f32, viewport_height_px: f32) -> f32 {
        // Orthographic: the same everywhere, as at the target's depth.
        let depth = if self.orthographic {
            self.distance
        } else {
            depth
        };
        2.0 * depth * (self.fov_y_deg.to_radians() * 0.5).tan() / viewport_height_px.max(1.0)
    }

    /// Pans so the point under the pointer follows it; `viewport_height_px` scales pixels to world.
    pub fn pan(&mut self, delta_px: Vec2, viewport_height_px: f32) {
        let world_per_px = self.world_per_px(self.distance, viewport_height_px);
        self.target += (-self.right() * delta_px.x + self.up() * delta_px.y) * world_per_px;
    }

    /// Multiplies the distance by `factor` (< 1 moves closer).
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(DISTANCE_RANGE.0, DISTANCE_RANGE.1);
        }
    }

    /// Centres a bounding sphere and sets the distance so it fills the view.
    pub fn frame(&mut self, center: Vec3, radius: f32, aspect: f32) {
        let half_fov_y = self.fov_y_deg.to_radians() * 0.5;
        let half_fov_x = (half_fov_y.tan() * aspect.clamp(0.1, 10.0)).atan();
        let half = half_fov_y.min(half_fov_x).max(0.05);
        self.target = center;
        self.distance =
            (radius.max(1e-3) / half.sin() * 1.05).clamp(DISTANCE_RANGE.0, DISTANCE_RANGE.1);
    }

    pub(super) fn sanitize(&mut self) {
        let d = Self::default();
        if !self.target.is_finite() {
            self.target = d.target;
        }
        self.yaw_deg = finite_or(self.yaw_deg, d.yaw_deg).rem_euclid(360.0);
        self.pitch_deg = finite_or(self.pitch_deg, d.pitch_deg).clamp(-PITCH_LIMIT, PITCH_LIMIT);
        self.distance =
            finite_or(self.distance, d.distance).clamp(DISTANCE_RANGE.0, DISTANCE_RANGE.1);
        self.fov_y_deg = finite_or(self.fov_y_deg, d.fov_y_deg).clamp(5.0, 120.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ndc_bounds_hold_every_projected_point_of_the_box() {
        let cam = OrbitCamera::default();
        let (lo, hi) = (Vec3::new(-2.0, 1.0, -1.0), Vec3::new(3.0, 4.0, 2.0));
        let [x0, y0, x1, y1] = cam.ndc_bounds(lo, hi, 1.6).unwrap();
        for i in 0..=10 {
            for j in 0..=10 {
                for k in 0..=10 {
                    let t = Vec3::new(i as f32, j as f32, k as f32) / 10.0;
                    let q = cam.project(lo + (hi - lo) * t, 1.6).unwrap();
                    assert!(
                        q.x >= x0 - 1e-5
                            && q.x <= x1 + 1e-5
                            && q.y >= y0 - 1e-5
                            && q.y <= y1 + 1e-5
                    );
                }
            }
        }
        assert!(x1 - x0 < 1.5, "a box in the middle does not fill the view");
        // Behind the camera: nothing; around the camera: the whole view.
        let back = cam.eye() - cam.forward() * 50.0;
        assert_eq!(
            cam.ndc_bounds(back - Vec3::ONE, back + Vec3::ONE, 1.6),
            None
        );
        let eye = cam.eye();
        assert_eq!(
            cam.ndc_bounds(eye - Vec3::ONE, eye + Vec3::ONE, 1.6),
            Some([-1.0, -1.0, 1.0, 1.0])
        );
    }

    #[test]
    fn rays_go_through_the_points_they_project_from_in_both_projections() {
        for orthographic in [false, true] {
            let mut cam = OrbitCamera {
                yaw_deg: 30.0,
                pitch_deg: 20.0,
                ..Default::default()
            };
            cam.orthographic = orthographic;
            for p in [Vec3::new(1.0, 4.0, -2.0), Vec3::new(-3.0, 2.0, 1.5)] {
                let ndc = cam.project(p, 1.5).unwrap();
                let ray = cam.ray(ndc, 1.5);
                let closest = ray.at((p - ray.origin).dot(ray.dir));
                assert!(
                    closest.distance(p) < 1e-3,
                    "{orthographic}: {closest} vs {p}"
                );
            }
        }
        // Orthographic rays are parallel; perspective ones are not.
        let mut cam = OrbitCamera {
            orthographic: true,
            ..Default::default()
        };
        assert_eq!(
            cam.ray(Vec2::new(-0.9, 0.3), 1.5).dir,
            cam.ray(Vec2::new(0.8, -0.7), 1.5).dir
        );
        cam.orthographic = false;
        assert_ne!(
            cam.ray(Vec2::new(-0.9, 0.3), 1.5).dir,
            cam.ray(Vec2::new(0.8, -0.7), 1.5).dir
        );
    }

    #[test]
    fn standard_views_look_along_the_axes() {
        let mut cam = OrbitCamera::default();
        for (view, forward) in [
            (StandardView::Front, Vec3::NEG_Z),
            (StandardView::Back, Vec3::Z),
            (StandardView::Right, Vec3::NEG_X),
            (StandardView::Left, Vec3::X),
            (StandardView::Top, Vec3::NEG_Y),
            (StandardView::Bottom, Vec3::Y),
        ] {
            cam.set_view(view);
            assert!(
                cam.forward().dot(forward) > 0.999,
                "{view:?}: {}",
                cam.forward()
            );
        }
    }

    #[test]
    fn basis_is_orthonormal_and_looks_at_target() {
        let cam = OrbitCamera {
            yaw_deg: 37.0,
            pitch_deg: -20.0,
            ..Default::default()
        };
        let (f, r, u) = (cam.forward(), cam.right(), cam.up());
        for v in [f, r, u] {
            assert!((v.length() - 1.0).abs() < 1e-5);
        }
        assert!(f.dot(r).abs() < 1e-5 && f.dot(u).abs() < 1e-5 && r.dot(u).abs() < 1e-5);
        assert!((cam.eye() + f * cam.distance).abs_diff_eq(cam.target, 1e-4));
    }

    #[test]
    fn target_projects_to_centre_and_ray_round_trips() {
        let cam = OrbitCamera {
            yaw_deg: 123.0,
            pitch_deg: 30.0,
            ..Default::default()
        };
        let aspect = 1.6;
        let c = cam.project(cam.target, aspect).unwrap();
        assert!(c.length() < 1e-5, "{c}");
        let ndc = Vec2::new(0.4, -0.7);
        let ray = cam.ray(ndc, aspect);
        let p = ray.at(7.0);
        assert!(cam.project(p, aspect).unwrap().abs_diff_eq(ndc, 1e-4));
    }

    #[test]
    fn orbit_keeps_distance_and_clamps_pitch() {
        let mut cam = OrbitCamera::default();
        let d = cam.eye().distance(cam.target);
        cam.orbit(Vec2::new(100.0, 10_000.0));
        assert!((cam.eye().distance(cam.target) - d).abs() < 1e-3);
        assert!(cam.pitch_deg <= PITCH_LIMIT);
        assert!(cam.up().is_finite());
    }

    #[test]
    fn pan_moves_target_in_image_plane() {
        let mut cam = OrbitCamera::default();
        let before = cam.target;
        cam.pan(Vec2::new(50.0, 0.0), 500.0);
        let moved = cam.target - before;
        assert!(moved.dot(cam.forward()).abs() < 1e-4);
        assert!(
            moved.dot(cam.right()) < 0.0,
            "drag right moves the scene right, so the target goes left"
        );
    }

    #[test]
    fn zoom_and_frame() {
        let mut cam = OrbitCamera::default();
        cam.zoom(0.5);
        assert!((cam.distance - 9.5).abs() < 1e-4);
        cam.zoom(f32::NAN);
        assert!((cam.distance - 9.5).abs() < 1e-4);
        cam.frame(Vec3::new(1.0, 2.0, 3.0), 2.0, 1.0);
        assert_eq!(cam.target, Vec3::new(1.0, 2.0, 3.0));
        // The framed sphere fits: its silhouette angle is within the half field of view.
        assert!((2.0f32 / cam.distance).asin() <= cam.fov_y_deg.to_radians() * 0.5 + 1e-4);
    }

    #[test]
    fn plane_hit() {
        let ray = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::NEG_Z,
        };
        assert_eq!(ray.hit_plane(Vec3::new(0.0, 0.0, -5.0), Vec3::Z), Some(5.0));
        assert_eq!(ray.hit_plane(Vec3::new(0.0, 0.0, 5.0), Vec3::Z), None);
        assert_eq!(ray.hit_plane(Vec3::new(0.0, 0.0, -5.0), Vec3::X), None);
    }
}
