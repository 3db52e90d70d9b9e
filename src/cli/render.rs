//! `render`: a scene offscreen to PNG or EXR with the app's renderer, at full quality.

use std::path::Path;

use super::checkpoints::FrameCheckpoints;
use super::sequence::{Made, Pattern, Sequence, SequenceArgs, stable_hash};
use super::{ImageFile, read_scene_or_link, write};
use crate::derive::{Derived, Frame};
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

/// What `cloudsketch render` was asked for.
pub struct Request<'a> {
    /// Scene file or link; the default scene when `None`.
    pub scene: Option<&'a str>,
    /// Output image, or a sequence's name pattern.
    pub output: &'a Path,
    /// `--format`: png or exr (else the output's extension says).
    pub format: Option<&'a str>,
    /// The cloud alone over a transparent background.
    pub transparent: bool,
    /// `WIDTHxHEIGHT`.
    pub size: &'a str,
    /// `--set PATH=VALUE` overrides.
    pub sets: &'a [String],
    /// The moment to render (else the scene's time).
    pub at: Option<crate::scene::Moment>,
    /// Through the shot camera.
    pub shot: bool,
    /// `--frames`, `--fps`, `--progress`, `--overwrite`.
    pub sequence: &'a SequenceArgs,
}

/// `cloudsketch render [SCENE|URL] -o OUT.png --size WxH --set PATH=VALUE… [--time T | --frame N
/// | --frames A..B -o out/frame_####.png] [--shot]`.
pub fn run(r: &Request) -> Result<(), String> {
    let (width, height) = parse_size(r.size)?;
    let file = ImageFile::choose(r.format, r.output)?;
    let backdrop = if r.transparent {
        Backdrop::Transparent
    } else {
        Backdrop::Sky
    };
    let inputs = r.scene.into_iter().collect::<Vec<_>>();
    if Pattern::of(r.output).is_none() {
        super::check_outputs(&inputs, &[r.output])?;
    }
    let mut scene = match r.scene {
        Some(arg) => read_scene_or_link(arg)?,
        None => Scene::default(),
    };
    for assignment in r.sets {
        let (set, repairs) = set_by_pointer(&scene, assignment).map_err(|e| e.to_string())?;
        for r in repairs {
            eprintln!("warning: --set {assignment}: repaired {r}");
        }
        scene = set;
    }
    let plan = r.sequence.plan(r.output, &mut scene, r.at)?;
    if r.shot && scene.shot.is_none() {
        return Err(
            "--shot: the scene has no shot camera (View › Set shot from view makes one)".into(),
        );
    }
    // Through the shot camera where asked.
    let framed = |mut frame: Frame| {
        if r.shot
            && let Some(shot) = frame.scene.shot.clone()
        {
            frame.scene.camera = shot;
        }
        frame
    };
    let mut derived = Derived::default();
    let mut offscreen = Offscreen::with_output(file.output()).map_err(|e| e.to_string())?;
    if let Some(plan) = plan {
        let key = stable_hash(
            format!(
                "{}\nrender {width}x{height} shot={} {} transparent={} {}",
                scene.to_json(),
                r.shot,
                file.name(),
                r.transparent,
                env!("CARGO_PKG_VERSION")
            )
            .as_bytes(),
        );
        let mut checkpoints = FrameCheckpoints::open(r.sequence.checkpoints.as_deref())?;
        return Sequence {
            frames: plan.frames,
            pattern: &plan.pattern,
            key,
            overwrite: r.sequence.overwrite,
            report: plan.report,
            verb: "rendered",
            inputs: &inputs,
        }
        .run(|frame, main| {
            let t = scene.clock.seconds(frame);
            let note = checkpoints.before(&mut derived, &scene, t);
            let made = framed(derived.frame(&scene, Some(t)));
            let bytes =
                super::render_file(&mut offscreen, &made, [width, height], backdrop, file, None)?;
            checkpoints.after(&mut derived, &scene);
            Ok(Made {
                files: vec![(main.to_path_buf(), bytes)],
                note,
            })
        });
    }
    // Without a moment, the scene as read (a --set of a keyed value shows, as an edit does).
    let at =
        r.at.map(|moment| moment.seconds(&scene.clock))
            .transpose()?;
    let start = std::time::Instant::now();
    let frame = framed(derived.frame(&scene, at));
    let scene = &frame.scene;
    let bytes = super::render_shown(&mut offscreen, &frame, [width, height], backdrop, file)?;
    write(r.output, &bytes)?;
    eprintln!(
        "rendered {width}x{height} {}, {} slices on {} in {:.2} s → {}",
        file.name(),
        scene.render.slices,
        offscreen.adapter_name(),
        start.elapsed().as_secs_f64(),
        r.output.display()
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
