//! The viewport's tools, one struct per tool behind [`ViewTool`], and the [`Toolbox`] that holds
//! them: which one is out, the guides every tool shares, box selection and Blender's modal
//! G/R/S, which act on the selection whichever tool is out.
//!
//! - `navigate`: a drag orbits, a click selects;
//! - `stroke`: Sketch and Cut, capturing a stroke and placing its drawing plane (Wither et
//!   al. §2);
//! - `ellipsoid`: a click adds an ellipsoid where it lands;
//! - `manipulate`: Move, Rotate and Scale, dragged with their gizmos;
//! - `modal`: G, R and S, Blender's modal grab, rotate and scale with typed numbers;
//! - `box_select`: B, a dragged box that selects;
//! - `overlay`: the strokes, grids, indicators and skeletons drawn over the view.

mod box_select;
mod ellipsoid;
mod manipulate;
mod modal;
mod navigate;
mod overlay;
mod stroke;

use egui::{Color32, Rect, Response, Ui};

use crate::derive::Derived;
use crate::scene::Document;
use crate::ui::gizmo::Gizmo;
use crate::ui::notice::Notices;
use crate::ui::selection::{Item, Selection};
use crate::ui::shortcuts::Shortcut;
use crate::ui::tool::{ModalKind, Tool};
use crate::ui::transform::Axis;

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

/// What the toolbox shares with the tool that is out.
#[derive(Clone, Copy, Debug, Default)]
pub struct Shared {
    /// The world axis (X, Y, Z) Move, Rotate and Scale drags are locked to, or free.
    pub axis_lock: Option<Axis>,
    /// Every ellipsoid's indicator is drawn, so a click on one selects it.
    pub indicators: bool,
}

/// One tool of the viewport: what the primary button does while it is out, what it draws over
/// the view and the hint it shows.
pub trait ViewTool {
    /// Takes this frame's pointer; returns whether the primary button is the tool's (so the
    /// camera does not orbit with it).
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, shared: &Shared) -> bool;

    /// Esc or a right-click: takes back what the tool has under way (a drag, a stroke);
    /// returns whether there was something.
    fn cancel(&mut self, _doc: &mut Document) -> bool {
        false
    }

    /// Draws what the tool has under way (the stroke being drawn).
    fn overlay(&self, _painter: &egui::Painter) {}

    /// The hint at the top of the view, if the tool has one now.
    fn hint(&self, doc: &Document, selection: &Selection, shared: &Shared) -> Option<String>;
}

/// Every tool, the one that is out, and what they share.
#[derive(Default)]
pub struct Toolbox {
    /// The tool that is out.
    pub tool: Tool,
    /// Show every plane's grid, not only the selected one's.
    pub show_all_planes: bool,
    /// Hide strokes and grids (H), to look at the cloud alone.
    pub hide_guides: bool,
    /// Show the selected outline's skeleton and spheres (K), as in Wither et al.'s Figure 4.
    pub show_skeleton: bool,
    /// The world axis Move, Rotate and Scale drags are locked to (X, Y or Z), or free.
    pub axis_lock: Option<Axis>,
    navigate: navigate::NavigateTool,
    /// Sketch (and its "behind the cloud" choice).
    pub sketch: stroke::SketchTool,
    cut: stroke::CutTool,
    ellipsoid: ellipsoid::EllipsoidTool,
    moving: manipulate::MoveTool,
    rotate: manipulate::RotateTool,
    scale: manipulate::ScaleTool,
    boxes: box_select::BoxSelect,
    /// The modal G, R or S under way.
    modal: Option<modal::Modal>,
    /// A click confirmed a modal transform: the button is the toolbox's until it is released.
    swallow: bool,
    /// This frame's pointer was the modal transform's (or swallowed), even where the transform
    /// ended and the button was released within the frame: the camera takes none of it.
    took_pointer: bool,
    /// The pointer and the view as of the last frame (where a modal transform starts from).
    last_pointer: Option<egui::Pos2>,
    last_rect: Option<Rect>,
}

impl Toolbox {
    /// The tool that is out, as its struct.
    fn active(&self) -> &dyn ViewTool {
        match self.tool {
            Tool::Navigate => &self.navigate,
            Tool::Sketch => &self.sketch,
            Tool::Cut => &self.cut,
            Tool::Ellipsoid => &self.ellipsoid,
            Tool::Move => &self.moving,
            Tool::Rotate => &self.rotate,
            Tool::Scale => &self.scale,
        }
    }

