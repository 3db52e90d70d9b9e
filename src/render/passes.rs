//! The render passes: sky (the gradient behind the cloud, when the document has one), slices
//! (view-aligned slices back to front into an accumulation target) and composite (the
//! accumulated image over the output). Pipelines are created once.
//! The slice pass has its own ring of uniform slots addressed by dynamic offsets, so several
//! slice draws recorded before one submit never overwrite each other's uniforms.

use std::num::NonZeroU64;

use super::gpu_types::{
    BehindUniforms, LightSliceUniforms, SKY_TABLE_SCALE, SkyUniforms, VolumeUniforms,
};
use super::shaders;

/// Slice draws one frame (one submit) may record.
pub const MAX_SLICE_DRAWS_PER_FRAME: u32 = 8;

/// A uniform buffer entry of `size` bytes at `binding`, with a dynamic offset when `dynamic`.
pub fn uniform_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    size: u64,
    dynamic: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: NonZeroU64::new(size),
        },
        count: None,
    }
}

fn texture_entry(
    binding: u32,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

fn texture_3d(binding: u32) -> wgpu::BindGroupLayoutEntry {
    texture_entry(binding, wgpu::TextureViewDimension::D3)
}

fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
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

/// Whether a target of `format` holds linear light (a float target: the offscreen image an EXR
/// holds) rather than display-encoded colour (8 bits: the screen, a PNG). The sky and the
/// composite write it with their `_linear` entry points: no tone map, no sRGB encoding.
pub fn linear_output(format: wgpu::TextureFormat) -> bool {
    matches!(
        format,
        wgpu::TextureFormat::Rgba16Float | wgpu::TextureFormat::Rgba32Float
    )
}

/// The fragment entry point of the sky and composite shaders that writes into `format`:
/// `display` for display-encoded targets, its linear counterpart for linear ones.
fn output_entry(format: wgpu::TextureFormat, display: &'static str) -> &'static str {
    if !linear_output(format) {
        return display;
    }
    match display {
        "fs_main" | "fs_transparent" => "fs_linear",
        // Over a transparent background the linear composite is the same: light with no alpha
        // is kept as it is.
        "fs_shafts" | "fs_shafts_transparent" => "fs_shafts_linear",
        "fs_shafts_beyond" | "fs_shafts_beyond_transparent" => "fs_shafts_beyond_linear",
        other => other,
    }
}

fn pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    layout: &wgpu::BindGroupLayout,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    full_pipeline(
        device,
        label,
        source,
        &[layout],
        format,
        Some(PREMULTIPLIED_OVER),
    )
}

/// A pipeline of `source`'s `vs_main` (no vertex buffers) and `fs_main` into one `format`
/// target, with `blend` (none: replace).
pub fn full_pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    format: wgpu::TextureFormat,
    blend: Option<wgpu::BlendState>,
) -> wgpu::RenderPipeline {
    targets_pipeline(device, label, source, layouts, "fs_main", &[format], blend)
}

/// A pipeline of `source`'s `vs_main` (no vertex buffers) and `fragment` into `formats`
/// (one target each, all with `blend`; none: replace).
pub fn targets_pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    layouts: &[&wgpu::BindGroupLayout],
    fragment: &str,
    formats: &[wgpu::TextureFormat],
    blend: Option<wgpu::BlendState>,
) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(*l)).collect();
    let targets: Vec<Option<wgpu::ColorTargetState>> = formats
        .iter()
        .map(|&format| {
            Some(wgpu::ColorTargetState {
                format,
                blend,
                write_mask: wgpu::ColorWrites::ALL,
            })
        })
        .collect();
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
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
            entry_point: Some(fragment),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The slice pass: pipelines, bind group layout and its ring of uniform slots.
