//! Frame sequences on the command line: `render` and `export` with `--frames A..B` write one
//! file set per frame under a name pattern (`out/frame_####.png`: the `#` run is the frame
//! number, zero-padded to its length), report each finished frame (a progress line on a
//! terminal, or one JSON line on standard output with `--progress json`), and skip a frame a
//! previous run finished with the same scene and options: a sidecar beside each frame
//! (`frame_0012.png.cloudsketch.json`) records a hash of both and the files' sizes, written
//! after the frame's files (`--overwrite` redoes every frame). Every file is written under a
//! temporary name and renamed, so a failure (a full disk) leaves no partial file under a final
//! name; the frames finished before it stay.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::limits::MAX_SEQUENCE_FRAMES;
use crate::scene::Clock;

/// The frame-sequence options of `render` and `export`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct SequenceArgs {
    /// Frames A..B (inclusive) of the scene's clock, one output each: the output name's run
    /// of `#` is the frame number, zero-padded (out/frame_####.png). `--frames` alone, or an
    /// output name with `#` and no --frames, is the document's range.
    #[arg(
        long,
        value_name = "A..B",
        num_args = 0..=1,
        default_missing_value = "",
        conflicts_with_all = ["time", "frame"]
    )]
    pub frames: Option<String>,
    /// Frames per second (else the scene's): what --frame and --frames count in.
    #[arg(long)]
    pub fps: Option<f32>,
    /// How a sequence reports each finished frame: line (a progress line on a terminal) or
    /// json (one JSON object per frame on standard output).
    #[arg(long, default_value = "line")]
    pub progress: String,
    /// Redo the frames of a sequence that a previous run finished with the same scene and
    /// options (else they are skipped).
    #[arg(long)]
    pub overwrite: bool,
    /// A folder of a simulated scene's checkpoints: a sequence starts its run from the
    /// furthest one at or before its first frame (else from step 0) and writes the run's
    /// snapshots there as it passes them, for the chunks after it.
    #[arg(long, value_name = "DIR")]
    pub checkpoints: Option<PathBuf>,
}

/// A sequence asked for on the command line.
pub struct Plan {
    /// The frames.
    pub frames: Frames,
    /// The output name's pattern.
    pub pattern: Pattern,
    /// How finished frames are reported.
    pub report: Report,
}

impl SequenceArgs {
    /// Sets `scene`'s frame rate to `--fps`; returns the sequence asked for, or `None` for
    /// one output (no `--frames` and no `#` in `output`'s name). With `#` in the name,
    /// `--frame N` is the sequence of frame N alone.
    pub fn plan(
        &self,
        output: &Path,
        scene: &mut crate::scene::Scene,
        at: Option<crate::scene::Moment>,
    ) -> Result<Option<Plan>, String> {
        if let Some(fps) = self.fps {
            let range = crate::limits::FRAME_RATE;
            if !(fps.is_finite() && (range.min..=range.max).contains(&f64::from(fps))) {
                return Err(format!(
                    "--fps {fps}: {} to {} frames per second",
                    range.min, range.max
                ));
            }
            scene.clock.fps = fps;
            scene.clock.sanitize();
        }
        let report = Report::parse(&self.progress)?;
        let pattern = Pattern::of(output);
        match (&self.frames, pattern) {
            (None, None) => Ok(None),
            (Some(_), None) => Err(format!(
                "--frames: the output name {} has no run of # for the frame number (e.g. \
                 out/frame_####.png)",
                output.display()
            )),
            (frames, Some(pattern)) => {
                let frames = match (frames, at) {
                    (Some(text), _) => Frames::parse(text, &scene.clock)?,
                    (None, Some(crate::scene::Moment::Frame(n))) => {
                        Frames::parse(&n.to_string(), &scene.clock)?
                    }
                    (None, Some(crate::scene::Moment::Seconds(_))) => {
                        return Err(format!(
                            "--time with the name {}, whose # stands for a frame number: give \
                             --frame N or --frames A..B",
                            output.display()
                        ));
                    }
                    (None, None) => Frames::parse("", &scene.clock)?,
                };
                Ok(Some(Plan {
                    frames,
                    pattern,
                    report,
                }))
            }
        }
    }
}

