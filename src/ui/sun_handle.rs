//! The sun handle: a small orb in the view's top-right corner showing where the sun is as seen
//! from the camera (a dot on a sphere: filled when the sun is behind the cloud, facing you; a
//! ring when it is behind you). Dragging the dot turns the sun, one undo step per drag; a
//! double-click puts it back to the default direction.

use egui::{Color32, Pos2, Sense, Stroke, Vec2};
use glam::Vec3;

use crate::limits;
use crate::scene::{Document, Edit, Lighting, OrbitCamera};

/// The orb's radius in points.
const RADIUS: f32 = 34.0;
/// The merge key of a drag's edits.
const MERGE: &str = "sun handle";

/// Where the sun sits on the orb: its direction in the camera's frame, `x` right, `y` up, `z`
/// toward the viewer (so `z < 0`: the sun is behind the cloud and lights it from the back).
pub fn orb_position(camera: &OrbitCamera, light: &Lighting) -> Vec3 {
    let sun = light.sun_direction();
    Vec3::new(
        sun.dot(camera.right()),
        sun.dot(camera.up()),
        -sun.dot(camera.forward()),
    )
}

/// The sun's azimuth and elevation (degrees) for a point `p` of the orb (unit disk, y up) on
/// the hemisphere toward the viewer (`toward_viewer`) or away from it; a point outside the disk
/// lies on its rim. Elevation is kept within the slider's range.
pub fn sun_at(camera: &OrbitCamera, p: glam::Vec2, toward_viewer: bool) -> (f32, f32) {
    let p = if p.length() > 1.0 { p.normalize() } else { p };
    let z = (1.0 - p.length_squared()).max(0.0).sqrt();
    let z = if toward_viewer { z } else { -z };
    let dir =
        (camera.right() * p.x + camera.up() * p.y - camera.forward() * z).normalize_or(Vec3::Y);
    let elevation = limits::SUN_ELEVATION.fix_f32(dir.y.clamp(-1.0, 1.0).asin().to_degrees());
    let azimuth = dir.z.atan2(dir.x).to_degrees().rem_euclid(360.0);
    (azimuth, elevation)
}

/// The orb's centre and radius (points) in a view of `rect`, or `None` when the view is too
/// small to hold it.
pub fn orb(rect: egui::Rect) -> Option<(Pos2, f32)> {
    let center = rect.right_top() + Vec2::new(-RADIUS - 12.0, RADIUS + 44.0);
    rect.contains_rect(area(center)).then_some((center, RADIUS))
}

/// Where the orb takes the pointer in `rect`, if it fits there.
pub fn orb_area(rect: egui::Rect) -> Option<egui::Rect> {
    orb(rect).map(|(center, _)| area(center))
}

fn area(center: Pos2) -> egui::Rect {
    egui::Rect::from_center_size(center, Vec2::splat(2.0 * RADIUS + 8.0))
}

/// Draws the orb in the top-right corner of `rect` and applies a drag on it (egui gives the
/// press to the orb, registered last, rather than to the view's tools under it).
pub fn show(ui: &egui::Ui, rect: egui::Rect, doc: &mut Document) {
    let Some((center, _)) = orb(rect) else {
        return;
    };
    let response = ui
        .interact(area(center), egui::Id::unique("sun handle"), Sense::click_and_drag())
        .on_hover_text("The sun: drag to turn it (a filled dot is behind the cloud, a ring behind you); double-click resets");
    let scene = doc.scene();
    let here = orb_position(&scene.camera, &scene.light);
    if response.double_clicked() {
        let mut light = scene.light.clone();
        light.sun_azimuth_deg = limits::SUN_AZIMUTH.default as f32;
        light.sun_elevation_deg = limits::SUN_ELEVATION.default as f32;
        doc.apply(Edit::SetLight(light), None);
    } else if response.dragged()
        && let Some(pointer) = response.interact_pointer_pos()
    {
        let p = (pointer - center) / RADIUS;
        // The hemisphere the drag began on stays (a drag across the rim would flip the sun
        // through the viewer's back in one jump otherwise).
        let toward = ui.memory_mut(|m| {
            *m.data
                .get_temp_mut_or_insert_with(response.id, || here.z >= 0.0)
        });
        let (azimuth, elevation) = sun_at(&scene.camera, glam::Vec2::new(p.x, -p.y), toward);
        let mut light = scene.light.clone();
        light.sun_azimuth_deg = azimuth;
        light.sun_elevation_deg = elevation;
        doc.apply(Edit::SetLight(light), Some(MERGE));
    }
    if !response.dragged() {
        ui.memory_mut(|m| m.data.remove::<bool>(response.id));
    }
    paint(
        ui,
        center,
        doc.scene(),
        response.hovered() || response.dragged(),
    );
}