pub struct SlicePass {
    /// The slice pipeline.
    pub pipeline: wgpu::RenderPipeline,
    /// The slices with the shafts of light's shells among them, into two targets: the cloud
    /// and the shafts (`fs_shafts`).
    pub shafts_pipeline: wgpu::RenderPipeline,
    /// Every shell's light in one pass over the view, no slice (`fs_outside_shafts`), into the
    /// same two targets.
    pub outside_pipeline: wgpu::RenderPipeline,
    /// Layout of its bind group (uniforms, volume, sampler, noise, sampler).
    pub layout: wgpu::BindGroupLayout,
    /// Uniform ring, [`MAX_SLICE_DRAWS_PER_FRAME`] slots of `stride` bytes.
    pub uniforms: wgpu::Buffer,
    stride: u64,
    next_slot: u32,
    format: wgpu::TextureFormat,
}

impl SlicePass {
    /// Creates the pass accumulating into `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let size = std::mem::size_of::<VolumeUniforms>() as u64;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("volume"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, size, true),
                texture_3d(1),
                sampler_entry(2),
                texture_3d(3),
                sampler_entry(4),
                texture_3d(5),
            ],
        });
        let align = device.limits().min_uniform_buffer_offset_alignment.max(16) as u64;
        let stride = size.div_ceil(align) * align;
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("volume uniforms"),
            size: stride * MAX_SLICE_DRAWS_PER_FRAME as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            pipeline: pipeline(device, "volume slices", shaders::VOLUME, &layout, format),
            shafts_pipeline: targets_pipeline(
                device,
                "volume slices with shafts of light",
                shaders::VOLUME,
                &[&layout],
                "fs_shafts",
                &[format, format],
                Some(PREMULTIPLIED_OVER),
            ),
            outside_pipeline: targets_pipeline(
                device,
                "shafts of light apart from the clouds",
                shaders::VOLUME,
                &[&layout],
                "fs_outside_shafts",
                &[format, format],
                Some(PREMULTIPLIED_OVER),
            ),
            layout,
            uniforms,
            stride,
            next_slot: 0,
            format,
        }
    }

    /// A pipeline for the benchmark baseline (`plain_slices.wgsl`) with the same layout.
    pub fn baseline(&self, device: &wgpu::Device) -> wgpu::RenderPipeline {
        pipeline(
            device,
            "plain slices (baseline)",
            shaders::PLAIN_SLICES,
            &self.layout,
            self.format,
        )
    }

    /// Starts a frame: uniform slots are reused from the first.
    pub fn begin_frame(&mut self) {
        self.next_slot = 0;
    }

    /// Writes `uniforms` into the next free slot; returns its dynamic offset. Past
    /// [`MAX_SLICE_DRAWS_PER_FRAME`] draws in one frame the last slot is reused (and logged).
    pub fn write(&mut self, queue: &wgpu::Queue, uniforms: &VolumeUniforms) -> u32 {
        let slot = if self.next_slot < MAX_SLICE_DRAWS_PER_FRAME {
            self.next_slot += 1;
            self.next_slot - 1
        } else {
            log::warn!("more than {MAX_SLICE_DRAWS_PER_FRAME} slice draws in one frame");
            MAX_SLICE_DRAWS_PER_FRAME - 1
        };
        let offset = slot as u64 * self.stride;
        queue.write_buffer(&self.uniforms, offset, bytemuck::bytes_of(uniforms));
        offset as u32
    }
}

/// The composite pass: draws an accumulation target over the output. Every pipeline's group 1
/// says what lies behind the cloud ([`CompositePass::behind_group`]): over a background the
/// display composites read it, to map the light of the two together once.
pub struct CompositePass {
    /// The composite pipeline.
    pub pipeline: wgpu::RenderPipeline,
    /// The same over a transparent background: the cloud alone (`fs_transparent`).
    pub transparent_pipeline: wgpu::RenderPipeline,
    /// Layout of its bind group (source texture, sampler).
    pub layout: wgpu::BindGroupLayout,
    /// The composite of a target with its shafts of light added (`fs_shafts`).
    pub shafts_pipeline: wgpu::RenderPipeline,
    /// The same over a transparent background: the shafts' light with alpha of its own
    /// (`fs_shafts_transparent`).
    pub shafts_transparent_pipeline: wgpu::RenderPipeline,
    /// Layout of their bind group (source texture, sampler, shafts texture).
    pub shafts_layout: wgpu::BindGroupLayout,
    /// The composite of a cropped target with its shafts and those of the shells beyond the
    /// box drawn apart (`fs_shafts_beyond`), and over a transparent background.
    pub beyond_pipeline: wgpu::RenderPipeline,
    /// The same over a transparent background (`fs_shafts_beyond_transparent`).
    pub beyond_transparent_pipeline: wgpu::RenderPipeline,
    /// Layout of their bind group: the shafts layout's, then the beyond light's texture and
    /// where the target lies in it (a uniform `vec4`).
    pub beyond_layout: wgpu::BindGroupLayout,
    /// Layout of group 1: the view behind the cloud (a 2D texture of display colours) and a
    /// [`BehindUniforms`].
    pub behind_layout: wgpu::BindGroupLayout,
}

