//! `link`: a scene file to a share link, or a link back to a scene file.

use std::path::Path;

use super::{read_scene_or_link, write};
use crate::share::{decode_link, link_url};

/// `cloudsketch link SCENE.json [--base URL]`: prints the URL and its length.
pub fn encode(scene: &str, base: &str) -> Result<(), String> {
    let scene = read_scene_or_link(scene)?;
    let url = link_url(base, &scene).map_err(|e| e.to_string())?;
    println!("{url}");
    eprintln!("{} characters", url.len());
    Ok(())
}

/// `cloudsketch link --decode URL -o SCENE.json`.
pub fn decode(url: &str, output: &Path) -> Result<(), String> {
    let (scene, repairs) = decode_link(url).map_err(|e| e.to_string())?;
    for r in repairs {
        eprintln!("warning: the link's scene: repaired {r}");
    }
    write(output, scene.to_json().as_bytes())
}
