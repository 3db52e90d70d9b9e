//! The Sketch and Cut tools (Wither et al. §2): capturing a stroke in the viewport, however its
//! samples fall into frames, and placing its drawing plane.

use egui::{Color32, Pos2, Rect, Stroke};
use glam::Vec3;

use super::{Shared, ToolContext, ViewInput, ViewTool};
use crate::derive::Shape;
use crate::scene::{Document, DrawingPlane, Edit, MAX_PLANE_POINTS, MAX_PLANES, StrokeKind};
use crate::seeded::hash64;
use crate::ui::projection::ndc;
use crate::ui::selection::{Item, Selection};
use crate::ui::transform::drawing_axes;

/// A stroke being captured: its screen points and pen pressure.
#[derive(Default)]
pub struct StrokeCapture {
    /// Screen points of the stroke being drawn.
    pub stroke: Vec<Pos2>,
    /// Pen pressure at each point of `stroke`, where the platform reports one.
    pressure: Vec<Option<f32>>,
    /// A stroke is being drawn (between drag start and stop).
    drawing: bool,
    /// The primary button last went down on the view itself (not on a handle over it).
    pressed_on_view: bool,
}

/// Sketch: a drag draws a cloud's outline.
#[derive(Default)]
pub struct SketchTool {
    capture: StrokeCapture,
    /// New outlines land behind the cloud (the far side under the stroke's start) instead of
    /// in front of it (Q).
    pub behind: bool,
}

/// Cut: a drag draws a line; the cloud below it is removed (a flat base).
#[derive(Default)]
pub struct CutTool {
    capture: StrokeCapture,
}

impl ViewTool for SketchTool {
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, _: &Shared) -> bool {
        let placement = if self.behind {
            Placement::Behind
        } else {
            Placement::Front
        };
        self.capture
            .input_into_plane(view, tc, StrokeKind::Outline, placement);
        true
    }

    fn cancel(&mut self, _: &mut Document) -> bool {
        self.capture.cancel()
    }

    fn overlay(&self, painter: &egui::Painter) {
        self.capture.overlay(painter, Color32::WHITE);
    }

    fn hint(&self, doc: &Document, _: &Selection, _: &Shared) -> Option<String> {
        (doc.scene().planes.is_empty() && self.capture.stroke.is_empty())
            .then(|| "Drag to draw a cloud's outline".to_owned())
    }
}

impl ViewTool for CutTool {
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, _: &Shared) -> bool {
        self.capture
            .input_into_plane(view, tc, StrokeKind::Cut, Placement::Front);
        true
    }

    fn cancel(&mut self, _: &mut Document) -> bool {
        self.capture.cancel()
    }

    fn overlay(&self, painter: &egui::Painter) {
        self.capture
            .overlay(painter, Color32::from_rgb(255, 150, 60));
    }

    fn hint(&self, doc: &Document, _: &Selection, _: &Shared) -> Option<String> {
        (doc.scene().planes.is_empty() && self.capture.stroke.is_empty())
            .then(|| "Drag to draw a cut line: the cloud is removed below it".to_owned())
    }
}

/// Whether recorded samples are a drag, not a click: several points spread over more than a
/// few points of the screen.
fn is_drag(samples: &[(Pos2, Option<f32>)]) -> bool {
    let Some(&(first, _)) = samples.first() else {
        return false;
    };
    samples.len() >= 3 && samples.iter().any(|(p, _)| p.distance(first) > 6.0)
}

/// A stroke's pen pressure, one value per point, when a pen drew it (any sample has a
/// pressure); points without one (the press itself, samples from egui's events) take the
/// nearest earlier value, or the first one known. Empty for the mouse and touch.
fn pen_pressure(samples: &[Option<f32>]) -> Vec<f32> {
    let Some(first) = samples.iter().flatten().next().copied() else {
        return Vec::new();
    };
    let mut last = first;
    samples
        .iter()
        .map(|p| {
            last = p.unwrap_or(last);
            last
        })
        .collect()
}

/// A finished stroke: its screen points (clipped to the view), its pen pressure and, when
/// points were clipped, a warning saying so.
type Finished = (Vec<Pos2>, Vec<f32>, Option<String>);

