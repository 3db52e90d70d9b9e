//! Everything that touches the GPU. Only this module imports wgpu.
//!
//! - [`volume`]: pipelines and resources, created once ([`VolumeRenderer`]);
//! - [`gpu_types`]: the Pod structs mirrored in WGSL;
//! - [`progressive`]: the frame-time budget that picks preview and refinement work (pure);
//! - [`noise`]: the periodic noise volume (pure);
//! - [`viewport`]: the egui paint callback that runs the renderer inside the app;
//! - `offscreen` (native): headless rendering for the CLI, benchmarks and tests.

pub mod gpu_types;
pub mod noise;
pub mod progressive;
pub mod viewport;
pub mod volume;

#[cfg(not(target_arch = "wasm32"))]
pub mod offscreen;

use std::sync::Arc;

pub use volume::{SliceJob, VolumeData, VolumeRenderer, shaders};

use crate::field::{Field, FieldInputs, bake};
use crate::scene::Scene;

/// Derives the baked volume from a document, re-baking only when the field's inputs change.
#[derive(Default)]
pub struct VolumeCache {
    inputs: Option<FieldInputs>,
    data: Option<Arc<VolumeData>>,
    generation: u64,
}

impl VolumeCache {
    /// The volume for `scene`; cheap when nothing it depends on changed.
    pub fn update(&mut self, scene: &Scene) -> Arc<VolumeData> {
        match (&self.inputs, &self.data) {
            (Some(old), Some(data)) if old.matches(scene) => data.clone(),
            _ => {
                let inputs = FieldInputs::of(scene);
                self.generation += 1;
                let grid = bake(&Field::from_scene(scene), &inputs.grid);
                let data = Arc::new(VolumeData {
                    generation: self.generation,
                    grid,
                    noise_seed: scene.seed,
                });
                self.inputs = Some(inputs);
                self.data = Some(data.clone());
                data
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_rebakes_only_on_field_changes() {
        let mut cache = VolumeCache::default();
        let mut scene = Scene::default();
        let a = cache.update(&scene);
        scene.camera.yaw_deg += 30.0;
        scene.render.slices = 64;
        assert_eq!(cache.update(&scene).generation, a.generation);
        scene.light.sun_azimuth_deg += 90.0;
        let b = cache.update(&scene);
        assert!(b.generation > a.generation);
        scene.seed += 1;
        assert!(cache.update(&scene).generation > b.generation);
    }
}
