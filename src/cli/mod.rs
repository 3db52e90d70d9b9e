//! The native command line: `cloudsketch` alone opens the desktop app; subcommands work
//! headless. One file per subcommand: `new`, `render`, `sketch`, `link`, `export`, `simulate` (`bench` is
//! `crate::bench`);
//! `desktop` opens the window.

mod checkpoints;
mod desktop;
mod export;
mod link;
mod new;
mod progress;
mod render;
mod sequence;
mod simulate;
mod sketch;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::limits::MAX_FILE_BYTES;
use crate::scene::{Moment, Scene};

pub use render::parse_size;

#[derive(Parser)]
#[command(
    name = "cloudsketch",
    version,
    about = "Sketch a cloud's outline, get a volumetric 3D cloud.",
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Scene file (or share link) to open in the desktop app.
    scene: Option<String>,
    /// The desktop window's size in points, as WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x800")]
    window: String,
    /// Save the desktop window's first full-quality image (side panel and all) as this PNG,
    /// then close it.
    #[arg(long, value_name = "PNG")]
    screenshot: Option<PathBuf>,
    /// With --screenshot: also write the app's state (scene and view) as JSON here.
    #[arg(long, value_name = "JSON", requires = "screenshot")]
    state_out: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Write a new scene document.
    New {
        /// Starting point: cumulus (default), stratus, cirrus, cumulonimbus, sunset, empty,
        /// simulated or developing.
        #[arg(long, default_value = "cumulus")]
        preset: String,
        /// Where to write the scene JSON.
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Render a scene offscreen to PNG or EXR with the app's renderer (full quality).
    Render {
        /// Scene JSON or share link (`…#s=…`); the default scene when left out.
        scene: Option<String>,
        /// Output image: .png, or .exr for linear light (or a sequence's name pattern).
        #[arg(short, long)]
        output: PathBuf,
        /// png (display colour, 8 bits) or exr (linear half floats before the tone map,
        /// exposure applied); else the output's extension says, else png.
        #[arg(long)]
        format: Option<String>,
        /// The cloud alone over a transparent background (EXR: premultiplied alpha; PNG:
        /// straight).
        #[arg(long)]
        transparent: bool,
        /// Image size as WIDTHxHEIGHT.
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Override a scene value by JSON Pointer, e.g. /render/slices=256 (repeatable).
        #[arg(long = "set", value_name = "PATH=VALUE")]
        set: Vec<String>,
        /// Render at this scene time in seconds (the media's wind, a simulation's steps).
        #[arg(long, conflicts_with = "frame")]
        time: Option<f32>,
        /// Render at this frame of the scene's clock (its frames per second).
        #[arg(long)]
        frame: Option<u32>,
        /// Render through the scene's shot camera (posed at the time) instead of its view.
        #[arg(long)]
        shot: bool,
        #[command(flatten)]
        sequence: sequence::SequenceArgs,
    },
    /// Run a scene's cloud simulation (the `simulated` preset without SCENE) and write the
    /// smoothed density after N steps as a Mitsuba .vol or an OpenVDB .vdb.
    Simulate {
        /// Scene JSON or share link with a simulation; the `simulated` preset when left out.
        scene: Option<String>,
        /// Steps to run (100 unless --time or --frame says).
        #[arg(long, conflicts_with_all = ["time", "frame"])]
        steps: Option<u64>,
        /// Run to this scene time in seconds: the step at or before it, at the simulation's
        /// steps per second.
        #[arg(long, conflicts_with = "frame")]
        time: Option<f32>,
        /// Run to this frame of the scene's clock.
        #[arg(long)]
        frame: Option<u32>,
        /// Seed of the random terms (else the scene's).
        #[arg(long)]
        seed: Option<u64>,
        /// Output: .vol or .vdb.
        #[arg(short, long)]
        output: PathBuf,
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
        /// Levels of billows on each outline (puffs on puffs), as the app gives a new stroke
        /// (0: a smooth body).
        #[arg(long, default_value_t = crate::scene::Billows::NEW.levels)]
        billows: u32,
    },
    /// Print a share link for a scene (`link SCENE.json`), or decode one back into a scene
    /// file (`link --decode URL -o SCENE.json`).
    #[command(arg_required_else_help = true)]
    Link {
        /// Scene JSON to make a link of.
        #[arg(conflicts_with = "decode")]
        scene: Option<String>,
        /// A link to decode into a scene file (needs -o).
        #[arg(long, value_name = "URL", requires = "output")]
        decode: Option<String>,
        /// Where to write the decoded scene JSON.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// The app's address the link opens.
        #[arg(long, default_value = crate::share::DEFAULT_BASE)]
        base: String,
    },
    /// Export the cloud for other tools: vdb (OpenVDB fog volume), mitsuba (scene XML + .vol + .sky.pfm),
    /// glb, obj, ply (its surface), png (the rendered view).
    Export {
        /// Scene JSON or share link; the default scene when left out.
        scene: Option<String>,
        /// vdb, mitsuba, glb, obj, ply or png.
        #[arg(long)]
        format: String,
        /// Output file (Mitsuba's .vol and .sky.pfm are written beside its XML).
        #[arg(short, long)]
        output: PathBuf,
        /// Grid texels along the cloud's longest side (8 to 256).
        #[arg(long, default_value_t = 128)]
        resolution: u32,
        /// The file's up axis: y (the app's, glTF's) or z (Blender's).
        #[arg(long, default_value = "y")]
        up: String,
        /// File length units per world unit.
        #[arg(long, default_value_t = 1.0)]
        scale: f32,
        /// Leave the noise media out (the plain blended field).
        #[arg(long)]
        no_noise: bool,
        /// Image size, WIDTHxHEIGHT (png; Mitsuba's sensor).
        #[arg(long, default_value = "960x540")]
        size: String,
        /// PNG over a transparent background.
        #[arg(long)]
        transparent: bool,
        /// Mitsuba's samples per pixel.
        #[arg(long, default_value_t = 64)]
        samples: u32,
        /// Export the scene at this time in seconds (else the scene's own).
        #[arg(long, conflicts_with = "frame")]
        time: Option<f32>,
        /// Export the scene at this frame of its clock.
        #[arg(long)]
        frame: Option<u32>,
        #[command(flatten)]
        sequence: sequence::SequenceArgs,
    },
    /// Run the benchmark suite.
    Bench {
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
        /// Run only these groups, comma-separated: sketch, light, stroke, worst, field, time,
        /// sequence (frame sequences and checkpoints), link,
        /// mesh, simulate, shafts (the ground's shadow and the shafts of light), ca (simulate
        /// and shafts), render, march (the slices marched against rasterised), quality, gpu.
        #[arg(long)]
        only: Option<String>,
    },
}