/// An inclusive range of frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Frames {
    /// First frame.
    pub first: u32,
    /// Last frame (inclusive).
    pub last: u32,
}

impl Frames {
    /// Parses `--frames`: `A..B` (inclusive, as Blender's), `A..=B`, or one frame `N`; empty
    /// text is `clock`'s own range. Refuses reversed ranges, frames past `clock`'s last and
    /// more than [`MAX_SEQUENCE_FRAMES`] frames.
    pub fn parse(text: &str, clock: &Clock) -> Result<Self, String> {
        let text = text.trim();
        let frames = if text.is_empty() {
            Self {
                first: clock.start,
                last: clock.end,
            }
        } else {
            let number = |s: &str| {
                s.trim().parse::<u32>().map_err(|_| {
                    format!("--frames {text:?}: A..B with whole frame numbers (e.g. 0..120)")
                })
            };
            match text.split_once("..") {
                Some((a, b)) => Self {
                    first: number(a)?,
                    last: number(b.strip_prefix('=').unwrap_or(b))?,
                },
                None => {
                    let n = number(text)?;
                    Self { first: n, last: n }
                }
            }
        };
        if frames.last < frames.first {
            return Err(format!(
                "--frames {}..{}: the range is reversed (the first frame comes first)",
                frames.first, frames.last
            ));
        }
        if frames.last > clock.last_frame() {
            return Err(format!(
                "--frames: frame {} is past the last, {}, at {} frames per second ({} s)",
                frames.last,
                clock.last_frame(),
                clock.fps,
                crate::limits::MAX_TIME
            ));
        }
        if frames.len() > MAX_SEQUENCE_FRAMES {
            return Err(format!(
                "--frames {}..{}: {} frames, at most {MAX_SEQUENCE_FRAMES} in one run (split \
                 the range into chunks)",
                frames.first,
                frames.last,
                frames.len()
            ));
        }
        Ok(frames)
    }

    /// How many frames.
    pub fn len(&self) -> u32 {
        self.last - self.first + 1
    }

    /// The frames, first to last.
    pub fn iter(&self) -> std::ops::RangeInclusive<u32> {
        self.first..=self.last
    }
}

/// An output name with a run of `#` standing for the frame number.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pattern {
    folder: PathBuf,
    before: String,
    digits: usize,
    after: String,
}

impl Pattern {
    /// The pattern of `path`, whose file name holds a run of `#` (the last run where there
    /// are several), or `None` where it holds none.
    pub fn of(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_str()?;
        let end = name.rfind('#')? + 1;
        let start = name[..end].trim_end_matches('#').len();
        Some(Self {
            folder: path.parent().map(Path::to_path_buf).unwrap_or_default(),
            before: name[..start].to_string(),
            digits: end - start,
            after: name[end..].to_string(),
        })
    }

    /// The file of frame `frame` (a number longer than the run is written whole).
    pub fn path(&self, frame: u32) -> PathBuf {
        self.folder.join(format!(
            "{}{frame:0width$}{}",
            self.before,
            self.after,
            width = self.digits
        ))
    }

    /// The folder the frames go in ("" for the working folder).
    pub fn folder(&self) -> &Path {
        &self.folder
    }
}

/// How finished frames are reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Report {
    /// A progress line on standard error when it is a terminal, and a summary.
    Line,
    /// One JSON object per finished frame on standard output.
    Json,
}

impl Report {
    /// Parses `--progress`: `line` (the default) or `json`.
    pub fn parse(text: &str) -> Result<Self, String> {
        match text {
            "line" | "bar" => Ok(Self::Line),
            "json" => Ok(Self::Json),
            other => Err(format!("--progress {other:?}: line or json")),
        }
    }
}

