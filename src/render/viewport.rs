//! The egui paint callback that runs the volume renderer inside the app's viewport.
//!
//! The renderer lives in egui-wgpu's callback resources (created once at start-up); each frame
//! the app hands over a plain `Send + Sync` snapshot: the derived volumes, the job (with its
//! view) and which target to show. Uniforms are built here, from the snapshot.

use super::renderer::{SliceJob, VolumeRenderer};
use super::resources::accumulation_format;
use crate::derive::Volumes;

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
}

impl egui_wgpu::CallbackTrait for ViewportPaint {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(renderer) = resources.get_mut::<VolumeRenderer>() {
            renderer.begin_frame();
            renderer.upload(device, queue, &self.volumes);
            if let Some(job) = &self.job {
                renderer.update_light(device, queue, encoder, &job.view);
                renderer.draw_slices(device, queue, encoder, job, None);
            }
            if let Some(capture) = &self.capture {
                capture.advance(renderer, device, queue);
            }
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let (Some(renderer), Some(target)) = (resources.get::<VolumeRenderer>(), self.display) {
            renderer.composite(pass, target, false);
        }
    }
}

/// The sky gradient behind the cloud, over the whole view (drawn before [`ViewportPaint`]).
pub struct SkyPaint {
    /// Camera, light (its colours) and aspect of the view.
    pub view: super::gpu_types::View,
}

impl egui_wgpu::CallbackTrait for SkyPaint {
    fn prepare(
        &self,
        _device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(renderer) = resources.get::<VolumeRenderer>() {
            renderer.prepare_sky(queue, &self.view);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(renderer) = resources.get::<VolumeRenderer>() {
            renderer.draw_sky(pass);
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
/// is what the GL backend is called on this platform (`webgl2` in the browser).
pub fn install(render_state: &egui_wgpu::RenderState, gl_name: &'static str) -> BackendInfo {
    let format = accumulation_format(&render_state.adapter);
    let renderer = VolumeRenderer::new(
        &render_state.device,
        &render_state.queue,
        render_state.target_format,
        format,
    );
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
    log::info!("graphics: {backend} on {adapter} (volume accumulates in {format:?})");
    BackendInfo { backend, adapter }
}
