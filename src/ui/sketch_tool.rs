//! The Sketch and Cut tools and the drawing planes (Wither et al. §2): capturing a stroke in
//! the viewport, placing its plane, the plane list and each plane's controls, and the overlay
//! that shows strokes and the selected plane's grid.

use egui::{Color32, Pos2, Rect, Response, Stroke, Ui};
use glam::{EulerRot, Quat, Vec2, Vec3};

use super::app::CloudApp;
use crate::field::Field;
use crate::scene::{DrawingPlane, Edit, MAX_PLANE_POINTS, MAX_PLANES, OrbitCamera, StrokeKind};
use crate::sketch::outline;

/// What a primary drag in the viewport does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tool {
    /// Drag orbits (Blender-like camera).
    #[default]
    Navigate,
    /// Drag draws a cloud outline.
    Sketch,
    /// Drag draws a cut line (flat base).
    Cut,
    /// Drag moves the selected drawing plane parallel to the view (Shift: toward or away).
    Move,
    /// Drag turns the selected drawing plane (sideways: about the vertical; up/down: tilt).
    Rotate,
}

impl Tool {
    /// Name for the UI and the page state.
    pub fn name(self) -> &'static str {
        match self {
            Tool::Navigate => "navigate",
            Tool::Sketch => "sketch",
            Tool::Cut => "cut",
            Tool::Move => "move",
            Tool::Rotate => "rotate",
        }
    }
}

/// A message for the user (errors stay until replaced; notes fade).
#[derive(Clone, Debug)]
pub struct Notice {
    /// Text.
    pub text: String,
    /// Whether it reports a refusal.
    pub error: bool,
    /// When it was posted (egui time).
    pub at: f64,
}

/// State of the sketch tools.
#[derive(Default)]
pub struct SketchUi {
    /// Active tool.
    pub tool: Tool,
    /// Screen points of the stroke being drawn.
    pub stroke: Vec<Pos2>,
    /// Selected drawing plane.
    pub selected: Option<usize>,
    /// Last message.
    pub notice: Option<Notice>,
    /// Show every plane's grid, not only the selected one's.
    pub show_all_planes: bool,
    /// Hide strokes and grids (H), to look at the cloud alone.
    pub hide_guides: bool,
}