    fn active_mut(&mut self) -> &mut dyn ViewTool {
        match self.tool {
            Tool::Navigate => &mut self.navigate,
            Tool::Sketch => &mut self.sketch,
            Tool::Cut => &mut self.cut,
            Tool::Ellipsoid => &mut self.ellipsoid,
            Tool::Move => &mut self.moving,
            Tool::Rotate => &mut self.rotate,
            Tool::Scale => &mut self.scale,
        }
    }

    fn shared(&self) -> Shared {
        Shared {
            axis_lock: self.axis_lock,
            indicators: self.indicators_shown(),
        }
    }

    /// Whether a modal G, R or S is under way (the document's merge run is its, and digits,
    /// Enter and Backspace are its keys).
    pub fn modal_active(&self) -> bool {
        self.modal.is_some()
    }

    /// Whose a drag is that egui never saw (pressed and released within a frame or two): none
    /// of the camera's while a modal transform has the pointer or its confirming click's
    /// button is held, or was either this frame (`None`: a right-click that cancels a
    /// transform, pressed, moved and released within one frame, pans nothing); else the
    /// camera's, with the primary button's too where the
    /// tool that is out leaves its drags to the camera (Navigate, Ellipsoid) and no box
    /// selection is armed.
    pub fn quick_drags(&self) -> Option<bool> {
        (self.modal.is_none() && !self.swallow && !self.took_pointer).then(|| {
            matches!(self.tool, Tool::Navigate | Tool::Ellipsoid) && !self.boxes.is_active()
        })
    }

    /// The modal transform under way, for the page state: its kind, its locked axis and what
    /// was typed.
    pub fn modal_state(&self) -> Option<(ModalKind, Option<Axis>, String)> {
        self.modal
            .as_ref()
            .map(|m| (m.kind, m.lock, m.typed.clone()))
    }

    /// Whether new outlines land behind the cloud.
    pub fn behind(&self) -> bool {
        self.sketch.behind
    }

    /// One of the tools' shortcuts: V navigate, D draw, C cut, E ellipsoid, Shift+G/R/S the
    /// Move, Rotate and Scale tools; G, R, S a modal grab, rotate or scale of the selection (X,
    /// Y or Z locks an axis, the same key again frees it; typed numbers; Enter confirms, Esc
    /// cancels); H hides guides, Shift+H hides the selected item (Alt+H shows all), K shows the
    /// skeleton and spheres, Q puts new outlines behind the cloud, Esc cancels a drag or a
    /// stroke (or clears the selection), Delete removes the selection, Ctrl+D duplicates it.
    /// Other shortcuts are not the tools'.
    pub fn shortcut(&mut self, shortcut: Shortcut, tc: &mut ToolContext<'_>, now: f64) {
        if let Some(m) = self.modal.as_mut() {
            let done = match shortcut {
                Shortcut::Lock(axis) => {
                    m.lock = (m.lock != Some(axis)).then_some(axis);
                    None
                }
                Shortcut::Typed(c) => {
                    m.type_char(c);
                    None
                }
                Shortcut::Erase => {
                    m.typed.pop();
                    None
                }
                Shortcut::Modal(kind) => {
                    m.switch(kind, tc.doc);
                    None
                }
                Shortcut::Confirm => Some(true),
                Shortcut::Escape => Some(false),
                // Nothing else acts until the transform is confirmed or cancelled.
                _ => None,
            };
            if let Some(confirm) = done {
                self.end_modal(confirm, tc, now);
            } else if let Some(m) = self.modal.as_mut() {
                m.apply(tc.doc);
            }
            return;
        }
        let message = match shortcut {
            Shortcut::Tool(tool) => {
                self.tool = tool;
                None
            }
            Shortcut::Modal(kind) => match modal::Modal::start(
                kind,
                tc.doc,
                tc.selection,
                (
                    self.last_pointer,
                    (self.last_rect).unwrap_or(Rect::from_min_size(
                        egui::Pos2::ZERO,
                        egui::vec2(1280.0, 800.0),
                    )),
                ),
            ) {
                Ok(m) => {
                    self.modal = Some(m);
                    None
                }
                Err(e) => Some(e.to_owned()),
            },
            Shortcut::BoxSelect => {
                self.boxes.arm();
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
                self.sketch.behind = !self.sketch.behind;
                Some(if self.sketch.behind {
                    "New outlines go behind the cloud (Q again: in front)".to_owned()
                } else {
                    "New outlines go in front of the cloud".to_owned()
                })
            }
            Shortcut::Escape => self.escape(tc),
            Shortcut::HideSelected => crate::ui::selection::toggle_hidden(tc.doc, tc.selection)
                .map(|m| format!("{m} (Shift+H again shows it, Alt+H shows all)")),
            Shortcut::ShowAll => crate::ui::selection::show_all(tc.doc),
            Shortcut::Duplicate => crate::ui::selection::duplicate(tc.doc, tc.selection),
            Shortcut::Delete => crate::ui::selection::delete(tc.doc, tc.selection),
            _ => None,
        };
        if let Some(m) = message {
            tc.notices.note(now, m);
        }
    }

