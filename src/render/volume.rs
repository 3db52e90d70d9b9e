//! The volume renderer: pipelines and GPU resources, created once, used by the app viewport
//! (through an egui paint callback) and by offscreen rendering alike.

use std::ops::Range;

use wgpu::util::DeviceExt as _;

use super::gpu_types::{CompositeUniforms, VolumeUniforms};
use super::noise::{NOISE_SIZE, noise_volume};
use crate::field::FieldGrid;

/// Shader sources, compiled into the binary.
pub mod shaders {
    /// `shaders/volume.wgsl`.
    pub const VOLUME: &str = include_str!("../../shaders/volume.wgsl");
    /// `shaders/composite.wgsl`.
    pub const COMPOSITE: &str = include_str!("../../shaders/composite.wgsl");
    /// `shaders/plain_slices.wgsl` (the benchmark baseline).
    pub const PLAIN_SLICES: &str = include_str!("../../shaders/plain_slices.wgsl");
    /// Every shader file with its name (for validation).
    pub const ALL: [(&str, &str); 3] = [
        ("volume.wgsl", VOLUME),
        ("composite.wgsl", COMPOSITE),
        ("plain_slices.wgsl", PLAIN_SLICES),
    ];
}

/// The field grid and noise seed a frame draws, with a generation that changes when they do.
#[derive(Clone, Debug)]
pub struct VolumeData {
    /// Bumped whenever `grid` changes; the renderer re-uploads only then.
    pub generation: u64,
    /// Baked field and transmittance.
    pub grid: FieldGrid,
    /// Seed of the noise volume.
    pub noise_seed: u64,
}

/// One volume draw: slices `range` of `total`, into accumulation target `target`.
#[derive(Clone, Debug, PartialEq)]
pub struct SliceJob {
    /// Which accumulation target (0 or 1).
    pub target: usize,
    /// Target size in pixels.
    pub size: [u32; 2],
    /// Slices of the whole image drawn by this job (0 = farthest).
    pub range: Range<u32>,
    /// Clear the target first (the first chunk of an image).
    pub clear: bool,
    /// Camera, light and media for the whole image.
    pub uniforms: VolumeUniforms,
}

/// Number of accumulation targets (a preview and a refinement).
pub const TARGETS: usize = 2;

struct Target {
    size: [u32; 2],
    view: wgpu::TextureView,
    composite_bind_group: wgpu::BindGroup,
}

struct UploadedField {
    generation: u64,
    noise_seed: u64,
    bind_group: wgpu::BindGroup,
    empty: bool,
}

/// Pipelines, samplers, uniform buffers and the accumulation targets.
pub struct VolumeRenderer {
    accum_format: wgpu::TextureFormat,
    slice_pipeline: wgpu::RenderPipeline,
    composite_pipeline: wgpu::RenderPipeline,
    volume_layout: wgpu::BindGroupLayout,
    composite_layout: wgpu::BindGroupLayout,
    volume_uniforms: wgpu::Buffer,
    composite_uniforms: wgpu::Buffer,
    clamp_sampler: wgpu::Sampler,
    repeat_sampler: wgpu::Sampler,
    noise: Option<(u64, wgpu::TextureView)>,
    field: Option<UploadedField>,
    targets: [Option<Target>; TARGETS],
}

/// Picks the accumulation format: 16-bit float where the adapter can render and blend it
/// (smooth gradients over many faint slices), 8-bit otherwise (plain WebGL2).
pub fn accumulation_format(adapter: &wgpu::Adapter) -> wgpu::TextureFormat {
    let f = adapter.get_texture_format_features(wgpu::TextureFormat::Rgba16Float);
    let ok = f
        .allowed_usages
        .contains(wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING)
        && f.flags.contains(
            wgpu::TextureFormatFeatureFlags::BLENDABLE
                | wgpu::TextureFormatFeatureFlags::FILTERABLE,
        );
    if ok {
        wgpu::TextureFormat::Rgba16Float
    } else {
        wgpu::TextureFormat::Rgba8Unorm
    }
}

fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        },
        count: None,
    }
}

fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

const PREMULTIPLIED_OVER: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
};

