//! The Ellipsoid tool: a click adds an ellipsoid where it lands, sized for what it lands on.

use super::{Shared, ToolContext, ViewInput, ViewTool};
use crate::scene::Document;
use crate::ui::selection::Selection;

/// Ellipsoid: a click adds one where it lands (a drag orbits).
#[derive(Default)]
pub struct EllipsoidTool;

impl ViewTool for EllipsoidTool {
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, _: &Shared) -> bool {
        let (ui, response, rect) = (view.ui, view.response, view.rect);
        if response.clicked()
            && let Some(p) = response.interact_pointer_pos()
            && let Some(m) =
                crate::ui::ellipsoids::add_at(tc.doc, tc.derived, tc.selection, rect, p)
        {
            tc.notices.note(ui.input(|i| i.time), m);
        }
        false
    }

    fn hint(&self, _: &Document, _: &Selection, _: &Shared) -> Option<String> {
        Some("Click to add an ellipsoid there (a drag orbits) · G, R, S move, turn or scale the selection".to_owned())
    }
}