/// Entry point of the native binary.
pub fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let runtime_folder = std::env::var_os("XDG_RUNTIME_DIR")
        .is_some_and(|d| !d.is_empty() && std::path::Path::new(&d).is_dir());
    if cli.command.is_some() || !runtime_folder {
        headless_vulkan();
    }
    let result = match cli.command {
        None => parse_size(&cli.window).and_then(|size| {
            let shot = cli.screenshot.map(|output| desktop::Screenshot {
                output,
                state: cli.state_out,
            });
            desktop::run(cli.scene.as_deref(), size, shot)
        }),
        Some(Command::New { preset, output }) => new::run(&preset, &output),
        Some(Command::Render {
            scene,
            output,
            format,
            transparent,
            size,
            set,
            time,
            frame,
            shot,
            sequence,
        }) => Moment::from_args(time, frame).and_then(|at| {
            render::run(&render::Request {
                scene: scene.as_deref(),
                output: &output,
                format: format.as_deref(),
                transparent,
                size: &size,
                sets: &set,
                at,
                shot,
                sequence: &sequence,
            })
        }),
        Some(Command::Simulate {
            scene,
            steps,
            time,
            frame,
            seed,
            output,
        }) => Moment::from_args(time, frame)
            .and_then(|at| simulate::run(scene.as_deref(), steps, at, seed, &output)),
        Some(Command::Link {
            scene,
            decode,
            output,
            base,
        }) => match (scene, decode, output) {
            (_, Some(url), Some(output)) => link::decode(&url, &output),
            (Some(scene), None, _) => link::encode(&scene, &base),
            _ => Err("give a scene file, or --decode URL -o SCENE.json".into()),
        },
        Some(Command::Sketch {
            strokes,
            output,
            spheres_out,
            inflate,
            no_extend,
            seed,
            billows,
        }) => sketch::run(
            &strokes,
            &output,
            spheres_out.as_deref(),
            inflate,
            !no_extend,
            seed,
            billows,
        ),
        Some(Command::Export {
            scene,
            format,
            output,
            resolution,
            up,
            scale,
            no_noise,
            size,
            transparent,
            samples,
            time,
            frame,
            sequence,
        }) => Moment::from_args(time, frame).and_then(|at| {
            export::run(&export::Request {
                scene: scene.as_deref(),
                format: &format,
                output: &output,
                resolution,
                up: &up,
                scale,
                no_noise,
                size: &size,
                transparent,
                samples,
                at,
                sequence: &sequence,
            })
        }),
        Some(Command::Bench { json, only }) => crate::bench::run(json, only.as_deref()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Headless subcommands choose their adapter themselves, so Mesa's implicit Vulkan layer that
/// picks a default GPU for windows (`VK_LAYER_MESA_device_select`) has nothing to do; on a
/// machine without a display it connects to Wayland to look for one and prints two
/// `error: XDG_RUNTIME_DIR is invalid…` lines that read like a failure. The layer's own switch
/// turns it off for this process (unless the user set it). The desktop window keeps the layer
/// where a session has a runtime folder (every graphical login does); without one, or with one
/// that is not a folder (a virtual X display, as `xvfb-run` gives), the layer would print the
/// same lines four times.
fn headless_vulkan() {
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called at start-up, before this process starts any thread.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

/// Reads a text file with a size cap ([`crate::files::read_bounded_text`]: a byte-order mark is
/// dropped, and nothing past the cap is read).
pub fn read_capped(path: &Path) -> Result<String, String> {
    crate::files::read_bounded_text(path, MAX_FILE_BYTES).map_err(|e| e.at(path))
}

/// Reads and validates a scene document (as the app opens one); each repair validation made
/// is a warning.
pub fn read_scene(path: &Path) -> Result<Scene, String> {
    let text = read_capped(path)?;
    let name = path.display().to_string();
    let (scene, repairs) =
        crate::share::open_scene_file(&name, text.as_bytes()).map_err(|e| e.to_string())?;
    for r in repairs {
        eprintln!("warning: {name}: repaired {r}");
    }
    Ok(scene)
}

/// Whether a command-line argument is a share link rather than a file: it holds `#s=` and no
/// file of that name exists (a path that exists is a file, whatever its name).
pub fn is_link(arg: &str) -> bool {
    arg.contains("#s=") && !Path::new(arg).exists()
}

/// Reads a scene from a file, or from a share link ([`is_link`]).
pub fn read_scene_or_link(arg: &str) -> Result<Scene, String> {
    if !is_link(arg) {
        return read_scene(Path::new(arg));
    }
    let (scene, repairs) = crate::share::decode_link(arg).map_err(|e| e.to_string())?;
    for r in repairs {
        eprintln!("warning: the link's scene: repaired {r}");
    }
    Ok(scene)
}

/// Refuses, before any work, outputs that cannot be written or that collide with each other or
/// with an input (compared as canonical paths: `./a.json` and `a.json` are one file, and so are
/// a link and its target). `inputs` that are links or missing files take no part. An output's
/// folder that does not exist yet is fine where it can be made (the nearest folder above it
/// takes new entries): the write makes it ([`crate::files::write_atomic`]), so a refused or
/// failed command leaves no empty folder.
pub fn check_outputs(inputs: &[&str], outputs: &[&Path]) -> Result<(), String> {
    let mut taken: Vec<(PathBuf, String)> = inputs
        .iter()
        .filter(|arg| !is_link(arg))
        .filter_map(|arg| {
            Some((
                Path::new(arg).canonicalize().ok()?,
                format!("the input {arg}"),
            ))
        })
        .collect();
    for out in outputs {
        let key = canonical_output(out)?;
        if let Some((_, what)) = taken.iter().find(|(k, _)| *k == key) {
            return Err(format!(
                "{}: the same file as {what} (nothing was written)",
                out.display()
            ));
        }
        match missing_folder(out) {
            Some((folder, above)) => {
                crate::files::check_writable(&above.join(".cloudsketch-probe")).map_err(|e| {
                    format!(
                        "cannot make the folder {}: {e} (nothing was written)",
                        folder.display()
                    )
                })?
            }
            None => crate::files::check_writable(out)
                .map_err(|e| format!("cannot write {}: {e}", out.display()))?,
        }
        taken.push((key, format!("the output {}", out.display())));
    }
    Ok(())
}

/// The canonical path an output will have: its own if it exists, else the nearest existing
/// folder above it, canonical, with the rest of the path (folders the write will make, and the
/// name).
fn canonical_output(path: &Path) -> Result<PathBuf, String> {
    if path.as_os_str().is_empty() {
        return Err("an output path is empty".into());
    }
    if let Ok(c) = path.canonicalize() {
        return Ok(c);
    }
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file name", path.display()))?;
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut rest = vec![name.to_owned()];
    let mut above = dir;
    loop {
        if let Ok(c) = above.canonicalize() {
            return Ok(rest.iter().rev().fold(c, |p, part| p.join(part)));
        }
        match (above.file_name(), above.parent()) {
            (Some(part), Some(parent)) => {
                rest.push(part.to_owned());
                above = if parent.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    parent
                };
            }
            _ => return Err(format!("{}: no folder above it exists", path.display())),
        }
    }
}

/// For an output whose folder does not exist: that folder, and the nearest existing one above
/// it (where the write will make the rest).
fn missing_folder(path: &Path) -> Option<(PathBuf, PathBuf)> {
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty())?;
    if folder.exists() {
        return None;
    }
    let above = folder
        .ancestors()
        .skip(1)
        .map(|a| {
            if a.as_os_str().is_empty() {
                Path::new(".")
            } else {
                a
            }
        })
        .find(|a| a.is_dir())
        .unwrap_or(Path::new("."));
    Some((folder.to_path_buf(), above.to_path_buf()))
}

/// An image file `render` writes (and `export --format png`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFile {
    /// 8-bit display colour, tone-mapped and sRGB-encoded (straight alpha when transparent).
    Png,
    /// Linear half floats before any tone map, exposure applied (premultiplied alpha).
    Exr,
}

