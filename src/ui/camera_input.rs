//! Blender-like camera controls for the viewport: drag orbits, Shift/right/middle drag pans,
//! wheel and pinch zoom, F frames the cloud. Mouse, pen and touch all arrive as pointer events.

use egui::{PointerButton, Response};
use glam::Vec2;

use crate::scene::OrbitCamera;

/// Applies this frame's camera input. `orbit_with_primary` is false while a drawing tool owns
/// the primary button (then Alt+drag or two fingers still orbit). Returns whether the camera moved.
pub fn handle(
    ui: &egui::Ui,
    response: &Response,
    camera: &mut OrbitCamera,
    orbit_with_primary: bool,
) -> bool {
    let before = camera.clone();
    let rect = response.rect;
    let (modifiers, multi_touch, scroll, zoom) = ui.input(|i| {
        (
            i.modifiers,
            i.multi_touch(),
            i.smooth_scroll_delta,
            i.zoom_delta(),
        )
    });
    let delta = response.drag_delta();
    let delta = Vec2::new(delta.x, delta.y);
    // While a drawing tool owns the primary button, the middle button orbits instead of panning.
    let middle_orbits = !orbit_with_primary && !modifiers.shift;
    let pan = response.dragged_by(PointerButton::Secondary)
        || (response.dragged_by(PointerButton::Middle) && !middle_orbits)
        || (response.dragged_by(PointerButton::Primary) && modifiers.shift && orbit_with_primary);
    let primary_orbit = (response.dragged_by(PointerButton::Primary)
        && (orbit_with_primary || modifiers.alt))
        || (response.dragged_by(PointerButton::Middle) && middle_orbits);

    if let Some(touch) =
        multi_touch.filter(|_| response.hovered() || response.is_pointer_button_down_on())
    {
        // Two fingers: orbit with their common motion; pinch arrives as zoom below.
        let t = touch.translation_delta;
        camera.orbit(Vec2::new(t.x, t.y));
    } else if pan {
        camera.pan(delta, rect.height());
    } else if primary_orbit {
        camera.orbit(delta);
    }
    if response.hovered() {
        if scroll.y != 0.0 {
            camera.zoom((-scroll.y * 0.0025).exp());
        }
        if zoom != 1.0 {
            camera.zoom(1.0 / zoom);
        }
    }
    *camera != before
}
