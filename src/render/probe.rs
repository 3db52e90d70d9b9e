//! The media as the slices' shader computes them, at probe points (`shaders/media_probe.wgsl`):
//! for tests that hold the CPU's media (`field::media`, which the exports bake) against the
//! shader's, atmospheric tiers included. A compute pass: native adapters only, never the app's
//! frame.

use super::passes::compute_volume_layout;
use super::shaders;

/// Probes a workgroup (`media_probe.wgsl`'s `@workgroup_size`).
pub const PROBE_WORKGROUP: u32 = 64;

/// The probe pipeline and its two groups' layouts.
pub struct ProbePass {
    /// The compute pipeline (`cs_probe`).
    pub pipeline: wgpu::ComputePipeline,
    /// Group 0: the slice group's bindings, visible to compute.
    pub layout: wgpu::BindGroupLayout,
    /// Group 1: the probes (read) and their densities (written).
    pub probes_layout: wgpu::BindGroupLayout,
}

impl ProbePass {
    /// Creates the pipeline.
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = compute_volume_layout(device, "media probe: volume");
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let probes_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("media probe: points"),
            entries: &[storage(0, true), storage(1, false)],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("media probe"),
            source: wgpu::ShaderSource::Wgsl(shaders::MEDIA_PROBE.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("media probe"),
            bind_group_layouts: &[Some(&layout), Some(&probes_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("media probe"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("cs_probe"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            pipeline,
            layout,
            probes_layout,
        }
    }

    /// Records the pass over `probes` (each a world point and the field's value there) with
    /// `volume` as group 0 at uniform offset `offset`; returns the buffer the densities will be
    /// copied into for reading (one `f32` a probe). `probes` must not be empty.
    pub fn record(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        volume: &wgpu::BindGroup,
        offset: u32,
        probes: &[[f32; 4]],
    ) -> wgpu::Buffer {
        use wgpu::util::DeviceExt as _;
        let points = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("media probe: points"),
            contents: bytemuck::cast_slice(probes),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let size = (probes.len() * std::mem::size_of::<f32>()) as u64;
        let densities = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("media probe: densities"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("media probe: readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("media probe: points"),
            layout: &self.probes_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: points.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: densities.as_entire_binding(),
                },
            ],
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("media probe"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, volume, &[offset]);
            pass.set_bind_group(1, &group, &[]);
            pass.dispatch_workgroups((probes.len() as u32).div_ceil(PROBE_WORKGROUP), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&densities, 0, &readback, 0, size);
        readback
    }
}
