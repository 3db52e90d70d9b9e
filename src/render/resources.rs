//! GPU resources of the volume renderer: the field and noise 3D textures (uploaded only when
//! their generation changes), samplers, and the accumulation targets.

use std::sync::Arc;

use crate::derive::Volumes;
use crate::field::DensityVolume;
use crate::field::media::NoiseMeans;
use crate::field::noise::{NOISE_SIZE, noise_volume};

/// Number of accumulation targets (a preview, a refinement, and captures for export).
pub const TARGETS: usize = 3;
/// The accumulation target captures render into (see `render::capture`).
pub const CAPTURE_TARGET: usize = 2;

/// The field as the bytes of an `R8Unorm` texture.
fn pack(field: &[f32]) -> Vec<u8> {
    field
        .iter()
        .map(|&v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect()
}

/// Creates a 3D texture holding `data` and returns its view.
pub fn upload_3d(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    dims: [u32; 3],
    format: wgpu::TextureFormat,
    data: &[u8],
) -> wgpu::TextureView {
    let size = wgpu::Extent3d {
        width: dims[0],
        height: dims[1],
        depth_or_array_layers: dims[2],
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size,
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
        size,
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

/// Replaces `slot`'s texture with `make()` unless it already holds version `key`; returns
/// whether it did.
fn refresh(
    slot: &mut Option<(u64, wgpu::TextureView)>,
    key: u64,
    make: impl FnOnce() -> wgpu::TextureView,
) -> bool {
    if slot.as_ref().is_some_and(|(k, _)| *k == key) {
        return false;
    }
    *slot = Some((key, make()));
    true
}

/// The volume's textures as uploaded.
pub struct VolumeTextures {
    /// The field (red) as uploaded, keyed by the density volume's generation, and its view.
    pub volume: Option<(u64, wgpu::TextureView)>,
    /// The density volume uploaded (its box places the slices).
    pub density_volume: Arc<DensityVolume>,
    /// Seed of the uploaded noise and its view.
    pub noise: Option<(u64, wgpu::TextureView)>,
    /// The uploaded noise's means through each filter (the light pass's blur takes them).
    pub noise_means: NoiseMeans,
}

impl VolumeTextures {
    /// Nothing uploaded yet.
    pub fn new() -> Self {
        Self {
            volume: None,
            density_volume: Arc::new(DensityVolume::default()),
            noise: None,
            noise_means: NoiseMeans::default(),
        }
    }

    /// Uploads whatever changed in `volumes`; returns whether any texture was replaced.
    pub fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, v: &Volumes) -> bool {
        let d = &v.density.data;
        let volume = refresh(&mut self.volume, v.density.generation, || {
            let r8 = wgpu::TextureFormat::R8Unorm;
            if d.is_empty() {
                upload_3d(device, queue, "volume", [1, 1, 1], r8, &[0])
            } else {
                let bytes = pack(&d.values);
                upload_3d(device, queue, "volume", d.dims.to_array(), r8, &bytes)
            }
        });
        if volume {
            self.density_volume = d.clone();
        }
        let noise = refresh(&mut self.noise, v.noise_seed, || {
            let n = NOISE_SIZE;
            let bytes = noise_volume(v.noise_seed);
            self.noise_means = NoiseMeans::of(&bytes);
            upload_3d(
                device,
                queue,
                "noise",
                [n, n, n],
                wgpu::TextureFormat::Rg8Unorm,
                &bytes,
            )
        });
        volume || noise
    }
}

impl Default for VolumeTextures {
    fn default() -> Self {
        Self::new()
    }
}

/// An accumulation target and the bind group that composites it.
pub struct Target {
    /// Size in pixels.
    pub size: [u32; 2],
    /// The render target view.
    pub view: wgpu::TextureView,
    /// Composite bind group reading it.
    pub composite: wgpu::BindGroup,
    /// The shafts of light's target beside it (made when first needed) and the composite
    /// bind group reading both.
    pub shafts: Option<(wgpu::TextureView, wgpu::BindGroup)>,
    /// Whether the image in it was drawn with shafts of light.
    pub has_shafts: bool,
    /// The marched slices' images of its size, when the renderer marches.
    pub marched: Option<MarchImages>,
}

/// The two images a draw of marched slices writes (the cloud, the shafts' light) and the bind
/// groups that write and read them.
pub struct MarchImages {
    /// The compute pass's group 1: both images as storage.
    pub output: wgpu::BindGroup,
    /// The blend's group: both images as textures.
    pub blend: wgpu::BindGroup,
}

impl MarchImages {
    /// Two images of `size` for `pass`.
    pub fn new(device: &wgpu::Device, pass: &super::passes::MarchPass, size: [u32; 2]) -> Self {
        let image = || {
            image_2d(
                device,
                "marched slices",
                size,
                super::passes::MARCH_FORMAT,
                wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
            )
        };
        let (cloud, shafts) = (image(), image());
        let group = |label, layout| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&cloud),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&shafts),
                    },
                ],
            })
        };
        Self {
            output: group("marched slices: images", &pass.output_layout),
            blend: group("marched slices: blend", &pass.blend_layout),
        }
    }
}

