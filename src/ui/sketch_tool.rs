//! The Sketch, Cut, Move and Rotate tools (Wither et al. §2): capturing a stroke in the
//! viewport, placing its drawing plane, transforming the selected plane, and the overlay that
//! shows strokes and the selected plane's grid.

use egui::{Color32, Pos2, Rect, Response, Stroke, Ui};
use glam::{Quat, Vec2, Vec3};

use super::ellipsoids;
use super::gizmo::{Gizmo, Handle, ring_turn};
use super::notice::Notices;
use super::picking;
use super::projection::{ndc, project};
use super::selection::{Item, Selection};
use super::shortcuts::Shortcut;
use super::tool::Tool;
use super::transform::{Axis, SNAP_STEP, drag_scale, drag_turn, drawing_axes, view_move};
use crate::derive::{Derived, Shape};
use crate::scene::{
    Document, DrawingPlane, Edit, MAX_PLANE_POINTS, MAX_PLANES, OrbitCamera, StrokeKind,
};
use crate::seeded::hash64;

/// State of the sketch tools.
#[derive(Default)]
pub struct SketchTool {
    /// Active tool.
    pub tool: Tool,
    /// Screen points of the stroke being drawn.
    pub stroke: Vec<Pos2>,
    /// Pen pressure at each point of `stroke`, where the platform reports one.
    pressure: Vec<Option<f32>>,
    /// Show every plane's grid, not only the selected one's.
    pub show_all_planes: bool,
    /// Hide strokes and grids (H), to look at the cloud alone.
    pub hide_guides: bool,
    /// Show the selected outline's skeleton and spheres (K), as in Wither et al.'s Figure 4.
    pub show_skeleton: bool,
    /// A stroke is being drawn (between drag start and stop).
    drawing: bool,
    /// The primary button last went down on the view itself (not on a handle over it).
    pressed_on_view: bool,
    /// The world axis Rotate turns about (X, Y or Z), or free.
    pub axis_lock: Option<Axis>,
    /// The Move/Rotate/Scale drag under way: what it started from and the drag so far.
    gesture: Option<Gesture>,
    /// B was pressed: the next drag draws a selection box.
    box_armed: bool,
    /// The selection box being dragged: where it began and where the pointer is.
    area: Option<(Pos2, Pos2)>,
    /// New outlines land behind the cloud (the far side under the stroke's start) instead of
    /// in front of it (Q).
    pub behind: bool,
}

/// Where a selected item was when a drag began: its place, turn and radii (a plane's are ones).
type Start = (Item, Vec3, Quat, Vec3);

/// A Move, Rotate or Scale drag: the active item's place, turn and radii when it began (and
/// every selected item's, which follow it), the gizmo as it was laid out then and the handle the
/// press took, and the drag so far (the transform is taken from the whole drag, so snapping
/// sees the total).
#[derive(Clone, Debug)]
struct Gesture {
    starts: Vec<Start>,
    origin: Vec3,
    rotation: Quat,
    radii: Vec3,
    drag: Vec2,
    gizmo: Option<Gizmo>,
    handle: Option<Handle>,
    /// Turn so far about a ring's axis, and the pointer when it was last measured.
    angle: f32,
    last: Pos2,
    /// Esc or a right-click took the drag back: nothing more happens until release.
    cancelled: bool,
}

/// The pointer in the viewport this frame.
pub struct ViewInput<'a> {
    /// The viewport's `Ui`.
    pub ui: &'a Ui,
    /// The viewport's response (drags, clicks).
    pub response: &'a Response,
    /// The viewport's rectangle.
    pub rect: Rect,
}

/// What the tools need from the app for one frame.
pub struct ToolContext<'a> {
    /// The document.
    pub doc: &'a mut Document,
    /// The derivation cache (field for ray casts, stroke interpretation).
    pub derived: &'a mut Derived,
    /// The selection.
    pub selection: &'a mut Selection,
    /// Where messages go.
    pub notices: &'a mut Notices,
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