fn paint(ui: &egui::Ui, center: Pos2, scene: &crate::scene::Scene, active: bool) {
    let painter = ui.painter();
    let alpha = if active { 200 } else { 110 };
    painter.circle(
        center,
        RADIUS,
        Color32::from_black_alpha(alpha / 3),
        Stroke::new(1.0, Color32::from_white_alpha(alpha)),
    );
    // The horizon: the world's ground plane seen from the camera, an ellipse on the orb.
    let camera = &scene.camera;
    let horizon: Vec<Pos2> = (0..=48)
        .map(|i| {
            let a = i as f32 / 48.0 * std::f32::consts::TAU;
            let d = Vec3::new(a.cos(), 0.0, a.sin());
            center + Vec2::new(d.dot(camera.right()), -d.dot(camera.up())) * RADIUS
        })
        .collect();
    painter.add(egui::Shape::line(
        horizon,
        Stroke::new(1.0, Color32::from_white_alpha(alpha / 2)),
    ));
    let p = orb_position(camera, &scene.light);
    let at = center + Vec2::new(p.x, -p.y) * RADIUS;
    // The sun's colour: as picked, or the physical sky's (its hue, at full brightness; a sun
    // below the horizon, which lights nothing, grey).
    let colour = if scene.light.physical_sky {
        let light = scene.light.sun_light();
        let top = light.max_element();
        if top > 0.0 {
            (light / top)
                .to_array()
                .map(crate::render::tone::linear_to_srgb)
        } else {
            [0.4; 3]
        }
    } else {
        scene.light.sun_color
    };
    let [r, g, b] = colour.map(|c| (c.clamp(0.0, 1.0) * 255.0) as u8);
    let sun = Color32::from_rgb(r, g, b);
    if p.z < 0.0 {
        painter.circle_filled(at, 7.0, sun);
    } else {
        painter.circle_stroke(at, 6.0, Stroke::new(2.5, sun));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_of_the_orb_gives_back_the_sun_it_shows() {
        let mut camera = OrbitCamera::default();
        camera.yaw_deg += 37.0;
        camera.pitch_deg = 20.0;
        for (az, el) in [(20.0, 35.0), (200.0, 10.0), (300.0, 60.0), (95.0, -20.0)] {
            let light = Lighting {
                sun_azimuth_deg: az,
                sun_elevation_deg: el,
                ..Lighting::default()
            };
            let p = orb_position(&camera, &light);
            let (a, e) = sun_at(&camera, glam::Vec2::new(p.x, p.y), p.z >= 0.0);
            let back = Lighting {
                sun_azimuth_deg: a,
                sun_elevation_deg: e,
                ..Lighting::default()
            };
            assert!(
                back.sun_direction().dot(light.sun_direction()) > 0.9999,
                "({az}, {el}) came back as ({a}, {e})"
            );
        }
    }

    #[test]
    fn dragging_toward_the_top_of_the_orb_raises_the_sun() {
        let camera = OrbitCamera::default();
        let (_, low) = sun_at(&camera, glam::Vec2::new(0.6, 0.1), false);
        let (_, high) = sun_at(&camera, glam::Vec2::new(0.6, 0.7), false);
        assert!(high > low + 20.0, "{low} then {high}");
        // Off the disk: on the rim, a sun on the horizon of the view.
        let (_, e) = sun_at(&camera, glam::Vec2::new(3.0, 0.0), true);
        assert!(e.abs() < 45.0);
    }
}
