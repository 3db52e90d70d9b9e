//! cloudsketch: sketch a cloud's outline, get a volumetric 3D cloud.
//!
//! One crate for the browser (wasm32, WebGPU with a WebGL2 fallback) and native (desktop
//! window and a headless CLI). See ARCHITECTURE.md for the map; in short:
//!
//! - [`atmosphere`]: the physical sky's tables (pure);
//! - [`scene`]: the document, the only state a user makes, with undo and revisions (pure);
//! - [`sketch`]: stroke → skeleton → spheres (pure);
//! - [`density`]: the density volume every source lands in (pure);
//! - [`field`]: the blended implicit field, baked into a density volume (pure);
//! - [`derive`]: document → per-plane spheres → field → density and light volumes, cached
//!   per part (pure);
//! - [`share`]: share links and scene files, read as untrusted input (pure);
//! - [`limits`], [`seeded`]: every cap and range, and seeded randomness (pure);
//! - [`render`]: the only user of wgpu;
//! - [`ui`]: the eframe app;
//! - `files` (native): the one safe writer and the one bounded reader;
//! - `cli`, `bench` (native) and `web` (wasm32): the entry points of each target.

pub mod atmosphere;
pub mod density;
pub mod derive;
pub mod export;
pub mod field;
pub mod limits;
pub mod render;
pub mod scene;
pub mod seeded;
pub mod share;
pub mod simulate;
pub mod sketch;
pub mod ui;

#[cfg(not(target_arch = "wasm32"))]
pub mod bench;
#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
#[cfg(not(target_arch = "wasm32"))]
pub mod files;
#[cfg(target_arch = "wasm32")]
pub mod web;

pub use ui::CloudApp;
