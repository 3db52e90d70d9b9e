//! `export`: the cloud for other tools — OpenVDB, Mitsuba 3, glb/OBJ/PLY meshes — or the
//! rendered view as a PNG (optionally over a transparent background).

use std::path::{Path, PathBuf};

use super::checkpoints::FrameCheckpoints;
use super::render::parse_size;
use super::sequence::{FrameFiles, Made, Pattern, Sequence, SequenceArgs, stable_hash};
use super::{check_outputs, read_scene_or_link, write};
use crate::export::{Format, Options, Up, export};
use crate::render::offscreen::{Backdrop, Offscreen};
use crate::scene::Scene;

/// What `cloudsketch export` was asked for.
pub struct Request<'a> {
    /// Scene file or link; the default scene when `None`.
    pub scene: Option<&'a str>,
    /// Format name.
    pub format: &'a str,
    /// Output path (the main file; Mitsuba's `.vol` and `.sky.pfm` go beside it).
    pub output: &'a Path,
    /// Grid texels along the longest side.
    pub resolution: u32,
    /// `y` or `z`.
    pub up: &'a str,
    /// File units per world unit.
    pub scale: f32,
    /// Leave the noise media out.
    pub no_noise: bool,
    /// Image size (PNG, Mitsuba's sensor).
    pub size: &'a str,
    /// PNG over a transparent background.
    pub transparent: bool,
    /// Mitsuba's samples per pixel.
    pub samples: u32,
    /// The moment to export (else the scene's time).
    pub at: Option<crate::scene::Moment>,
    /// `--frames`, `--fps`, `--progress`, `--overwrite`.
    pub sequence: &'a SequenceArgs,
}

/// Runs an export.
pub fn run(r: &Request) -> Result<(), String> {
    let format = Format::from_name(r.format).ok_or_else(|| {
        let names: Vec<&str> = Format::ALL.iter().map(|(_, n)| *n).collect();
        format!("unknown format {:?}: one of {}", r.format, names.join(", "))
    })?;
    let up = match r.up {
        "y" | "Y" => Up::Y,
        "z" | "Z" => Up::Z,
        other => return Err(format!("--up {other:?}: y or z")),
    };
    // Past a million units per world unit a far scene's coordinates leave the files' 32-bit
    // floats (1e38 wrote -inf vertices and a glb without bounds).
    if !(r.scale.is_finite() && (1e-6..=1e6).contains(&r.scale)) {
        return Err(format!("--scale {}: a number from 1e-6 to 1e6", r.scale));
    }
    let max = crate::limits::MAX_EXPORT_RESOLUTION;
    if !(8..=max).contains(&r.resolution) {
        return Err(format!("--resolution {}: 8 to {max}", r.resolution));
    }
    let (width, height) = parse_size(r.size)?;
    let backdrop = if r.transparent {
        Backdrop::Transparent
    } else {
        Backdrop::Sky
    };
    let options = Options {
        resolution: r.resolution,
        axes_up: up,
        scale: r.scale,
        noise: !r.no_noise,
        image: [width, height],
        samples: r.samples.clamp(1, 65_536),
    };
    if Pattern::of(r.output).is_some() {
        return sequence(r, format, &options, backdrop);
    }
    let paths = files_of(format, r.output);
    check_outputs(
        &r.scene.into_iter().collect::<Vec<_>>(),
        &paths.iter().map(PathBuf::as_path).collect::<Vec<_>>(),
    )?;
    let mut scene = read(r)?;
    // --fps applied; --frames with a name without # refused (no sequence without #).
    r.sequence.plan(r.output, &mut scene, r.at)?;
    let at =
        r.at.map(|moment| moment.seconds(&scene.clock))
            .transpose()?;
    let start = std::time::Instant::now();
    if format == Format::Png {
        let mut offscreen = Offscreen::new().map_err(|e| e.to_string())?;
        let png = super::render_shown(
            &mut offscreen,
            &crate::derive::frame_of(&scene, at),
            [width, height],
            backdrop,
            super::ImageFile::Png,
        )?;
        write(r.output, &png)?;
    } else {
        // The exporters sample the posed scene's field at their own resolution.
        let posed = match at {
            Some(t) => scene.posed_at(t),
            None => scene,
        };
        let files =
            export(&posed, format, &options, &stem_of(r.output)).map_err(|e| e.to_string())?;
        // The companions first and the main file last, so a main file never refers to a
        // volume that is not there; on a failure, what this run wrote is removed.
        let mut written: Vec<&Path> = Vec::new();
        for (f, path) in files.iter().zip(&paths).rev() {
            if let Err(e) = write(path, &f.bytes) {
                for done in written {
                    let _ = std::fs::remove_file(done);
                }
                return Err(e);
            }
            written.push(path);
        }
        for (f, path) in files.iter().zip(&paths) {
            eprintln!("wrote {} ({} bytes)", path.display(), f.bytes.len());
        }
    }
    eprintln!(
        "exported {} in {:.2} s → {}",
        format.name(),
        start.elapsed().as_secs_f64(),
        r.output.display()
    );
    Ok(())
}