impl ImageFile {
    /// The kind `--format` names, else the one `output`'s extension names (`.exr`), else PNG;
    /// an error for an unknown name or one the extension contradicts.
    pub fn choose(format: Option<&str>, output: &Path) -> Result<Self, String> {
        let by_name = match output
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("exr") => Some(Self::Exr),
            Some("png") => Some(Self::Png),
            _ => None,
        };
        let Some(format) = format else {
            return Ok(by_name.unwrap_or(Self::Png));
        };
        let asked = match format.to_ascii_lowercase().as_str() {
            "png" => Self::Png,
            "exr" => Self::Exr,
            other => return Err(format!("--format {other:?}: png or exr")),
        };
        match by_name {
            Some(named) if named != asked => Err(format!(
                "--format {format} but the output {} names a .{} file",
                output.display(),
                named.name()
            )),
            _ => Ok(asked),
        }
    }

    /// Its name, as `--format` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Png => "png",
            Self::Exr => "exr",
        }
    }

    /// What the offscreen renderer makes for it.
    pub fn output(self) -> crate::render::offscreen::Output {
        match self {
            Self::Png => crate::render::offscreen::Output::Display,
            Self::Exr => crate::render::offscreen::Output::Linear,
        }
    }
}

/// Renders `frame` at full quality and encodes it as `file`, with a progress line where the
/// terminal shows one (the renderer must make `file.output()`'s images).
pub fn render_shown(
    offscreen: &mut crate::render::offscreen::Offscreen,
    frame: &crate::derive::Frame,
    size: [u32; 2],
    backdrop: crate::render::offscreen::Backdrop,
    file: ImageFile,
) -> Result<Vec<u8>, String> {
    let mut progress = progress::Progress::share(format!("rendering {}x{}", size[0], size[1]));
    if progress.shown() {
        render_file(
            offscreen,
            frame,
            size,
            backdrop,
            file,
            Some(&mut |done| progress.set(done)),
        )
    } else {
        render_file(offscreen, frame, size, backdrop, file, None)
    }
}

