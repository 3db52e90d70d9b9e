//! A capture of the viewport's view at a chosen size, for the app's PNG export: rendered at
//! full quality into its own accumulation target ([`CAPTURE_TARGET`], so the viewport's
//! preview and refinement stay as they are), composited over the background (or transparent),
//! copied into a buffer and read back once the GPU is done — a frame or more later, which the
//! browser requires (its buffers map asynchronously).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use super::progressive::JobPlan;
use super::renderer::{SliceJob, VolumeRenderer};
use super::resources::CAPTURE_TARGET;
use super::{FULL_VIEW, View};

/// Where a capture stands; shared by the UI (which polls it) and the paint callback.
enum State {
    /// Asked for; encoded by the next frame's paint callback.
    Asked,
    /// Rendered and copied; the buffer maps when the GPU is done.
    Reading {
        buffer: wgpu::Buffer,
        row: u32,
        mapped: Arc<AtomicBool>,
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
                if mapped.load(Ordering::Acquire)
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
        let [width, height] = self.size;
        let format = renderer.output_format();
        let bgra = matches!(
            format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        let output = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("capture"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let target = output.create_view(&wgpu::TextureViewDescriptor::default());
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
        renderer.update_light(device, queue, &mut encoder, &job.view);
        renderer.draw_slices(device, queue, &mut encoder, &job, None);
        let sky = self.view.light.sky_gradient && !self.transparent;
        if sky {
            renderer.prepare_sky(queue, &self.view);
        }
        {
            let clear = if self.transparent {
                wgpu::Color::TRANSPARENT
            } else {
                let [r, g, b] = self.view.light.background.map(|v| v as f64);
                wgpu::Color { r, g, b, a: 1.0 }
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("capture composite"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(clear),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if sky {
                renderer.draw_sky(&mut pass);
            }
            renderer.composite(&mut pass, CAPTURE_TARGET);
        }
        let row = (width * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("capture readback"),
            size: (row * height) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &output,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        let mapped = Arc::new(AtomicBool::new(false));
        let flag = mapped.clone();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            // A failed map leaves the flag down; the read below reports it as empty.
            flag.store(r.is_ok(), Ordering::Release);
        });
        State::Reading {
            buffer,
            row,
            mapped,
            bgra,
        }
    }

    fn read(&self, buffer: &wgpu::Buffer, row: u32, bgra: bool) -> Result<Vec<u8>, String> {
        let [width, height] = self.size;
        let slice = buffer.slice(..);
        let mapped = slice
            .get_mapped_range()
            .map_err(|e| format!("the capture could not be read back: {e}"))?;
        let mut rgba = Vec::with_capacity((width * height * 4) as usize);
        for y in 0..height as usize {
            let start = y * row as usize;
            rgba.extend_from_slice(&mapped[start..start + width as usize * 4]);
        }
        drop(mapped);
        buffer.unmap();
        for p in rgba.chunks_exact_mut(4) {
            if bgra {
                p.swap(0, 2);
            }
            // The composite writes premultiplied colour; a PNG holds straight alpha.
            if self.transparent && p[3] > 0 && p[3] < 255 {
                let a = p[3] as f32 / 255.0;
                for c in &mut p[..3] {
                    *c = (*c as f32 / a).round().min(255.0) as u8;
                }
            }
        }
        Ok(rgba)
    }
}
