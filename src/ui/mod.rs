//! The eframe app: the side panel's views, the 3D viewport and its tools. The only module
//! that uses egui widgets; it changes the scene only through [`crate::scene::Document`] and
//! hands the renderer a per-frame snapshot.
//!
//! - `app`: [`CloudApp`], the frame loop, shortcuts and the page status;
//! - `autosave`: when the document is written to the platform's store, and what a session
//!   starts with;
//! - `viewport`: the 3D view (progressive quality, camera input, status line);
//! - `tools`: one struct per viewport tool behind one trait (Navigate, Sketch, Cut,
//!   Ellipsoid, Move, Rotate, Scale), box selection, Blender's modal G/R/S and the overlay;
//! - `tool`: which tool the primary drag serves; `transform`: the world axes a drag locks to,
//!   what Move, Rotate and Scale drags do, the axes of a new drawing plane; `projection`: the
//!   view's maths between screen and world (shared by the tools, the gizmo and picking);
//! - `ellipsoids`: adding, picking, moving, duplicating and deleting ellipsoids;
//! - `gizmo`: the on-canvas Move, Rotate and Scale handles and their drag maths;
//! - `picking`: what a click or a dragged box selects;
//! - `sun_handle`: the orb in the view's corner that shows and turns the sun;
//! - `guide`: the reference image (loading, texture, drawing, its panel group);
//! - `scene_files`: Open, Save, Copy link, the unsaved marker and links pasted into the page;
//! - `panels`: one struct per side-panel group, each with its own `ui()`;
//! - `shortcuts`: a frame's key presses as shortcuts, in the order they were pressed;
//! - `press_record`: every pointer sample of a press, however few frames it spans;
//! - `click_timing`: a click held across a slow frame still clicks;
//! - `selection`, `notice`, `widgets`: small shared pieces;
//! - `platform_native` / `platform_web`: the one platform seam (chosen by `cfg` on the module).

mod app;
mod autosave;
mod camera_input;
mod click_timing;
mod ellipsoids;
mod flipbook;
mod gizmo;
mod guide;
mod notice;
mod panels;
mod picking;
#[cfg(not(target_arch = "wasm32"))]
#[path = "platform_native.rs"]
mod platform;
#[cfg(target_arch = "wasm32")]
#[path = "platform_web.rs"]
mod platform;
mod press_record;
mod projection;
mod scene_files;
mod selection;
mod shortcuts;
mod sun_handle;
mod tool;
mod tools;
mod transform;
mod viewport;
mod widgets;

pub use app::{CloudApp, Host, PageStatus, StartOptions};
pub use autosave::{Opening, Start, start_session};

/// The view rectangle the UI's unit tests place things in: 1280×800 points at the origin.
#[cfg(test)]
fn test_view() -> egui::Rect {
    egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0))
}
pub use platform::{forget_opening_in_url, wake};
pub use selection::Selection;
pub use tool::Tool;