impl CompositePass {
    /// Creates the pass writing into `output_format`.
    pub fn new(device: &wgpu::Device, output_format: wgpu::TextureFormat) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite"),
            entries: &[
                texture_entry(0, wgpu::TextureViewDimension::D2),
                sampler_entry(1),
            ],
        });
        let shafts_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite with shafts"),
            entries: &[
                texture_entry(0, wgpu::TextureViewDimension::D2),
                sampler_entry(1),
                texture_entry(2, wgpu::TextureViewDimension::D2),
            ],
        });
        let beyond_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite with shafts beyond"),
            entries: &[
                texture_entry(0, wgpu::TextureViewDimension::D2),
                sampler_entry(1),
                texture_entry(2, wgpu::TextureViewDimension::D2),
                texture_entry(3, wgpu::TextureViewDimension::D2),
                uniform_entry(4, wgpu::ShaderStages::FRAGMENT, 16, false),
            ],
        });
        let behind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("composite: behind the cloud"),
            entries: &[
                texture_entry(0, wgpu::TextureViewDimension::D2),
                uniform_entry(
                    1,
                    wgpu::ShaderStages::FRAGMENT,
                    std::mem::size_of::<BehindUniforms>() as u64,
                    false,
                ),
            ],
        });
        let make = |label: &str, layout: &wgpu::BindGroupLayout, entry: &'static str| {
            targets_pipeline(
                device,
                label,
                shaders::COMPOSITE,
                &[layout, &behind_layout],
                output_entry(output_format, entry),
                &[output_format],
                Some(PREMULTIPLIED_OVER),
            )
        };
        Self {
            pipeline: make("volume composite", &layout, "fs_main"),
            transparent_pipeline: make("volume composite, transparent", &layout, "fs_transparent"),
            shafts_pipeline: make("volume composite with shafts", &shafts_layout, "fs_shafts"),
            shafts_transparent_pipeline: make(
                "volume composite with shafts, transparent",
                &shafts_layout,
                "fs_shafts_transparent",
            ),
            beyond_pipeline: make(
                "volume composite with shafts beyond",
                &beyond_layout,
                "fs_shafts_beyond",
            ),
            beyond_transparent_pipeline: make(
                "volume composite with shafts beyond, transparent",
                &beyond_layout,
                "fs_shafts_beyond_transparent",
            ),
            layout,
            shafts_layout,
            beyond_layout,
            behind_layout,
        }
    }

    /// The group 1 that says what lies behind the cloud: `texture` (display colours over the
    /// whole view) and `uniforms` (a [`BehindUniforms`]: where the image lies in it, or a flat
    /// colour instead).
    pub fn behind_group(
        &self,
        device: &wgpu::Device,
        texture: &wgpu::TextureView,
        uniforms: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite: behind the cloud"),
            layout: &self.behind_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(texture),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: uniforms.as_entire_binding(),
                },
            ],
        })
    }

    /// The bind group that composites `source`, with the shafts of light in `shafts` (for
    /// `shafts_pipeline`) or without.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        source: &wgpu::TextureView,
        shafts: Option<&wgpu::TextureView>,
        sampler: &wgpu::Sampler,
    ) -> wgpu::BindGroup {
        let mut entries = vec![
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(source),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(sampler),
            },
        ];
        if let Some(shafts) = shafts {
            entries.push(wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::TextureView(shafts),
            });
        }
        let (label, layout) = match shafts {
            Some(_) => ("composite with shafts", &self.shafts_layout),
            None => ("composite", &self.layout),
        };
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout,
            entries: &entries,
        })
    }

    /// The bind group that composites `source` with its `shafts` and the light of the shells
    /// beyond the box in `beyond`, where `place` (a 16-byte uniform: xy + uv · zw) says where
    /// the source lies in it.
    pub fn beyond_bind_group(
        &self,
        device: &wgpu::Device,
        [source, shafts, beyond]: [&wgpu::TextureView; 3],
        sampler: &wgpu::Sampler,
        place: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let texture = |binding, view| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        };
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("composite with shafts beyond"),
            layout: &self.beyond_layout,
            entries: &[
                texture(0, source),
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
                texture(2, shafts),
                texture(3, beyond),
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: place.as_entire_binding(),
                },
            ],
        })
    }
}

