//! The egui paint callback that runs the volume renderer inside the app's viewport.
//!
//! The renderer lives in egui-wgpu's callback resources (created once at start-up); each frame
//! the app hands over a plain `Send + Sync` snapshot: the derived volumes, the job (with its
//! view) and which target to show. Uniforms are built here, from the snapshot.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use super::progressive::GpuReport;
use super::renderer::{SliceJob, VolumeRenderer};
use super::resources::{accumulation_format, can_march, marches_by_default};
use crate::derive::Volumes;

/// The GPU's reports of the viewport's volume jobs (see
/// [`super::progressive::Progressive::plan`]), shared by the app and the paint callback. The
/// callback submits each job on its own, asking the queue for two reports: one when the work
/// before the job is done (the GPU is free to start it) and one when the job is done. Their
/// difference is the GPU's time for the job without the frames queued before it; it still
/// holds a fixed delay of the reports themselves (about 0.16 s in SwiftShader's WebGPU at
/// 1920×1080), which the planner tells apart from the work by fitting a line through chunks
/// of different sizes. The last report also wakes the app, so refinement waiting for it goes
/// on at once.
#[derive(Clone)]
pub struct JobFence(Arc<FenceState>);

struct FenceState {
    /// The last job handed to the GPU.
    sent: AtomicU64,
    /// A job recorded with a frame's own commands whose report is yet to be asked for (0:
    /// none): the frame is submitted after its callbacks, so the next frame asks.
    in_frame: AtomicU64,
    done: AtomicU64,
    times: Mutex<Times>,
    clock: fn() -> f64,
    /// Wakes the app after the given seconds.
    wake: Box<dyn Fn(f64) + Send + Sync>,
}

/// What a [`JobFence`] knows of the jobs' times.
#[derive(Default)]
struct Times {
    /// The job the GPU last became free for, and when.
    free: Option<(u64, f64)>,
    /// The last job timed, and its seconds.
    timed: Option<(u64, f64)>,
}

impl JobFence {
    /// A fence that calls `wake` (with the seconds after which to wake the app) whenever a
    /// job is reported done, or a chunk started that is due a while after, timing jobs by
    /// `clock` (seconds).
    pub fn new(wake: impl Fn(f64) + Send + Sync + 'static, clock: fn() -> f64) -> Self {
        Self(Arc::new(FenceState {
            sent: AtomicU64::new(0),
            in_frame: AtomicU64::new(0),
            done: AtomicU64::new(0),
            times: Mutex::new(Times::default()),
            clock,
            wake: Box::new(wake),
        }))
    }

    /// What the GPU has reported so far.
    pub fn report(&self) -> GpuReport {
        let (timed, free) = self
            .0
            .times
            .lock()
            .map_or((None, None), |t| (t.timed, t.free));
        let now = (self.0.clock)();
        GpuReport {
            done: self.0.done.load(Ordering::Acquire),
            timed,
            started: free.map(|(job, at)| (job, (now - at).max(0.0))),
        }
    }

    /// Whether a job handed to the GPU is not yet reported done.
    pub fn outstanding(&self) -> bool {
        self.0.sent.load(Ordering::Acquire) > self.0.done.load(Ordering::Acquire)
    }

    /// Job `job` is handed to the GPU.
    fn sent(&self, job: u64) {
        self.0.sent.fetch_max(job, Ordering::AcqRel);
    }

    /// Job `job` is recorded with this frame's own commands (submitted after the callbacks).
    fn recorded_in_frame(&self, job: u64) {
        self.sent(job);
        self.0.in_frame.store(job, Ordering::Release);
    }

    /// Asks `queue` to report the job recorded with an earlier frame's commands, if any: those
    /// are submitted by now, and a report covers what is submitted when it is asked for.
    fn ask_for_frame_report(&self, queue: &wgpu::Queue) {
        let job = self.0.in_frame.swap(0, Ordering::AcqRel);
        if job > 0 {
            let fence = self.clone();
            queue.on_submitted_work_done(move || fence.finished(job));
        }
    }

