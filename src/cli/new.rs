//! `new`: writes a new scene document from a preset.

use std::path::Path;

use super::write;
use crate::scene::{Preset, Scene};

/// `cloudsketch new --preset NAME -o SCENE.json`.
pub fn run(preset: &str, output: &Path) -> Result<(), String> {
    let preset = Preset::from_name(preset).ok_or_else(|| {
        let names: Vec<_> = Preset::ALL.iter().map(|(_, n)| *n).collect();
        format!(
            "unknown preset {preset:?} (choose one of: {})",
            names.join(", ")
        )
    })?;
    super::check_outputs(&[], &[output])?;
    write(output, Scene::preset(preset).to_json().as_bytes())
}