/// Creates an accumulation target of `size` in `format`.
pub fn accumulation_texture(
    device: &wgpu::Device,
    size: [u32; 2],
    format: wgpu::TextureFormat,
) -> wgpu::TextureView {
    render_texture(device, "volume accumulation", size, format)
}

/// Creates a 2D texture of `size` in `format` to render into and sample, and returns its view.
pub fn render_texture(
    device: &wgpu::Device,
    label: &str,
    size: [u32; 2],
    format: wgpu::TextureFormat,
) -> wgpu::TextureView {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    image_2d(device, label, size, format, usage)
}

/// Creates a 2D texture of `size` in `format` for `usage` and returns its view.
fn image_2d(
    device: &wgpu::Device,
    label: &str,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size[0],
                height: size[1],
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
        .create_view(&wgpu::TextureViewDescriptor::default())
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

/// The scale the slices apply to the light they accumulate in `format`: 1 in floats,
/// [`super::gpu_types::EIGHT_BIT_LIGHT_SCALE`] in 8 bits (the composite scales it back).
pub fn accumulation_light_scale(format: wgpu::TextureFormat) -> f32 {
    if format == wgpu::TextureFormat::Rgba16Float {
        1.0
    } else {
        super::gpu_types::EIGHT_BIT_LIGHT_SCALE
    }
}

/// Whether `device` (of `adapter`) can march the slices (`shaders/volume_march.wgsl`):
/// compute shaders, storage images of the marched slices' format, and limits that allow the
/// pass (a device asked for WebGL2's limits, as egui-wgpu asks on every GL backend, has none).
pub fn can_march(adapter: &wgpu::Adapter, device: &wgpu::Device) -> bool {
    let compute = adapter
        .get_downlevel_capabilities()
        .flags
        .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS);
    let storage = adapter
        .get_texture_format_features(super::passes::MARCH_FORMAT)
        .allowed_usages
        .contains(wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING);
    let limits = device.limits();
    let side = super::passes::MARCH_WORKGROUP;
    let fits = limits.max_storage_textures_per_shader_stage >= 2
        && limits.max_compute_workgroup_size_x >= side
        && limits.max_compute_workgroup_size_y >= side
        && limits.max_compute_invocations_per_workgroup >= side * side
        && limits.max_compute_workgroups_per_dimension > 0;
    compute && storage && fits
}

/// Whether the renderer marches the slices on `device` unless told otherwise: on GPUs that
/// can, a browser's WebGPU included (it says only whether its adapter is a fallback one, which
/// wgpu reports as a CPU). CPU adapters (lavapipe, SwiftShader) rasterise them: there the march
/// is slower (lavapipe: 1.1 s against 1.0 s a 720p frame), and the page's frame budget was
/// measured that way. WebGL2 cannot march them.
pub fn marches_by_default(adapter: &wgpu::Adapter, device: &wgpu::Device) -> bool {
    use wgpu::DeviceType::{Cpu, DiscreteGpu, IntegratedGpu, Other, VirtualGpu};
    let info = adapter.get_info();
    let gpu = match info.device_type {
        DiscreteGpu | IntegratedGpu | VirtualGpu => true,
        Other => info.backend == wgpu::Backend::BrowserWebGpu,
        Cpu => false,
    };
    gpu && can_march(adapter, device)
}

/// Records a copy of a 2D `texture` of `size` (of any uncompressed format: 4 bytes a pixel for
/// RGBA8, 8 for half floats) into a new mappable buffer; returns it and its row pitch (rows
/// padded to wgpu's copy alignment).
pub fn copy_for_readback(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    size: [u32; 2],
) -> (wgpu::Buffer, u32) {
    let [width, height] = size;
    let pixel = texture.format().block_copy_size(None).unwrap_or(4);
    let row = (width * pixel).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (row * height) as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
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
    (buffer, row)
}

/// The pixels (`pixel` bytes each) of a mapped readback buffer without the rows' padding,
/// then unmaps it.
pub fn read_rows(
    buffer: &wgpu::Buffer,
    size: [u32; 2],
    row: u32,
    pixel: u32,
) -> Result<Vec<u8>, String> {
    let [width, height] = size;
    let slice = buffer.slice(..);
    let mapped = slice
        .get_mapped_range()
        .map_err(|e| format!("the image could not be read back: {e}"))?;
    let line = (width * pixel) as usize;
    let mut rgba = Vec::with_capacity(line * height as usize);
    for y in 0..height as usize {
        let start = y * row as usize;
        rgba.extend_from_slice(&mapped[start..start + line]);
    }
    drop(mapped);
    buffer.unmap();
    Ok(rgba)
}

/// Premultiplied RGBA8 (what the composite writes) → straight alpha (what a PNG holds).
pub fn unpremultiply(rgba: &mut [u8]) {
    for p in rgba.chunks_exact_mut(4) {
        if p[3] > 0 && p[3] < 255 {
            let a = p[3] as f32 / 255.0;
            for c in &mut p[..3] {
                *c = (*c as f32 / a).round().min(255.0) as u8;
            }
        }
    }
}

/// A linear-filtering sampler with the given addressing.
pub fn sampler(device: &wgpu::Device, mode: wgpu::AddressMode) -> wgpu::Sampler {
    device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("volume sampler"),
        address_mode_u: mode,
        address_mode_v: mode,
        address_mode_w: mode,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    })
}