    /// Confirms (one undo step) or cancels (back where it began, no undo step) the modal
    /// transform.
    fn end_modal(&mut self, confirm: bool, tc: &mut ToolContext<'_>, now: f64) {
        let Some(m) = self.modal.take() else {
            return;
        };
        if confirm {
            m.apply(tc.doc);
            tc.doc.end_merge();
        } else {
            m.revert(tc.doc);
            tc.notices.note(
                now,
                format!("Cancelled: {} back where it began", m.kind.verb()),
            );
        }
    }

    /// Esc: drops an armed or dragged selection box, else cancels the drag under way, else
    /// drops the stroke being drawn (and with none, clears the selection).
    fn escape(&mut self, tc: &mut ToolContext<'_>) -> Option<String> {
        if self.boxes.cancel() {
            return None;
        }
        let drawing = matches!(self.tool, Tool::Sketch | Tool::Cut);
        if self.active_mut().cancel(tc.doc) {
            return (!drawing).then(|| "Cancelled: back where the drag began".to_owned());
        }
        tc.selection.clear();
        None
    }

    /// This frame's pointer in the view: a modal transform takes it first, then box selection,
    /// then the tool that is out. Returns whether the primary button is taken (so the camera
    /// must not orbit with it).
    pub fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>) -> bool {
        let ui = view.ui;
        self.last_rect = Some(view.rect);
        self.last_pointer = ui.input(|i| i.pointer.latest_pos()).or(self.last_pointer);
        self.took_pointer = self.modal.is_some() || self.swallow;
        if self.took_pointer {
            // The pointer is the transform's: the samples a stroke would take are dropped.
            ui.input(crate::ui::platform::record_frame);
            let _ = crate::ui::press_record::take_pointer_samples();
            let _ = crate::ui::press_record::take_finished_press();
            let now = ui.input(|i| i.time);
            if let Some(m) = self.modal.as_mut() {
                let (primary, secondary) = ui.input(|i| {
                    (
                        i.pointer.button_pressed(egui::PointerButton::Primary),
                        i.pointer.button_pressed(egui::PointerButton::Secondary),
                    )
                });
                m.pointer(view, tc.doc);
                if primary || secondary {
                    self.swallow = true;
                    self.end_modal(primary, tc, now);
                }
            }
            if !ui.input(|i| i.pointer.any_down()) {
                self.swallow = false;
            }
            return true;
        }
        let shared = self.shared();
        let empty = matches!(self.tool, Tool::Move | Tool::Rotate | Tool::Scale)
            && manipulate::target(self.tool, tc.doc, tc.selection).is_none();
        if self.boxes.input(view, tc, empty) {
            return true;
        }
        self.active_mut().input(view, tc, &shared)
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

    /// The gizmo of the tool that is out on the selected item, as drawn this frame.
    pub fn gizmo(&self, doc: &Document, selection: &Selection, rect: Rect) -> Option<Gizmo> {
        if self.hide_guides || self.modal.is_some() {
            return None;
        }
        let (_, origin, rotation, _) = manipulate::target(self.tool, doc, selection)?;
        Gizmo::layout(self.tool, &doc.scene().camera, rect, origin, rotation)
    }

    /// Strokes of every plane, the selected plane's grid (and, with K, its skeleton and
    /// spheres), indicators, the gizmo, what the tool has under way and the hint.
    pub fn overlay(
        &self,
        ui: &Ui,
        rect: Rect,
        doc: &Document,
        derived: &Derived,
        selection: &Selection,
    ) {
        let painter = ui.painter_at(rect);
        if !self.hide_guides {
            overlay::guides(
                &painter,
                rect,
                doc,
                derived,
                selection,
                overlay::Shown {
                    indicators: self.indicators_shown() || self.modal.is_some(),
                    all_planes: self.show_all_planes,
                    skeleton: self.show_skeleton,
                },
            );
        }
        if let Some(gizmo) = self.gizmo(doc, selection, rect) {
            let active = match self.tool {
                Tool::Move => self.moving.handle(),
                Tool::Rotate => self.rotate.handle(),
                Tool::Scale => self.scale.handle(),
                _ => None,
            };
            let hovered = ui
                .input(|i| i.pointer.hover_pos())
                .and_then(|p| gizmo.hit(p));
            gizmo.draw(&painter, active, hovered);
        }
        self.boxes.overlay(&painter);
        self.active().overlay(&painter);
        let hint = if let Some(m) = &self.modal {
            m.overlay(&painter, &doc.scene().camera, rect);
            Some(m.hint())
        } else if self.boxes.is_active() {
            Some(
                "Drag a box round what to select (Shift adds to the selection) · Esc cancels"
                    .to_owned(),
            )
        } else {
            self.active().hint(doc, selection, &self.shared())
        };
        if let Some(hint) = hint {
            // Wrapped to the view clear of the sun orb in its top-right corner (a narrow window
            // breaks it into lines), each line centred.
            let color = Color32::from_white_alpha(200);
            let mut job = egui::text::LayoutJob::simple(
                hint,
                egui::FontId::proportional(15.0),
                color,
                (rect.width() - 200.0).max(160.0),
            );
            job.halign = egui::Align::Center;
            let galley = painter.layout_job(job);
            painter.galley(rect.center_top() + egui::vec2(0.0, 36.0), galley, color);
        }
    }
}