/// What a sidecar records of a finished frame.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
struct Sidecar {
    /// The frame.
    frame: u32,
    /// Hash of the scene and the options that made it.
    key: String,
    /// The frame's files (names beside the sidecar) and their sizes.
    files: Vec<(String, u64)>,
}

/// The sidecar of a frame whose main file is `main`.
fn sidecar_path(main: &Path) -> PathBuf {
    let mut name = main.file_name().unwrap_or_default().to_os_string();
    name.push(".cloudsketch.json");
    main.with_file_name(name)
}

pub use crate::seeded::stable_hash;

/// Whether a previous run finished frame `frame` at `main` with `key`: its sidecar says so
/// and every file it lists is there with its size.
fn finished(main: &Path, frame: u32, key: &str) -> bool {
    let Ok(text) = crate::files::read_bounded_text(&sidecar_path(main), 1 << 16) else {
        return false;
    };
    let Ok(sidecar) = serde_json::from_str::<Sidecar>(&text) else {
        return false;
    };
    let folder = main.parent().unwrap_or(Path::new(""));
    sidecar.frame == frame
        && sidecar.key == key
        && !sidecar.files.is_empty()
        && sidecar.files.iter().all(|(name, bytes)| {
            !name.contains(['/', '\\'])
                && std::fs::metadata(folder.join(name)).is_ok_and(|m| m.len() == *bytes)
        })
}

/// One frame's files: the main file last (a main file never refers to a companion that is
/// not there yet).
pub type FrameFiles = Vec<(PathBuf, Vec<u8>)>;

/// A frame made: its files, and what its making has to say (where a simulation started).
pub struct Made {
    /// The files.
    pub files: FrameFiles,
    /// Said with the frame's report.
    pub note: Option<String>,
}

impl From<FrameFiles> for Made {
    fn from(files: FrameFiles) -> Self {
        Self { files, note: None }
    }
}

/// A sequence to write.
pub struct Sequence<'a> {
    /// The frames.
    pub frames: Frames,
    /// The main file's name pattern.
    pub pattern: &'a Pattern,
    /// The scene's and options' hash ([`stable_hash`]), for the sidecars.
    pub key: u64,
    /// Redo frames a previous run finished.
    pub overwrite: bool,
    /// How finished frames are reported.
    pub report: Report,
    /// What is made, for messages ("rendered", "exported").
    pub verb: &'a str,
    /// The command's inputs (a scene file or a link): no frame may overwrite one.
    pub inputs: &'a [&'a str],
}