impl SketchTool {
    /// One of the tools' shortcuts: V navigate, D draw, C cut, E ellipsoid, G move, R rotate,
    /// S scale (then X, Y or Z locks the axis, the same key again frees it), H hides guides,
    /// Shift+H hides the selected item (Alt+H shows all), K shows the skeleton and spheres, Esc
    /// cancels a drag or a stroke (or clears the selection), Delete removes the selected
    /// ellipsoid or plane, Ctrl+D duplicates it. Other shortcuts are not the tools'.
    pub fn shortcut(&mut self, shortcut: Shortcut, tc: &mut ToolContext<'_>, now: f64) {
        let message = match shortcut {
            Shortcut::Tool(tool) => {
                self.tool = tool;
                None
            }
            Shortcut::BoxSelect => {
                self.box_armed = true;
                None
            }
            Shortcut::Lock(axis) => {
                if matches!(self.tool, Tool::Move | Tool::Rotate | Tool::Scale) {
                    self.axis_lock = (self.axis_lock != Some(axis)).then_some(axis);
                }
                None
            }
            Shortcut::ToggleGuides => {
                self.hide_guides = !self.hide_guides;
                None
            }
            Shortcut::ToggleSkeleton => {
                self.show_skeleton = !self.show_skeleton;
                None
            }
            Shortcut::ToggleBehind => {
                self.behind = !self.behind;
                Some(if self.behind {
                    "New outlines go behind the cloud (Q again: in front)".to_owned()
                } else {
                    "New outlines go in front of the cloud".to_owned()
                })
            }
            Shortcut::Escape => self.escape(tc),
            Shortcut::HideSelected => super::selection::toggle_hidden(tc.doc, tc.selection)
                .map(|m| format!("{m} (Shift+H again shows it, Alt+H shows all)")),
            Shortcut::ShowAll => super::selection::show_all(tc.doc),
            Shortcut::Duplicate => super::selection::duplicate(tc.doc, tc.selection),
            Shortcut::Delete => super::selection::delete(tc.doc, tc.selection),
            _ => None,
        };
        if let Some(m) = message {
            tc.notices.note(now, m);
        }
    }

    /// Esc: drops an armed or dragged selection box, else cancels the drag under way, else
    /// drops the stroke being drawn (and with none, clears the selection).
    fn escape(&mut self, tc: &mut ToolContext<'_>) -> Option<String> {
        if self.box_armed || self.area.is_some() {
            (self.box_armed, self.area) = (false, None);
        } else if self.cancel_gesture(tc.doc) {
            return Some("Cancelled: back where the drag began".to_owned());
        } else {
            if self.stroke.is_empty() {
                tc.selection.clear();
            }
            self.stroke.clear();
            self.drawing = false;
        }
        None
    }

