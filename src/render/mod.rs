//! Everything that touches the GPU. Only this module imports wgpu.
//!
//! - [`renderer`]: the volume renderer ([`VolumeRenderer`]), built from
//!   [`passes`] (slice and composite pipelines, created once) and [`resources`] (textures,
//!   samplers, accumulation targets);
//! - [`gpu_types`]: the Pod structs mirrored in WGSL, and the plain [`View`] snapshot;
//! - [`field_gpu`]: the field evaluated on the GPU, the baseline of the CPU bake in `bench`;
//! - [`shaders`]: WGSL sources, composed;
//! - [`tone`]: the one tone map (pure), the sky's and the composite's shared curve;
//! - [`progressive`]: the frame-time budget that picks preview and refinement work (pure);
//! - [`crop`]: the pixels the cloud's box covers on screen, which the viewport draws the
//!   volume over;
//! - [`capture`]: the view rendered at a chosen size and read back (the app's PNG export);
//! - [`viewport`]: the egui paint callback that runs the renderer inside the app;
//! - `offscreen` (native): headless rendering for the CLI, benchmarks and tests.

pub mod capture;
pub mod crop;
pub mod field_gpu;
pub mod gpu_types;
pub mod passes;
pub mod probe;
pub mod progressive;
pub mod renderer;
pub mod resources;
pub mod shaders;
pub mod tone;
pub mod viewport;

#[cfg(not(target_arch = "wasm32"))]
pub mod offscreen;

pub use gpu_types::{FULL_VIEW, View};
pub use renderer::{SliceJob, VolumeRenderer};