    /// The work submitted before job `job` is done: the GPU can start it. A job `due` seconds
    /// later ([`super::progressive::FramePlan::due_after_start`]) wakes the app then.
    fn free_for(&self, job: u64, due: Option<f64>) {
        let now = (self.0.clock)();
        if let Ok(mut t) = self.0.times.lock() {
            t.free = Some((job, now));
        }
        if let Some(due) = due {
            (self.0.wake)(due);
        }
    }

    /// Reports job `job` (and every job before it) done.
    pub fn finished(&self, job: u64) {
        let now = (self.0.clock)();
        if let Ok(mut t) = self.0.times.lock()
            && let Some((id, at)) = t.free
            && id == job
        {
            t.timed = Some((job, (now - at).max(0.0)));
        }
        self.0.done.fetch_max(job, Ordering::AcqRel);
        // A later job on the GPU wakes the app itself (when due, or done): a frame now would
        // plan nothing and only delay it.
        if job >= self.0.sent.load(Ordering::Acquire) {
            (self.0.wake)(0.0);
        }
    }
}

/// What one frame of the viewport draws.
pub struct ViewportPaint {
    /// The derived volumes (each uploaded only when its generation changes).
    pub volumes: Volumes,
    /// Volume work for this frame.
    pub job: Option<SliceJob>,
    /// Accumulation target to composite into the frame.
    pub display: Option<usize>,
    /// A capture of the view for export, advanced every frame until read back.
    pub capture: Option<super::capture::Capture>,
    /// The fence the jobs are reported through (a job recorded with an earlier frame's
    /// commands is reported from this frame on, job or not).
    pub fence: Option<JobFence>,
    /// The job's number ([`super::progressive::FramePlan::job_id`]).
    pub job_id: u64,
    /// Where the shown image lies in the whole view (normalised device coordinates, x0, y0,
    /// x1, y1; y up): the cloud's box on screen.
    pub crop: [f32; 4],
    /// Whether the job goes to the GPU on its own, ahead of the frame, timed by the fence
    /// ([`super::progressive::FramePlan::own_submission`]); else with the frame's commands.
    pub own_submission: bool,
    /// Seconds after the GPU starts the job when the next frame may queue another behind it
    /// ([`super::progressive::FramePlan::due_after_start`]).
    pub due_after_start: Option<f64>,
    /// The flat background's display colour (the frame's clear colour) where the view has no
    /// backdrop ([`BackdropPaint`]); the composite maps the cloud's light with its light.
    pub flat: Option<[f32; 3]>,
}

impl RendererPaint for ViewportPaint {
    fn prepare(&self, renderer: &mut VolumeRenderer, frame: FrameGpu<'_>) {
        let FrameGpu {
            device,
            queue,
            commands,
        } = frame;
        renderer.begin_frame();
        renderer.upload(device, queue, &self.volumes);
        if let Some(fence) = &self.fence {
            fence.ask_for_frame_report(queue);
        }
        if let Some(job) = &self.job {
            if self.own_submission {
                // A timed chunk goes to the GPU now, in a submission of its own (before the
                // frame's, which composites it), so that the queue can report when the GPU is
                // free for it and when it is done: a report asked for here covers only what is
                // already submitted.
                let mut own = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("volume job"),
                });
                renderer.update_light(device, queue, &mut own, &job.view);
                renderer.draw_slices(device, queue, &mut own, job, None);
                if let Some(fence) = self.fence.clone() {
                    let (id, due) = (self.job_id, self.due_after_start);
                    fence.sent(id);
                    queue.on_submitted_work_done(move || fence.free_for(id, due));
                }
                queue.submit([own.finish()]);
                if let Some(fence) = self.fence.clone() {
                    let id = self.job_id;
                    queue.on_submitted_work_done(move || fence.finished(id));
                }
            } else {
                renderer.update_light(device, queue, commands, &job.view);
                renderer.draw_slices(device, queue, commands, job, None);
                if let Some(fence) = &self.fence {
                    fence.recorded_in_frame(self.job_id);
                }
            }
        }
        if let Some(capture) = &self.capture {
            capture.advance(renderer, device, queue);
        }
    }

    fn finish_prepare(&self, renderer: &mut VolumeRenderer, frame: FrameGpu<'_>) {
        // Every callback's `prepare` is done: the shafts beyond the box are drawn by now.
        if let Some(target) = self.display {
            renderer.prepare_cropped_composite(frame.device, frame.queue, target, self.crop);
            renderer.prepare_behind(frame.queue, self.crop, self.flat);
        }
    }

    fn paint(&self, renderer: &VolumeRenderer, pass: &mut wgpu::RenderPass<'static>) {
        if let Some(target) = self.display {
            renderer.composite_cropped(pass, target, false, renderer.viewport_behind());
        }
    }
}