impl Sequence<'_> {
    /// Makes the folder, checks it can be written (before any frame), then has `make` make
    /// each frame not already finished (`make(frame, main path)` gives its files), writes
    /// them and their sidecar, and reports it. An error names its frame; the frames finished
    /// before it stay.
    pub fn run(
        &self,
        mut make: impl FnMut(u32, &Path) -> Result<Made, String>,
    ) -> Result<(), String> {
        let folder = self.pattern.folder();
        if !folder.as_os_str().is_empty() {
            std::fs::create_dir_all(folder)
                .map_err(|e| format!("cannot make the folder {}: {e}", folder.display()))?;
        }
        self.check_inputs()?;
        let first = self.pattern.path(self.frames.first);
        crate::files::check_writable(&first).map_err(|e| {
            format!(
                "cannot write {}: {e} (no frame was written)",
                first.display()
            )
        })?;
        let key = format!("{:016x}", self.key);
        let total = self.frames.len();
        let start = Instant::now();
        let mut line = super::progress::Progress::counting(
            format!("frames {}..{}", self.frames.first, self.frames.last),
            total as u64,
        );
        let (mut made, mut skipped) = (0u32, 0u32);
        for (i, frame) in self.frames.iter().enumerate() {
            let main = self.pattern.path(frame);
            let began = Instant::now();
            let skip = !self.overwrite && finished(&main, frame, &key);
            let mut note = None;
            if skip {
                skipped += 1;
            } else {
                let frame_made = make(frame, &main).map_err(|e| format!("frame {frame}: {e}"))?;
                self.write(frame, &main, &frame_made.files, &key)?;
                note = frame_made.note;
                made += 1;
            }
            let done = i as u32 + 1;
            match self.report {
                Report::Json => {
                    let mut record = serde_json::json!({
                        "frame": frame,
                        "file": main.display().to_string(),
                        "skipped": skip,
                        "seconds": began.elapsed().as_secs_f64(),
                        "done": done,
                        "total": total,
                    });
                    if let Some(note) = note {
                        record["simulation"] = note.into();
                    }
                    let mut out = std::io::stdout().lock();
                    let _ = writeln!(out, "{record}");
                    let _ = out.flush();
                }
                Report::Line => {
                    if let Some(note) = note {
                        line.note(&format!("frame {frame}: the simulation runs from {note}"));
                    }
                    line.done(u64::from(done))
                }
            }
        }
        drop(line);
        eprintln!(
            "{} {made} frames ({skipped} already there, same scene and options) in {:.2} s → {}",
            self.verb,
            start.elapsed().as_secs_f64(),
            self.pattern.path(self.frames.first).display()
        );
        Ok(())
    }

    /// Refuses, before any frame, a range one of whose files is an input (compared as real
    /// paths: `./s_1.json` and `s_1.json` are one file).
    fn check_inputs(&self) -> Result<(), String> {
        let inputs: Vec<PathBuf> = self
            .inputs
            .iter()
            .filter(|arg| !super::is_link(arg))
            .filter_map(|arg| Path::new(arg).canonicalize().ok())
            .collect();
        let folder = match self.pattern.folder() {
            f if f.as_os_str().is_empty() => Path::new("."),
            f => f,
        };
        let (Ok(folder), false) = (folder.canonicalize(), inputs.is_empty()) else {
            return Ok(());
        };
        for frame in self.frames.iter() {
            let path = self.pattern.path(frame);
            let name = path.file_name().unwrap_or_default();
            if inputs.contains(&folder.join(name)) {
                return Err(format!(
                    "{}: frame {frame} would overwrite the input (no frame was written)",
                    path.display()
                ));
            }
        }
        Ok(())
    }

    /// Writes one frame's files (each under a temporary name, then renamed), then its
    /// sidecar; on a failure, removes what this frame wrote.
    fn write(&self, frame: u32, main: &Path, files: &FrameFiles, key: &str) -> Result<(), String> {
        let sidecar = sidecar_path(main);
        // A stale sidecar must not vouch for the files about to be replaced.
        let _ = std::fs::remove_file(&sidecar);
        let mut written: Vec<&Path> = Vec::new();
        for (path, bytes) in files {
            if let Err(e) = super::write(path, bytes) {
                for done in written {
                    let _ = std::fs::remove_file(done);
                }
                return Err(format!("frame {frame}: {e} (earlier frames are kept)"));
            }
            written.push(path);
        }
        let record = Sidecar {
            frame,
            key: key.to_string(),
            files: files
                .iter()
                .map(|(path, bytes)| {
                    let name = path.file_name().unwrap_or_default().to_string_lossy();
                    (name.into_owned(), bytes.len() as u64)
                })
                .collect(),
        };
        let text = serde_json::to_string(&record).map_err(|e| e.to_string())?;
        super::write(&sidecar, text.as_bytes()).map_err(|e| {
            // Files without their sidecar would be redone by a rerun anyway; a full disk
            // gets its room back now, and the folder holds whole frames only.
            for done in written {
                let _ = std::fs::remove_file(done);
            }
            format!("frame {frame}: {e} (earlier frames are kept)")
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_inclusive_and_refuse_what_is_not_a_range() {
        let clock = Clock::default();
        let f = |t: &str| Frames::parse(t, &clock);
        assert_eq!(
            f("0..120"),
            Ok(Frames {
                first: 0,
                last: 120
            })
        );
        assert_eq!(f("3..=5").map(|r| r.len()), Ok(3));
        assert_eq!(f("7"), Ok(Frames { first: 7, last: 7 }));
        assert_eq!(
            f(""),
            Ok(Frames {
                first: 0,
                last: 120
            })
        );
        for (bad, says) in [
            ("5..2", "reversed"),
            ("a..b", "whole frame numbers"),
            ("-1..4", "whole frame numbers"),
            ("1.5..3", "whole frame numbers"),
            ("0..20000", "at most"),
            ("0..99999999", "past the last"),
        ] {
            let err = f(bad).unwrap_err();
            assert!(err.contains(says), "{bad}: {err}");
        }
    }

    #[test]
    fn a_pattern_numbers_its_last_run_of_hashes() {
        let p = Pattern::of(Path::new("out/frame_####.png")).unwrap();
        assert_eq!(p.path(7), Path::new("out/frame_0007.png"));
        assert_eq!(p.path(123_456), Path::new("out/frame_123456.png"));
        let p = Pattern::of(Path::new("cloud.#.vdb")).unwrap();
        assert_eq!(p.path(12), Path::new("cloud.12.vdb"));
        assert_eq!(
            Pattern::of(Path::new("a#b/c_##.vdb")).unwrap().path(3),
            Path::new("a#b/c_03.vdb")
        );
        assert!(Pattern::of(Path::new("out#/frame.png")).is_none());
        assert!(Pattern::of(Path::new("frame.png")).is_none());
    }

    #[test]
    fn a_frame_is_skipped_only_with_its_key_and_whole_files() {
        let dir = std::env::temp_dir().join(format!("cloudsketch-seq-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let pattern = Pattern::of(&dir.join("f_##.txt")).unwrap();
        let run = |key: u64, overwrite: bool, made: &mut Vec<u32>| {
            Sequence {
                frames: Frames { first: 1, last: 3 },
                pattern: &pattern,
                key,
                overwrite,
                report: Report::Line,
                verb: "made",
                inputs: &[],
            }
            .run(|frame, main| {
                made.push(frame);
                Ok(vec![(main.to_path_buf(), format!("frame {frame}").into_bytes())].into())
            })
        };
        let mut made = vec![];
        run(1, false, &mut made).unwrap();
        assert_eq!(made, [1, 2, 3]);
        assert_eq!(std::fs::read(pattern.path(2)).unwrap(), b"frame 2");
        made.clear();
        run(1, false, &mut made).unwrap();
        assert!(made.is_empty(), "finished frames were made again: {made:?}");
        // A frame cut short (its file changed size) and another key redo frames.
        std::fs::write(pattern.path(2), b"fr").unwrap();
        run(1, false, &mut made).unwrap();
        assert_eq!(made, [2]);
        made.clear();
        run(2, false, &mut made).unwrap();
        assert_eq!(made, [1, 2, 3]);
        made.clear();
        run(2, true, &mut made).unwrap();
        assert_eq!(made, [1, 2, 3]);
        // A failing frame names itself and keeps the frames before it.
        std::fs::remove_dir_all(&dir).unwrap();
        let err = Sequence {
            frames: Frames { first: 1, last: 3 },
            pattern: &pattern,
            key: 3,
            overwrite: false,
            report: Report::Line,
            verb: "made",
            inputs: &[],
        }
        .run(|frame, main| {
            if frame == 2 {
                return Err("no room".into());
            }
            Ok(vec![(main.to_path_buf(), vec![1, 2, 3])].into())
        })
        .unwrap_err();
        assert!(err.contains("frame 2") && err.contains("no room"), "{err}");
        assert!(pattern.path(1).exists() && !pattern.path(2).exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
