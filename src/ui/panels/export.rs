//! The Export group: the cloud for other tools (OpenVDB, Mitsuba, glb, OBJ, PLY) or the view
//! as a PNG. Sampling runs a slab at a time within a frame budget, with a progress bar, so
//! the app stays responsive; the files then download (in the browser; Mitsuba's two as one
//! ZIP) or are written beside the scene file (natively). Ctrl+E exports again.

use egui::Ui;

use crate::export::{File, Format, Options, Sampling, Up, write, zip_pieces};
use crate::scene::{Document, Scene};
use crate::ui::flipbook::Frames;
use crate::ui::notice::Notices;
use crate::ui::platform;
use crate::ui::widgets::mark;

/// Seconds of sampling per frame.
const FRAME_BUDGET: f64 = 0.025;

/// An export under way.
enum Job {
    /// Sampling the density; the scene as it was when the export began.
    Sampling {
        sampling: Sampling,
        scene: Box<Scene>,
        format: Format,
        options: Options,
        place: Place,
    },
    /// Waiting for the renderer's capture of the view.
    Capture { place: Place },
    /// Waiting for the frames of the range, captured one by one (the app's flipbook).
    Record { place: Place },
    /// A recording's video being finished by the encoder: what it saved, once it has.
    Finishing {
        saved: std::sync::Arc<std::sync::Mutex<Option<Result<String, String>>>>,
        /// Set by Cancel: the encoder's file is then not saved.
        cancelled: std::sync::Arc<std::sync::atomic::AtomicBool>,
    },
}

/// Where an export's files go: their common name and (natively) their folder.
struct Place {
    dir: std::path::PathBuf,
    stem: String,
}

impl Place {
    /// From the scene file's name or path (`clouds/storm.json` → `clouds/`, `storm`).
    fn of(scene_file: &str) -> Self {
        let path = std::path::Path::new(scene_file);
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .filter(|s| !s.is_empty())
            .unwrap_or("cloud")
            .to_owned();
        Self {
            dir: path.parent().map(|p| p.to_path_buf()).unwrap_or_default(),
            stem,
        }
    }

    /// Where file `name` goes (a download's name in the browser).
    fn path(&self, name: &str) -> String {
        self.dir.join(name).to_string_lossy().into_owned()
    }
}

/// The Export group's state.
pub struct ExportPanel {
    /// The chosen format.
    pub format: Format,
    /// Resolution, axes, scale, noise, image size.
    pub options: Options,
    /// PNG width in pixels (the height follows the view's shape).
    pub png_width: u32,
    /// PNG over a transparent background.
    pub transparent: bool,
    /// PNG of every frame of the range (a recording), not of the view's frame.
    pub range: bool,
    job: Option<Job>,
    /// The last export's result, for the page state: the file names or the error.
    pub last: Option<Result<Vec<String>, String>>,
    /// How far the view's capture is (the app reports it each frame).
    pub capture_progress: f32,
}

impl Default for ExportPanel {
    fn default() -> Self {
        Self {
            format: Format::Glb,
            options: Options::default(),
            png_width: 1920,
            transparent: false,
            range: false,
            job: None,
            last: None,
            capture_progress: 0.0,
        }
    }
}

/// A recording of the range the Export group asks for.
pub struct RecordAsk {
    /// Pixel size of the frames.
    pub size: [u32; 2],
    /// Over a transparent background (PNGs only).
    pub transparent: bool,
    /// The files' common name.
    pub stem: String,
    /// The video encoder the frames go to; without one, PNG files.
    pub video: Option<Box<dyn crate::ui::flipbook::VideoSink>>,
}

/// What the app must do for the group this frame.
#[derive(Default)]
pub struct ExportAsk {
    /// Render a capture of the view at this size (pixels), transparent or not.
    pub capture: Option<([u32; 2], bool)>,
    /// Drop the capture under way (Cancel).
    pub cancel_capture: bool,
    /// Record every frame of the range.
    pub record: Option<RecordAsk>,
    /// Stop the recording under way (Cancel).
    pub cancel_record: bool,
}

impl ExportPanel {
    /// The share of the running export done, if one runs.
    pub fn progress(&self) -> Option<f32> {
        match &self.job {
            Some(Job::Sampling { sampling, .. }) => Some(sampling.progress() * 0.9),
            Some(Job::Capture { .. } | Job::Record { .. }) => Some(self.capture_progress),
            Some(Job::Finishing { .. }) => Some(1.0),
            None => None,
        }
    }