    /// Stroke capture in the viewport. Returns whether the primary button draws (so the camera
    /// must not orbit with it). In Navigate, a click selects the drawing plane under the pointer.
    pub fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>) -> bool {
        let (ui, response, rect) = (view.ui, view.response, view.rect);
        if matches!(
            self.tool,
            Tool::Navigate | Tool::Move | Tool::Rotate | Tool::Scale
        ) && response.clicked()
            && let Some(p) = response.interact_pointer_pos()
        {
            // A drawing plane whose stroke is under the click, an ellipsoid whose indicator it
            // touches, else the ellipsoid that shapes the cloud there; Shift adds or removes.
            let shift = ui.input(|i| i.modifiers.shift);
            let indicators = self.indicators_shown();
            match picking::item_at(tc.doc, tc.derived, rect, p, indicators) {
                Some(item) if shift => tc.selection.toggle(item),
                Some(item) => tc.selection.set(item),
                None if shift => {}
                None => tc.selection.clear(),
            }
        }
        if self.select_box(view, tc) {
            return true;
        }
        if self.tool == Tool::Ellipsoid
            && response.clicked()
            && let Some(p) = response.interact_pointer_pos()
            && let Some(m) = ellipsoids::add_at(tc.doc, tc.derived, tc.selection, rect, p)
        {
            tc.notices.note(ui.input(|i| i.time), m);
        }
        match self.tool {
            Tool::Navigate | Tool::Ellipsoid => return false,
            Tool::Move | Tool::Rotate | Tool::Scale => return self.manipulate(view, tc),
            Tool::Sketch | Tool::Cut => {}
        }
        ui.input(super::platform::record_frame);
        let (alt, multi) = ui.input(|i| (i.modifiers.alt, i.multi_touch().is_some()));
        if alt || multi {
            self.stroke.clear();
            self.drawing = false;
            // An orbit, not a stroke: its recorded press is dropped.
            let _ = super::press_record::take_finished_press();
            return true;
        }
        // Every pointer sample since the last frame, not one position per frame: on a slow
        // adapter a frame can hold a dozen samples of a fast stroke.
        let samples = super::press_record::take_pointer_samples();
        // A whole press → release recorded (see `quick` below).
        let press = super::press_record::take_finished_press();
        // The stroke starts from the recorded press, which holds this frame's samples too; a
        // press the record missed starts where egui saw the button go down.
        let mut seeded = false;
        if response.drag_started_by(egui::PointerButton::Primary) {
            // Every sample since the button went down, not just where it went down: egui
            // recognises the drag a frame or more after the press, and those frames hold the
            // stroke's start (this frame's samples among them).
            let so_far = super::press_record::press_samples();
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
        if response.drag_stopped_by(egui::PointerButton::Primary) || quick.is_some() {
            self.drawing = false;
            let mut stroke = std::mem::take(&mut self.stroke);
            let pressure = pen_pressure(&std::mem::take(&mut self.pressure));
            // A stroke that leaves the view (over the side panel, off the window) is clipped
            // to the view's edge, and the user is told.
            let outside = stroke.iter().filter(|p| !rect.contains(**p)).count();
            for p in &mut stroke {
                *p = rect.clamp(*p);
            }
            let clipped = (outside > 0).then(|| {
                format!("{outside} of its points were outside the view and were moved to its edge")
            });
            self.finish_stroke(now, rect, (&stroke, &pressure), clipped, tc);
        }
        true
    }

    /// Turns a finished screen stroke into a drawing plane: parallel to the view, through the
    /// point where the first point's ray meets the cloud, or through the focus point. The
    /// stroke is interpreted once, through the derivation cache.
    fn finish_stroke(
        &mut self,
        now: f64,
        rect: Rect,
        (stroke, pressure): (&[Pos2], &[f32]),
        clipped: Option<String>,
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
        let kind = if self.tool == Tool::Cut {
            StrokeKind::Cut
        } else {
            StrokeKind::Outline
        };
        let camera = scene.camera.clone();
        let aspect = rect.aspect_ratio();
        let Some(&first) = stroke.first() else { return };
        let first_ray = camera.ray(ndc(rect, first), aspect);
        let field = tc.derived.field(scene, Some(tc.doc.revisions().geometry));
        // Wither's rule: through the cloud's near side under the stroke's start; Behind, its
        // far side; over the sky, the focus point.
        let hit = if self.behind && kind == StrokeKind::Outline {
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

    /// Whether every ellipsoid's indicator is drawn (and can be clicked).
    fn indicators_shown(&self) -> bool {
        !self.hide_guides
            && (self.show_all_planes
                || matches!(
                    self.tool,
                    Tool::Ellipsoid | Tool::Move | Tool::Rotate | Tool::Scale
                ))
    }

    /// Box selection: after B, or with Move, Rotate or Scale and nothing selected, a drag draws
    /// a box and selects every plane and ellipsoid whose centre it holds (Shift adds to the
    /// selection). Returns whether the drag is a box (so the camera stays).
    fn select_box(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>) -> bool {
        let (ui, response, rect) = (view.ui, view.response, view.rect);
        if response.drag_started_by(egui::PointerButton::Primary) {
            let empty = matches!(self.tool, Tool::Move | Tool::Rotate | Tool::Scale)
                && self.target(tc.doc, tc.selection).is_none();
            if self.box_armed || empty {
                let from = ui
                    .input(|i| i.pointer.press_origin())
                    .or(response.interact_pointer_pos());
                self.area = from.map(|p| (p, p));
            }
        }
        let Some((from, _)) = self.area else {
            return false;
        };
        let to = response
            .interact_pointer_pos()
            .map_or(from, |p| rect.clamp(p));
        self.area = Some((from, to));
        if !response.dragged_by(egui::PointerButton::Primary) {
            let shift = ui.input(|i| i.modifiers.shift);
            let items = picking::items_in(tc.doc, rect, Rect::from_two_pos(from, to));
            let now = ui.input(|i| i.time);
            tc.notices.note(
                now,
                format!(
                    "Selected {} item{}",
                    items.len(),
                    if items.len() == 1 { "" } else { "s" }
                ),
            );
            tc.selection.select_all(items, shift);
            self.area = None;
            self.box_armed = false;
        }
        true
    }

    /// Takes back the Move/Rotate/Scale drag under way (Esc, right-click); returns whether
    /// there was one.
    fn cancel_gesture(&mut self, doc: &mut Document) -> bool {
        let Some(g) = self.gesture.as_mut().filter(|g| !g.cancelled) else {
            return false;
        };
        g.cancelled = true;
        doc.revert_merge("drag");
        true
    }

    /// The item a Move/Rotate/Scale drag places its gizmo on, and where it is.
    fn target(&self, doc: &Document, selection: &Selection) -> Option<Start> {
        // The active item; Scale reshapes ellipsoids only, so it takes the last one selected.
        let item = match self.tool {
            Tool::Scale => selection.ellipsoid().map(Item::Ellipsoid),
            _ => selection.active(),
        }?;
        start_of(doc, item)
    }

    /// The gizmo of the current tool on the selected item, as drawn this frame.
    pub fn gizmo(&self, doc: &Document, selection: &Selection, rect: Rect) -> Option<Gizmo> {
        if self.hide_guides {
            return None;
        }
        let (_, origin, rotation, _) = self.target(doc, selection)?;
        Gizmo::layout(self.tool, &doc.scene().camera, rect, origin, rotation)
    }

    /// Move, Rotate and Scale: a primary drag transforms the selected plane or ellipsoid (one
    /// undo step per drag). A press on a gizmo handle constrains the drag to its axis (or ring);
    /// elsewhere X/Y/Z locks do. Esc or a right-click cancels. Without a selection the drag
    /// orbits as in Navigate.
    fn manipulate(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>) -> bool {
        let (ui, response, rect) = (view.ui, view.response, view.rect);
        let Some((_, origin, rotation, radii)) = self.target(tc.doc, tc.selection) else {
            return false;
        };
        if ui.input(|i| i.modifiers.alt || i.multi_touch().is_some()) {
            return true;
        }
        if !response.dragged_by(egui::PointerButton::Primary) {
            self.gesture = None;
            return true;
        }
        let camera = tc.doc.scene().camera.clone();
        if response.drag_started() || self.gesture.is_none() {
            let press = ui
                .input(|i| i.pointer.press_origin())
                .or(response.interact_pointer_pos())
                .unwrap_or(rect.center());
            let gizmo = Gizmo::layout(self.tool, &camera, rect, origin, rotation);
            let starts = (tc.selection.items().iter())
                .filter(|i| self.tool != Tool::Scale || i.ellipsoid().is_some())
                .filter_map(|&i| start_of(tc.doc, i))
                .collect();
            self.gesture = Some(Gesture {
                starts,
                origin,
                rotation,
                radii,
                drag: Vec2::ZERO,
                // An axis locked from the keyboard wins over the handle under the press.
                handle: gizmo
                    .as_ref()
                    .filter(|_| self.axis_lock.is_none())
                    .and_then(|g| g.hit(press)),
                gizmo,
                angle: 0.0,
                last: press,
                cancelled: false,
            });
        }
        if ui.input(|i| i.pointer.button_pressed(egui::PointerButton::Secondary))
            && self.cancel_gesture(tc.doc)
        {
            let now = ui.input(|i| i.time);
            tc.notices.note(now, "Cancelled: back where the drag began");
        }
        let lock = self.axis_lock;
        let Some(g) = self.gesture.as_mut().filter(|g| !g.cancelled) else {
            return true;
        };
        let delta = response.drag_delta();
        let pointer = response.interact_pointer_pos().unwrap_or(g.last);
        if delta == egui::Vec2::ZERO && pointer == g.last {
            return true;
        }
        g.drag += Vec2::new(delta.x, delta.y);
        let snap = ui.input(|i| i.modifiers.ctrl || i.modifiers.command);
        let handle_axis = match g.handle {
            Some(Handle::Axis(a)) => Some(a),
            _ => None,
        };
        let (mut origin, mut rotation, mut radii) = (g.origin, g.rotation, g.radii);
        match self.tool {
            Tool::Move => match (handle_axis.or(lock), &g.gizmo) {
                (Some(axis), Some(gizmo)) => {
                    origin += gizmo.along(axis, g.drag).map_or(Vec3::ZERO, |(_, w)| w);
                }
                _ => {
                    let depth = (g.origin - camera.eye()).dot(camera.forward()).max(0.1);
                    let per_px = camera.world_per_px(depth, rect.height());
                    let toward = ui.input(|i| i.modifiers.shift);
                    origin += view_move(&camera, g.drag, per_px, toward);
                }
            },
            Tool::Scale => {
                let factor = match (handle_axis, &g.gizmo) {
                    (Some(axis), Some(gizmo)) => {
                        let px = gizmo.along(axis, g.drag).map_or(0.0, |(px, _)| px);
                        drag_scale(Vec2::new(px, 0.0), Some(axis), snap)
                    }
                    _ => drag_scale(g.drag, lock, snap),
                };
                radii = (g.radii * factor).clamp(Vec3::splat(0.01), Vec3::splat(1e4));
            }
            _ => match (handle_axis, &g.gizmo) {
                (Some(axis), Some(gizmo)) => {
                    let toward_viewer = -axis.vector().dot(camera.forward());
                    g.angle += ring_turn(gizmo.center, g.last, pointer, toward_viewer);
                    let angle = if snap {
                        (g.angle / SNAP_STEP).round() * SNAP_STEP
                    } else {
                        g.angle
                    };
                    rotation =
                        (Quat::from_axis_angle(axis.vector(), angle) * g.rotation).normalize();
                }
                _ => {
                    let turn = drag_turn(g.drag, lock, snap, camera.right());
                    rotation = (turn * g.rotation).normalize();
                }
            },
        }
        g.last = pointer;
        if snap && self.tool == Tool::Move {
            // Ctrl snaps the move to tenths of a world unit.
            origin = g.origin + ((origin - g.origin) * 10.0).round() / 10.0;
        }
        // Every selected item follows the active one: the same shift, the same turn and the
        // same scale, each about its own centre.
        let turn = rotation * g.rotation.inverse();
        let factor = radii / g.radii;
        let moved: Vec<Start> = (g.starts.iter())
            .map(|&(i, o, r, rad)| {
                let rad = (rad * factor).clamp(Vec3::splat(0.01), Vec3::splat(1e4));
                (i, o + (origin - g.origin), (turn * r).normalize(), rad)
            })
            .collect();
        apply_starts(tc.doc, &moved);
        true
    }

    /// Strokes of every plane, the selected plane's grid (and, with K, its skeleton and
    /// spheres), the stroke being drawn and the hints.
    pub fn overlay(
        &self,
        ui: &Ui,
        rect: Rect,
        doc: &Document,
        derived: &Derived,
        selection: &Selection,
    ) {
        let painter = ui.painter_at(rect);
        let scene = doc.scene();
        let camera = &scene.camera;
        if !self.hide_guides {
            // Every ellipsoid's indicator while a modelling tool is out (noise can hide a
            // primitive), the selected one bright.
            let all = matches!(
                self.tool,
                Tool::Ellipsoid | Tool::Move | Tool::Rotate | Tool::Scale
            );
            for (i, e) in scene.ellipsoids.iter().enumerate() {
                let selected = selection.contains(Item::Ellipsoid(i));
                if selected || all || self.show_all_planes {
                    draw_ellipsoid(&painter, camera, rect, e, selected);
                }
            }
        }
        if let Some(gizmo) = self.gizmo(doc, selection, rect) {
            let active = self
                .gesture
                .as_ref()
                .filter(|g| !g.cancelled)
                .and_then(|g| g.handle);
            let hovered = ui
                .input(|i| i.pointer.hover_pos())
                .and_then(|p| gizmo.hit(p));
            gizmo.draw(&painter, active, hovered);
        }
        if self.show_skeleton
            && !self.hide_guides
            && let Some(plane) = selection.plane().and_then(|i| scene.planes.get(i))
            && let Some(shape) = derived.derived_shape(plane)
            && let Shape::Outline {
                spheres, skeleton, ..
            } = &*shape
        {
            draw_skeleton(&painter, camera, rect, plane, spheres, skeleton);
        }
        let planes = if self.hide_guides {
            &[][..]
        } else {
            &scene.planes[..]
        };
        for (i, plane) in planes.iter().enumerate() {
            let selected = selection.contains(Item::Plane(i));
            if selected || self.show_all_planes {
                draw_grid(&painter, camera, rect, plane, selected);
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
        if let Some((from, to)) = self.area {
            let area = Rect::from_two_pos(from, to);
            painter.rect_filled(area, 0.0, Color32::from_white_alpha(18));
            painter.rect_stroke(
                area,
                0.0,
                Stroke::new(1.0, Color32::from_white_alpha(180)),
                egui::StrokeKind::Inside,
            );
        }
        if self.stroke.len() >= 2 {
            let color = if self.tool == Tool::Cut {
                Color32::from_rgb(255, 150, 60)
            } else {
                Color32::WHITE
            };
            painter.add(egui::Shape::line(
                self.stroke.clone(),
                Stroke::new(2.0, color),
            ));
        }
        let lock_hint;
        let lock = |free: &'static str| match self.axis_lock {
            Some(a) => format!(
                "Locked to {} (X/Y/Z: another axis, {} again: free) · Ctrl snaps · Esc or right-click cancels",
                a.name(),
                a.name()
            ),
            None => free.to_owned(),
        };
        let hint = match self.tool {
            _ if self.box_armed || self.area.is_some() => {
                Some("Drag a box round what to select (Shift adds to the selection) · Esc cancels")
            }
            Tool::Move | Tool::Rotate if selection.is_empty() => Some(
                "Click a drawing plane or the cloud (Shift adds), or drag a box round several, to move or turn them",
            ),
            Tool::Ellipsoid => Some("Click to add an ellipsoid there (a drag orbits)"),
            Tool::Scale if selection.ellipsoid().is_none() => {
                Some("Scale works on ellipsoids: click the cloud (or pick one in the list)")
            }
            Tool::Move => {
                lock_hint = lock(
                    "Drag an arrow to move along it, elsewhere to move in the view (Shift: toward you) · X/Y/Z lock · Esc cancels",
                );
                Some(lock_hint.as_str())
            }
            Tool::Scale => {
                lock_hint = lock(
                    "Drag a box to scale one axis, elsewhere right or up to grow · Ctrl snaps to tenths · Esc cancels",
                );
                Some(lock_hint.as_str())
            }
            Tool::Rotate => {
                lock_hint = lock(
                    "Drag a ring to turn about its axis, elsewhere to turn freely · Ctrl snaps to 15° · Esc cancels",
                );
                Some(lock_hint.as_str())
            }
            Tool::Sketch if scene.planes.is_empty() && self.stroke.is_empty() => {
                Some("Drag to draw a cloud's outline")
            }
            Tool::Cut if scene.planes.is_empty() && self.stroke.is_empty() => {
                Some("Drag to draw a cut line: the cloud is removed below it")
            }
            _ => None,
        };
        if let Some(hint) = hint {
            painter.text(
                rect.center_top() + egui::vec2(0.0, 36.0),
                egui::Align2::CENTER_TOP,
                hint,
                egui::FontId::proportional(15.0),
                Color32::from_white_alpha(200),
            );
        }
    }
}

/// Where `item` is now, if the document has it.
fn start_of(doc: &Document, item: Item) -> Option<Start> {
    let scene = doc.scene();
    match item {
        Item::Plane(i) => scene
            .planes
            .get(i)
            .map(|p| (item, p.origin, p.rotation, Vec3::ONE)),
        Item::Ellipsoid(i) => scene
            .ellipsoids
            .get(i)
            .map(|e| (item, e.center, e.rotation, e.radii)),
    }
}

/// Puts items where a drag took them, folded into the drag's one undo step.
fn apply_starts(doc: &mut Document, items: &[Start]) {
    let mut ellipsoids = doc.scene().ellipsoids.clone();
    for &(item, origin, rotation, radii) in items {
        match item {
            Item::Plane(i) => {
                let Some(p) = doc.scene().planes.get(i) else {
                    continue;
                };
                let mut p = (**p).clone();
                (p.origin, p.rotation) = (origin, rotation);
                doc.apply(Edit::SetPlane(i, p), Some("drag"));
            }
            Item::Ellipsoid(i) => {
                if let Some(slot) = ellipsoids.get_mut(i) {
                    let mut e = (**slot).clone();
                    (e.center, e.rotation, e.radii) = (origin, rotation, radii);
                    *slot = std::sync::Arc::new(e);
                }
            }
        }
    }
    doc.apply(Edit::SetEllipsoids(ellipsoids), Some("drag"));
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

    /// A stroke through egui as the window gets it: the pointer over the view, then pressed at
    /// the right of a circle, 60 moves around it and the release, those events split over
    /// `frames` frames 0.15 s apart (a slow adapter's), then two idle frames. Returns each drawing plane's
    /// point count.
    fn stroke_over_frames(frames: usize) -> Vec<usize> {
        let tool = SketchTool {
            tool: Tool::Sketch,
            ..Default::default()
        };
        let doc = Document::new(crate::scene::Scene::preset(crate::scene::Preset::Empty));
        let (doc, _) = draw_circle(doc, tool, frames, 120.0);
        doc.scene().planes.iter().map(|p| p.points.len()).collect()
    }

    /// Draws a circle of `radius` points about the view's centre with `tool` over `doc`, its
    /// events split over `frames` frames; returns the document and the tool.
    fn draw_circle(
        mut doc: Document,
        mut tool: SketchTool,
        frames: usize,
        radius: f32,
    ) -> (Document, SketchTool) {
        use egui::{Event, Modifiers, PointerButton, RawInput, Sense, pos2};
        let rect = crate::ui::test_view();
        let at = |i: usize| {
            let a = i as f32 / 60.0 * std::f32::consts::TAU;
            pos2(640.0 + radius * a.cos(), 400.0 + radius * a.sin())
        };
        let button = |pressed| Event::PointerButton {
            pos: at(60),
            button: PointerButton::Primary,
            pressed,
            modifiers: Modifiers::NONE,
        };
        let mut events = vec![button(true)];
        events.extend((1..=60).map(|i| Event::PointerMoved(at(i))));
        events.push(button(false));
        let per_frame = events.len().div_ceil(frames);
        // A frame with the pointer over the view first (egui hit-tests against the last frame).
        let mut chunks = vec![vec![Event::PointerMoved(at(0))]];
        chunks.extend(events.chunks(per_frame).map(<[_]>::to_vec));
        chunks.extend([Vec::new(), Vec::new()]);

        let ctx = egui::Context::default();
        let (mut derived, mut selection, mut notices) = Default::default();
        for (frame, events) in chunks.into_iter().enumerate() {
            let raw = RawInput {
                screen_rect: Some(rect),
                time: Some(frame as f64 * 0.15),
                events,
                ..Default::default()
            };
            let mut output = ctx.run_ui(raw, |ui| {
                let response = ui.allocate_rect(rect, Sense::click_and_drag());
                let view = ViewInput {
                    ui,
                    response: &response,
                    rect,
                };
                let mut tc = ToolContext {
                    doc: &mut doc,
                    derived: &mut derived,
                    selection: &mut selection,
                    notices: &mut notices,
                };
                tool.input(&view, &mut tc);
            });
            // No painter here: the font atlas's first upload is dropped on purpose.
            output.textures_delta.clear();
        }
        (doc, tool)
    }

    /// The depth along the view of the plane a small outline drawn over the default cumulus's
    /// middle lands on, in front or behind.
    fn outline_depth(behind: bool) -> f32 {
        let scene = crate::scene::Scene::default();
        let camera = scene.camera.clone();
        let tool = SketchTool {
            tool: Tool::Sketch,
            behind,
            ..Default::default()
        };
        let (doc, _) = draw_circle(Document::new(scene), tool, 5, 40.0);
        let plane = doc.scene().planes.last().expect("a plane").clone();
        (plane.origin - camera.eye()).dot(camera.forward())
    }

    #[test]
    fn an_outline_over_the_cloud_lands_in_front_or_behind_it() {
        let target = {
            let c = crate::scene::Scene::default().camera;
            (c.target - c.eye()).dot(c.forward())
        };
        let (front, back) = (outline_depth(false), outline_depth(true));
        // In front: nearer than the focus point (the cloud's near side); behind: beyond it.
        assert!(front < target - 0.5, "front {front} vs focus {target}");
        assert!(back > target + 0.5, "behind {back} vs focus {target}");
    }

    #[test]
    fn a_view_near_level_draws_on_vertical_planes() {
        let mut camera = crate::scene::Scene::default().camera;
        assert!((camera.pitch_deg - 8.0).abs() < 1e-3, "the default view");
        let (_, up, normal) = drawing_axes(&camera);
        assert_eq!(up, Vec3::Y);
        assert!(normal.y.abs() < 1e-6, "{normal}");
        // The plane of an outline drawn in the default view stands upright.
        let doc = Document::new(crate::scene::Scene::preset(crate::scene::Preset::Empty));
        let tool = SketchTool {
            tool: Tool::Sketch,
            ..Default::default()
        };
        let (doc, _) = draw_circle(doc, tool, 3, 120.0);
        let plane_up = doc.scene().planes[0].rotation * Vec3::Y;
        assert!(plane_up.abs_diff_eq(Vec3::Y, 1e-5), "{plane_up}");
        // Looking down steeply, the plane faces the view.
        camera.pitch_deg = 40.0;
        let (_, up, normal) = drawing_axes(&camera);
        assert!(up.abs_diff_eq(camera.up(), 1e-6));
        assert!(normal.abs_diff_eq(-camera.forward(), 1e-6));
    }

    #[test]
    fn a_stroke_keeps_every_sample_however_its_events_fall_into_frames() {
        // 61 samples (the press and 60 moves), all kept: within one frame and over two egui
        // sees no drag (the press record draws it), over more the drag starts a frame after
        // the press (and begins with every sample since it).
        for frames in [1, 2, 3, 5, 31, 63] {
            assert_eq!(stroke_over_frames(frames), [61], "over {frames} frames");
        }
    }
}
