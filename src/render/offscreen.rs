//! Headless rendering on any wgpu adapter (lavapipe on CPU-only machines): `render`, `bench`
//! and the image tests use it, with the same renderer and shaders as the app.

use super::field_gpu::{FieldEvaluator, FieldGpuError};
use super::gpu_types::{FULL_VIEW, View};
use super::passes::MAX_SLICE_DRAWS_PER_FRAME;
use super::progressive::JobPlan;
use super::renderer::{SliceJob, VolumeRenderer};
use super::resources::{
    accumulation_format, can_march, copy_for_readback, marches_by_default, read_rows, unpremultiply,
};
use crate::derive::{Frame, Volumes};
use crate::field::{DensityVolume, Field};
use crate::scene::Scene;

pub use crate::limits::MAX_RENDER_SIDE as MAX_SIDE;

/// What an offscreen renderer's images hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// Display colour, tone-mapped and sRGB-encoded, 8 bits: what the viewport shows, what a
    /// PNG holds ([`Offscreen::render`]).
    Display,
    /// Linear light before any tone map (exposure applied), half floats: what an EXR holds
    /// ([`Offscreen::render_linear`]).
    Linear,
}

impl Output {
    /// The target format: the same 8-bit, non-sRGB kind of target egui composites into, or a
    /// float one.
    fn format(self) -> wgpu::TextureFormat {
        match self {
            Output::Display => wgpu::TextureFormat::Rgba8Unorm,
            Output::Linear => wgpu::TextureFormat::Rgba16Float,
        }
    }
}

/// Errors of headless rendering.
#[derive(Debug, thiserror::Error)]
pub enum OffscreenError {
    /// No adapter at all.
    #[error(
        "no GPU adapter found (on Linux without a GPU install Mesa's lavapipe: mesa-vulkan-drivers)"
    )]
    NoAdapter,
    /// Device creation failed.
    #[error("could not open the GPU device: {0}")]
    Device(String),
    /// Size out of range.
    #[error("image size {0}x{1} is out of range (1..={MAX_SIDE} per side)")]
    Size(u32, u32),
    /// Reading the image back failed.
    #[error("reading the image back failed: {0}")]
    Readback(String),
    /// Linear images were asked of an adapter without blendable float targets.
    #[error("this adapter cannot render linear images (no blendable half-float target): use PNG")]
    NoFloatTarget,
    /// An image of the other kind was asked of the renderer ([`Output`]).
    #[error("this renderer makes {0:?} images, not the kind asked for")]
    Output(Output),
    /// Marching the slices was asked of an adapter without compute shaders.
    #[error("this adapter cannot march the slices (it has no compute shaders or storage images)")]
    NoMarching,
}

