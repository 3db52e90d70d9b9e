//! The side panel: one view per collapsible group, each with its own `ui()` that takes only
//! what it needs (the document, the selection, the tool state), as egui's demo app does.

mod export;
mod light;
mod render;
mod scene;
mod simulation;
mod sketch;
mod timeline;
mod view;

pub use export::{ExportAsk, ExportPanel};
pub use light::LIGHT;
pub use render::{RENDER, take_removed_tier};
pub use scene::ScenePanel;
pub use simulation::SimulationPanel;
pub use sketch::SketchPanel;
pub use timeline::{Timeline, state as timeline_state};
pub use view::{GeometryUpdate, ViewPanel, ViewStats};

use egui::Ui;

use crate::scene::{Document, Edit, Scene};

/// A group that edits one part of the document (the light, the render settings): `body`
/// changes a copy, and a change becomes one undoable edit (a slider drag folds into one step).
pub struct PartPanel<T: 'static> {
    /// The group's title (also the merge key of its edits).
    pub title: &'static str,
    /// The part it edits.
    pub part: fn(&Scene) -> &T,
    /// The edit that replaces the part.
    pub edit: fn(T) -> Edit,
    /// The group's widgets.
    pub body: fn(&mut Ui, &mut T),
    /// Open until the user closes it (the groups a new user needs first).
    pub open: bool,
}

impl<T: Clone + PartialEq> PartPanel<T> {
    /// A group titled `title` whose `body` edits the `part` that `edit` replaces, open at
    /// first when `open` says.
    pub const fn new(
        title: &'static str,
        part: fn(&Scene) -> &T,
        edit: fn(T) -> Edit,
        body: fn(&mut Ui, &mut T),
        open: bool,
    ) -> Self {
        Self {
            title,
            part,
            edit,
            body,
            open,
        }
    }

    /// Draws the group.
    pub fn ui(&self, ui: &mut Ui, doc: &mut Document) {
        crate::ui::widgets::group(ui, self.title, self.open, |ui| {
            let mut value = (self.part)(doc.scene()).clone();
            (self.body)(ui, &mut value);
            if value != *(self.part)(doc.scene()) {
                doc.apply((self.edit)(value), Some(self.title));
            }
        });
    }
}