/// What lies behind the cloud in the viewport: the background colour, the physical sky or the
/// sky gradient, the ground, and the shafts of light around the cloud's box, where no cloud lies in front of
/// them. Drawn into a texture of its own when any of it changes (`redraw`), and laid from it
/// on every frame, under everything else: on a CPU adapter the ground's shading and the
/// shafts' lay, redone on every frame, took over half of each frame of a refinement.
pub struct BackdropPaint {
    /// The whole view ([`super::FULL_VIEW`]).
    pub view: super::gpu_types::View,
    /// The background colour, sRGB-encoded (as egui's colours and the sky are).
    pub background: [f32; 3],
    /// The viewport's size in pixels.
    pub size: [u32; 2],
    /// The derived volumes (uploaded here too: the cloud's box may be out of view), whose
    /// light volume shades the ground and the shafts; none without a cloud.
    pub volumes: Option<Volumes>,
    /// The shafts of light drawn apart from the cloud's box, if the view has shafts.
    pub shafts: Option<ShaftsApart>,
    /// The cloud's box in the backdrop's pixels (x0, y0, x1, y1; none when out of view): the
    /// shafts drawn apart are added around it, and its composite adds its own.
    pub crop: Option<[u32; 4]>,
    /// Everything it is drawn from: the renderer draws it again when this differs from what
    /// it last drew (kept by the renderer, so a frame the GPU never got draws it again).
    pub key: u64,
}

/// The shafts of light outside the cloud's box on screen, and those of the shells beyond it,
/// which the box's composite adds ([`VolumeRenderer::draw_outside_shafts`]).
pub struct ShaftsApart {
    /// Slices of the image the shells are counted for.
    pub total: u32,
    /// Their target's size in pixels (a fraction of the view's: the light is soft).
    pub size: [u32; 2],
}

impl RendererPaint for BackdropPaint {
    fn finish_prepare(&self, renderer: &mut VolumeRenderer, frame: FrameGpu<'_>) {
        // After every callback's `prepare`: the box's starts the frame's uniforms (and a PNG
        // export's may leave its own light volume current). Before the box's
        // `finish_prepare`, which binds the shafts beyond the box drawn here.
        if renderer.backdrop_key() == Some(self.key) {
            return;
        }
        let FrameGpu {
            device,
            queue,
            commands,
        } = frame;
        if let Some(volumes) = &self.volumes {
            renderer.upload(device, queue, volumes);
            // The ground's shadows and the shafts come from this view's light volume.
            renderer.update_light(device, queue, commands, &self.view);
        }
        let laid = self.shafts.as_ref().is_some_and(|shafts| {
            renderer.draw_outside_shafts(
                device,
                queue,
                commands,
                &self.view,
                shafts.total,
                shafts.size,
            )
        });
        renderer.draw_backdrop(
            device,
            queue,
            commands,
            &self.view,
            self.size,
            self.background,
            laid,
            self.crop,
            self.key,
        );
    }

