//! The Move, Rotate and Scale tools: a primary drag transforms the selection, one undo step per
//! drag. A press on a gizmo handle constrains the drag to its axis (or ring); elsewhere the
//! X/Y/Z lock does. Esc or a right-click cancels. Without a selection the drag draws a box.

use egui::Pos2;
use glam::{Quat, Vec2, Vec3};

use super::{
    Shared, Start, ToolContext, ViewInput, ViewTool, apply_starts, click_select, start_of,
};
use crate::scene::{Document, OrbitCamera};
use crate::ui::gizmo::{Gizmo, Handle, ring_turn};
use crate::ui::selection::{Item, Selection};
use crate::ui::tool::Tool;
use crate::ui::transform::{Axis, SNAP_STEP, drag_scale, drag_turn, view_move};

/// The merge run a drag's edits fold into.
const DRAG: &str = "drag";

/// A drag under way: the active item's place, turn and radii when it began (and every selected
/// item's, which follow it), the gizmo as it was laid out then and the handle the press took,
/// and the drag so far (the transform is taken from the whole drag, so snapping sees the
/// total).
#[derive(Clone, Debug)]
pub struct Gesture {
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

/// What one frame of a drag sees: the camera, the pointer, the keys held, the lock.
struct DragFrame<'a> {
    camera: &'a OrbitCamera,
    view_height: f32,
    pointer: Pos2,
    snap: bool,
    shift: bool,
    lock: Option<Axis>,
}

/// Move: a drag moves the selection across the view (Shift: toward or away), along an arrow, or
/// along the locked axis.
#[derive(Default)]
pub struct MoveTool {
    gesture: Option<Gesture>,
}

/// Rotate: a drag turns the selection freely, about a ring's axis, or about the locked axis.
#[derive(Default)]
pub struct RotateTool {
    gesture: Option<Gesture>,
}

/// Scale: a drag right or up grows the selected ellipsoids, one axis on a box or with a lock.
#[derive(Default)]
pub struct ScaleTool {
    gesture: Option<Gesture>,
}

/// The item a Move/Rotate/Scale drag places its gizmo on, and where it is: the active item;
/// Scale reshapes ellipsoids only, so it takes the last one selected.
pub fn target(tool: Tool, doc: &Document, selection: &Selection) -> Option<Start> {
    let item = match tool {
        Tool::Move | Tool::Rotate => selection.active(),
        Tool::Scale => selection.ellipsoid().map(Item::Ellipsoid),
        _ => None,
    }?;
    start_of(doc, item)
}

/// The hint of a transform tool: what a drag does, and the lock when one is set.
fn lock_hint(shared: &Shared, free: &str) -> String {
    match shared.axis_lock {
        Some(a) => format!(
            "Locked to {} (X/Y/Z: another axis, {} again: free) · Ctrl snaps · Esc or right-click cancels",
            a.name(),
            a.name()
        ),
        None => free.to_owned(),
    }
}

impl ViewTool for MoveTool {
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, shared: &Shared) -> bool {
        drag(&mut self.gesture, Tool::Move, view, tc, shared, |g, f| {
            let handle_axis = g.handle_axis();
            let mut origin = match (handle_axis.or(f.lock), &g.gizmo) {
                (Some(axis), Some(gizmo)) => {
                    g.origin + gizmo.along(axis, g.drag).map_or(Vec3::ZERO, |(_, w)| w)
                }
                _ => {
                    let depth = (g.origin - f.camera.eye()).dot(f.camera.forward()).max(0.1);
                    let per_px = f.camera.world_per_px(depth, f.view_height);
                    g.origin + view_move(f.camera, g.drag, per_px, f.shift)
                }
            };
            if f.snap {
                // Ctrl snaps the move to tenths of a world unit.
                origin = g.origin + ((origin - g.origin) * 10.0).round() / 10.0;
            }
            (origin, g.rotation, g.radii)
        })
    }

    fn cancel(&mut self, doc: &mut Document) -> bool {
        cancel(&mut self.gesture, doc)
    }

    fn hint(&self, _: &Document, selection: &Selection, shared: &Shared) -> Option<String> {
        Some(if selection.is_empty() {
            "Move (Shift+G): click a drawing plane or the cloud (Shift adds), or drag a box round several · G grabs without the arrows".to_owned()
        } else {
            lock_hint(
                shared,
                "Move (Shift+G): drag an arrow to move along it, elsewhere in the view (Shift: toward you) · X/Y/Z lock · Esc cancels · G grabs",
            )
        })
    }
}