/// Which of the sky pass's two uniform slots a draw uses: the viewport's view behind the
/// cloud and an image's (a PNG export's capture) may both be drawn before one submission.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkySlot {
    /// The viewport's.
    Viewport = 0,
    /// An image's (offscreen renders, captures).
    Image = 1,
}

/// The sky pass: the sky (gradient, flat colour, ground and the shafts around the clouds' box)
/// over a whole target, drawn before the cloud's composite.
pub struct SkyPass {
    pipeline: wgpu::RenderPipeline,
    uniforms: [wgpu::Buffer; 2],
    layout: wgpu::BindGroupLayout,
    bind_groups: [wgpu::BindGroup; 2],
    /// Each slot's physical sky view table (`atmosphere::SkyTables::view` × `SKY_TABLE_SCALE`,
    /// half floats): an image and the viewport drawn in one submission may have their suns
    /// at two elevations.
    atmosphere: [wgpu::Texture; 2],
    atmosphere_views: [wgpu::TextureView; 2],
    /// The sun elevation's bits the table holds (`NO_ATMOSPHERE`: none yet).
    atmosphere_keys: [std::sync::atomic::AtomicU32; 2],
}

/// `SkyPass::atmosphere_keys` before any table is written (a NaN's bits: no elevation's).
const NO_ATMOSPHERE: u32 = u32::MAX;