/// Renders `frame` at full quality and encodes it as `file`; with `progress`, the slices in
/// chunks, each reported (the same image).
pub fn render_file(
    offscreen: &mut crate::render::offscreen::Offscreen,
    frame: &crate::derive::Frame,
    [width, height]: [u32; 2],
    backdrop: crate::render::offscreen::Backdrop,
    file: ImageFile,
    progress: Option<&mut dyn FnMut(f32)>,
) -> Result<Vec<u8>, String> {
    let chunks = if progress.is_some() { 32 } else { 1 };
    match file {
        ImageFile::Png => {
            let image = match progress {
                Some(report) => {
                    offscreen.render_with_progress(frame, [width, height], backdrop, chunks, report)
                }
                None => offscreen.render(frame, width, height, backdrop),
            }
            .map_err(|e| e.to_string())?;
            image
                .to_png()
                .map_err(|e| format!("PNG encoding failed: {e}"))
        }
        ImageFile::Exr => offscreen
            .render_linear(frame, [width, height], backdrop, chunks, progress)
            .map_err(|e| e.to_string())?
            .to_exr(),
    }
}

/// Writes a file ([`crate::files::write_atomic`]: on failure the old file, if any, is kept
/// whole), with the path in the error.
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    crate::files::write_atomic(path, bytes)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}
