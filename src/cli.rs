//! The native command line: `cloudsketch` alone opens the desktop app; subcommands work
//! headless (`new`, `render`, `bench`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::render::offscreen::{MAX_SIDE, Offscreen};
use crate::scene::{Preset, Scene, set_by_pointer};
use crate::ui::{CloudApp, StartOptions};

/// Largest scene or stroke file read.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

#[derive(Parser)]
#[command(
    name = "cloudsketch",
    version,
    about = "Sketch a cloud's outline, get a volumetric 3D cloud."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Write a new scene document.
    New {
        /// Starting point: cumulus (default) or empty.
        #[arg(long, default_value = "cumulus")]
        preset: String,
        /// Where to write the scene JSON.
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Render a scene offscreen to PNG with the app's renderer (full quality).
    Render {
        /// Scene JSON; the default scene when left out.
        scene: Option<PathBuf>,
        /// Output PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// Image size as WIDTHxHEIGHT.
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Override a scene value by JSON Pointer, e.g. /render/slices=256 (repeatable).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
    },
    /// Turn drawn outlines into a scene (one drawing plane per stroke), headless.
    Sketch {
        /// Stroke files: {"points": [[x, y], ...], "closed": true|false}, y pointing down.
        #[arg(required = true)]
        strokes: Vec<PathBuf>,
        /// Where to write the scene JSON.
        #[arg(short, long)]
        output: PathBuf,
        /// Also write the first stroke's final spheres, in its own units and axes.
        #[arg(long)]
        spheres_out: Option<PathBuf>,
        /// Inflation slider t in [0, 1] (0 keeps the maximal balls).
        #[arg(long, default_value_t = 0.0)]
        inflate: f64,
        /// Turn the automatic 3D extension off.
        #[arg(long)]
        no_extend: bool,
        /// Seed of the 3D extension.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Run the benchmark suite.
    Bench {
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
    },
}

/// Entry point of the native binary.
pub fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        None => run_desktop(),
        Some(Command::New { preset, output }) => new_scene(&preset, &output),
        Some(Command::Render {
            scene,
            output,
            size,
            set,
        }) => render(scene.as_deref(), &output, &size, &set),
        Some(Command::Sketch {
            strokes,
            output,
            spheres_out,
            inflate,
            no_extend,
            seed,
        }) => sketch(
            &strokes,
            &output,
            spheres_out.as_deref(),
            inflate,
            !no_extend,
            seed,
        ),
        Some(Command::Bench { json }) => crate::bench::run(json),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run_desktop() -> Result<(), String> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("cloudsketch")
            .with_inner_size([1280.0, 800.0]),
        ..Default::default()
    };
    eframe::run_native(
        "cloudsketch",
        options,
        Box::new(|cc| {
            Ok(Box::new(CloudApp::new(
                cc,
                StartOptions {
                    initial_cost: 1e-8,
                    ..Default::default()
                },
            )))
        }),
    )
    .map_err(|e| format!("could not open the desktop window: {e}"))
}

/// Reads a text file with a size cap.
pub fn read_capped(path: &Path) -> Result<String, String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if meta.len() > MAX_INPUT_BYTES {
        return Err(format!(
            "{}: {} bytes is more than the {} MiB limit",
            path.display(),
            meta.len(),
            MAX_INPUT_BYTES >> 20
        ));
    }
    std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))
}

/// Reads and validates a scene document.
pub fn read_scene(path: &Path) -> Result<Scene, String> {
    Scene::from_json(&read_capped(path)?).map_err(|e| format!("{}: {e}", path.display()))
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    std::fs::write(path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

fn new_scene(preset: &str, output: &Path) -> Result<(), String> {
    let preset = Preset::from_name(preset).ok_or_else(|| {
        let names: Vec<_> = Preset::ALL.iter().map(|(_, n)| *n).collect();
        format!(
            "unknown preset {preset:?} (choose one of: {})",
            names.join(", ")
        )
    })?;
    write(output, Scene::preset(preset).to_json().as_bytes())
}

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

fn render(scene: Option<&Path>, output: &Path, size: &str, sets: &[String]) -> Result<(), String> {
    let (width, height) = parse_size(size)?;
    let mut scene = match scene {
        Some(path) => read_scene(path)?,
        None => Scene::default(),
    };
    for assignment in sets {
        scene = set_by_pointer(&scene, assignment).map_err(|e| e.to_string())?;
    }
    let mut offscreen = Offscreen::new().map_err(|e| e.to_string())?;
    let start = std::time::Instant::now();
    let image = offscreen
        .render(&scene, width, height)
        .map_err(|e| e.to_string())?;
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

/// A stroke file.
#[derive(serde::Deserialize)]
struct StrokeFile {
    points: Vec<[f64; 2]>,
    #[serde(default = "yes")]
    closed: bool,
}

fn yes() -> bool {
    true
}

/// World height the strokes are scaled to, so the default camera frames them.
const SKETCH_WORLD_HEIGHT: f64 = 6.0;

fn sketch(
    paths: &[PathBuf],
    output: &Path,
    spheres_out: Option<&Path>,
    inflate: f64,
    extend: bool,
    seed: u64,
) -> Result<(), String> {
    use crate::scene::{DrawingPlane, MAX_PLANES, StrokeKind};
    use crate::sketch::{SketchParams, interpret};
    if !(0.0..=1.0).contains(&inflate) {
        return Err(format!("--inflate {inflate} is outside 0..=1"));
    }
    if paths.len() > MAX_PLANES {
        return Err(format!("{} strokes (at most {MAX_PLANES})", paths.len()));
    }
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
        // y down → y up, so the plane's points read like the world.
        let points: Vec<[f64; 2]> = file.points.iter().map(|&[x, y]| [x, -y]).collect();
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
        scene.planes.push(DrawingPlane {
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
            ..Default::default()
        });
    }
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