    /// Draws the group. `view_px` is the viewport's size in pixels; `scene_file` (the File
    /// group's name or path) names the files and, natively, their folder.
    pub fn ui(
        &mut self,
        ui: &mut Ui,
        doc: &Document,
        notices: &mut Notices,
        view_px: [u32; 2],
        scene_file: &str,
    ) -> ExportAsk {
        let mut ask = ExportAsk::default();
        crate::ui::widgets::group(ui, "Export", false, |ui| {
            ui.horizontal_wrapped(|ui| {
                for (format, name) in Format::ALL {
                    let r = ui.selectable_label(self.format == format, name);
                    mark(ui, &format!("export:{name}"), r.rect);
                    if r.clicked() {
                        self.format = format;
                    }
                }
            });
            let o = &mut self.options;
            if self.format == Format::Png {
                ui.horizontal(|ui| {
                    let r = ui.add(egui::DragValue::new(&mut self.png_width).range(16..=8192));
                    mark(ui, "export:width", r.rect);
                    let h = png_height(self.png_width, view_px);
                    ui.label(format!("× {h} px (the view's shape)"));
                });
                let r = ui.checkbox(&mut self.transparent, "transparent background");
                mark(ui, "export:transparent", r.rect);
                let r = ui
                    .checkbox(&mut self.range, "every frame of the range")
                    .on_hover_text(platform::RECORD_HINT);
                mark(ui, "export:range", r.rect);
            } else {
                ui.add(
                        egui::Slider::new(&mut o.resolution, 16..=crate::limits::MAX_EXPORT_RESOLUTION)
                            .text("grid (texels)"),
                    )
                    .on_hover_text("Texels along the cloud's longest side: finer grids take longer and make bigger files");
                ui.checkbox(&mut o.noise, "noise media as shown")
                    .on_hover_text(
                        "Off: the plain blended field (a smooth surface, a soft density)",
                    );
                if self.format != Format::Mitsuba {
                    ui.horizontal(|ui| {
                        ui.label("up:");
                        ui.selectable_value(&mut o.axes_up, Up::Y, "Y (glTF, Houdini)");
                        ui.selectable_value(&mut o.axes_up, Up::Z, "Z (Blender)");
                    });
                    ui.add(
                        egui::DragValue::new(&mut o.scale)
                            .range(1e-4..=1e4)
                            .speed(0.01)
                            .prefix("scale ×"),
                    );
                }
            }
            let running = self.job.is_some();
            ui.horizontal(|ui| {
                let button = ui
                    .add_enabled(
                        !running,
                        egui::Button::new(format!("Export {}", self.format.name())),
                    )
                    .on_hover_text("Ctrl+E");
                mark(ui, "export:run", button.rect);
                if button.clicked() {
                    ask = self.start(doc, notices, ui.input(|i| i.time), view_px, scene_file);
                }
                if running {
                    let cancel = ui.button("Cancel");
                    mark(ui, "export:cancel", cancel.rect);
                    if cancel.clicked() {
                        ask = self.cancel(notices, ui.input(|i| i.time));
                    }
                }
            });
            if let Some(p) = self.progress() {
                ui.add(egui::ProgressBar::new(p).show_percentage());
            }
        });
        ask
    }

    /// Starts an export of the document as the group is set (Ctrl+E, the button).
    pub fn start(
        &mut self,
        doc: &Document,
        notices: &mut Notices,
        now: f64,
        view_px: [u32; 2],
        scene_file: &str,
    ) -> ExportAsk {
        if self.job.is_some() {
            return ExportAsk::default();
        }
        if self.format == Format::Png && self.range {
            return self.record(doc, view_px, scene_file);
        }
        let place = Place::of(scene_file);
        if self.format == Format::Png {
            let size = [
                self.png_width.clamp(16, 8192),
                png_height(self.png_width, view_px),
            ];
            self.capture_progress = 0.0;
            self.job = Some(Job::Capture { place });
            return ExportAsk {
                capture: Some((size, self.transparent)),
                ..Default::default()
            };
        }
        let scene = doc.scene().clone();
        match Sampling::start(&scene, self.format, &self.options) {
            Ok(sampling) => {
                self.job = Some(Job::Sampling {
                    sampling,
                    scene: Box::new(scene),
                    format: self.format,
                    options: self.options.clone(),
                    place,
                });
            }
            Err(e) => {
                notices.error(now, format!("Could not export: {e}"));
                self.last = Some(Err(e.to_string()));
            }
        }
        ExportAsk::default()
    }

