//! A capture of the viewport's view at a chosen size, for the app's PNG export: rendered at
//! full quality into its own accumulation target ([`CAPTURE_TARGET`], so the viewport's
//! preview and refinement stay as they are), composited over the background (or transparent),
//! copied into a buffer and read back once the GPU is done — a frame or more later, which the
//! browser requires (its buffers map asynchronously).

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Arc, Mutex};

use super::progressive::JobPlan;
use super::renderer::{SliceJob, VolumeRenderer};
use super::resources::{CAPTURE_TARGET, copy_for_readback, read_rows, unpremultiply};
use super::{FULL_VIEW, View};

/// The read-back buffer's mapping: under way, done, failed.
const MAPPING: u8 = 0;
const MAPPED: u8 = 1;
const MAP_FAILED: u8 = 2;

/// Where a capture stands; shared by the UI (which polls it) and the paint callback.
enum State {
    /// Asked for; encoded by the next frame's paint callback.
    Asked,
    /// Rendered and copied; the buffer maps when the GPU is done.
    Reading {
        buffer: wgpu::Buffer,
        row: u32,
        mapped: Arc<AtomicU8>,
        bgra: bool,
    },
    /// The straight-alpha RGBA pixels, or why there are none.
    Done(Result<Vec<u8>, String>),
    /// Handed to the UI.
    Taken,
}

/// A capture under way.
#[derive(Clone)]
pub struct Capture {
    /// Size in pixels.
    pub size: [u32; 2],
    /// Transparent background (no sky), straight alpha; otherwise the view's background.
    pub transparent: bool,
    view: View,
    state: Arc<Mutex<State>>,
}

impl Capture {
    /// Asks for `view` at `size` pixels.
    pub fn new(view: &View, size: [u32; 2], transparent: bool) -> Self {
        Self {
            size,
            transparent,
            view: View {
                aspect: size[0] as f32 / size[1].max(1) as f32,
                crop: FULL_VIEW,
                ..view.clone()
            },
            state: Arc::new(Mutex::new(State::Asked)),
        }
    }

    /// The pixels once read back (once), or why the capture failed.
    pub fn take(&self) -> Option<Result<Vec<u8>, String>> {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match &*state {
            State::Done(_) => match std::mem::replace(&mut *state, State::Taken) {
                State::Done(r) => Some(r),
                _ => None,
            },
            _ => None,
        }
    }

    /// Advances the capture from the paint callback: encodes and submits it the first time,
    /// then reads the buffer back once mapped.
    pub fn advance(
        &self,
        renderer: &mut VolumeRenderer,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match &*state {
            State::Asked => *state = self.encode(renderer, device, queue),
            State::Reading { mapped, .. } => {
                // Native backends map during a poll; the browser maps on its own.
                let _ = device.poll(wgpu::PollType::Poll);
                let outcome = mapped.load(Ordering::Acquire);
                if outcome == MAP_FAILED {
                    // The device was lost, say: an error to show, never a wait without end.
                    *state = State::Done(Err(
                        "the GPU could not hand the image back (its device was lost?)".into(),
                    ));
                } else if outcome == MAPPED
                    && let State::Reading {
                        buffer, row, bgra, ..
                    } = std::mem::replace(&mut *state, State::Taken)
                {
                    *state = State::Done(self.read(&buffer, row, bgra));
                }
            }
            State::Done(_) | State::Taken => {}
        }
    }

    fn encode(
        &self,
        renderer: &mut VolumeRenderer,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> State {
        let bgra = matches!(
            renderer.output_format(),
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        let slices = self.view.render.slices;
        let job = SliceJob {
            plan: JobPlan {
                target: CAPTURE_TARGET,
                size: self.size,
                total: slices,
                range: 0..slices,
                clear: true,
            },
            view: self.view.clone(),
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("capture"),
        });
        let background = (!self.transparent).then_some(self.view.light.background);
        let output = renderer.render_image(device, queue, &mut encoder, &job, background, None);
        let (buffer, row) = copy_for_readback(device, &mut encoder, &output, self.size);
        queue.submit([encoder.finish()]);
        let mapped = Arc::new(AtomicU8::new(MAPPING));
        let flag = mapped.clone();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            // A failed map leaves the flag down (the capture then never completes; the
            // export's Cancel remains).
            flag.store(
                if r.is_ok() { MAPPED } else { MAP_FAILED },
                Ordering::Release,
            );
        });
        State::Reading {
            buffer,
            row,
            mapped,
            bgra,
        }
    }

    fn read(&self, buffer: &wgpu::Buffer, row: u32, bgra: bool) -> Result<Vec<u8>, String> {
        let mut rgba = read_rows(buffer, self.size, row)?;
        if bgra {
            for p in rgba.chunks_exact_mut(4) {
                p.swap(0, 2);
            }
        }
        if self.transparent {
            unpremultiply(&mut rgba);
        }
        Ok(rgba)
    }
}
