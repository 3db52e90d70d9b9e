//! The eframe app: panels, the 3D viewport and its tools. The only module that uses egui
//! widgets; it edits the scene document through [`crate::scene::History`] and hands the
//! renderer a per-frame snapshot.

mod app;
mod camera_input;
mod panels;
mod sketch_tool;

pub use app::{CloudApp, Host, PageStatus, StartOptions};
pub use sketch_tool::Tool;