    fn paint(&self, renderer: &VolumeRenderer, pass: &mut wgpu::RenderPass<'static>) {
        renderer.lay_backdrop(pass);
    }
}

/// A flat colour over a rectangle: the side panel's background, which egui then leaves
/// unfilled (its own fill samples a texture and converts gamma at every pixel: on CPU adapters
/// the panel's fill was a sixth of a frame).
pub struct FillPaint {
    /// The colour as egui would paint it.
    pub colour: egui::Color32,
}

impl RendererPaint for FillPaint {
    fn paint(&self, renderer: &VolumeRenderer, pass: &mut wgpu::RenderPass<'static>) {
        // egui's colours are sRGB-encoded (premultiplied) and so is what it writes into the
        // frame's (non-sRGB) target: the bytes go in as they are.
        let [r, g, b, a] = self.colour.to_array().map(|c| f64::from(c) / 255.0);
        renderer.draw_fill(pass, wgpu::Color { r, g, b, a });
    }
}

/// A part of the viewport the volume renderer draws: its GPU work before egui's render pass,
/// then its draw inside that pass. [`paint_callback`] hands one to egui.
pub trait RendererPaint: Send + Sync + 'static {
    /// Uploads and records what the draw needs (nothing, unless implemented).
    fn prepare(&self, _renderer: &mut VolumeRenderer, _frame: FrameGpu<'_>) {}
    /// Records what depends on every callback's `prepare` (nothing, unless implemented).
    fn finish_prepare(&self, _renderer: &mut VolumeRenderer, _frame: FrameGpu<'_>) {}
    /// Draws into egui's render pass, clipped to the callback's rectangle.
    fn paint(&self, renderer: &VolumeRenderer, pass: &mut wgpu::RenderPass<'static>);
}

/// What a [`RendererPaint`] prepares with.
pub struct FrameGpu<'a> {
    /// The device.
    pub device: &'a wgpu::Device,
    /// Its queue (a submission of its own goes ahead of the frame's).
    pub queue: &'a wgpu::Queue,
    /// The frame's commands, submitted with egui's render pass after every callback's
    /// `prepare`.
    pub commands: &'a mut wgpu::CommandEncoder,
}

/// An egui paint callback over `rect` that runs `paint` on the renderer kept in egui-wgpu's
/// callback resources (nothing, before the renderer exists).
pub fn paint_callback(rect: egui::Rect, paint: impl RendererPaint) -> egui::PaintCallback {
    egui_wgpu::Callback::new_paint_callback(rect, OnRenderer(paint))
}

/// Adapts a [`RendererPaint`] to egui-wgpu's callback, finding the renderer among its
/// resources.
struct OnRenderer<P>(P);

/// Runs `f` on the renderer among `resources` (nothing, before it exists) with the frame's GPU.
fn on_renderer(
    resources: &mut egui_wgpu::CallbackResources,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    commands: &mut wgpu::CommandEncoder,
    f: impl FnOnce(&mut VolumeRenderer, FrameGpu<'_>),
) {
    if let Some(renderer) = resources.get_mut::<VolumeRenderer>() {
        f(
            renderer,
            FrameGpu {
                device,
                queue,
                commands,
            },
        );
    }
}

impl<P: RendererPaint> egui_wgpu::CallbackTrait for OnRenderer<P> {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        on_renderer(resources, device, queue, encoder, |r, frame| {
            self.0.prepare(r, frame)
        });
        Vec::new()
    }

    fn finish_prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        on_renderer(resources, device, queue, encoder, |r, frame| {
            self.0.finish_prepare(r, frame)
        });
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(renderer) = resources.get::<VolumeRenderer>() {
            self.0.paint(renderer, pass);
        }
    }
}

