//! `link`: a scene file to a share link, or a link back to a scene file.

use std::path::Path;

use super::{read_scene_or_link, write};
use crate::share::{decode_link, link_url};

/// `cloudsketch link SCENE.json [--base URL]`: prints the URL and its length.
pub fn encode(scene: &str, base: &str) -> Result<(), String> {
    let mut scene = read_scene_or_link(scene)?;
    // The link holds strokes on their grid: say so when that moves any.
    let moved = scene.snap_strokes();
    if moved > 0 {
        eprintln!(
            "warning: {moved} stroke(s) off the stroke grid moved onto it in the link (by at most half a step)"
        );
    }
    let url = link_url(base, &scene).map_err(|e| e.to_string())?;
    println!("{url}");
    eprintln!("{} characters", url.len());
    Ok(())
}

/// `cloudsketch link --decode URL -o SCENE.json`.
pub fn decode(url: &str, output: &Path) -> Result<(), String> {
    super::check_outputs(&[], &[output])?;
    let (scene, repairs) = decode_link(url).map_err(|e| e.to_string())?;
    for r in repairs {
        eprintln!("warning: the link's scene: repaired {r}");
    }
    write(output, scene.to_json().as_bytes())
}