impl SkyPass {
    /// Creates the pass writing into `output_format`, shading the ground through `light` (a
    /// 3D texture of transmittance) and adding the shafts' light in `shafts` (a 2D texture);
    /// rebind with [`SkyPass::bind`] when either changes.
    pub fn new(
        device: &wgpu::Device,
        output_format: wgpu::TextureFormat,
        light: &wgpu::TextureView,
        shafts: &wgpu::TextureView,
        sampler: &wgpu::Sampler,
    ) -> Self {
        let size = std::mem::size_of::<SkyUniforms>() as u64;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("sky"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::FRAGMENT, size, false),
                texture_3d(1),
                sampler_entry(2),
                texture_entry(3, wgpu::TextureViewDimension::D2),
                texture_entry(4, wgpu::TextureViewDimension::D2),
            ],
        });
        let [w, h] = crate::atmosphere::VIEW_SIZE;
        let atmosphere = [0, 1].map(|_| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some("physical sky"),
                size: wgpu::Extent3d {
                    width: w as u32,
                    height: h as u32,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba16Float,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            })
        });
        let atmosphere_views = [0, 1].map(|i| atmosphere[i].create_view(&Default::default()));
        let uniforms = [0, 1].map(|_| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("sky uniforms"),
                size,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        let bind_groups = [0, 1].map(|i| {
            Self::group(
                device,
                &layout,
                &uniforms[i],
                [light, shafts, &atmosphere_views[i]],
                sampler,
            )
        });
        Self {
            pipeline: targets_pipeline(
                device,
                "sky",
                shaders::SKY,
                &[&layout],
                output_entry(output_format, "fs_main"),
                &[output_format],
                None,
            ),
            uniforms,
            layout,
            bind_groups,
            atmosphere,
            atmosphere_views,
            atmosphere_keys: [0, 1].map(|_| std::sync::atomic::AtomicU32::new(NO_ATMOSPHERE)),
        }
    }

    /// The bind group of one slot: its uniforms, the light volume, the shafts and the
    /// physical sky's table.
    fn group(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        uniforms: &wgpu::Buffer,
        [light, shafts, atmosphere]: [&wgpu::TextureView; 3],
        sampler: &wgpu::Sampler,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(light),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(shafts),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(atmosphere),
                },
            ],
        })
    }

    /// Shades the ground through this light volume, and adds these shafts, from now on.
    pub fn bind(
        &mut self,
        device: &wgpu::Device,
        light: &wgpu::TextureView,
        shafts: &wgpu::TextureView,
        sampler: &wgpu::Sampler,
    ) {
        self.bind_groups = [0, 1].map(|i| {
            Self::group(
                device,
                &self.layout,
                &self.uniforms[i],
                [light, shafts, &self.atmosphere_views[i]],
                sampler,
            )
        });
    }

    /// Sets the sky the next [`SkyPass::draw`] in `slot` draws, with the physical sky of
    /// `light`'s sun elevation when it has one (the slot's table written when its elevation
    /// moved).
    pub fn write(
        &self,
        queue: &wgpu::Queue,
        slot: SkySlot,
        uniforms: &SkyUniforms,
        light: &crate::scene::Lighting,
    ) {
        if light.physical_sky {
            self.write_atmosphere(queue, slot, light.sun_elevation_deg);
        }
        queue.write_buffer(
            &self.uniforms[slot as usize],
            0,
            bytemuck::bytes_of(uniforms),
        );
    }

    fn write_atmosphere(&self, queue: &wgpu::Queue, slot: SkySlot, elevation_deg: f32) {
        use std::sync::atomic::Ordering;
        let key = elevation_deg.to_bits();
        if self.atmosphere_keys[slot as usize].swap(key, Ordering::Relaxed) == key {
            return;
        }
        let tables = crate::atmosphere::sky(elevation_deg);
        let texels: Vec<u16> = tables
            .view
            .iter()
            .flat_map(|&[r, g, b]| {
                [r, g, b, 1.0].map(|x| half::f16::from_f32(x * SKY_TABLE_SCALE).to_bits())
            })
            .collect();
        let [w, h] = crate::atmosphere::VIEW_SIZE;
        queue.write_texture(
            self.atmosphere[slot as usize].as_image_copy(),
            bytemuck::cast_slice(&texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w as u32 * 8),
                rows_per_image: Some(h as u32),
            },
            wgpu::Extent3d {
                width: w as u32,
                height: h as u32,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Draws the sky of `slot` over the current render pass's viewport, replacing what is there.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, slot: SkySlot) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_groups[slot as usize], &[]);
        pass.draw(0..3, 0..1);
    }
}

/// A flat colour over the current viewport (`shaders/fill.wgsl`): the render pass's blend
/// constant, blended over nothing, so the pipeline binds nothing.
pub struct FillPass {
    pipeline: wgpu::RenderPipeline,
}

impl FillPass {
    /// Creates the pass writing into `output_format`.
    pub fn new(device: &wgpu::Device, output_format: wgpu::TextureFormat) -> Self {
        const CONSTANT: wgpu::BlendComponent = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Constant,
            dst_factor: wgpu::BlendFactor::Zero,
            operation: wgpu::BlendOperation::Add,
        };
        let blend = wgpu::BlendState {
            color: CONSTANT,
            alpha: CONSTANT,
        };
        Self {
            pipeline: full_pipeline(
                device,
                "fill",
                shaders::FILL,
                &[],
                output_format,
                Some(blend),
            ),
        }
    }

    /// Fills the current render pass's viewport with `colour` (the values the target stores).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, colour: wgpu::Color) {
        pass.set_pipeline(&self.pipeline);
        pass.set_blend_constant(colour);
        pass.draw(0..3, 0..1);
    }
}

