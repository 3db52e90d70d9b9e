//! The side panel: one struct per collapsible group, each with its own `ui()` that takes only
//! what it needs (the document, the selection, the tool state), as egui's demo app does.

mod light;
mod render;
mod scene;
mod sketch;
mod view;

pub use light::LightPanel;
pub use render::RenderPanel;
pub use scene::ScenePanel;
pub use sketch::SketchPanel;
pub use view::{ViewPanel, ViewStats};
