//! No subcommand: the desktop app in a window; with `--screenshot`, the window's first
//! full-quality image saved as a PNG, after which the window closes.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::render::offscreen::Image;
use crate::ui::{CloudApp, Host, Opening, PageStatus, Start, StartOptions};

/// How long `--screenshot` waits for a full-quality image before giving up.
const SCREENSHOT_WAIT_SECONDS: f64 = 240.0;

/// What `--screenshot` asks for.
pub struct Screenshot {
    /// The PNG to write: the whole window, side panel included.
    pub output: PathBuf,
    /// Where to write the app's state (scene and view, the page's `state()` JSON), if anywhere.
    pub state: Option<PathBuf>,
}

/// Opens the desktop window on a scene file or share link when one is given (keeping the
/// last session aside), else on the last session (autosaved), else on the default scene.
/// `size` is the window's inner size in points; `screenshot` saves its first full-quality image
/// and closes it.
pub fn run(
    open: Option<&str>,
    size: (u32, u32),
    screenshot: Option<Screenshot>,
) -> Result<(), String> {
    // A screenshot that could not be written, or two outputs (or an output and the scene) that
    // are one file, are found out before the window opens.
    if let Some(shot) = &screenshot {
        let outputs: Vec<&Path> = std::iter::once(shot.output.as_path())
            .chain(shot.state.as_deref())
            .collect();
        super::check_outputs(&open.into_iter().collect::<Vec<_>>(), &outputs)?;
    }
    let shooting = screenshot.is_some();
    let bytes = match open {
        Some(arg) if !super::is_link(arg) => Some(
            crate::files::read_bounded(Path::new(arg), crate::limits::MAX_FILE_BYTES)
                .map_err(|e| e.at(Path::new(arg)))?,
        ),
        _ => None,
    };
    let opening = match (open, &bytes) {
        (Some(path), Some(bytes)) => Opening::File(path, bytes),
        (Some(link), None) => Opening::Link(link),
        _ => Opening::Nothing,
    };
    // A screenshot run only looks: it keeps no autosave aside and writes none.
    let start = crate::ui::start_session(opening, !shooting);
    if let Some((message, true)) = &start.notice {
        // A screenshot run shows what it was asked to open, or nothing: not the last session.
        if shooting {
            return Err(message.clone());
        }
        eprintln!("error: {message}");
    }
    let Start {
        scene,
        notice,
        file,
        ..
    } = start;
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("cloudsketch")
            .with_inner_size([size.0 as f32, size.1 as f32]),
        ..Default::default()
    };
    let outcome = Arc::new(Mutex::new(None));
    let host = screenshot.map(|shot| {
        Box::new(WindowShot {
            shot,
            image: Arc::new(Mutex::new(None)),
            asked: false,
            outcome: outcome.clone(),
        }) as Box<dyn Host>
    });
    eframe::run_native(
        "cloudsketch",
        options,
        Box::new(|cc| {
            Ok(Box::new(CloudApp::new(
                cc,
                StartOptions {
                    scene,
                    host,
                    initial_cost: 1e-8,
                    notice,
                    file,
                    autosave: !shooting,
                    ..Default::default()
                },
            )))
        }),
    )
    .map_err(|e| format!("could not open the desktop window: {e}"))?;
    match outcome.lock().map(|mut o| o.take()) {
        Ok(Some(Ok(summary))) => {
            println!("{summary}");
            Ok(())
        }
        Ok(Some(Err(e))) => Err(e),
        Ok(None) if shooting => Err("the window closed before its screenshot was taken".into()),
        _ => Ok(()),
    }
}

/// The `--screenshot` run: once the view shows a full-quality image, asks for an image of the
/// next frame, writes it (and the state), then closes the window.
struct WindowShot {
    shot: Screenshot,
    /// The window's image, once painted.
    image: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
    asked: bool,
    /// The summary line or the error, read by [`run`] once the window has closed.
    outcome: Arc<Mutex<Option<Result<String, String>>>>,
}

impl WindowShot {
    /// Writes the image and the state; the summary line on success.
    fn save(&self, image: &egui::ColorImage, status: &PageStatus) -> Result<String, String> {
        let [width, height] = image.size.map(|s| s as u32);
        let png = Image {
            width,
            height,
            rgba: image.pixels.iter().flat_map(|c| c.to_array()).collect(),
        }
        .to_png()
        .map_err(|e| format!("PNG encoding failed: {e}"))?;
        let output = &self.shot.output;
        super::write(output, &png)?;
        if let Some(state) = &self.shot.state {
            super::write(state, status.state.as_bytes())?;
        }
        Ok(format!(
            "{}: the window, {width}x{height} pixels, at {} quality ({} on {})",
            output.display(),
            status.quality,
            status.backend,
            status.adapter
        ))
    }
}

impl Host for WindowShot {
    fn publish(&mut self, _status: &PageStatus) {}

    fn end_frame(&mut self, ctx: &egui::Context, status: &PageStatus) {
        let settled = |outcome: &Mutex<Option<_>>| outcome.lock().map_or(true, |o| o.is_some());
        if settled(&self.outcome) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        }
        let image = self.image.lock().ok().and_then(|mut i| i.take());
        let result = if let Some(image) = image {
            Some(self.save(&image, status))
        } else if !self.asked && status.ready && status.quality.starts_with("full") {
            // The image of the next frame: the same full-quality view, now painted.
            let slot = self.image.clone();
            let wake = ctx.clone();
            ctx.request_screenshot(move |image| {
                if let Ok(mut slot) = slot.lock() {
                    *slot = Some(image);
                }
                wake.request_repaint();
            });
            self.asked = true;
            None
        } else if ctx.input(|i| i.time) > SCREENSHOT_WAIT_SECONDS {
            Some(Err(format!(
                "no full-quality image within {SCREENSHOT_WAIT_SECONDS} s (the view shows {:?})",
                status.quality
            )))
        } else {
            None
        };
        if let Some(result) = result {
            if let Ok(mut outcome) = self.outcome.lock() {
                *outcome = Some(result);
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        // Frames keep coming while the run waits (refinement asks for its own too).
        ctx.request_repaint_after(std::time::Duration::from_millis(100));
    }
}