/// The active graphics backend, as the page and the panel name it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BackendInfo {
    /// `webgpu`, `webgl2`, `vulkan`, `metal`, `dx12` or `gl`.
    pub backend: &'static str,
    /// Adapter name as the driver reports it.
    pub adapter: String,
    /// How the slices are drawn: `marched` (a compute pass) or `rasterised`.
    pub slices: &'static str,
    /// Whether the adapter is a CPU one (lavapipe, SwiftShader): the view previews the light
    /// at less than the document asks ([`crate::limits::CPU_PREVIEW_LIGHT`]).
    pub on_cpu: bool,
}

/// Makes the queue's reports of finished work arrive without new work: wgpu's GL backend
/// (WebGL2 in the page) runs them only when the device is polled or given work, a frame or more
/// late; WebGPU runs them by itself.
#[derive(Clone)]
pub struct ReportPoll(Option<wgpu::Device>);

impl ReportPoll {
    /// The poll for `render_state`'s device (none where reports come by themselves).
    pub fn new(render_state: &egui_wgpu::RenderState) -> Self {
        let reports_itself =
            render_state.adapter.get_info().backend == wgpu::Backend::BrowserWebGpu;
        Self((!reports_itself).then(|| render_state.device.clone()))
    }

    /// Whether reports need polling.
    pub fn needed(&self) -> bool {
        self.0.is_some()
    }

    /// Runs the reports of work finished so far, without waiting.
    pub fn poll(&self) {
        if let Some(device) = &self.0
            && let Err(e) = device.poll(wgpu::PollType::Poll)
        {
            log::warn!("polling the GPU for finished work: {e}");
        }
    }
}

/// Sets the backends of the page's builds (index.html holds two): the WebGPU build draws with
/// WebGPU; the build with the WebGL2 fallback (`webgl_build`) only with WebGL2, as the page
/// loads it where WebGPU is missing or failed to start, or where `?backend=webgl` asks for it.
pub fn choose_web_backends(config: &mut egui_wgpu::WgpuConfiguration, webgl_build: bool) {
    if let egui_wgpu::WgpuSetup::CreateNew(setup) = &mut config.wgpu_setup {
        setup.instance_descriptor.backends = if webgl_build {
            wgpu::Backends::GL
        } else {
            wgpu::Backends::BROWSER_WEBGPU
        };
    }
}

/// Creates the renderer in egui-wgpu's callback resources; returns what is in use. `gl_name`
/// is what the GL backend is called on this platform (`webgl2` in the browser); `marching`
/// asks for marched (`Some(true)`) or rasterised slices instead of the adapter's default
/// ([`marches_by_default`]); a device that cannot march them rasterises them.
pub fn install(
    render_state: &egui_wgpu::RenderState,
    gl_name: &'static str,
    marching: Option<bool>,
) -> BackendInfo {
    let format = accumulation_format(&render_state.adapter);
    let mut renderer = VolumeRenderer::new(
        &render_state.device,
        &render_state.queue,
        render_state.target_format,
        format,
    );
    let (adapter, device) = (&render_state.adapter, &render_state.device);
    let marching = marching.unwrap_or_else(|| marches_by_default(adapter, device))
        && can_march(adapter, device);
    renderer.set_marching(&render_state.device, marching);
    render_state
        .renderer
        .write()
        .callback_resources
        .insert(renderer);
    let info = render_state.adapter.get_info();
    let backend = match info.backend {
        wgpu::Backend::BrowserWebGpu => "webgpu",
        wgpu::Backend::Gl => gl_name,
        wgpu::Backend::Vulkan => "vulkan",
        wgpu::Backend::Metal => "metal",
        wgpu::Backend::Dx12 => "dx12",
        _ => "other",
    };
    let adapter = if info.name.is_empty() {
        format!("{:?}", info.backend)
    } else {
        info.name.clone()
    };
    let slices = if marching { "marched" } else { "rasterised" };
    log::info!(
        "graphics: {backend} on {adapter} (volume accumulates in {format:?}; slices {slices})"
    );
    BackendInfo {
        backend,
        adapter,
        slices,
        on_cpu: info.device_type == wgpu::DeviceType::Cpu,
    }
}
