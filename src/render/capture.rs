//! A capture of the viewport's view at a chosen size, for the app's PNG export and cached
//! playback: rendered at full quality into its own accumulation target ([`CAPTURE_TARGET`],
//! so the viewport's preview and refinement stay as they are), its slices drawn a chunk a
//! frame (far to near, as refinement draws them: the same image as one draw) so the app
//! answers input meanwhile, over the cloud's box on screen alone (as the viewport draws it:
//! the shafts of light beyond it drawn apart), then composited over the background (or
//! transparent), copied into a buffer and read back once the GPU is done — a frame or more
//! later, which the browser requires (its buffers map asynchronously).

use std::sync::atomic::{AtomicU8, AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use super::crop::{OUTSIDE_SHAFTS_DIVISOR, PixelCrop};
use super::progressive::{JobPlan, slice_weight};
use super::renderer::{SliceJob, VolumeRenderer};
use super::resources::{CAPTURE_TARGET, copy_for_readback, read_rows, unpremultiply};
use super::{FULL_VIEW, View};

/// The read-back buffer's mapping: under way, done, failed.
const MAPPING: u8 = 0;
const MAPPED: u8 = 1;
const MAP_FAILED: u8 = 2;

/// Where a capture stands; shared by the UI (which polls it) and the paint callback.
enum State {
    /// Slices being drawn: chunk `done` of the capture's chunks is the next, one a frame,
    /// over `crop` (the cloud's box on screen, found at the first chunk; `None`: the whole
    /// view).
    Drawing { done: u32, crop: Option<PixelCrop> },
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
    /// Draws its slices are split into, one a frame (the last with the composite).
    chunks: u32,
    state: Arc<Mutex<State>>,
    /// Chunks drawn so far.
    drawn: Arc<AtomicU32>,
}

/// How many frames' chunks a capture of `pixels` pixels and `slices` slices takes, when a
/// pixel·slice costs `cost` seconds and a frame may spend `budget` seconds on it: at least
/// one, at most one a slice.
pub fn capture_chunks(pixels: u64, slices: u32, cost: f64, budget: f64) -> u32 {
    let seconds = pixels as f64 * slices as f64 * cost.max(0.0);
    let chunks = (seconds / budget.max(1e-6)).ceil();
    (chunks.clamp(1.0, slices.max(1) as f64)) as u32
}

/// How many frames' chunks a capture of `view` at `size` takes over `density` (the uploaded
/// clouds), when a plain pixel·slice costs `cost` seconds (the planner's) and a frame may spend
/// `budget` seconds: its slices are drawn over the cloud's box on screen alone, and with the
/// shafts of light among them each weighs [`slice_weight`]'s more.
pub fn chunks_for(
    view: &View,
    density: &crate::field::DensityVolume,
    size: [u32; 2],
    cost: f64,
    budget: f64,
) -> u32 {
    let aspect = size[0] as f32 / size[1].max(1) as f32;
    let pixels = (!density.is_empty())
        .then(|| {
            view.camera
                .ndc_bounds(density.min, density.min + density.size, aspect)
        })
        .flatten()
        .map_or(size, |ndc| PixelCrop::snap(ndc, size).size());
    let pixels = pixels[0] as u64 * pixels[1] as u64;
    let weight = slice_weight(view.light.shafts && !density.is_empty());
    capture_chunks(pixels, view.render.slices, cost * weight, budget)
}

impl Capture {
    /// Asks for `view` at `size` pixels, its slices drawn over `chunks` frames.
    pub fn new(view: &View, size: [u32; 2], transparent: bool, chunks: u32) -> Self {
        Self {
            size,
            transparent,
            chunks: chunks.clamp(1, view.render.slices.max(1)),
            drawn: Arc::new(AtomicU32::new(0)),
            view: View {
                aspect: size[0] as f32 / size[1].max(1) as f32,
                crop: FULL_VIEW,
                ..view.clone()
            },
            state: Arc::new(Mutex::new(State::Drawing {
                done: 0,
                crop: None,
            })),
        }
    }

    /// The same capture from its first chunk again (the clouds changed while it was drawn:
    /// its chunks would show two different clouds).
    pub fn restart(&self) -> Self {
        Self::new(&self.view, self.size, self.transparent, self.chunks)
    }

    /// Whether it is still drawing (not yet reading back).
    pub fn drawing(&self) -> bool {
        matches!(
            *self.state.lock().unwrap_or_else(|e| e.into_inner()),
            State::Drawing { .. }
        )
    }

    /// The share of the capture drawn, 0–1 (reading back is the last step).
    pub fn progress(&self) -> f32 {
        self.drawn.load(Ordering::Relaxed) as f32 / (self.chunks + 1) as f32
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
            State::Drawing { done, crop } => {
                let done = *done;
                // The box of the density the renderer holds now: a change of the clouds
                // later starts the capture over (`restart`), so every chunk has the same.
                let crop = if done == 0 {
                    self.crop_of(renderer)
                } else {
                    *crop
                };
                *state = if done + 1 < self.chunks {
                    self.draw_chunk(renderer, device, queue, done, crop.as_ref());
                    State::Drawing {
                        done: done + 1,
                        crop,
                    }
                } else {
                    self.encode(renderer, device, queue, done, crop.as_ref())
                };
                self.drawn.store(done + 1, Ordering::Relaxed);
            }
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

    /// The pixels of the capture the cloud's box covers, or `None` without a cloud or
    /// where the box reaches behind the camera (the whole view).
    fn crop_of(&self, renderer: &VolumeRenderer) -> Option<PixelCrop> {
        let (lo, hi) = renderer.density_box()?;
        let ndc = self.view.camera.ndc_bounds(lo, hi, self.view.aspect)?;
        Some(PixelCrop::snap(ndc, self.size))
    }

    /// The job of chunk `k` over the whole view: its slices, far to near; the first clears
    /// the target.
    fn chunk_job(&self, k: u32) -> SliceJob {
        let total = self.view.render.slices;
        let bound = |k: u32| (total as u64 * k as u64 / self.chunks as u64) as u32;
        let end = if k + 1 >= self.chunks {
            total
        } else {
            bound(k + 1)
        };
        SliceJob {
            plan: JobPlan {
                target: CAPTURE_TARGET,
                size: self.size,
                total,
                range: bound(k)..end,
                clear: k == 0,
            },
            view: self.view.clone(),
            shells_apart: false,
        }
    }

    /// Draws chunk `k` (not the last) into the capture's target and submits it.
    fn draw_chunk(
        &self,
        renderer: &mut VolumeRenderer,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        k: u32,
        crop: Option<&PixelCrop>,
    ) {
        let job = self.chunk_job(k);
        let job = match crop {
            Some(crop) => VolumeRenderer::cropped_job(&job, crop),
            None => job,
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("capture chunk"),
        });
        renderer.update_light(device, queue, &mut encoder, &job.view);
        renderer.draw_slices(device, queue, &mut encoder, &job, None);
        queue.submit([encoder.finish()]);
    }

    /// Draws the last chunk `k` with the composite, copies the image out and asks for it.
    fn encode(
        &self,
        renderer: &mut VolumeRenderer,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        k: u32,
        crop: Option<&PixelCrop>,
    ) -> State {
        let bgra = matches!(
            renderer.output_format(),
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        let job = self.chunk_job(k);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("capture"),
        });
        let background = (!self.transparent).then_some(self.view.light.background);
        let output = match crop {
            Some(crop) => renderer.render_image_cropped(
                device,
                queue,
                &mut encoder,
                &job,
                background,
                crop,
                OUTSIDE_SHAFTS_DIVISOR,
            ),
            None => renderer.render_image(device, queue, &mut encoder, &job, background, None),
        };
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
        let mut rgba = read_rows(buffer, self.size, row, 4)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_capture_takes_as_many_frames_as_its_cost_asks() {
        // 1920×1566 at 128 slices on a CPU adapter (about 1e-8 s a pixel·slice): 3.8 s of
        // work, 77 chunks of 50 ms (it took one frame of 35 s before).
        let chunks = capture_chunks(1920 * 1566, 128, 1e-8, 0.05);
        assert_eq!(chunks, 77);
        // A GPU's cost: one frame. Never more chunks than slices, never none.
        assert_eq!(capture_chunks(1920 * 1080, 128, 1e-12, 0.05), 1);
        assert_eq!(capture_chunks(8192 * 8192, 64, 1e-6, 0.05), 64);
        assert_eq!(capture_chunks(0, 0, 1.0, 0.05), 1);
    }

    #[test]
    fn a_capture_with_shafts_takes_twice_the_frames_and_counts_the_clouds_box_alone() {
        let scene = crate::scene::Scene::default();
        let density = crate::field::bake(&crate::derive::field_of(&scene), 32);
        let view = |shafts: bool| {
            let mut light = scene.light.clone();
            light.shafts = shafts;
            View {
                camera: scene.camera.clone(),
                light,
                render: scene.render.clone(),
                drift: crate::render::gpu_types::Drifts::of(&scene),
                aspect: 16.0 / 9.0,
                crop: FULL_VIEW,
            }
        };
        let (size, cost, budget) = ([1920, 1080], 1e-8, 0.05);
        let plain = chunks_for(&view(false), &density, size, cost, budget);
        let shafts = chunks_for(&view(true), &density, size, cost, budget);
        // The cloud's box on screen, not the whole view: fewer chunks than the whole view's.
        let whole = capture_chunks(1920 * 1080, scene.render.slices, cost, budget);
        assert!(plain > 1 && plain < whole, "{plain} of {whole}");
        assert!(
            (2 * plain).abs_diff(shafts) <= 1,
            "with shafts {shafts} chunks, without {plain}"
        );
        // Nothing uploaded yet: the whole view, and no shafts to weigh.
        let empty = crate::field::DensityVolume::default();
        assert_eq!(chunks_for(&view(true), &empty, size, cost, budget), whole);
    }
}