/// A linear-light RGBA image, rows top to bottom, colours premultiplied by alpha (over the sky
/// every pixel is opaque).
#[derive(Clone, Debug, PartialEq)]
pub struct LinearImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` values.
    pub rgba: Vec<f32>,
}

impl LinearImage {
    /// Encodes as OpenEXR: one RGBA layer of half floats (linear, premultiplied alpha, as EXR
    /// has it), ZIP-compressed scan lines. The same image gives the same bytes.
    pub fn to_exr(&self) -> Result<Vec<u8>, String> {
        use exr::prelude::{Encoding, Image, SpecificChannels, Vec2, WritableImage, f16};
        let width = self.width as usize;
        let rgba = &self.rgba;
        let pixels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
            let i = 4 * (y * width + x);
            let h = |v: f32| f16::from_f32(v);
            (h(rgba[i]), h(rgba[i + 1]), h(rgba[i + 2]), h(rgba[i + 3]))
        });
        let image = Image::from_encoded_channels(
            (width, self.height as usize),
            Encoding::SMALL_LOSSLESS,
            pixels,
        );
        let mut out = std::io::Cursor::new(Vec::new());
        image
            .write()
            .non_parallel()
            .to_buffered(&mut out)
            .map_err(|e| format!("EXR encoding failed: {e}"))?;
        Ok(out.into_inner())
    }

    /// The pixel at (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 4] {
        pixel_of(&self.rgba, self.width, x, y)
    }
}

/// The pixel at (x, y) of RGBA values `width` pixels a row.
fn pixel_of<T: Copy>(rgba: &[T], width: u32, x: u32, y: u32) -> [T; 4] {
    let i = 4 * (y * width + x) as usize;
    [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]]
}

/// An RGBA8 image, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba: Vec<u8>,
}

impl Image {
    /// The pixel at (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        pixel_of(&self.rgba, self.width, x, y)
    }

    /// Encodes as PNG.
    pub fn to_png(&self) -> Result<Vec<u8>, png::EncodingError> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width, self.height);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc.write_header()?;
        writer.write_image_data(&self.rgba)?;
        writer.finish()?;
        Ok(out)
    }
}

/// An image size the renderer accepts: 1 to [`MAX_SIDE`] pixels a side.
fn check_size(width: u32, height: u32) -> Result<(), OffscreenError> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(OffscreenError::Size(width, height));
    }
    Ok(())
}

/// What an offscreen image shows behind the cloud.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backdrop {
    /// The scene's sky or background colour, every pixel opaque.
    Sky,
    /// Nothing: the cloud's own alpha, colours not premultiplied (a PNG's straight alpha).
    Transparent,
}

/// A headless device with the volume renderer.
pub struct Offscreen {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    renderer: VolumeRenderer,
    /// The GPU field evaluation (the bench's baseline), made on first use.
    field_evaluator: Option<FieldEvaluator>,
    /// Timestamp queries around recorded work, where the adapter has them.
    stamps: Option<Stamps>,
    /// Whether the adapter can march the slices.
    can_march: bool,
    /// What its images hold.
    output: Output,
    /// The accumulation format the adapter allows (`resources::accumulation_format`).
    accumulation: wgpu::TextureFormat,
}

/// How a timed frame is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Drawing {
    /// The whole view, as exports and offscreen renders draw it.
    Whole,
    /// The whole view with the plain benchmark slice shader (the baseline).
    Plain,
    /// As the app's viewport draws it: the slices over the cloud's box on screen, the shafts
    /// of light around it apart ([`Offscreen::render_cropped`]).
    Cropped,
}

/// Which clock times the bench's GPU work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// The host's, from recording to the device being done (submission and waiting included).
    Wall,
    /// The device's own (timestamp queries).
    Device,
}

/// Two GPU timestamps (before and after a piece of recorded work) and the buffers that bring
/// them back: the device's own clock, so a frame's time excludes submission and waiting.
#[derive(Clone)]
struct Stamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    /// Nanoseconds per tick.
    period: f32,
}

impl Stamps {
    /// The features timestamps around whole command encoders need.
    const FEATURES: wgpu::Features =
        wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);
    const BYTES: u64 = 2 * std::mem::size_of::<u64>() as u64;

    fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: Self::BYTES,
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolve: buffer(
                "timestamps (resolved)",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            read: buffer(
                "timestamps (read back)",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
            period: queue.get_timestamp_period(),
        }
    }
}

impl Offscreen {
    /// Opens the first usable adapter (hardware first, then any, software included), to make
    /// display images.
    pub fn new() -> Result<Self, OffscreenError> {
        Self::with_output(Output::Display)
    }

    /// Opens the first usable adapter, to make images of `output`'s kind.
    pub fn with_output(output: Output) -> Result<Self, OffscreenError> {
        pollster::block_on(Self::new_async(output))
    }

    async fn new_async(output: Output) -> Result<Self, OffscreenError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let mut adapter = None;
        for force_fallback_adapter in [false, true] {
            let options = wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter,
                compatible_surface: None,
                apply_limit_buckets: false,
            };
            if let Ok(a) = instance.request_adapter(&options).await {
                adapter = Some(a);
                break;
            }
        }
        let adapter = match adapter {
            Some(a) => a,
            None => instance
                .enumerate_adapters(wgpu::Backends::all())
                .await
                .into_iter()
                .next()
                .ok_or(OffscreenError::NoAdapter)?,
        };
        // Linear light needs float targets (the accumulation and the output): an 8-bit one
        // would clip it at 1.
        if output == Output::Linear
            && accumulation_format(&adapter) != wgpu::TextureFormat::Rgba16Float
        {
            return Err(OffscreenError::NoFloatTarget);
        }
        let info = adapter.get_info();
        let limits = wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits());
        let features = adapter.features() & Stamps::FEATURES;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("cloudsketch offscreen"),
                required_features: features,
                required_limits: limits,
                ..Default::default()
            })
            .await
            .map_err(|e| OffscreenError::Device(e.to_string()))?;
        let stamps = (features == Stamps::FEATURES).then(|| Stamps::new(&device, &queue));
        let accumulation = accumulation_format(&adapter);
        let mut renderer = VolumeRenderer::new(&device, &queue, output.format(), accumulation);
        renderer.set_marching(&device, marches_by_default(&adapter, &device));
        let can_march = can_march(&adapter, &device);
        Ok(Self {
            device,
            queue,
            info,
            renderer,
            field_evaluator: None,
            stamps,
            can_march,
            output,
            accumulation,
        })
    }

    /// Draws as a browser without float targets (plain WebGL2) must: the slices accumulated
    /// and the light volume kept in 8 bits, the slices rasterised; or, `false`, back in the
    /// adapter's own formats (still rasterised after the 8 bits: [`Offscreen::set_marching`]
    /// marches again). So any adapter tests the 8-bit path. Display images only.
    pub fn set_eight_bit(&mut self, on: bool) -> Result<(), OffscreenError> {
        self.expect(Output::Display)?;
        let accumulation = if on {
            wgpu::TextureFormat::Rgba8Unorm
        } else {
            self.accumulation
        };
        let marching = !on && self.renderer.marching();
        self.renderer = VolumeRenderer::new(
            &self.device,
            &self.queue,
            self.output.format(),
            accumulation,
        );
        self.renderer.set_marching(&self.device, marching);
        Ok(())
    }

    /// Marches the slices in a compute pass (the default on GPUs that can) or rasterises them
    /// (the default elsewhere); an error where the adapter cannot march them.
    pub fn set_marching(&mut self, on: bool) -> Result<(), OffscreenError> {
        if on && !self.can_march {
            return Err(OffscreenError::NoMarching);
        }
        self.renderer.set_marching(&self.device, on);
        Ok(())
    }

    /// Whether the slices are marched (see [`Offscreen::set_marching`]).
    pub fn marching(&self) -> bool {
        self.renderer.marching()
    }

    /// Name and backend of the adapter, e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan)".
    pub fn adapter_name(&self) -> String {
        format!("{} ({:?})", self.info.name, self.info.backend)
    }

    /// Whether the adapter is a software one (lavapipe, SwiftShader): the CPU draws.
    pub fn on_cpu(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Renders `frame` (derived by [`crate::derive::Derived::frame`]) from its camera at full
    /// quality, over its sky or over nothing.
    pub fn render(
        &mut self,
        frame: &Frame,
        width: u32,
        height: u32,
        backdrop: Backdrop,
    ) -> Result<Image, OffscreenError> {
        self.render_in_chunks(frame, [width, height], backdrop, 1)
    }

    /// Renders `frame` as [`Offscreen::render`] does, its slices drawn in `chunks` draws of
    /// consecutive slices, far to near, as the app's refinement spreads an image over frames:
    /// the same image as one draw. At most [`MAX_SLICE_DRAWS_PER_FRAME`] chunks (one
    /// submission's uniform slots).
    pub fn render_in_chunks(
        &mut self,
        frame: &Frame,
        size: [u32; 2],
        backdrop: Backdrop,
        chunks: u32,
    ) -> Result<Image, OffscreenError> {
        self.render_chunked(frame, size, backdrop, chunks, None)
    }

    /// Renders `frame` as [`Offscreen::render`] does (the same image), its slices drawn in
    /// `chunks` submissions, each waited for, calling `progress` with the share done after each:
    /// a long render (8192² on a CPU adapter) shows how far it is.
    pub fn render_with_progress(
        &mut self,
        frame: &Frame,
        size: [u32; 2],
        backdrop: Backdrop,
        chunks: u32,
        progress: &mut dyn FnMut(f32),
    ) -> Result<Image, OffscreenError> {
        self.render_chunked(frame, size, backdrop, chunks, Some(progress))
    }

    /// The chunked render: all chunks in one submission, or with `progress` each chunk in its
    /// own, waited for and reported.
    fn render_chunked(
        &mut self,
        frame: &Frame,
        [width, height]: [u32; 2],
        backdrop: Backdrop,
        chunks: u32,
        progress: Option<&mut dyn FnMut(f32)>,
    ) -> Result<Image, OffscreenError> {
        let (encoder, output) = self.chunked(
            Output::Display,
            frame,
            [width, height],
            backdrop,
            chunks,
            progress,
        )?;
        let mut image = self.read_back(encoder, &output, [width, height])?;
        if backdrop == Backdrop::Transparent {
            unpremultiply(&mut image.rgba);
        }
        Ok(image)
    }

    /// Renders `frame` as [`Offscreen::render_with_progress`] does, as linear light before
    /// any tone map (exposure applied; the sky's colours as the light the tone map shows as
    /// them, `tone::light_of`), premultiplied:
    /// what an EXR holds. Needs an offscreen made with [`Output::Linear`].
    pub fn render_linear(
        &mut self,
        frame: &Frame,
        [width, height]: [u32; 2],
        backdrop: Backdrop,
        chunks: u32,
        progress: Option<&mut dyn FnMut(f32)>,
    ) -> Result<LinearImage, OffscreenError> {
        let size = [width, height];
        let (encoder, output) =
            self.chunked(Output::Linear, frame, size, backdrop, chunks, progress)?;
        let bytes = self.read_pixels(encoder, &output, size, 8)?;
        let rgba = bytes
            .chunks_exact(2)
            .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32())
            .collect();
        Ok(LinearImage {
            width,
            height,
            rgba,
        })
    }

    /// An error unless this offscreen makes `output`'s kind of image.
    fn expect(&self, output: Output) -> Result<(), OffscreenError> {
        if self.output == output {
            Ok(())
        } else {
            Err(OffscreenError::Output(self.output))
        }
    }

    /// Records the chunked render's image of `kind` (an error unless this offscreen makes
    /// it) into a new output texture: all chunks in one submission, or with `progress` each
    /// chunk in its own, waited for and reported; the last chunk and the composite over
    /// `backdrop` are left in the returned encoder.
    fn chunked(
        &mut self,
        kind: Output,
        frame: &Frame,
        [width, height]: [u32; 2],
        backdrop: Backdrop,
        chunks: u32,
        mut progress: Option<&mut dyn FnMut(f32)>,
    ) -> Result<(wgpu::CommandEncoder, wgpu::Texture), OffscreenError> {
        self.expect(kind)?;
        check_size(width, height)?;
        let background = (backdrop == Backdrop::Sky).then_some(frame.scene.light.background);
        let mut job = self.job(frame, width, height);
        let total = job.plan.total;
        // One submission holds at most MAX_SLICE_DRAWS_PER_FRAME draws' uniforms; chunks
        // submitted and waited for one by one may be as many as there are slices.
        let most = if progress.is_some() {
            total
        } else {
            MAX_SLICE_DRAWS_PER_FRAME
        };
        let chunks = chunks.clamp(1, most.clamp(1, total.max(1)));
        if chunks > 1 {
            let encoder = |device: &wgpu::Device| {
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("offscreen chunks"),
                })
            };
            let mut commands = encoder(&self.device);
            self.renderer
                .update_light(&self.device, &self.queue, &mut commands, &job.view);
            let bound = |k: u32| total * k / chunks;
            for k in 0..chunks - 1 {
                job.plan.range = bound(k)..bound(k + 1);
                job.plan.clear = k == 0;
                self.renderer
                    .draw_slices(&self.device, &self.queue, &mut commands, &job, None);
                if let Some(report) = progress.as_mut() {
                    let done = std::mem::replace(&mut commands, encoder(&self.device));
                    self.queue.submit([done.finish()]);
                    let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
                    // The chunk is done: its uniform slot may be written again.
                    self.renderer.begin_frame();
                    report((k + 1) as f32 / chunks as f32);
                }
            }
            // The last chunk with the composite.
            job.plan.range = bound(chunks - 1)..total;
            job.plan.clear = false;
            self.queue.submit([commands.finish()]);
        }
        Ok(self.encode(&job, background, None))
    }

    /// Renders `frame` over its sky as the app's viewport draws it: the volume over the
    /// cloud's box on screen alone, the shafts of light around it drawn apart at a fraction of
    /// the size ([`super::VolumeRenderer::render_image_cropped`]).
    pub fn render_cropped(
        &mut self,
        frame: &Frame,
        width: u32,
        height: u32,
    ) -> Result<Image, OffscreenError> {
        self.expect(Output::Display)?;
        check_size(width, height)?;
        let scene = &frame.scene;
        let job = self.job(frame, width, height);
        let Some(crop) = self.viewport_crop(scene, [width, height]) else {
            return self.draw(&job, Some(scene.light.background));
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("offscreen cropped"),
            });
        let output = self.renderer.render_image_cropped(
            &self.device,
            &self.queue,
            &mut encoder,
            &job,
            Some(scene.light.background),
            &crop,
            super::crop::OUTSIDE_SHAFTS_DIVISOR,
        );
        self.read_back(encoder, &output, [width, height])
    }

    /// The density the slices' shader gives `frame`'s media at each probe, a world point and
    /// the field's value there ([`super::probe`]): what the CPU's media (`field::media`, which
    /// the exports bake) must agree with.
    pub fn media_at(
        &mut self,
        frame: &Frame,
        probes: &[(glam::Vec3, f32)],
    ) -> Result<Vec<f32>, OffscreenError> {
        let job = self.job(frame, 16, 16);
        let data: Vec<[f32; 4]> = probes.iter().map(|(p, f)| [p.x, p.y, p.z, *f]).collect();
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("media probe"),
            });
        let Some(readback) =
            self.renderer
                .probe_media(&self.device, &self.queue, &mut encoder, &job.view, &data)
        else {
            return Ok(Vec::new());
        };
        self.queue.submit([encoder.finish()]);
        self.map_for_reading(&readback)?;
        let densities = {
            let bytes = readback
                .slice(..)
                .get_mapped_range()
                .map_err(|e| OffscreenError::Readback(e.to_string()))?;
            bytes
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect()
        };
        readback.unmap();
        Ok(densities)
    }

    /// Times `frames` full-quality draws of `frame` (slices and composite, no readback) drawn
    /// as `drawing` says, each waited for on the device, by `clock`; `None` for the device's
    /// clock where the adapter has no timestamp queries.
    pub fn time_frames(
        &mut self,
        frame: &Frame,
        [width, height]: [u32; 2],
        frames: usize,
        drawing: Drawing,
        clock: Clock,
    ) -> Result<Option<Vec<f64>>, OffscreenError> {
        check_size(width, height)?;
        let scene = &frame.scene;
        let job = self.job(frame, width, height);
        let pipeline =
            (drawing == Drawing::Plain).then(|| self.renderer.baseline_pipeline(&self.device));
        let crop = (drawing == Drawing::Cropped)
            .then(|| self.viewport_crop(scene, [width, height]))
            .flatten();
        let background = Some(scene.light.background);
        (0..frames)
            .map(|_| {
                self.renderer.begin_frame();
                self.timed(clock, |o, encoder| match &crop {
                    Some(crop) => {
                        o.renderer.render_image_cropped(
                            &o.device,
                            &o.queue,
                            encoder,
                            &job,
                            background,
                            crop,
                            super::crop::OUTSIDE_SHAFTS_DIVISOR,
                        );
                    }
                    None => {
                        o.renderer.render_image(
                            &o.device,
                            &o.queue,
                            encoder,
                            &job,
                            background,
                            pipeline.as_ref(),
                        );
                    }
                })
            })
            .collect()
    }

    /// The pixels of a `size` view the app's viewport would draw the uploaded clouds over.
    fn viewport_crop(&self, scene: &Scene, size: [u32; 2]) -> Option<super::crop::PixelCrop> {
        let (lo, hi) = self.renderer.density_box()?;
        let aspect = size[0] as f32 / size[1].max(1) as f32;
        let ndc = scene.camera.ndc_bounds(lo, hi, aspect)?;
        Some(super::crop::PixelCrop::snap(ndc, size))
    }

    /// Uploads `volumes` (only where their generation changed) and draws them with `scene`'s
    /// view, light and quality whole into a `size` image, waiting for the device (no
    /// read-back): one frame of live playback, whose cost the bench times from the new time
    /// on (the derivation included).
    pub fn draw_and_wait(
        &mut self,
        scene: &Scene,
        volumes: &Volumes,
        [width, height]: [u32; 2],
    ) -> Result<(), OffscreenError> {
        check_size(width, height)?;
        let job = self.job_of(scene, volumes, width, height);
        let (encoder, _output) = self.encode(&job, Some(scene.light.background), None);
        self.submit_and_wait(encoder)
    }

    /// Times `runs` computations of `frame`'s light volume on the GPU (every slice marched
    /// toward the sun through the field and its noise), each waited for on the device, by
    /// `clock`; `None` for the device's clock where the adapter has no timestamp queries.
    pub fn time_light_volume(
        &mut self,
        frame: &Frame,
        runs: usize,
        clock: Clock,
    ) -> Result<Option<Vec<f64>>, OffscreenError> {
        let job = self.job(frame, 64, 64);
        (0..runs)
            .map(|_| {
                self.renderer.invalidate_light();
                self.renderer.begin_frame();
                self.timed(clock, |o, encoder| {
                    o.renderer
                        .update_light(&o.device, &o.queue, encoder, &job.view);
                })
            })
            .collect()
    }

    /// Records `record`, submits it, waits for the device and returns the seconds it took by
    /// `clock`; `None` for the device's clock where the adapter has no timestamp queries.
    fn timed(
        &mut self,
        clock: Clock,
        record: impl FnOnce(&mut Self, &mut wgpu::CommandEncoder),
    ) -> Result<Option<f64>, OffscreenError> {
        if clock == Clock::Device {
            return self.stamped(record);
        }
        let start = std::time::Instant::now();
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("timed"),
            });
        record(self, &mut encoder);
        self.submit_and_wait(encoder)?;
        Ok(Some(start.elapsed().as_secs_f64()))
    }

    /// Records `record` between two timestamps, submits it, waits and returns the seconds the
    /// device spent between them; `None` where the adapter has no timestamp queries.
    fn stamped(
        &mut self,
        record: impl FnOnce(&mut Self, &mut wgpu::CommandEncoder),
    ) -> Result<Option<f64>, OffscreenError> {
        let Some(stamps) = self.stamps.clone() else {
            return Ok(None);
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("timed"),
            });
        encoder.write_timestamp(&stamps.set, 0);
        record(self, &mut encoder);
        encoder.write_timestamp(&stamps.set, 1);
        encoder.resolve_query_set(&stamps.set, 0..2, &stamps.resolve, 0);
        encoder.copy_buffer_to_buffer(&stamps.resolve, 0, &stamps.read, 0, Stamps::BYTES);
        self.queue.submit([encoder.finish()]);
        self.map_for_reading(&stamps.read)?;
        let ticks = {
            let bytes = stamps
                .read
                .slice(..)
                .get_mapped_range()
                .map_err(|e| OffscreenError::Readback(e.to_string()))?;
            let t =
                |i: usize| u64::from_le_bytes(bytes[8 * i..8 * i + 8].try_into().unwrap_or([0; 8]));
            t(1).saturating_sub(t(0))
        };
        stamps.read.unmap();
        Ok(Some(ticks as f64 * f64::from(stamps.period) * 1e-9))
    }

    /// `field` evaluated on the GPU on the grid the CPU bake uses at `resolution`, read back.
    pub fn field_on_gpu(
        &mut self,
        field: &Field,
        resolution: u32,
    ) -> Result<DensityVolume, FieldGpuError> {
        let evaluator = self
            .field_evaluator
            .get_or_insert_with(|| FieldEvaluator::new(&self.device));
        match evaluator.evaluate(&self.device, &self.queue, field, resolution)? {
            Some(gpu) => FieldEvaluator::read_back(&self.device, &self.queue, &gpu),
            None => Ok(DensityVolume::default()),
        }
    }

    /// Times `runs` GPU evaluations of `field` into its 3D texture (primitives uploaded, every
    /// slice rendered, waited for on the device; no readback: the renderer would sample the
    /// texture where it is).
    pub fn time_field_on_gpu(
        &mut self,
        field: &Field,
        resolution: u32,
        runs: usize,
    ) -> Result<Vec<f64>, FieldGpuError> {
        let evaluator = self
            .field_evaluator
            .get_or_insert_with(|| FieldEvaluator::new(&self.device));
        let mut times = Vec::with_capacity(runs);
        for _ in 0..runs {
            let start = std::time::Instant::now();
            let gpu = evaluator.evaluate(&self.device, &self.queue, field, resolution)?;
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| FieldGpuError::Readback(e.to_string()))?;
            drop(gpu);
            times.push(start.elapsed().as_secs_f64());
        }
        Ok(times)
    }

    /// Maps all of `buffer` for reading, waiting for the device to finish what was submitted.
    fn map_for_reading(&self, buffer: &wgpu::Buffer) -> Result<(), OffscreenError> {
        let (tx, rx) = std::sync::mpsc::channel();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| OffscreenError::Readback(e.to_string()))?;
        rx.recv()
            .map_err(|e| OffscreenError::Readback(e.to_string()))?
            .map_err(|e| OffscreenError::Readback(e.to_string()))
    }

    /// Submits `encoder` and waits for the device to finish it.
    fn submit_and_wait(&self, encoder: wgpu::CommandEncoder) -> Result<(), OffscreenError> {
        self.queue.submit([encoder.finish()]);
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| OffscreenError::Readback(e.to_string()))
    }

    /// Uploads `frame`'s volumes and returns the full-quality job for a `width`×`height` image.
    fn job(&mut self, frame: &Frame, width: u32, height: u32) -> SliceJob {
        self.job_of(&frame.scene, &frame.volumes, width, height)
    }

    /// Uploads `volumes` (only where their generation changed) and returns the full-quality
    /// job drawing them with `scene`'s view for a `width`×`height` image.
    fn job_of(&mut self, scene: &Scene, volumes: &Volumes, width: u32, height: u32) -> SliceJob {
        self.renderer.begin_frame();
        self.renderer.upload(&self.device, &self.queue, volumes);
        SliceJob {
            plan: JobPlan {
                target: 0,
                size: [width, height],
                total: scene.render.slices,
                range: 0..scene.render.slices,
                clear: true,
            },
            view: View {
                camera: scene.camera.clone(),
                light: scene.light.clone(),
                render: scene.render.clone(),
                drift: crate::render::gpu_types::Drifts::of(scene),
                aspect: width as f32 / height as f32,
                crop: FULL_VIEW,
            },
            shells_apart: false,
        }
    }

    /// Records slices and composite into a new output texture.
    fn encode(
        &mut self,
        job: &SliceJob,
        background: Option<[f32; 3]>,
        pipeline: Option<&wgpu::RenderPipeline>,
    ) -> (wgpu::CommandEncoder, wgpu::Texture) {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("offscreen"),
            });
        let output = self.renderer.render_image(
            &self.device,
            &self.queue,
            &mut encoder,
            job,
            background,
            pipeline,
        );
        (encoder, output)
    }

    fn draw(
        &mut self,
        job: &SliceJob,
        background: Option<[f32; 3]>,
    ) -> Result<Image, OffscreenError> {
        let (encoder, output) = self.encode(job, background, None);
        self.read_back(encoder, &output, job.plan.size)
    }

    /// Submits `encoder` with a copy of `output` (`size` pixels) and reads the image back.
    fn read_back(
        &self,
        encoder: wgpu::CommandEncoder,
        output: &wgpu::Texture,
        size: [u32; 2],
    ) -> Result<Image, OffscreenError> {
        let rgba = self.read_pixels(encoder, output, size, 4)?;
        Ok(Image {
            width: size[0],
            height: size[1],
            rgba,
        })
    }

    /// Submits `encoder` with a copy of `output` (`size` pixels of `pixel` bytes) and reads
    /// its pixels back, rows without padding.
    fn read_pixels(
        &self,
        mut encoder: wgpu::CommandEncoder,
        output: &wgpu::Texture,
        size: [u32; 2],
        pixel: u32,
    ) -> Result<Vec<u8>, OffscreenError> {
        let (readback, row) = copy_for_readback(&self.device, &mut encoder, output, size);
        self.queue.submit([encoder.finish()]);
        self.map_for_reading(&readback)?;
        read_rows(&readback, size, row, pixel).map_err(OffscreenError::Readback)
    }
}
