//! Box selection: after B (or with Move, Rotate or Scale and nothing selected) a drag draws a
//! box and selects every drawing plane and ellipsoid whose centre it holds.

use egui::{Color32, Pos2, Rect, Stroke};

use super::{ToolContext, ViewInput};

/// The selection box, armed or being dragged.
#[derive(Default)]
pub struct BoxSelect {
    /// B was pressed: the next drag draws a box.
    armed: bool,
    /// The box being dragged: where it began and where the pointer is.
    area: Option<(Pos2, Pos2)>,
}

impl BoxSelect {
    /// B: the next drag draws a box.
    pub fn arm(&mut self) {
        self.armed = true;
    }

    /// Whether a box is armed or being dragged.
    pub fn is_active(&self) -> bool {
        self.armed || self.area.is_some()
    }

    /// Esc: drops an armed or dragged box; returns whether there was one.
    pub fn cancel(&mut self) -> bool {
        let was = self.is_active();
        (self.armed, self.area) = (false, None);
        was
    }

    /// Takes a drag when armed, or when `empty` (a transform tool with nothing to transform);
    /// selects on release (Shift adds). Returns whether the drag is a box (so the camera stays).
    pub fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, empty: bool) -> bool {
        let (ui, response, rect) = (view.ui, view.response, view.rect);
        if response.drag_started_by(egui::PointerButton::Primary) && (self.armed || empty) {
            let from = ui
                .input(|i| i.pointer.press_origin())
                .or(response.interact_pointer_pos());
            self.area = from.map(|p| (p, p));
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
            let items = crate::ui::picking::items_in(tc.doc, rect, Rect::from_two_pos(from, to));
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
            self.armed = false;
        }
        true
    }

    /// The box being dragged.
    pub fn overlay(&self, painter: &egui::Painter) {
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
    }
}