/// The view behind the cloud laid again from the texture it was drawn into
/// (`shaders/backdrop.wgsl`): a texture read a pixel, replacing what lies under it.
pub struct BackdropPass {
    pipeline: wgpu::RenderPipeline,
}

impl BackdropPass {
    /// Creates the pass writing into `output_format`, its group laid out as `layout` (a 2D
    /// texture and a sampler: the composite's).
    pub fn new(
        device: &wgpu::Device,
        output_format: wgpu::TextureFormat,
        layout: &wgpu::BindGroupLayout,
    ) -> Self {
        Self {
            pipeline: full_pipeline(
                device,
                "backdrop",
                shaders::BACKDROP,
                &[layout],
                output_format,
                None,
            ),
        }
    }

    /// Lays the texture of `group` over the current render pass's viewport.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, group: &wgpu::BindGroup) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// Light slices one light volume may have (its grid's cap per side).
pub const MAX_LIGHT_SLICES: u32 = 128;

/// The light volume pass: transmittance toward the sun at every texel of a 3D texture, one
/// render pass per z-slice, reading the slices' uniforms, field and noise (bindings 0–4 of
/// their group; not 5, the light texture it writes).
pub struct LightPass {
    /// The pipeline.
    pub pipeline: wgpu::RenderPipeline,
    /// Layout of group 0: the slice group without the light texture.
    pub volume_layout: wgpu::BindGroupLayout,
    /// Per-slice uniforms (group 1): two banks of [`MAX_LIGHT_SLICES`] slots of `stride`
    /// bytes, used in turn, so that two light volumes computed before one submission (the
    /// viewport's and a PNG export's) keep their own.
    uniforms: wgpu::Buffer,
    /// Group 1.
    pub slice_group: wgpu::BindGroup,
    stride: u64,
    /// The bank the next [`LightPass::write`] uses.
    bank: u64,
}

/// The light volume's format where the adapter renders and filters half floats (as it must to
/// accumulate in them): transmittance toward the sun (stored as T^(1/8)), the sky's light let
/// through from above, and the multiple scattering's diffusion through the cloud's thickness
/// and the cloud around (halved), in [0, 1]. Half floats keep the multiple scattering smooth: its octaves raise the
/// stored transmittance to small powers, so 8 bits of it step by a level of the image.
pub const LIGHT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The light volume's format where half floats are not renderable (plain WebGL2).
pub const LIGHT_FORMAT_8BIT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The light volume's format for slices accumulated in `accum_format`: half floats where the
/// adapter accumulates in them, 8 bits otherwise.
pub fn light_format(accum_format: wgpu::TextureFormat) -> wgpu::TextureFormat {
    if accum_format == wgpu::TextureFormat::Rgba16Float {
        LIGHT_FORMAT
    } else {
        LIGHT_FORMAT_8BIT
    }
}

impl LightPass {
    /// Creates the pass, rendering the light volume's slices in `format` (`light_format`).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let volume_size = std::mem::size_of::<VolumeUniforms>() as u64;
        let volume_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("light volume: volume"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, volume_size, true),
                texture_3d(1),
                sampler_entry(2),
                texture_3d(3),
                sampler_entry(4),
            ],
        });
        let size = std::mem::size_of::<LightSliceUniforms>() as u64;
        let slice_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("light volume: slice"),
            entries: &[uniform_entry(0, wgpu::ShaderStages::FRAGMENT, size, true)],
        });
        let align = device.limits().min_uniform_buffer_offset_alignment.max(16) as u64;
        let stride = size.div_ceil(align) * align;
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light slices"),
            size: 2 * stride * MAX_LIGHT_SLICES as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let slice_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("light volume: slice"),
            layout: &slice_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &uniforms,
                    offset: 0,
                    size: NonZeroU64::new(size),
                }),
            }],
        });
        let pipeline = full_pipeline(
            device,
            "light volume",
            shaders::LIGHT_MARCH,
            &[&volume_layout, &slice_layout],
            format,
            None,
        );
        Self {
            pipeline,
            volume_layout,
            uniforms,
            slice_group,
            stride,
            bank: 0,
        }
    }

    /// Writes the slices' uniforms into the next bank; returns each slice's dynamic offset.
    pub fn write(&mut self, queue: &wgpu::Queue, slices: &[LightSliceUniforms]) -> Vec<u32> {
        let n = slices.len().min(MAX_LIGHT_SLICES as usize);
        let mut bytes = vec![0u8; (self.stride * n as u64) as usize];
        for (i, s) in slices[..n].iter().enumerate() {
            let at = i * self.stride as usize;
            bytes[at..at + std::mem::size_of::<LightSliceUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(s));
        }
        let base = self.bank * self.stride * MAX_LIGHT_SLICES as u64;
        self.bank = 1 - self.bank;
        queue.write_buffer(&self.uniforms, base, &bytes);
        (0..n as u64)
            .map(|i| (base + i * self.stride) as u32)
            .collect()
    }
}