fn pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    layout: &wgpu::BindGroupLayout,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format,
                blend: Some(PREMULTIPLIED_OVER),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl VolumeRenderer {
    /// Creates pipelines for compositing into `output_format`, accumulating in `accum_format`.
    pub fn new(
        device: &wgpu::Device,
        output_format: wgpu::TextureFormat,
        accum_format: wgpu::TextureFormat,
    ) -> Self {
        let volume_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volume"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT),
                texture_entry(1),
                sampler_entry(2),
                texture_entry(3),
                sampler_entry(4),
            ],
        });
        let composite_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::FRAGMENT),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                sampler_entry(2),
            ],
        });
        let slice_pipeline = pipeline(
            device,
            "volume slices",
            shaders::VOLUME,
            &volume_layout,
            accum_format,
        );
        let composite_pipeline = pipeline(
            device,
            "volume composite",
            shaders::COMPOSITE,
            &composite_layout,
            output_format,
        );
        let volume_uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("volume uniforms"),
            size: std::mem::size_of::<VolumeUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let composite_uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("composite uniforms"),
            contents: bytemuck::bytes_of(&CompositeUniforms {
                params: [1.0, 0.0, 0.0, 0.0],
            }),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let sampler = |mode: wgpu::AddressMode| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("volume sampler"),
                address_mode_u: mode,
                address_mode_v: mode,
                address_mode_w: mode,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            })
        };
        Self {
            accum_format,
            slice_pipeline,
            composite_pipeline,
            volume_layout,
            composite_layout,
            volume_uniforms,
            composite_uniforms,
            clamp_sampler: sampler(wgpu::AddressMode::ClampToEdge),
            repeat_sampler: sampler(wgpu::AddressMode::Repeat),
            noise: None,
            field: None,
            targets: [None, None],
        }
    }

    /// The accumulation format in use.
    pub fn accumulation_format(&self) -> wgpu::TextureFormat {
        self.accum_format
    }

    /// Uploads the field grid and noise volume if they changed since the last call.
    pub fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, data: &VolumeData) {
        if self
            .field
            .as_ref()
            .is_some_and(|f| f.generation == data.generation && f.noise_seed == data.noise_seed)
        {
            return;
        }
        if self
            .noise
            .as_ref()
            .is_none_or(|(seed, _)| *seed != data.noise_seed)
        {
            let n = NOISE_SIZE;
            let view = upload_3d(
                device,
                queue,
                "noise",
                [n, n, n],
                wgpu::TextureFormat::R8Unorm,
                &noise_volume(data.noise_seed),
            );
            self.noise = Some((data.noise_seed, view));
        }
        let grid = &data.grid;
        let empty = grid.is_empty();
        let field_view = if empty {
            upload_3d(
                device,
                queue,
                "field",
                [1, 1, 1],
                wgpu::TextureFormat::Rg8Unorm,
                &[0, 255],
            )
        } else {
            upload_3d(
                device,
                queue,
                "field",
                grid.dims.to_array(),
                wgpu::TextureFormat::Rg8Unorm,
                &grid.texels,
            )
        };
        let Some((_, noise_view)) = &self.noise else {
            return;
        };
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("volume"),
            layout: &self.volume_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.volume_uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&field_view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&self.clamp_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(noise_view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(&self.repeat_sampler),
                },
            ],
        });
        self.field = Some(UploadedField {
            generation: data.generation,
            noise_seed: data.noise_seed,
            bind_group,
            empty,
        });
    }

    fn ensure_target(&mut self, device: &wgpu::Device, index: usize, size: [u32; 2]) {
        let size = [size[0].max(1), size[1].max(1)];
        if self.targets[index].as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("volume accumulation"),
            size: wgpu::Extent3d {
                width: size[0],
                height: size[1],
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.accum_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let composite_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite"),
            layout: &self.composite_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.composite_uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&self.clamp_sampler),
                },
            ],
        });
        self.targets[index] = Some(Target {
            size,
            view,
            composite_bind_group,
        });
    }

    /// A pipeline for the benchmark baseline (`shaders/plain_slices.wgsl`), for
    /// [`VolumeRenderer::draw_slices_with`].
    pub fn baseline_pipeline(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        pipeline(
            device,
            "plain slices (baseline)",
            shaders::PLAIN_SLICES,
            &self.volume_layout,
            self.accum_format,
        )
    }

    /// Records one volume draw (see [`SliceJob`]). Call [`VolumeRenderer::upload`] first.
    pub fn draw_slices(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        job: &SliceJob,
    ) {
        self.draw_slices_with(device, queue, encoder, job, None);
    }

    /// Like [`VolumeRenderer::draw_slices`] with another slice pipeline of the same layout.
    pub fn draw_slices_with(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        job: &SliceJob,
        pipeline: Option<&wgpu::RenderPipeline>,
    ) {
        let index = job.target.min(TARGETS - 1);
        self.ensure_target(device, index, job.size);
        queue.write_buffer(
            &self.volume_uniforms,
            0,
            bytemuck::bytes_of(&job.uniforms.starting_at(job.range.start)),
        );
        let (Some(target), Some(field)) = (&self.targets[index], &self.field) else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("volume slices"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: if job.clear {
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
        let count = job.range.end.saturating_sub(job.range.start);
        if field.empty || count == 0 {
            return;
        }
        pass.set_pipeline(pipeline.unwrap_or(&self.slice_pipeline));
        pass.set_bind_group(0, &field.bind_group, &[]);
        // Instances start at 0 (WebGL2 has no base instance); the first slice is a uniform.
        pass.draw(0..6, 0..count);
    }

    /// Draws accumulation target `index` over the current render pass's viewport.
    pub fn composite(&self, pass: &mut wgpu::RenderPass<'_>, index: usize) {
        let Some(target) = self.targets.get(index).and_then(|t| t.as_ref()) else {
            return;
        };
        pass.set_pipeline(&self.composite_pipeline);
        pass.set_bind_group(0, &target.composite_bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

fn upload_3d(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    dims: [u32; 3],
    format: wgpu::TextureFormat,
    data: &[u8],
) -> wgpu::TextureView {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: dims[0],
            height: dims[1],
            depth_or_array_layers: dims[2],
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let bytes_per_texel = format.block_copy_size(None).unwrap_or(1);
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        data,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(dims[0] * bytes_per_texel),
            rows_per_image: Some(dims[1]),
        },
        wgpu::Extent3d {
            width: dims[0],
            height: dims[1],
            depth_or_array_layers: dims[2],
        },
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}
