//! Blender's modal transforms: G grabs, R rotates and S scales the selection as the mouse moves,
//! whichever tool is out. X, Y or Z locks a world axis (the same key again frees it); typed
//! numbers set the distance, the angle in degrees or the factor exactly; Ctrl snaps (tenths of
//! a unit, 15°, tenths of the size); a click or Enter confirms (one undo step); Esc or a
//! right-click puts everything back where it began, with no undo step.
//!
//! Every item turns and scales about the selection's median point, as Blender's default pivot.

use egui::{Color32, Pos2, Rect, Stroke};
use glam::{Quat, Vec3};

use super::{Start, ViewInput, apply_starts, start_of};
use crate::scene::{Document, OrbitCamera};
use crate::ui::gizmo::ring_turn;
use crate::ui::projection::project;
use crate::ui::selection::Selection;
use crate::ui::tool::ModalKind;
use crate::ui::transform::{Axis, SNAP_STEP, view_move};

/// The merge run a modal transform's edits fold into.
const MODAL: &str = "modal";

/// The longest typed number kept.
const MAX_TYPED: usize = 16;

/// A modal transform under way.
#[derive(Clone, Debug)]
pub struct Modal {
    /// Grab, rotate or scale (G, R, S again switch).
    pub kind: ModalKind,
    /// The world axis it is locked to.
    pub lock: Option<Axis>,
    /// The number typed so far ("", "-", "2.5").
    pub typed: String,
    /// Every selected item as it was when the transform began.
    starts: Vec<Start>,
    /// The selection's median point.
    pivot: Vec3,
    /// The pointer when the transform began (or switched kind), and now.
    from: Option<Pos2>,
    pointer: Option<Pos2>,
    /// The turn so far on screen (radians, counter-clockwise), and where it was last measured.
    angle: f32,
    last: Option<Pos2>,
    /// Ctrl is held.
    snap: bool,
    /// The view and its camera as of the last frame.
    rect: Rect,
    camera: OrbitCamera,
}

