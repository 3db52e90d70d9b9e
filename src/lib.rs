//! cloudsketch: sketch a cloud's outline, get a volumetric 3D cloud.
//!
//! One crate for the browser (wasm32, WebGPU with a WebGL2 fallback) and native (desktop
//! window and a headless CLI). See ARCHITECTURE.md for the map; in short:
//!
//! - [`scene`]: the document, the only state a user makes (pure);
//! - [`sketch`]: stroke → skeleton → spheres (pure);
//! - [`field`]: the blended implicit field and its baked grid (pure);
//! - [`render`]: the only user of wgpu;
//! - [`ui`]: the eframe app;
//! - `cli`, `bench` (native) and `web` (wasm32): the entry points of each target.

pub mod field;
pub mod render;
pub mod scene;
pub mod sketch;
pub mod ui;

#[cfg(not(target_arch = "wasm32"))]
pub mod bench;
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
#[cfg(target_arch = "wasm32")]
pub mod web;

pub use ui::CloudApp;