    /// Starts a recording of every frame of the range (the timeline's Record, or Export with
    /// "every frame of the range"), whatever format the group shows: at the group's PNG width
    /// and the view's shape, over the sky or transparent as the group is set. Nothing starts
    /// while another export runs.
    pub fn record(&mut self, doc: &Document, view_px: [u32; 2], scene_file: &str) -> ExportAsk {
        if self.job.is_some() {
            return ExportAsk::default();
        }
        let place = Place::of(scene_file);
        let size = [
            self.png_width.clamp(16, 8192),
            png_height(self.png_width, view_px),
        ];
        self.capture_progress = 0.0;
        // A WebM over the sky (VP9 wants even sides; WebCodecs encodes no alpha), else PNGs.
        let even = size.map(|v| (v & !1).max(2));
        let fps = f64::from(doc.scene().clock.fps);
        let video = (!self.transparent)
            .then(|| platform::video_sink(even, fps))
            .flatten();
        let ask = RecordAsk {
            size: if video.is_some() { even } else { size },
            transparent: self.transparent,
            stem: place.stem.clone(),
            video,
        };
        self.job = Some(Job::Record { place });
        ExportAsk {
            record: Some(ask),
            ..Default::default()
        }
    }

    /// Stops the export under way (Cancel): nothing of it is saved.
    pub fn cancel(&mut self, notices: &mut Notices, now: f64) -> ExportAsk {
        let ask = ExportAsk {
            cancel_capture: matches!(self.job, Some(Job::Capture { .. })),
            cancel_record: matches!(self.job, Some(Job::Record { .. })),
            ..Default::default()
        };
        if let Some(Job::Finishing { cancelled, .. }) = &self.job {
            cancelled.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        if self.job.take().is_some() {
            notices.note(now, "Export cancelled");
        }
        ask
    }

    /// A recording's progress (its frames, then its video's finishing), if one runs.
    pub fn recording(&self) -> Option<f32> {
        match self.job {
            Some(Job::Record { .. } | Job::Finishing { .. }) => self.progress(),
            _ => None,
        }
    }

    /// Whether an export of any kind runs.
    pub fn running(&self) -> bool {
        self.job.is_some()
    }

    /// Advances a running export within this frame's budget; saves its files when done.
    /// Returns whether one is still running (the app keeps repainting).
    pub fn step(&mut self, notices: &mut Notices, now: f64) -> bool {
        if let Some(Job::Finishing { saved, .. }) = &self.job {
            let done = saved.lock().ok().and_then(|mut s| s.take());
            if let Some(saved) = done {
                self.job = None;
                self.report(saved.map(|w| vec![w]), notices, now);
            }
            return self.job.is_some();
        }
        let Some(Job::Sampling { sampling, .. }) = &mut self.job else {
            return self.job.is_some();
        };
        let t0 = platform::now();
        while !sampling.step(1) {
            if platform::now() - t0 > FRAME_BUDGET {
                return true;
            }
        }
        let Some(Job::Sampling {
            sampling,
            scene,
            format,
            options,
            place,
        }) = self.job.take()
        else {
            return false;
        };
        let grid = sampling.finish();
        let files = write(&scene, &grid, format, &options, &place.stem);
        // The browser gets one download (several files as a ZIP); natively every file.
        let saved: Result<Vec<String>, String> = if platform::HAS_PICKER && files.len() > 1 {
            let name = format!("{}-{}.zip", place.stem, format.name());
            save_zip(&name, &files)
        } else {
            files
                .iter()
                .map(|f| platform::save_bytes(&place.path(&f.name), &f.bytes, mime(format)))
                .collect()
        };
        self.report(saved, notices, now);
        false
    }

    /// Saves a finished capture of the view as the PNG export.
    pub fn captured(
        &mut self,
        size: [u32; 2],
        pixels: Result<Vec<u8>, String>,
        notices: &mut Notices,
        now: f64,
    ) {
        // (Only a capture's job: a recording's frames are the flipbook's.)
        if !matches!(self.job, Some(Job::Capture { .. })) {
            return;
        }
        let Some(Job::Capture { place }) = self.job.take() else {
            return;
        };
        let path = place.path(&format!("{}.png", place.stem));
        let saved = pixels
            .and_then(|rgba| platform::save_png(&path, size[0], size[1], rgba))
            .map(|w| vec![w]);
        self.report(saved, notices, now);
    }

    /// Saves a finished recording's frames: a video as `STEM.webm` once its encoder is done;
    /// PNGs in the browser as one zip download (`STEM-frames.zip`), natively each beside the
    /// scene file.
    pub fn recorded(&mut self, frames: Result<Frames, String>, notices: &mut Notices, now: f64) {
        if !matches!(self.job, Some(Job::Record { .. })) {
            return;
        }
        let Some(Job::Record { place }) = self.job.take() else {
            return;
        };
        let frames = match frames {
            Ok(Frames::Video(video, _)) => {
                let saved = std::sync::Arc::new(std::sync::Mutex::new(None));
                let cancelled = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
                let into = saved.clone();
                video.finish(
                    place.path(&format!("{}.webm", place.stem)),
                    cancelled.clone(),
                    Box::new(move |result| {
                        if let Ok(mut s) = into.lock() {
                            *s = Some(result);
                        }
                    }),
                );
                self.job = Some(Job::Finishing { saved, cancelled });
                return;
            }
            Ok(Frames::Pngs(files)) => Ok(files),
            Err(e) => Err(e),
        };
        let saved = frames.and_then(|files| {
            if platform::HAS_PICKER {
                let name = format!("{}-frames.zip", place.stem);
                save_zip(&name, &files)
            } else {
                files
                    .iter()
                    .map(|f| platform::save_bytes(&place.path(&f.name), &f.bytes, "image/png"))
                    .collect()
            }
        });
        // Natively a range writes a file a frame: the first and the last name them.
        let saved = saved.map(|names| match names.as_slice() {
            [first, .., last] if names.len() > 2 => {
                vec![format!("{} frames, {first} … {last}", names.len())]
            }
            _ => names,
        });
        self.report(saved, notices, now);
    }

    fn report(&mut self, saved: Result<Vec<String>, String>, notices: &mut Notices, now: f64) {
        match &saved {
            Ok(names) => notices.note(now, format!("Exported {}", names.join(", "))),
            Err(e) => notices.error(now, format!("Could not export: {e}")),
        }
        self.last = Some(saved);
    }
}

fn png_height(width: u32, view_px: [u32; 2]) -> u32 {
    let aspect = view_px[1].max(1) as f64 / view_px[0].max(1) as f64;
    ((width.clamp(16, 8192) as f64 * aspect).round() as u32).clamp(16, 8192)
}

fn mime(format: Format) -> &'static str {
    match format {
        Format::Glb => "model/gltf-binary",
        Format::Obj => "model/obj",
        Format::Ply => "application/octet-stream",
        Format::Vdb => "application/octet-stream",
        Format::Mitsuba => "application/xml",
        Format::Png => "image/png",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Preset;

    /// The timeline's Record starts a recording whatever format the group shows, at the PNG
    /// width and the view's shape; a second press while it runs starts nothing; Stop (the
    /// group's Cancel) asks the flipbook to end it and leaves no job behind.
    #[test]
    fn record_starts_from_any_format_once_and_cancel_ends_it() {
        let doc = Document::new(Scene::preset(Preset::Cumulus));
        let mut notices = Notices::default();
        let mut panel = ExportPanel {
            format: Format::Glb,
            png_width: 320,
            ..Default::default()
        };
        assert_eq!(panel.recording(), None);
        let ask = panel.record(&doc, [1000, 500], "clouds/storm.json");
        let record = ask.record.expect("a recording starts");
        assert_eq!(record.size, [320, 160]);
        assert_eq!(record.stem, "storm");
        assert_eq!(panel.recording(), Some(0.0));
        assert!(panel.record(&doc, [1000, 500], "x.json").record.is_none());
        // An export of the group's format waits too.
        assert!(
            panel
                .start(&doc, &mut notices, 0.0, [1000, 500], "x.json")
                .record
                .is_none()
        );
        let ask = panel.cancel(&mut notices, 1.0);
        assert!(ask.cancel_record && !ask.cancel_capture);
        assert!(!panel.running());
        assert_eq!(panel.recording(), None);
        assert_eq!(
            notices.latest.as_ref().map(|n| (n.text.as_str(), n.at)),
            Some(("Export cancelled", 1.0))
        );
        // Nothing to cancel: nothing asked, nothing said.
        let ask = panel.cancel(&mut notices, 2.0);
        assert!(!ask.cancel_record && !ask.cancel_capture);
        assert_eq!(notices.latest.as_ref().map(|n| n.at), Some(1.0));
        // A Sampling export is running but not a recording.
        let ask = panel.start(&doc, &mut notices, 3.0, [1000, 500], "x.json");
        assert!(ask.record.is_none() && panel.running());
        assert_eq!(panel.recording(), None);
    }
}

/// Saves `files` as one zip download named `name`, handed over in pieces (the archive is never
/// built beside the files).
fn save_zip(name: &str, files: &[File]) -> Result<Vec<String>, String> {
    let pieces = zip_pieces(files);
    let pieces: Vec<&[u8]> = pieces.iter().map(|p| &**p).collect();
    platform::save_pieces(name, &pieces, "application/zip").map(|w| vec![w])
}