fn ndc(rect: Rect, p: Pos2) -> Vec2 {
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

fn project(camera: &OrbitCamera, rect: Rect, p: Vec3) -> Option<Pos2> {
    camera
        .project(p, rect.aspect_ratio())
        .map(|n| screen(rect, n))
}

impl CloudApp {
    fn notify(&mut self, ui: &Ui, text: String, error: bool) {
        self.sketch.notice = Some(Notice {
            text,
            error,
            at: ui.input(|i| i.time),
        });
    }

    /// Tool shortcuts: V navigate, D draw, C cut, G move, R rotate, H hides guides, Esc cancels
    /// a stroke (or clears the selection), Delete removes the selected plane, Ctrl+D duplicates it.
    pub(super) fn sketch_shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let (g, r) = ctx.input_mut(|i| {
            (
                i.consume_key(egui::Modifiers::NONE, egui::Key::G),
                i.consume_key(egui::Modifiers::NONE, egui::Key::R),
            )
        });
        if g {
            self.sketch.tool = Tool::Move;
        }
        if r {
            self.sketch.tool = Tool::Rotate;
        }
        let (v, d, c, esc, del, dup, h) = ctx.input_mut(|i| {
            (
                i.consume_key(egui::Modifiers::NONE, egui::Key::V),
                i.consume_key(egui::Modifiers::NONE, egui::Key::D),
                i.consume_key(egui::Modifiers::NONE, egui::Key::C),
                i.consume_key(egui::Modifiers::NONE, egui::Key::Escape),
                i.consume_key(egui::Modifiers::NONE, egui::Key::Delete),
                i.consume_key(egui::Modifiers::COMMAND, egui::Key::D),
                i.consume_key(egui::Modifiers::NONE, egui::Key::H),
            )
        });
        if h {
            self.sketch.hide_guides = !self.sketch.hide_guides;
        }
        if dup {
            self.duplicate_selected();
        } else if d {
            self.sketch.tool = Tool::Sketch;
        }
        if v {
            self.sketch.tool = Tool::Navigate;
        }
        if c {
            self.sketch.tool = Tool::Cut;
        }
        if esc {
            if self.sketch.stroke.is_empty() {
                self.sketch.selected = None;
            }
            self.sketch.stroke.clear();
        }
        if del {
            self.delete_selected();
        }
    }

    /// Stroke capture in the viewport. Returns whether the primary button draws (so the camera
    /// must not orbit with it). In Navigate, a click selects the drawing plane under the pointer.
    pub(super) fn sketch_input(&mut self, ui: &Ui, response: &Response, rect: Rect) -> bool {
        if matches!(self.sketch.tool, Tool::Navigate | Tool::Move | Tool::Rotate)
            && response.clicked()
            && let Some(p) = response.interact_pointer_pos()
        {
            self.sketch.selected = self.plane_at(rect, p);
        }
        match self.sketch.tool {
            Tool::Navigate => return false,
            Tool::Move | Tool::Rotate => return self.manipulate(ui, response, rect),
            Tool::Sketch | Tool::Cut => {}
        }
        let (alt, multi) = ui.input(|i| (i.modifiers.alt, i.multi_touch().is_some()));
        if alt || multi {
            self.sketch.stroke.clear();
            return true;
        }
        if response.drag_started_by(egui::PointerButton::Primary) {
            self.sketch.stroke.clear();
            // Start where the button went down, not where the drag was recognised.
            if let Some(p) = ui
                .input(|i| i.pointer.press_origin())
                .or(response.interact_pointer_pos())
            {
                self.sketch.stroke.push(p);
            }
        }
        if response.dragged_by(egui::PointerButton::Primary)
            && let Some(p) = response.interact_pointer_pos()
            && self
                .sketch
                .stroke
                .last()
                .is_none_or(|q| q.distance(p) >= 1.0)
            && self.sketch.stroke.len() < MAX_PLANE_POINTS
        {
            self.sketch.stroke.push(p);
        }
        if response.drag_stopped_by(egui::PointerButton::Primary) {
            let stroke = std::mem::take(&mut self.sketch.stroke);
            self.finish_stroke(ui, rect, &stroke);
        }
        true
    }

    /// Turns a finished screen stroke into a drawing plane: parallel to the view, through the
    /// point where the first point's ray meets the cloud, or through the focus point.
    fn finish_stroke(&mut self, ui: &Ui, rect: Rect, stroke: &[Pos2]) {
        if self.scene.planes.len() >= MAX_PLANES {
            self.notify(
                ui,
                format!("at most {MAX_PLANES} drawing planes: delete one first"),
                true,
            );
            return;
        }
        let kind = if self.sketch.tool == Tool::Cut {
            StrokeKind::Cut
        } else {
            StrokeKind::Outline
        };
        let camera = self.scene.camera.clone();
        let aspect = rect.aspect_ratio();
        let Some(&first) = stroke.first() else { return };
        let first_ray = camera.ray(ndc(rect, first), aspect);
        let field = Field::from_scene(&self.scene);
        let step = field
            .bounding_sphere()
            .map(|(_, r)| r / 200.0)
            .unwrap_or(0.05);
        let anchor = field.raycast(&first_ray, step).unwrap_or(camera.target);
        let normal = -camera.forward();
        let world: Vec<Vec3> = stroke
            .iter()
            .filter_map(|&p| {
                let ray = camera.ray(ndc(rect, p), aspect);
                ray.hit_plane(anchor, normal).map(|t| ray.at(t))
            })
            .collect();
        let count = self.scene.planes.iter().filter(|p| p.kind == kind).count() + 1;
        let name = match kind {
            StrokeKind::Outline => format!("Outline {count}"),
            StrokeKind::Cut => format!("Cut {count}"),
        };
        let seed = crate::render::noise::hash64(
            self.scene.seed ^ ((self.scene.planes.len() as u64) << 32) ^ world.len() as u64,
        );
        let plane = DrawingPlane::facing(
            name,
            kind,
            anchor,
            camera.right(),
            camera.up(),
            &world,
            seed,
        );
        let result = match kind {
            StrokeKind::Outline => {
                crate::sketch::interpret(&plane.stroke(), true, &plane.sketch, plane.seed)
                    .map(|s| s.warnings)
            }
            StrokeKind::Cut => crate::sketch::cut_line(&plane.stroke()).map(|_| Vec::new()),
        };
        match result {
            Err(e) => self.notify(ui, format!("Stroke not used: {e}"), true),
            Ok(warnings) => {
                let mut planes = self.scene.planes.clone();
                planes.push(plane);
                let index = planes.len() - 1;
                self.apply(Edit::SetPlanes(planes), None);
                self.sketch.selected = Some(index);
                let text = if warnings.is_empty() {
                    format!("Added {} (Ctrl+Z undoes)", self.scene.planes[index].name)
                } else {
                    format!(
                        "Added {}: {}",
                        self.scene.planes[index].name,
                        warnings.join("; ")
                    )
                };
                self.notify(ui, text, false);
            }
        }
    }

    /// Move and Rotate: a primary drag transforms the selected plane (one undo step per drag).
    /// Without a selection the drag orbits as in Navigate.
    fn manipulate(&mut self, ui: &Ui, response: &Response, rect: Rect) -> bool {
        let Some(i) = self
            .sketch
            .selected
            .filter(|&i| i < self.scene.planes.len())
        else {
            return false;
        };
        if ui.input(|i| i.modifiers.alt || i.multi_touch().is_some()) {
            return true;
        }
        if !response.dragged_by(egui::PointerButton::Primary) {
            return true;
        }
        let delta = response.drag_delta();
        if delta == egui::Vec2::ZERO {
            return true;
        }
        let camera = &self.scene.camera;
        let mut plane = self.scene.planes[i].clone();
        match self.sketch.tool {
            Tool::Move => {
                // World units per pixel at the plane's depth.
                let depth = (plane.origin - camera.eye()).dot(camera.forward()).max(0.1);
                let per_px = 2.0 * depth * (camera.fov_y_deg.to_radians() * 0.5).tan()
                    / rect.height().max(1.0);
                let shift = ui.input(|i| i.modifiers.shift);
                plane.origin += if shift {
                    camera.forward() * (delta.y * per_px)
                } else {
                    camera.right() * (delta.x * per_px) - camera.up() * (delta.y * per_px)
                };
            }
            _ => {
                const RAD_PER_PX: f32 = 0.01;
                let turn = Quat::from_axis_angle(Vec3::Y, delta.x * RAD_PER_PX)
                    * Quat::from_axis_angle(camera.right(), delta.y * RAD_PER_PX);
                plane.rotation = (turn * plane.rotation).normalize();
            }
        }
        let mut planes = self.scene.planes.clone();
        planes[i] = plane;
        self.apply(Edit::SetPlanes(planes), Some("plane-drag"));
        true
    }

    /// The drawing plane whose stroke encloses screen point `p` (outlines by their inside, cuts
    /// within a few pixels of their line), the nearest to the camera when several do.
    fn plane_at(&self, rect: Rect, p: Pos2) -> Option<usize> {
        let camera = &self.scene.camera;
        let eye = camera.eye();
        let mut best: Option<(f32, usize)> = None;
        for (i, plane) in self.scene.planes.iter().enumerate() {
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

    fn delete_selected(&mut self) {
        if let Some(i) = self
            .sketch
            .selected
            .filter(|&i| i < self.scene.planes.len())
        {
            let mut planes = self.scene.planes.clone();
            planes.remove(i);
            self.apply(Edit::SetPlanes(planes), None);
            self.sketch.selected = None;
        }
    }

    fn duplicate_selected(&mut self) {
        let Some(i) = self
            .sketch
            .selected
            .filter(|&i| i < self.scene.planes.len())
        else {
            return;
        };
        if self.scene.planes.len() >= MAX_PLANES {
            return;
        }
        let mut copy = self.scene.planes[i].clone();
        let width = copy
            .points
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.x), b.max(p.x)));
        // Behind the original by a third of its width, so the copy thickens the cloud.
        copy.origin -= copy.normal() * ((width.1 - width.0).max(0.1) / 3.0);
        copy.name = format!("{} copy", copy.name);
        copy.seed = crate::render::noise::hash64(copy.seed);
        let mut planes = self.scene.planes.clone();
        planes.insert(i + 1, copy);
        self.apply(Edit::SetPlanes(planes), None);
        self.sketch.selected = Some(i + 1);
    }

    /// Strokes of every plane, the selected plane's grid, the stroke being drawn and the notice.
    pub(super) fn sketch_overlay(&mut self, ui: &Ui, rect: Rect) {
        let painter = ui.painter_at(rect);
        let camera = &self.scene.camera;
        let planes = if self.sketch.hide_guides {
            &[][..]
        } else {
            &self.scene.planes[..]
        };
        for (i, plane) in planes.iter().enumerate() {
            let selected = self.sketch.selected == Some(i);
            if selected || self.sketch.show_all_planes {
                draw_grid(&painter, camera, rect, plane, selected);
            }
            let color = match (plane.kind, selected) {
                (StrokeKind::Cut, _) => Color32::from_rgb(255, 150, 60),
                (_, true) => Color32::from_rgb(255, 90, 90),
                _ => Color32::from_white_alpha(70),
            };
            let pts: Vec<Pos2> = plane
                .points
                .iter()
                .filter_map(|p| project(camera, rect, plane.to_world(p.extend(0.0))))
                .collect();
            if pts.len() >= 2 {
                let mut pts = pts;
                if plane.kind == StrokeKind::Outline {
                    pts.push(pts[0]);
                }
                painter.add(egui::Shape::line(
                    pts,
                    Stroke::new(if selected { 2.0 } else { 1.0 }, color),
                ));
            }
        }
        if self.sketch.stroke.len() >= 2 {
            let color = if self.sketch.tool == Tool::Cut {
                Color32::from_rgb(255, 150, 60)
            } else {
                Color32::WHITE
            };
            painter.add(egui::Shape::line(
                self.sketch.stroke.clone(),
                Stroke::new(2.0, color),
            ));
        }
        let now = ui.input(|i| i.time);
        if let Some(n) = &self.sketch.notice {
            let age = now - n.at;
            if n.error || age < 6.0 {
                let color = if n.error {
                    Color32::from_rgb(255, 140, 140)
                } else {
                    Color32::from_white_alpha(220)
                };
                painter.text(
                    rect.left_top() + egui::vec2(10.0, 10.0),
                    egui::Align2::LEFT_TOP,
                    &n.text,
                    egui::FontId::proportional(14.0),
                    color,
                );
                if !n.error {
                    ui.ctx()
                        .request_repaint_after(std::time::Duration::from_millis(500));
                }
            }
        }
        if matches!(self.sketch.tool, Tool::Move | Tool::Rotate) && self.sketch.selected.is_none() {
            painter.text(
                rect.center_top() + egui::vec2(0.0, 36.0),
                egui::Align2::CENTER_TOP,
                "Click a drawing plane (or pick one in the list) to move or rotate it",
                egui::FontId::proportional(15.0),
                Color32::from_white_alpha(200),
            );
        }
        if matches!(self.sketch.tool, Tool::Sketch | Tool::Cut)
            && self.scene.planes.is_empty()
            && self.sketch.stroke.is_empty()
        {
            let hint = if self.sketch.tool == Tool::Cut {
                "Drag to draw a cut line: the cloud is removed below it"
            } else {
                "Drag to draw a cloud's outline"
            };
            painter.text(
                rect.center_top() + egui::vec2(0.0, 36.0),
                egui::Align2::CENTER_TOP,
                hint,
                egui::FontId::proportional(15.0),
                Color32::from_white_alpha(200),
            );
        }
    }

    /// The Sketch group of the side panel: tools, the plane list and the selected plane.
    pub(super) fn sketch_group(&mut self, ui: &mut Ui) {
        egui::CollapsingHeader::new("Sketch")
            .default_open(true)
            .show(ui, |ui| {
                ui.horizontal_wrapped(|ui| {
                    for (tool, label, key) in [
                        (Tool::Navigate, "Navigate", "V"),
                        (Tool::Sketch, "✏ Sketch", "D"),
                        (Tool::Cut, "✂ Cut", "C"),
                        (Tool::Move, "✥ Move", "G"),
                        (Tool::Rotate, "⟳ Rotate", "R"),
                    ] {
                        ui.selectable_value(&mut self.sketch.tool, tool, label)
                            .on_hover_text(key);
                    }
                });
                ui.horizontal(|ui| {
                    ui.checkbox(&mut self.sketch.show_all_planes, "all grids");
                    ui.checkbox(&mut self.sketch.hide_guides, "hide guides")
                        .on_hover_text("H");
                });
                if self.scene.planes.is_empty() {
                    ui.label("No drawing planes yet. Pick Sketch and drag an outline in the view.");
                    return;
                }
                ui.label("Drawing planes:");
                for i in 0..self.scene.planes.len() {
                    let selected = self.sketch.selected == Some(i);
                    let name = self.scene.planes[i].name.clone();
                    if ui.selectable_label(selected, name).clicked() {
                        self.sketch.selected = if selected { None } else { Some(i) };
                    }
                }
                if let Some(i) = self
                    .sketch
                    .selected
                    .filter(|&i| i < self.scene.planes.len())
                {
                    ui.separator();
                    self.plane_controls(ui, i);
                }
            });
    }

    fn plane_controls(&mut self, ui: &mut Ui, i: usize) {
        let mut plane = self.scene.planes[i].clone();
        ui.label(egui::RichText::new(&plane.name).strong());
        if plane.kind == StrokeKind::Outline {
            ui.add(egui::Slider::new(&mut plane.sketch.inflate, 0.0..=1.0).text("deflate (t)"))
                .on_hover_text("0 keeps the maximal balls; 1 shrinks the big body spheres to the feature radius");
            ui.add(egui::Slider::new(&mut plane.sketch.simplify, 0.0..=0.08).text("simplify"));
            ui.add(egui::Slider::new(&mut plane.sketch.prune, 0.0..=0.2).text("prune branches"));
            ui.checkbox(&mut plane.sketch.extend, "3D extension");
            ui.add_enabled(
                plane.sketch.extend,
                egui::Slider::new(&mut plane.sketch.copies, 0..=6).text("branch copies"),
            );
        }
        ui.horizontal(|ui| {
            ui.label("move");
            for (axis, v) in ["x", "y", "z"].iter().zip(plane.origin.as_mut()) {
                ui.add(
                    egui::DragValue::new(v)
                        .speed(0.05)
                        .prefix(format!("{axis} ")),
                );
            }
        });
        let (mut yaw, mut pitch, mut roll) = plane.rotation.to_euler(EulerRot::YXZ);
        let before = (yaw, pitch, roll);
        ui.horizontal(|ui| {
            ui.label("rotate");
            for (label, v) in [
                ("yaw ", &mut yaw),
                ("pitch ", &mut pitch),
                ("roll ", &mut roll),
            ] {
                let mut deg = v.to_degrees();
                if ui
                    .add(
                        egui::DragValue::new(&mut deg)
                            .speed(0.5)
                            .prefix(label)
                            .suffix("°"),
                    )
                    .changed()
                {
                    *v = deg.to_radians();
                }
            }
        });
        if (yaw, pitch, roll) != before {
            plane.rotation = Quat::from_euler(EulerRot::YXZ, yaw, pitch, roll);
        }
        if plane != self.scene.planes[i] {
            let mut planes = self.scene.planes.clone();
            planes[i] = plane;
            self.apply(Edit::SetPlanes(planes), Some("plane"));
        }
        ui.horizontal(|ui| {
            if ui.button("Duplicate").on_hover_text("Ctrl+D").clicked() {
                self.duplicate_selected();
            }
            if ui.button("Delete").on_hover_text("Delete").clicked() {
                self.delete_selected();
            }
        });
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