/// The format of the marched slices' images (a storage format on every adapter with compute).
pub const MARCH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// Pixels along each side of a marched slices' workgroup (`@workgroup_size` in
/// `volume_march.wgsl`).
pub const MARCH_WORKGROUP: u32 = 8;

/// The marched slices (`shaders/volume_march.wgsl`, for adapters with compute shaders): a
/// compute pass writes each draw's slices composited per pixel into two images (the cloud, the
/// shafts' light), and a full-screen pass (`march_blend.wgsl`) lays them over the accumulation
/// targets with the slices' "over" blending. Same uniforms and textures as the slice pass.
pub struct MarchPass {
    /// The compute pipeline.
    pub pipeline: wgpu::ComputePipeline,
    /// Group 0: the slice group's bindings, visible to compute.
    pub layout: wgpu::BindGroupLayout,
    /// Group 1: the two images it writes.
    pub output_layout: wgpu::BindGroupLayout,
    /// The images over the cloud's target.
    pub blend: wgpu::RenderPipeline,
    /// The images over both targets, with shafts of light.
    pub blend_shafts: wgpu::RenderPipeline,
    /// Layout of the blend's group: the two images.
    pub blend_layout: wgpu::BindGroupLayout,
}

/// The slice group's bindings (`volume_common.wgsl`'s group 0) for a compute pass.
pub fn compute_volume_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    let compute = |mut e: wgpu::BindGroupLayoutEntry| {
        e.visibility = wgpu::ShaderStages::COMPUTE;
        e
    };
    let size = std::mem::size_of::<VolumeUniforms>() as u64;
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            uniform_entry(0, wgpu::ShaderStages::COMPUTE, size, true),
            compute(texture_3d(1)),
            compute(sampler_entry(2)),
            compute(texture_3d(3)),
            compute(sampler_entry(4)),
            compute(texture_3d(5)),
        ],
    })
}

impl MarchPass {
    /// Creates the pass blending into accumulation targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let layout = compute_volume_layout(device, "marched slices: volume");
        let image = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: MARCH_FORMAT,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            count: None,
        };
        let output_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("marched slices: images"),
            entries: &[image(0), image(1)],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("marched slices"),
            source: wgpu::ShaderSource::Wgsl(shaders::VOLUME_MARCH.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("marched slices"),
            bind_group_layouts: &[Some(&layout), Some(&output_layout)],
            immediate_size: 0,
        });
        let compute_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("marched slices"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let loaded = |binding| {
            let mut e = texture_entry(binding, wgpu::TextureViewDimension::D2);
            e.ty = wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            };
            e
        };
        let blend_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("marched slices: blend"),
            entries: &[loaded(0), loaded(1)],
        });
        Self {
            pipeline: compute_pipeline,
            layout,
            output_layout,
            blend: pipeline(
                device,
                "marched slices: blend",
                shaders::MARCH_BLEND,
                &blend_layout,
                format,
            ),
            blend_shafts: targets_pipeline(
                device,
                "marched slices: blend with shafts of light",
                shaders::MARCH_BLEND,
                &[&blend_layout],
                "fs_shafts",
                &[format, format],
                Some(PREMULTIPLIED_OVER),
            ),
            blend_layout,
        }
    }
}
