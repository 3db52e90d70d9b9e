//! The eframe app: panels, the 3D viewport and its tools. The only module that uses egui
//! widgets; it edits the scene document through [`crate::scene::History`] and hands the
//! renderer a per-frame snapshot.

mod app;
mod camera_input;
#[cfg(not(target_arch = "wasm32"))]
#[path = "files_native.rs"]
mod files;
#[cfg(target_arch = "wasm32")]
#[path = "files_web.rs"]
mod files;
mod guide;
mod panels;
mod sketch_tool;

pub use app::{CloudApp, Host, PageStatus, StartOptions};
pub use sketch_tool::Tool;
