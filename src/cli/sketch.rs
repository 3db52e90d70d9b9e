//! `sketch`: drawn outlines (stroke files) into a scene, headless.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::{read_capped, write};
use crate::scene::Scene;

/// A stroke file.
#[derive(serde::Deserialize)]
struct StrokeFile {
    /// Each `[x, y]` (checked after reading, so a wrong count is named as such).
    points: Vec<Vec<f64>>,
    #[serde(default = "yes")]
    closed: bool,
}

fn yes() -> bool {
    true
}

/// World height the strokes are scaled to, so the default camera frames them.
const SKETCH_WORLD_HEIGHT: f64 = 6.0;

/// `cloudsketch sketch STROKE.json… -o SCENE.json`.
pub fn run(
    paths: &[PathBuf],
    output: &Path,
    spheres_out: Option<&Path>,
    inflate: f64,
    extend: bool,
    seed: u64,
    billows: u32,
) -> Result<(), String> {
    use crate::scene::{Billows, DrawingPlane, MAX_PLANES, StrokeKind};
    use crate::sketch::{SketchParams, interpret};
    if !(0.0..=1.0).contains(&inflate) {
        return Err(format!("--inflate {inflate} is outside 0..=1"));
    }
    let levels = crate::limits::BILLOW_LEVELS;
    if !(levels.min..=levels.max).contains(&f64::from(billows)) {
        return Err(format!(
            "--billows {billows} is outside {}..={}",
            levels.min, levels.max
        ));
    }
    let billows = Billows {
        levels: billows,
        ..Billows::NEW
    };
    if paths.len() > MAX_PLANES {
        return Err(format!("{} strokes (at most {MAX_PLANES})", paths.len()));
    }
    let inputs: Vec<&str> = paths.iter().filter_map(|p| p.to_str()).collect();
    let outputs: Vec<&Path> = std::iter::once(output).chain(spheres_out).collect();
    super::check_outputs(&inputs, &outputs)?;
    let params = SketchParams {
        inflate,
        extend,
        ..Default::default()
    };
    let mut strokes = Vec::new();
    for path in paths {
        let file: StrokeFile = serde_json::from_str(&read_capped(path)?).map_err(|e| {
            format!(
                "{}: not a stroke file ({{\"points\": [[x, y], ...]}}): {e}",
                path.display()
            )
        })?;
        if let Some((i, p)) = file.points.iter().enumerate().find(|(_, p)| p.len() != 2) {
            return Err(format!(
                "{}: point {i} has {} numbers (a point is [x, y])",
                path.display(),
                p.len()
            ));
        }
        // y down → y up, so the plane's points read like the world.
        let flipped: Vec<[f64; 2]> = file.points.iter().map(|p| [p[0], -p[1]]).collect();
        // The scene stores the stroke that was used: thinned here, not refused later.
        let (points, thinned) = crate::sketch::outline::thin(&flipped);
        if let Some(w) = thinned {
            eprintln!("warning: {}: {w}", path.display());
        }
        let sketch = interpret(
            &points,
            file.closed,
            &params,
            seed.wrapping_add(strokes.len() as u64),
        )
        .map_err(|e| format!("{}: {e}", path.display()))?;
        for w in &sketch.warnings {
            eprintln!("warning: {}: {w}", path.display());
        }
        strokes.push((points, file.closed, sketch));
    }
    // One frame for all strokes (they were drawn on one canvas): fit their box to the view.
    let all: Vec<glam::DVec2> = strokes
        .iter()
        .flat_map(|(_, _, s)| s.outline.points.iter().copied())
        .collect();
    let (lo, hi) = all
        .iter()
        .fold((glam::DVec2::MAX, glam::DVec2::MIN), |(a, b), &q| {
            (a.min(q), b.max(q))
        });
    let scale = SKETCH_WORLD_HEIGHT / (hi.y - lo.y).max((hi.x - lo.x) * 0.5).max(1e-9);
    let mut scene = Scene::preset(crate::scene::Preset::Empty);
    let target = scene.camera.target.as_dvec3();
    let centre = (lo + hi) * 0.5;
    for (i, (points, closed, _)) in strokes.iter().enumerate() {
        let c = crate::scene::centre_of(
            &points
                .iter()
                .map(|&[x, y]| glam::DVec2::new(x, y))
                .collect::<Vec<_>>(),
        );
        let origin = target + ((c - centre) * scale).extend(0.0);
        scene.planes.push(Arc::new(DrawingPlane {
            name: format!("Outline {}", i + 1),
            kind: StrokeKind::Outline,
            origin: origin.as_vec3(),
            points: points
                .iter()
                .map(|&[x, y]| ((glam::DVec2::new(x, y) - c) * scale).as_vec2())
                .collect(),
            closed: *closed,
            sketch: params.clone(),
            seed: seed.wrapping_add(i as u64),
            billows,
            ..Default::default()
        }));
    }
    // On the stroke grid, as the app stores a new stroke: the scene's link is then exact.
    scene.snap_strokes();
    scene.validate().map_err(|e| e.to_string())?;
    write(output, scene.to_json().as_bytes())?;
    if let Some(path) = spheres_out {
        let spheres: Vec<serde_json::Value> = strokes[0]
            .2
            .spheres
            .iter()
            .map(|s| serde_json::json!({"center": [s.center.x, -s.center.y, s.center.z], "radius": s.radius}))
            .collect();
        let text = serde_json::to_string_pretty(&serde_json::json!({ "spheres": spheres }))
            .map_err(|e| e.to_string())?;
        write(path, text.as_bytes())?;
    }
    let total: usize = strokes.iter().map(|s| s.2.spheres.len()).sum();
    eprintln!(
        "{} stroke(s) → {total} spheres → {}",
        strokes.len(),
        output.display()
    );
    Ok(())
}