/// A click in the view selects what is under it: a drawing plane whose stroke is there, an
/// ellipsoid whose indicator it touches, else the ellipsoid that shapes the cloud there; Shift
/// adds or removes.
fn click_select(view: &ViewInput<'_>, tc: &mut ToolContext<'_>, shared: &Shared) {
    let (ui, response, rect) = (view.ui, view.response, view.rect);
    if !response.clicked() {
        return;
    }
    let Some(p) = response.interact_pointer_pos() else {
        return;
    };
    let shift = ui.input(|i| i.modifiers.shift);
    match crate::ui::picking::item_at(tc.doc, tc.derived, rect, p, shared.indicators) {
        Some(item) if shift => tc.selection.toggle(item),
        Some(item) => tc.selection.set(item),
        None if shift => {}
        None => tc.selection.clear(),
    }
}

/// Where a selected item was when a transform began: its place, turn and radii (a plane's
/// are ones).
type Start = (Item, glam::Vec3, glam::Quat, glam::Vec3);

/// Where `item` is now, if the document has it.
fn start_of(doc: &Document, item: Item) -> Option<Start> {
    let scene = doc.scene();
    match item {
        Item::Plane(i) => scene
            .planes
            .get(i)
            .map(|p| (item, p.origin, p.rotation, glam::Vec3::ONE)),
        Item::Ellipsoid(i) => scene
            .ellipsoids
            .get(i)
            .map(|e| (item, e.center, e.rotation, e.radii)),
    }
}

/// Puts items where a transform took them, folded into the merge run `key` (one undo step).
fn apply_starts(doc: &mut Document, items: &[Start], key: &'static str) {
    use crate::scene::Edit;
    let mut ellipsoids = doc.scene().ellipsoids.clone();
    for &(item, origin, rotation, radii) in items {
        match item {
            Item::Plane(i) => {
                let Some(p) = doc.scene().planes.get(i) else {
                    continue;
                };
                let mut p = (**p).clone();
                (p.origin, p.rotation) = (origin, rotation);
                doc.apply(Edit::SetPlane(i, p), Some(key));
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
    doc.apply(Edit::SetEllipsoids(ellipsoids), Some(key));
}

#[cfg(test)]
mod tests;