impl ViewTool for RotateTool {
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, shared: &Shared) -> bool {
        drag(&mut self.gesture, Tool::Rotate, view, tc, shared, |g, f| {
            let rotation = match (g.handle_axis(), &g.gizmo) {
                (Some(axis), Some(gizmo)) => {
                    let toward_viewer = -axis.vector().dot(f.camera.forward());
                    g.angle += ring_turn(gizmo.center, g.last, f.pointer, toward_viewer);
                    let angle = if f.snap {
                        (g.angle / SNAP_STEP).round() * SNAP_STEP
                    } else {
                        g.angle
                    };
                    (Quat::from_axis_angle(axis.vector(), angle) * g.rotation).normalize()
                }
                _ => {
                    let turn = drag_turn(g.drag, f.lock, f.snap, f.camera.right());
                    (turn * g.rotation).normalize()
                }
            };
            (g.origin, rotation, g.radii)
        })
    }

    fn cancel(&mut self, doc: &mut Document) -> bool {
        cancel(&mut self.gesture, doc)
    }

    fn hint(&self, _: &Document, selection: &Selection, shared: &Shared) -> Option<String> {
        Some(if selection.is_empty() {
            "Rotate (Shift+R): click a drawing plane or the cloud (Shift adds), or drag a box round several · R rotates without the rings".to_owned()
        } else {
            lock_hint(
                shared,
                "Rotate (Shift+R): drag a ring to turn about its axis, elsewhere freely · Ctrl snaps to 15° · Esc cancels · R rotates",
            )
        })
    }
}

impl ViewTool for ScaleTool {
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, shared: &Shared) -> bool {
        drag(&mut self.gesture, Tool::Scale, view, tc, shared, |g, f| {
            let factor = match (g.handle_axis(), &g.gizmo) {
                (Some(axis), Some(gizmo)) => {
                    let px = gizmo.along(axis, g.drag).map_or(0.0, |(px, _)| px);
                    drag_scale(Vec2::new(px, 0.0), Some(axis), f.snap)
                }
                _ => drag_scale(g.drag, f.lock, f.snap),
            };
            let radii = (g.radii * factor).clamp(Vec3::splat(0.01), Vec3::splat(1e4));
            (g.origin, g.rotation, radii)
        })
    }

    fn cancel(&mut self, doc: &mut Document) -> bool {
        cancel(&mut self.gesture, doc)
    }

    fn hint(&self, _: &Document, selection: &Selection, shared: &Shared) -> Option<String> {
        Some(if selection.ellipsoid().is_none() {
            "Scale (Shift+S) works on ellipsoids: click the cloud (or pick one in the list) · S scales without the boxes".to_owned()
        } else {
            lock_hint(
                shared,
                "Scale (Shift+S): drag a box to scale one axis, elsewhere right or up to grow · Ctrl snaps to tenths · Esc cancels · S scales",
            )
        })
    }
}

impl MoveTool {
    /// The gizmo handle the drag under way holds.
    pub fn handle(&self) -> Option<Handle> {
        handle(&self.gesture)
    }
}

impl RotateTool {
    /// The gizmo handle the drag under way holds.
    pub fn handle(&self) -> Option<Handle> {
        handle(&self.gesture)
    }
}

impl ScaleTool {
    /// The gizmo handle the drag under way holds.
    pub fn handle(&self) -> Option<Handle> {
        handle(&self.gesture)
    }
}

fn handle(gesture: &Option<Gesture>) -> Option<Handle> {
    gesture
        .as_ref()
        .filter(|g| !g.cancelled)
        .and_then(|g| g.handle)
}

