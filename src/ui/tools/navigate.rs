//! The Navigate tool: a drag orbits the view (the camera's input does that), a click selects.

use super::{Shared, ToolContext, ViewInput, ViewTool, click_select};
use crate::scene::Document;
use crate::ui::selection::Selection;

/// Navigate: the primary button orbits; a click selects what is under it.
#[derive(Default)]
pub struct NavigateTool;

impl ViewTool for NavigateTool {
    fn input(&mut self, view: &ViewInput<'_>, tc: &mut ToolContext<'_>, shared: &Shared) -> bool {
        click_select(view, tc, shared);
        false
    }

    fn hint(&self, _: &Document, _: &Selection, _: &Shared) -> Option<String> {
        None
    }
}