impl StrokeCapture {
    /// Takes this frame's pointer samples; once the stroke is finished, places it as a
    /// drawing plane of `kind` on the `placement` side of the cloud.
    fn input_into_plane(
        &mut self,
        view: &ViewInput<'_>,
        tc: &mut ToolContext<'_>,
        kind: StrokeKind,
        placement: Placement,
    ) {
        if let Some((stroke, pressure, clipped)) = self.input(view, tc) {
            let now = view.ui.input(|i| i.time);
            let stroke = (&stroke[..], &pressure[..]);
            finish_stroke(now, view.rect, stroke, clipped, kind, placement, tc);
        }
    }

    /// Drops the stroke being drawn; returns whether there was one.
    fn cancel(&mut self) -> bool {
        let had = !self.stroke.is_empty();
        self.stroke.clear();
        self.pressure.clear();
        self.drawing = false;
        had
    }

    /// Takes this frame's pointer samples into the stroke; returns the stroke once it is
    /// finished.
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>) -> Option<Finished> {
        let (ui, response, rect) = (view.ui, view.response, view.rect);
        ui.input(crate::ui::platform::record_frame);
        let (alt, multi) = ui.input(|i| (i.modifiers.alt, i.multi_touch().is_some()));
        if alt || multi {
            self.cancel();
            // An orbit, not a stroke: its recorded press is dropped.
            let _ = crate::ui::press_record::take_finished_press();
            return None;
        }
        // Every pointer sample since the last frame, not one position per frame: on a slow
        // adapter a frame can hold a dozen samples of a fast stroke.
        let samples = crate::ui::press_record::take_pointer_samples();
        // A whole press → release recorded (see `quick` below).
        let press = crate::ui::press_record::take_finished_press();
        // The stroke starts from the recorded press, which holds this frame's samples too; a
        // press the record missed starts where egui saw the button go down.
        let mut seeded = false;
        if response.drag_started_by(egui::PointerButton::Primary) {
            // Every sample since the button went down, not just where it went down: egui
            // recognises the drag a frame or more after the press, and those frames hold the
            // stroke's start (this frame's samples among them).
            let so_far = crate::ui::press_record::press_samples();
            seeded = !so_far.is_empty();
            (self.stroke, self.pressure) = so_far.into_iter().unzip();
            if !seeded
                && let Some(p) = ui
                    .input(|i| i.pointer.press_origin())
                    .or(response.interact_pointer_pos())
            {
                self.stroke.push(p);
                self.pressure.push(None);
            }
            self.drawing = true;
        }
        if self.drawing && !seeded {
            for (p, pressure) in samples {
                if self.stroke.last() != Some(&p) && self.stroke.len() < MAX_PLANE_POINTS {
                    self.stroke.push(p);
                    self.pressure.push(pressure);
                }
            }
        }
        let now = ui.input(|i| i.time);
        // A whole stroke egui never saw as a drag (the press and the release within one long
        // frame, or in two, on a slow adapter, with the moves between them): every sample was
        // recorded, so it is drawn all the same, if the press landed on the view itself.
        if ui.input(|i| i.pointer.primary_pressed()) {
            self.pressed_on_view = response.hovered();
        }
        let quick = press.filter(|p| {
            self.pressed_on_view
                && ui.input(|i| i.pointer.primary_released())
                && !self.drawing
                && is_drag(p)
                && rect.contains(p[0].0)
                && !response.drag_stopped_by(egui::PointerButton::Primary)
        });
        if response.clicked_by(egui::PointerButton::Primary) && quick.is_none() {
            tc.notices.error(
                now,
                "A click draws nothing: drag to draw an outline (a cut: a line across the cloud)",
            );
        }
        if let Some(p) = &quick {
            self.stroke = p.iter().map(|s| s.0).collect();
            self.pressure = p.iter().map(|s| s.1).collect();
        }
        if !(response.drag_stopped_by(egui::PointerButton::Primary) || quick.is_some()) {
            return None;
        }
        self.drawing = false;
        let mut stroke = std::mem::take(&mut self.stroke);
        let pressure = pen_pressure(&std::mem::take(&mut self.pressure));
        // A stroke that leaves the view (over the side panel, off the window) is clipped to
        // the view's edge, and the user is told.
        let outside = stroke.iter().filter(|p| !rect.contains(**p)).count();
        for p in &mut stroke {
            *p = rect.clamp(*p);
        }
        let clipped = (outside > 0).then(|| {
            format!("{outside} of its points were outside the view and were moved to its edge")
        });
        Some((stroke, pressure, clipped))
    }

    /// The stroke being drawn.
    fn overlay(&self, painter: &egui::Painter, color: Color32) {
        if self.stroke.len() >= 2 {
            painter.add(egui::Shape::line(
                self.stroke.clone(),
                Stroke::new(2.0, color),
            ));
        }
    }
}