impl Gesture {
    fn handle_axis(&self) -> Option<Axis> {
        match self.handle {
            Some(Handle::Axis(a)) => Some(a),
            _ => None,
        }
    }
}

/// Takes back the drag under way (Esc, right-click); returns whether there was one.
fn cancel(gesture: &mut Option<Gesture>, doc: &mut Document) -> bool {
    let Some(g) = gesture.as_mut().filter(|g| !g.cancelled) else {
        return false;
    };
    g.cancelled = true;
    doc.revert_merge(DRAG);
    true
}

/// One frame of a Move, Rotate or Scale drag: a click selects, a drag starts a gesture on the
/// selection, `transform` says where the drag so far takes the active item, and every selected
/// item follows it. Returns whether the primary button is the tool's.
fn drag(
    gesture: &mut Option<Gesture>,
    tool: Tool,
    view: &ViewInput<'_>,
    tc: &mut ToolContext<'_>,
    shared: &Shared,
    transform: impl FnOnce(&mut Gesture, &DragFrame<'_>) -> (Vec3, Quat, Vec3),
) -> bool {
    click_select(view, tc, shared);
    let (ui, response, rect) = (view.ui, view.response, view.rect);
    let Some((_, origin, rotation, radii)) = target(tool, tc.doc, tc.selection) else {
        return false;
    };
    if ui.input(|i| i.modifiers.alt || i.multi_touch().is_some()) {
        return true;
    }
    if !response.dragged_by(egui::PointerButton::Primary) {
        *gesture = None;
        return true;
    }
    let camera = tc.doc.scene().camera.clone();
    if response.drag_started() || gesture.is_none() {
        let press = ui
            .input(|i| i.pointer.press_origin())
            .or(response.interact_pointer_pos())
            .unwrap_or(rect.center());
        let gizmo = Gizmo::layout(tool, &camera, rect, origin, rotation);
        let starts = (tc.selection.items().iter())
            .filter(|i| tool != Tool::Scale || i.ellipsoid().is_some())
            .filter_map(|&i| start_of(tc.doc, i))
            .collect();
        *gesture = Some(Gesture {
            starts,
            origin,
            rotation,
            radii,
            drag: Vec2::ZERO,
            // An axis locked from the keyboard wins over the handle under the press.
            handle: gizmo
                .as_ref()
                .filter(|_| shared.axis_lock.is_none())
                .and_then(|g| g.hit(press)),
            gizmo,
            angle: 0.0,
            last: press,
            cancelled: false,
        });
    }
    if ui.input(|i| i.pointer.button_pressed(egui::PointerButton::Secondary))
        && cancel(gesture, tc.doc)
    {
        let now = ui.input(|i| i.time);
        tc.notices.note(now, "Cancelled: back where the drag began");
    }
    let Some(g) = gesture.as_mut().filter(|g| !g.cancelled) else {
        return true;
    };
    let delta = response.drag_delta();
    let pointer = response.interact_pointer_pos().unwrap_or(g.last);
    if delta == egui::Vec2::ZERO && pointer == g.last {
        return true;
    }
    g.drag += Vec2::new(delta.x, delta.y);
    let frame = DragFrame {
        camera: &camera,
        view_height: rect.height(),
        pointer,
        snap: ui.input(|i| i.modifiers.ctrl || i.modifiers.command),
        shift: ui.input(|i| i.modifiers.shift),
        lock: shared.axis_lock,
    };
    let (origin, rotation, radii) = transform(g, &frame);
    g.last = pointer;
    // Every selected item follows the active one: the same shift, the same turn and the same
    // scale, each about its own centre.
    let turn = rotation * g.rotation.inverse();
    let factor = radii / g.radii;
    let moved: Vec<Start> = (g.starts.iter())
        .map(|&(i, o, r, rad)| {
            let rad = (rad * factor).clamp(Vec3::splat(0.01), Vec3::splat(1e4));
            (i, o + (origin - g.origin), (turn * r).normalize(), rad)
        })
        .collect();
    apply_starts(tc.doc, &moved, DRAG);
    true
}