/// The scene asked for.
fn read(r: &Request) -> Result<Scene, String> {
    match r.scene {
        Some(arg) => read_scene_or_link(arg),
        None => Ok(Scene::default()),
    }
}

/// The name a file's companions are named after (`cloud` of `out/cloud.vdb`).
fn stem_of(output: &Path) -> String {
    output
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .unwrap_or("cloud")
        .to_string()
}

/// The files an export to `output` writes: the main file where asked, the others (Mitsuba's
/// volume and sky map) beside it under their own names.
fn files_of(format: Format, output: &Path) -> Vec<PathBuf> {
    let dir = output.parent().unwrap_or(Path::new(""));
    let mut paths = vec![output.to_path_buf()];
    paths.extend(
        format
            .companions(&stem_of(output))
            .iter()
            .map(|name| dir.join(name)),
    );
    paths
}

/// `export --frames A..B -o out/cloud.####.vdb`: one export per frame. A simulated scene's
/// run steps on from frame to frame (one derivation cache for the whole sequence).
fn sequence(
    r: &Request,
    format: Format,
    options: &Options,
    backdrop: Backdrop,
) -> Result<(), String> {
    let mut scene = read(r)?;
    let Some(plan) = r.sequence.plan(r.output, &mut scene, r.at)? else {
        return Err(format!("{}: no # for the frame number", r.output.display()));
    };
    let key = stable_hash(
        format!(
            "{}\nexport {} {:?} transparent={} {}",
            scene.to_json(),
            format.name(),
            options,
            r.transparent,
            env!("CARGO_PKG_VERSION")
        )
        .as_bytes(),
    );
    let mut offscreen: Option<Offscreen> = None;
    // The derivation cache whose simulation run steps on from frame to frame.
    let mut derived = crate::derive::Derived::default();
    let mut checkpoints = FrameCheckpoints::open(r.sequence.checkpoints.as_deref())?;
    Sequence {
        frames: plan.frames,
        pattern: &plan.pattern,
        key,
        overwrite: r.sequence.overwrite,
        report: plan.report,
        verb: "exported",
        inputs: &r.scene.into_iter().collect::<Vec<_>>(),
    }
    .run(|frame, main: &Path| -> Result<Made, String> {
        let t = scene.clock.seconds(frame);
        if format == Format::Png && offscreen.is_none() {
            offscreen = Some(Offscreen::new().map_err(|e| e.to_string())?);
        }
        let note = checkpoints.before(&mut derived, &scene, t);
        let files: FrameFiles = match offscreen.as_mut() {
            Some(offscreen) => {
                let png = super::render_file(
                    offscreen,
                    &derived.frame(&scene, Some(t)),
                    options.image,
                    backdrop,
                    super::ImageFile::Png,
                    None,
                )?;
                vec![(main.to_path_buf(), png)]
            }
            None => crate::export::export_frame(
                &mut derived,
                &scene.posed_at(t),
                format,
                options,
                &stem_of(main),
            )
            .map_err(|e| e.to_string())?
            .into_iter()
            .zip(files_of(format, main))
            // The companions first, the main file last.
            .rev()
            .map(|(f, path)| (path, f.bytes))
            .collect(),
        };
        checkpoints.after(&mut derived, &scene);
        Ok(Made { files, note })
    })
}
