//! `render`: a scene offscreen to PNG with the app's renderer, at full quality.

use std::path::Path;

use super::{read_scene_or_link, write};
use crate::render::offscreen::{Backdrop, MAX_SIDE, Offscreen};
use crate::scene::{Scene, set_by_pointer};

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad =
        || format!("size {text:?} is not WIDTHxHEIGHT with sides 1..={MAX_SIDE} (e.g. 1280x720)");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(bad());
    }
    Ok((w, h))
}

/// `cloudsketch render [SCENE|URL] -o OUT.png --size WxH --set PATH=VALUE… [--time T | --frame N]
/// [--shot]`.
pub fn run(
    scene: Option<&str>,
    output: &Path,
    size: &str,
    sets: &[String],
    at: Option<crate::scene::Moment>,
    shot: bool,
) -> Result<(), String> {
    let (width, height) = parse_size(size)?;
    super::check_outputs(&scene.into_iter().collect::<Vec<_>>(), &[output])?;
    let mut scene = match scene {
        Some(arg) => read_scene_or_link(arg)?,
        None => Scene::default(),
    };
    for assignment in sets {
        let (set, repairs) = set_by_pointer(&scene, assignment).map_err(|e| e.to_string())?;
        for r in repairs {
            eprintln!("warning: --set {assignment}: repaired {r}");
        }
        scene = set;
    }
    if let Some(at) = at {
        scene = scene.posed_at(at.seconds(&scene.clock)?);
    }
    if shot {
        scene.camera = scene
            .shot
            .clone()
            .ok_or("--shot: the scene has no shot camera (View › Set shot from view makes one)")?;
    }
    let mut offscreen = Offscreen::new().map_err(|e| e.to_string())?;
    let start = std::time::Instant::now();
    let image = super::render_shown(&mut offscreen, &scene, [width, height], Backdrop::Sky)?;
    let png = image
        .to_png()
        .map_err(|e| format!("PNG encoding failed: {e}"))?;
    write(output, &png)?;
    eprintln!(
        "rendered {width}x{height}, {} slices on {} in {:.2} s → {}",
        scene.render.slices,
        offscreen.adapter_name(),
        start.elapsed().as_secs_f64(),
        output.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert_eq!(parse_size("64X48"), Ok((64, 48)));
        for bad in ["", "640", "0x10", "10x0", "x", "99999x10", "-1x5", "axb"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }
}