impl Modal {
    /// Starts `kind` on the selection, with the pointer at `at` in the view `rect`; a message
    /// when there is nothing it can act on.
    pub fn start(
        kind: ModalKind,
        doc: &mut Document,
        selection: &Selection,
        (at, rect): (Option<Pos2>, Rect),
    ) -> Result<Modal, &'static str> {
        let starts: Vec<Start> = (selection.items().iter())
            .filter_map(|&i| start_of(doc, i))
            .collect();
        if starts.is_empty() {
            return Err(
                "Select something first: G, R and S move, turn and scale the selection (click the cloud or a stroke)",
            );
        }
        if kind == ModalKind::Scale && !starts.iter().any(|s| s.0.ellipsoid().is_some()) {
            return Err("S scales ellipsoids: click the cloud (or pick one in the list)");
        }
        let pivot = starts.iter().map(|s| s.1).sum::<Vec3>() / starts.len() as f32;
        // A fresh undo step: the transform's edits fold into one, apart from what came before.
        doc.end_merge();
        Ok(Modal {
            kind,
            lock: None,
            typed: String::new(),
            starts,
            pivot,
            from: at,
            pointer: at,
            angle: 0.0,
            last: at,
            snap: false,
            rect,
            camera: doc.scene().camera.clone(),
        })
    }

    /// G, R or S while one is under way: switches to that transform, starting over from where
    /// the items began.
    pub fn switch(&mut self, kind: ModalKind, doc: &Document) {
        if kind == ModalKind::Scale && !self.starts.iter().any(|s| s.0.ellipsoid().is_some()) {
            return;
        }
        self.kind = kind;
        self.typed.clear();
        self.angle = 0.0;
        self.from = self.pointer;
        self.last = self.pointer;
        self.camera = doc.scene().camera.clone();
    }

    /// A typed character: a digit or a point adds to the number, a minus negates it.
    pub fn type_char(&mut self, c: char) {
        match c {
            '-' => {
                if let Some(rest) = self.typed.strip_prefix('-') {
                    self.typed = rest.to_owned();
                } else {
                    self.typed.insert(0, '-');
                }
            }
            '.' if self.typed.contains('.') => {}
            '0'..='9' | '.' if self.typed.len() < MAX_TYPED => self.typed.push(c),
            _ => {}
        }
    }

    /// The typed number, once there is one.
    fn typed_value(&self) -> Option<f32> {
        self.typed.parse::<f32>().ok().filter(|v| v.is_finite())
    }

    /// This frame's pointer and keys: where the mouse is, whether Ctrl is held. Applies the
    /// transform.
    pub fn pointer(&mut self, view: &ViewInput<'_>, doc: &mut Document) {
        let (pointer, snap) = view.ui.input(|i| {
            (
                i.pointer.latest_pos(),
                i.modifiers.ctrl || i.modifiers.command,
            )
        });
        self.rect = view.rect;
        self.camera = doc.scene().camera.clone();
        self.snap = snap;
        if let Some(p) = pointer {
            self.from.get_or_insert(p);
            if let Some(last) = self.last {
                self.angle += ring_turn(self.pivot_px(), last, p, 1.0);
            }
            self.last = Some(p);
            self.pointer = Some(p);
        }
        self.apply(doc);
    }

    /// The pivot on screen.
    fn pivot_px(&self) -> Pos2 {
        project(&self.camera, self.rect, self.pivot).unwrap_or(self.rect.center())
    }

    /// Puts every item where the transform takes it now (folded into one undo step).
    pub fn apply(&self, doc: &mut Document) {
        apply_starts(doc, &self.transformed(), MODAL);
    }

    /// Puts every item back where it began, leaving no undo step.
    pub fn revert(&self, doc: &mut Document) {
        if !doc.revert_merge(MODAL) {
            // Another edit broke the run (or nothing moved): put them back all the same.
            apply_starts(doc, &self.starts, MODAL);
            doc.end_merge();
        }
    }

    /// World units per screen pixel at the pivot's depth.
    fn per_px(&self) -> f32 {
        let depth = (self.pivot - self.camera.eye())
            .dot(self.camera.forward())
            .max(0.1);
        self.camera.world_per_px(depth, self.rect.height())
    }

    /// The pointer's travel since the transform began, in pixels.
    fn drag(&self) -> glam::Vec2 {
        match (self.from, self.pointer) {
            (Some(a), Some(b)) => glam::Vec2::new(b.x - a.x, b.y - a.y),
            _ => glam::Vec2::ZERO,
        }
    }

    /// How far the pointer's travel takes the pivot along `axis`: the travel projected on the
    /// axis as drawn on screen; an axis pointing at the viewer takes the vertical travel.
    fn along(&self, axis: Axis) -> f32 {
        let per_px = self.per_px();
        let unit = per_px * 100.0;
        let drag = self.drag();
        let ends = project(&self.camera, self.rect, self.pivot).zip(project(
            &self.camera,
            self.rect,
            self.pivot + axis.vector() * unit,
        ));
        match ends {
            Some((a, b)) if a.distance(b) > 5.0 => {
                let px_per_unit = glam::Vec2::new(b.x - a.x, b.y - a.y) / unit;
                drag.dot(px_per_unit) / px_per_unit.length_squared()
            }
            _ => -drag.y * per_px,
        }
    }

    /// The move so far.
    fn offset(&self) -> Vec3 {
        let offset = match (self.typed_value(), self.lock) {
            // A typed distance goes along the locked axis, else along X (as in Blender).
            (Some(v), lock) => lock.unwrap_or(Axis::X).vector() * v,
            (None, Some(axis)) => axis.vector() * self.along(axis),
            (None, None) => view_move(&self.camera, self.drag(), self.per_px(), false),
        };
        if self.snap && self.typed_value().is_none() {
            (offset * 10.0).round() / 10.0
        } else {
            offset
        }
    }

    /// The turn so far: its axis (the locked one, else the view's, toward the viewer) and
    /// angle in radians.
    fn turn(&self) -> (Vec3, f32) {
        let axis = self.lock.map_or(-self.camera.forward(), |a| a.vector());
        let angle = match self.typed_value() {
            Some(deg) => deg.to_radians(),
            None => {
                // The screen turn is counter-clockwise about the view's axis: about an axis
                // pointing away from the viewer it is the opposite turn.
                let sign = if axis.dot(self.camera.forward()) > 0.0 {
                    -1.0
                } else {
                    1.0
                };
                let a = self.angle * sign;
                if self.snap {
                    (a / SNAP_STEP).round() * SNAP_STEP
                } else {
                    a
                }
            }
        };
        (axis, angle)
    }

    /// The scale factor so far: the pointer's distance from the pivot against where it began.
    fn factor(&self) -> f32 {
        let f = match self.typed_value() {
            Some(v) => v,
            None => {
                let c = self.pivot_px();
                let (Some(a), Some(b)) = (self.from, self.pointer) else {
                    return 1.0;
                };
                let f = b.distance(c) / a.distance(c).max(1.0);
                if self.snap {
                    (f * 10.0).round() / 10.0
                } else {
                    f
                }
            }
        };
        if f.abs() < 1e-3 {
            1e-3_f32.copysign(f)
        } else {
            f
        }
    }

    /// Every item where the transform takes it now.
    fn transformed(&self) -> Vec<Start> {
        let pivot = self.pivot;
        match self.kind {
            ModalKind::Grab => {
                let d = self.offset();
                (self.starts.iter())
                    .map(|&(i, o, r, rad)| (i, o + d, r, rad))
                    .collect()
            }
            ModalKind::Rotate => {
                let (axis, angle) = self.turn();
                let q = Quat::from_axis_angle(axis, angle);
                (self.starts.iter())
                    .map(|&(i, o, r, rad)| (i, pivot + q * (o - pivot), (q * r).normalize(), rad))
                    .collect()
            }
            ModalKind::Scale => {
                let f = self.factor();
                let fv = self
                    .lock
                    .map_or(Vec3::splat(f), |a| Vec3::ONE + a.vector() * (f - 1.0));
                (self.starts.iter())
                    .map(|&(i, o, r, rad)| {
                        // Radii scale along the ellipsoid's own axes (a plane has none).
                        let rad = if i.ellipsoid().is_some() {
                            (rad * fv.abs()).clamp(Vec3::splat(0.01), Vec3::splat(1e4))
                        } else {
                            rad
                        };
                        (i, pivot + (o - pivot) * fv, r, rad)
                    })
                    .collect()
            }
        }
    }

    /// What the hint line says: the transform so far and its keys.
    pub fn hint(&self) -> String {
        let along = self
            .lock
            .map_or(String::new(), |a| format!(" along {}", a.name()));
        let typed = if self.typed.is_empty() {
            String::new()
        } else {
            format!(" [{}]", self.typed)
        };
        let now = match self.kind {
            ModalKind::Grab => {
                let d = self.offset();
                format!("Grab{along}: {:.2}, {:.2}, {:.2}{typed}", d.x, d.y, d.z)
            }
            ModalKind::Rotate => {
                let about = self.lock.map_or(" about the view".to_owned(), |a| {
                    format!(" about {}", a.name())
                });
                format!("Rotate{about}: {:.1}°{typed}", self.turn().1.to_degrees())
            }
            ModalKind::Scale => format!("Scale{along}: {:.2}{typed}", self.factor()),
        };
        format!(
            "{now} · X/Y/Z lock · type a number · Ctrl snaps · click or Enter confirms · Esc or right-click cancels"
        )
    }

    /// The locked axis through the pivot, and a line from the pivot to the pointer.
    pub fn overlay(&self, painter: &egui::Painter, camera: &OrbitCamera, rect: Rect) {
        let center = project(camera, rect, self.pivot);
        if let Some(axis) = self.lock {
            let reach = self.per_px() * rect.width().max(rect.height());
            let ends = project(camera, rect, self.pivot - axis.vector() * reach).zip(project(
                camera,
                rect,
                self.pivot + axis.vector() * reach,
            ));
            if let Some((a, b)) = ends {
                let color = match axis {
                    Axis::X => Color32::from_rgb(230, 80, 80),
                    Axis::Y => Color32::from_rgb(110, 200, 90),
                    Axis::Z => Color32::from_rgb(90, 140, 240),
                };
                painter.line_segment([a, b], Stroke::new(1.5, color));
            }
        }
        if self.kind != ModalKind::Grab
            && let (Some(c), Some(p)) = (center, self.pointer)
        {
            painter.add(egui::Shape::dashed_line(
                &[c, p],
                Stroke::new(1.0, Color32::from_white_alpha(160)),
                6.0,
                4.0,
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Ellipsoid, Scene};
    use crate::ui::selection::Item;
    use crate::ui::test_view;

    fn scene_with_two() -> (Document, Selection) {
        let mut scene = Scene::preset(crate::scene::Preset::Empty);
        for x in [-2.0, 2.0] {
            scene.ellipsoids.push(std::sync::Arc::new(Ellipsoid {
                center: Vec3::new(x, 0.0, 0.0),
                ..Ellipsoid::default()
            }));
        }
        let mut selection = Selection::default();
        selection.select_all([Item::Ellipsoid(0), Item::Ellipsoid(1)], false);
        (Document::new(scene), selection)
    }

    fn start(kind: ModalKind, doc: &mut Document, selection: &Selection) -> Modal {
        let rect = test_view();
        Modal::start(kind, doc, selection, (Some(rect.center()), rect)).unwrap()
    }

    #[test]
    fn a_typed_grab_along_a_locked_axis_moves_exactly_that_far_in_one_undo_step() {
        let (mut doc, selection) = scene_with_two();
        let undo = doc.undo_len();
        let mut m = start(ModalKind::Grab, &mut doc, &selection);
        m.pointer = Some(m.rect.center() + egui::vec2(80.0, 30.0));
        m.lock = Some(Axis::Z);
        for c in "-1.5".chars() {
            m.type_char(c);
        }
        m.apply(&mut doc);
        m.apply(&mut doc);
        let centers: Vec<Vec3> = doc.scene().ellipsoids.iter().map(|e| e.center).collect();
        assert_eq!(
            centers,
            [Vec3::new(-2.0, 0.0, -1.5), Vec3::new(2.0, 0.0, -1.5)]
        );
        doc.end_merge();
        assert_eq!(doc.undo_len(), undo + 1);
    }

    #[test]
    fn a_cancelled_transform_leaves_everything_exactly_where_it_was_and_no_undo_step() {
        for kind in [ModalKind::Grab, ModalKind::Rotate, ModalKind::Scale] {
            let (mut doc, selection) = scene_with_two();
            let before = doc.scene().ellipsoids.clone();
            let undo = doc.undo_len();
            let mut m = start(kind, &mut doc, &selection);
            m.pointer = Some(m.rect.center() + egui::vec2(137.0, -41.0));
            m.last = m.pointer;
            m.angle = 0.7;
            m.apply(&mut doc);
            assert_ne!(doc.scene().ellipsoids, before, "{kind:?} moved something");
            m.revert(&mut doc);
            assert_eq!(doc.scene().ellipsoids, before, "{kind:?}");
            assert_eq!(doc.undo_len(), undo, "{kind:?}");
        }
    }

    #[test]
    fn rotate_and_scale_act_about_the_median_point() {
        let (mut doc, selection) = scene_with_two();
        let mut m = start(ModalKind::Rotate, &mut doc, &selection);
        m.lock = Some(Axis::Y);
        m.typed = "90".into();
        m.apply(&mut doc);
        let c: Vec<Vec3> = doc.scene().ellipsoids.iter().map(|e| e.center).collect();
        assert!(c[0].abs_diff_eq(Vec3::new(0.0, 0.0, 2.0), 1e-5), "{c:?}");
        assert!(c[1].abs_diff_eq(Vec3::new(0.0, 0.0, -2.0), 1e-5), "{c:?}");
        m.revert(&mut doc);

        let radii = doc.scene().ellipsoids[0].radii;
        let mut m = start(ModalKind::Scale, &mut doc, &selection);
        m.typed = "2".into();
        m.apply(&mut doc);
        let e = &doc.scene().ellipsoids;
        assert_eq!(
            (e[0].center, e[1].center),
            (Vec3::new(-4.0, 0.0, 0.0), Vec3::new(4.0, 0.0, 0.0))
        );
        assert_eq!(e[0].radii, radii * 2.0);
    }

    #[test]
    fn a_free_grab_follows_the_pointer_across_the_view_and_ctrl_snaps_to_tenths() {
        let (mut doc, selection) = scene_with_two();
        let mut m = start(ModalKind::Grab, &mut doc, &selection);
        m.pointer = Some(m.rect.center() + egui::vec2(100.0, 0.0));
        let d = m.offset();
        let right = m.camera.right();
        assert!(d.normalize().abs_diff_eq(right, 1e-4), "{d} vs {right}");
        assert!((d.length() - 100.0 * m.per_px()).abs() < 1e-4);
        m.snap = true;
        let s = m.offset();
        assert_eq!(s, (d * 10.0).round() / 10.0);
        // Locked to X, the pointer moved along X's screen direction moves along X alone.
        m.snap = false;
        m.lock = Some(Axis::X);
        let x = m.offset();
        assert!(x.y == 0.0 && x.z == 0.0 && x.x > 0.0, "{x}");
    }

    #[test]
    fn nothing_selected_says_what_to_do() {
        let (mut doc, _) = scene_with_two();
        let rect = test_view();
        let e = Modal::start(
            ModalKind::Grab,
            &mut doc,
            &Selection::default(),
            (None, rect),
        )
        .unwrap_err();
        assert!(e.contains("Select something first"), "{e}");
    }

    #[test]
    fn typing_keeps_one_point_and_minus_negates() {
        let (mut doc, selection) = scene_with_two();
        let mut m = start(ModalKind::Grab, &mut doc, &selection);
        for c in "1.2.5-x".chars() {
            m.type_char(c);
        }
        assert_eq!(m.typed, "-1.25");
        assert_eq!(m.typed_value(), Some(-1.25));
    }
}