/// Which side of the cloud a new outline's plane goes through.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Placement {
    /// The near side under the stroke's start (Wither's rule).
    Front,
    /// The far side.
    Behind,
}

/// Turns a finished screen stroke into a drawing plane: parallel to the view (upright when the
/// view is near level), through the point where the first point's ray meets the cloud, or
/// through the focus point. The stroke is interpreted once, through the derivation cache.
fn finish_stroke(
    now: f64,
    rect: Rect,
    (stroke, pressure): (&[Pos2], &[f32]),
    clipped: Option<String>,
    kind: StrokeKind,
    placement: Placement,
    tc: &mut ToolContext<'_>,
) {
    let scene = tc.doc.scene();
    if scene.planes.len() >= MAX_PLANES {
        tc.notices.error(
            now,
            format!("at most {MAX_PLANES} drawing planes: delete one first"),
        );
        return;
    }
    let camera = scene.camera.clone();
    let aspect = rect.aspect_ratio();
    let Some(&first) = stroke.first() else { return };
    let first_ray = camera.ray(ndc(rect, first), aspect);
    let field = tc.derived.field(scene, Some(tc.doc.revisions().geometry));
    // Wither's rule: through the cloud's near side under the stroke's start; Behind, its far
    // side; over the sky, the focus point.
    let hit = if placement == Placement::Behind && kind == StrokeKind::Outline {
        field.surface_behind(&first_ray)
    } else {
        field.surface_under(&first_ray)
    };
    let anchor = hit.unwrap_or(camera.target);
    let (right, up, normal) = drawing_axes(&camera);
    // Each point with its pressure (when the pen gave one), so both stay paired.
    let (world, pressure): (Vec<Vec3>, Vec<Option<f32>>) = stroke
        .iter()
        .enumerate()
        .filter_map(|(i, &p)| {
            let ray = camera.ray(ndc(rect, p), aspect);
            let at = ray.hit_plane(anchor, normal).map(|t| ray.at(t))?;
            Some((at, pressure.get(i).copied()))
        })
        .unzip();
    let count = scene.planes.iter().filter(|p| p.kind == kind).count() + 1;
    let name = match kind {
        StrokeKind::Outline => format!("Outline {count}"),
        StrokeKind::Cut => format!("Cut {count}"),
    };
    let seed = hash64(scene.seed ^ ((scene.planes.len() as u64) << 32) ^ world.len() as u64);
    let mut plane = DrawingPlane::facing(name, kind, anchor, right, up, &world, seed);
    if kind == StrokeKind::Outline {
        // A new user's first cloud looks like a cloud.
        plane.billows = crate::scene::Billows::NEW;
    }
    plane.pressure = pressure.into_iter().flatten().collect();
    if plane.pressure.len() != plane.points.len() {
        plane.pressure.clear();
    }
    let mut warnings = match &*tc.derived.shape_of(&plane) {
        Shape::Unusable(e) => {
            tc.notices.error(now, format!("Stroke not used: {e}"));
            return;
        }
        Shape::Outline { warnings, .. } => warnings.clone(),
        Shape::Cut(_) => Vec::new(),
    };
    warnings.extend(clipped);
    let index = scene.planes.len();
    let name = plane.name.clone();
    if tc.doc.apply(Edit::InsertPlane(index, plane), None) {
        tc.selection.set(Item::Plane(index));
        let text = if warnings.is_empty() {
            format!("Added {name} (Ctrl+Z undoes)")
        } else {
            format!("Added {name}: {}", warnings.join("; "))
        };
        tc.notices.note(now, text);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pen_pressure_fills_the_points_without_one() {
        assert!(
            pen_pressure(&[None, None]).is_empty(),
            "a mouse stroke has none"
        );
        assert_eq!(
            pen_pressure(&[None, Some(0.2), None, Some(0.8)]),
            [0.2, 0.2, 0.2, 0.8]
        );
    }
}
