//! The field evaluated on the GPU into a 3D texture: the baseline `bench` measures the CPU
//! bake against (ARCHITECTURE.md, "The field at scale", says why the app bakes on the CPU).
//! One render pass per z-slice writes the slice through the colour attachment's depth slice
//! (WebGL2 can do this too; it has no compute), each fragment summing every primitive's
//! kernel (`shaders/field_eval.wgsl`). It evaluates summed primitives (ellipsoids); sketched
//! outlines' sphere groups and cuts are the CPU's alone.

use std::num::NonZeroU64;

use super::gpu_types::FieldSliceUniforms;
use super::passes::full_pipeline;
use super::shaders;
use crate::field::{Blob, DensityVolume, Field, lattice};

/// The field's texture format: one 32-bit float per texel, as the CPU bake stores it.
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// Rows of the primitive texture (WebGL2 guarantees 2048 per side).
const ROWS: u32 = 2048;

/// Why the GPU cannot evaluate a field.
#[derive(Debug, thiserror::Error)]
pub enum FieldGpuError {
    /// The field has parts only the CPU evaluates.
    #[error("the GPU evaluates summed primitives only (this field has outlines or cuts)")]
    Unsupported,
    /// Reading back failed.
    #[error("reading the field back failed: {0}")]
    Readback(String),
}

/// The pipeline (created once) and its per-slice uniform slots.
pub struct FieldEvaluator {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    stride: u64,
}

/// A field evaluated into a 3D texture, on the grid the CPU bake uses.
pub struct GpuField {
    /// The texture (R32Float, `dims`).
    pub texture: wgpu::Texture,
    /// Texels per axis.
    pub dims: [u32; 3],
    /// The grid's minimum corner and size (world), as in [`DensityVolume`].
    pub min: glam::Vec3,
    /// World size of the grid.
    pub size: glam::Vec3,
}

impl FieldEvaluator {
    /// Creates the pipeline.
    pub fn new(device: &wgpu::Device) -> Self {
        let size = std::mem::size_of::<FieldSliceUniforms>() as u64;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("field evaluation"),
            entries: &[
                super::passes::uniform_entry(0, wgpu::ShaderStages::FRAGMENT, size, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline = full_pipeline(
            device,
            "field evaluation",
            shaders::FIELD_EVAL,
            &[&layout],
            FORMAT,
            None,
        );
        let align = device.limits().min_uniform_buffer_offset_alignment.max(16) as u64;
        Self {
            pipeline,
            layout,
            stride: size.div_ceil(align) * align,
        }
    }

    /// Evaluates `field` on the grid [`crate::field::bake`] would use at `resolution`; the
    /// work is submitted, not waited for.
    pub fn evaluate(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        field: &Field,
        resolution: u32,
    ) -> Result<Option<GpuField>, FieldGpuError> {
        if !field.groups.is_empty() || !field.clips.is_empty() {
            return Err(FieldGpuError::Unsupported);
        }
        let Some((first, dims, h)) = lattice(field, resolution) else {
            return Ok(None);
        };
        let blobs = blob_texture(device, queue, &field.blobs);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("field (GPU)"),
            size: wgpu::Extent3d {
                width: dims.x,
                height: dims.y,
                depth_or_array_layers: dims.z,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("field slices"),
            size: self.stride * dims.z as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let rows = ROWS.min(field.blobs.len().max(1) as u32);
        let mut bytes = vec![0u8; (self.stride * dims.z as u64) as usize];
        for z in 0..dims.z {
            let u = FieldSliceUniforms {
                first_center: [first.x, first.y, first.z, h],
                slice: [z, field.blobs.len() as u32, rows, 0],
            };
            let at = (z as u64 * self.stride) as usize;
            bytes[at..at + std::mem::size_of::<FieldSliceUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
        }
        queue.write_buffer(&uniforms, 0, &bytes);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("field evaluation"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &uniforms,
                        offset: 0,
                        size: NonZeroU64::new(std::mem::size_of::<FieldSliceUniforms>() as u64),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(
                        &blobs.create_view(&wgpu::TextureViewDescriptor::default()),
                    ),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("field evaluation"),
        });
        for z in 0..dims.z {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("field slice"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: Some(z),
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[(z as u64 * self.stride) as u32]);
            pass.draw(0..3, 0..1);
        }
        queue.submit([encoder.finish()]);
        Ok(Some(GpuField {
            texture,
            dims: dims.to_array(),
            min: first - glam::Vec3::splat(h * 0.5),
            size: dims.as_vec3() * h,
        }))
    }

    /// Copies a GPU field back into a [`DensityVolume`] (for tests), waiting for the device.
    pub fn read_back(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        field: &GpuField,
    ) -> Result<DensityVolume, FieldGpuError> {
        let [w, h, d] = field.dims;
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("field readback"),
            size: (row * h * d) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("field readback"),
        });
        encoder.copy_texture_to_buffer(
            field.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            field.texture.size(),
        );
        queue.submit([encoder.finish()]);
        let slice = buffer.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| FieldGpuError::Readback(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| FieldGpuError::Readback(e.to_string()))?;
        let mut values = Vec::with_capacity((w * h * d) as usize);
        for z in 0..d {
            for y in 0..h {
                let at = ((z * h + y) * row) as usize;
                values.extend(
                    data[at..at + (w * 4) as usize]
                        .chunks_exact(4)
                        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                );
            }
        }
        drop(data);
        buffer.unmap();
        Ok(DensityVolume {
            dims: glam::UVec3::from_array(field.dims),
            min: field.min,
            size: field.size,
            values,
        })
    }
}

/// The primitives as a float texture: four texels each (centre and strength, then the rows
/// of the map to the unit ball of its influence), in column blocks of [`ROWS`] rows.
fn blob_texture(device: &wgpu::Device, queue: &wgpu::Queue, blobs: &[Blob]) -> wgpu::Texture {
    let rows = ROWS.min(blobs.len().max(1) as u32);
    let blocks = (blobs.len() as u32).div_ceil(rows).max(1);
    let width = 4 * blocks;
    let mut texels = vec![[0f32; 4]; (width * rows) as usize];
    for (i, b) in blobs.iter().enumerate() {
        let (row, col) = (i as u32 % rows, (i as u32 / rows) * 4);
        let at = |c: u32| (row * width + col + c) as usize;
        texels[at(0)] = [b.center.x, b.center.y, b.center.z, b.strength];
        for r in 0..3 {
            let m = b.to_unit.row(r);
            texels[at(1 + r as u32)] = [m.x, m.y, m.z, 0.0];
        }
    }
    let size = wgpu::Extent3d {
        width,
        height: rows,
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("field primitives"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(width * 16),
            rows_per_image: Some(rows),
        },
        size,
    );
    texture
}
