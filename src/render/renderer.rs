//! The volume renderer: passes and resources together, used by the app's viewport (through an
//! egui paint callback) and by offscreen rendering alike.

use super::gpu_types::{SkyUniforms, View, VolumeUniforms};
use super::passes::{CompositePass, SkyPass, SlicePass};
use super::progressive::JobPlan;
use super::resources::{TARGETS, Target, VolumeTextures, accumulation_texture, sampler};
use crate::derive::Volumes;

/// One volume draw: the planner's job (which slices, into which target) and what it shows.
#[derive(Clone, Debug, PartialEq)]
pub struct SliceJob {
    /// Slices `range` of `total` into accumulation target `target`.
    pub plan: JobPlan,
    /// Camera, light and media of the image.
    pub view: View,
}

/// Pipelines, samplers, textures and the accumulation targets.
pub struct VolumeRenderer {
    accum_format: wgpu::TextureFormat,
    slices: SlicePass,
    composite: CompositePass,
    sky: SkyPass,
    clamp_sampler: wgpu::Sampler,
    repeat_sampler: wgpu::Sampler,
    textures: VolumeTextures,
    bind_group: Option<wgpu::BindGroup>,
    targets: [Option<Target>; TARGETS],
}

impl VolumeRenderer {
    /// Creates pipelines for compositing into `output_format`, accumulating in `accum_format`.
    pub fn new(
        device: &wgpu::Device,
        output_format: wgpu::TextureFormat,
        accum_format: wgpu::TextureFormat,
    ) -> Self {
        Self {
            accum_format,
            slices: SlicePass::new(device, accum_format),
            composite: CompositePass::new(device, output_format),
            sky: SkyPass::new(device, output_format),
            clamp_sampler: sampler(device, wgpu::AddressMode::ClampToEdge),
            repeat_sampler: sampler(device, wgpu::AddressMode::Repeat),
            textures: VolumeTextures::new(),
            bind_group: None,
            targets: [None, None],
        }
    }

    /// The accumulation format in use.
    pub fn accumulation_format(&self) -> wgpu::TextureFormat {
        self.accum_format
    }

    /// Starts a frame (one submit): call before the frame's uploads and draws.
    pub fn begin_frame(&mut self) {
        self.slices.begin_frame();
    }

    /// Uploads whatever changed in `volumes` since the last call.
    pub fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, volumes: &Volumes) {
        if !self.textures.upload(device, queue, volumes) && self.bind_group.is_some() {
            return;
        }
        let t = &self.textures;
        let (Some((_, volume)), Some((_, noise))) = (&t.volume, &t.noise) else {
            return;
        };
        let entries = [
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.slices.uniforms,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<VolumeUniforms>() as u64),
                }),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(volume),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(&self.clamp_sampler),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(noise),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::Sampler(&self.repeat_sampler),
            },
        ];
        self.bind_group = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("volume"),
            layout: &self.slices.layout,
            entries: &entries,
        }));
    }

    fn ensure_target(&mut self, device: &wgpu::Device, index: usize, size: [u32; 2]) {
        let size = [size[0].max(1), size[1].max(1)];
        if self.targets[index].as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        let view = accumulation_texture(device, size, self.accum_format);
        let composite = self
            .composite
            .bind_group(device, &view, &self.clamp_sampler);
        self.targets[index] = Some(Target {
            size,
            view,
            composite,
        });
    }

    /// A pipeline for the benchmark baseline, for [`VolumeRenderer::draw_slices`].
    pub fn baseline_pipeline(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        self.slices.baseline(device)
    }

    /// Records one volume draw (see [`SliceJob`]), with the slice pipeline or `pipeline` (of
    /// the same layout: the bench baseline). Call [`VolumeRenderer::upload`] first.
    pub fn draw_slices(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        job: &SliceJob,
        pipeline: Option<&wgpu::RenderPipeline>,
    ) {
        let plan = &job.plan;
        let index = plan.target.min(TARGETS - 1);
        self.ensure_target(device, index, plan.size);
        let volume = &self.textures.density_volume;
        let uniforms = VolumeUniforms::new(&job.view, volume, plan.total, plan.range.start);
        let offset = self.slices.write(queue, &uniforms);
        let empty = volume.is_empty();
        let (Some(target), Some(bind_group)) = (&self.targets[index], &self.bind_group) else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("volume slices"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: if plan.clear {
                        wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let count = plan.range.end.saturating_sub(plan.range.start);
        if empty || count == 0 {
            return;
        }
        pass.set_pipeline(pipeline.unwrap_or(&self.slices.pipeline));
        pass.set_bind_group(0, bind_group, &[offset]);
        // Instances start at 0 (WebGL2 has no base instance); the first slice is a uniform.
        pass.draw(0..6, 0..count);
    }

    /// Sets the sky gradient of `view` (call before [`VolumeRenderer::draw_sky`]).
    pub fn prepare_sky(&self, queue: &wgpu::Queue, view: &View) {
        self.sky.write(
            queue,
            &SkyUniforms::new(&view.camera, &view.light, view.aspect),
        );
    }

    /// Draws the sky gradient over the current render pass's viewport.
    pub fn draw_sky(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.sky.draw(pass);
    }

    /// Draws accumulation target `index` over the current render pass's viewport.
    pub fn composite(&self, pass: &mut wgpu::RenderPass<'_>, index: usize) {
        let Some(target) = self.targets.get(index).and_then(|t| t.as_ref()) else {
            return;
        };
        pass.set_pipeline(&self.composite.pipeline);
        pass.set_bind_group(0, &target.composite, &[]);
        pass.draw(0..3, 0..1);
    }
}
