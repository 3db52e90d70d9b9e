//! The volume renderer: passes and resources together, used by the app's viewport (through an
//! egui paint callback) and by offscreen rendering alike.

use super::gpu_types::{
    BehindUniforms, LightSliceUniforms, Shells, SkyUniforms, View, VolumeUniforms,
};
use super::passes::{
    BackdropPass, CompositePass, FillPass, LIGHT_FORMAT, LightPass, MARCH_WORKGROUP,
    MAX_LIGHT_SLICES, MarchPass, SkyPass, SkySlot, SlicePass, light_format,
};
use super::progressive::JobPlan;
use super::resources::{
    MarchImages, TARGETS, Target, VolumeTextures, accumulation_light_scale, accumulation_texture,
    sampler, upload_3d,
};
use crate::derive::Volumes;

/// One volume draw: the planner's job (which slices, into which target) and what it shows.
#[derive(Clone, Debug, PartialEq)]
pub struct SliceJob {
    /// Slices `range` of `total` into accumulation target `target`.
    pub plan: JobPlan,
    /// Camera, light and media of the image.
    pub view: View,
    /// Whether the shafts of light's shells beyond the clouds' box are left out, drawn apart
    /// ([`VolumeRenderer::draw_outside_shafts`]) and added by
    /// [`VolumeRenderer::composite_cropped`]: the viewport's cropped image.
    pub shells_apart: bool,
}

/// Pipelines, samplers, textures and the accumulation targets.
pub struct VolumeRenderer {
    accum_format: wgpu::TextureFormat,
    /// The light volume's format (`passes::light_format`).
    light_format: wgpu::TextureFormat,
    output_format: wgpu::TextureFormat,
    slices: SlicePass,
    composite: CompositePass,
    sky: SkyPass,
    fill: FillPass,
    backdrop_pass: BackdropPass,
    /// The view behind the cloud as the viewport last drew it
    /// ([`VolumeRenderer::draw_backdrop`]).
    backdrop: Option<Backdrop>,
    /// The view behind an image's cloud (offscreen renders and captures), drawn for each.
    image_backdrop: Option<Backdrop>,
    /// The [`BehindUniforms`] of the viewport's composite and of an image's (the groups of
    /// [`Backdrop`]s bind them).
    behind_uniforms: [wgpu::Buffer; 2],
    /// The composite's group 1 where no texture lies behind the cloud: a flat background (the
    /// viewport's, its colour in its own uniforms), or none at all (transparent and linear
    /// images, whose composites do not read it).
    flat_behind: (wgpu::Buffer, wgpu::BindGroup),
    /// The same for an image over a flat background (its own uniforms: a capture and the
    /// viewport may both composite before one submission).
    flat_image: (wgpu::Buffer, wgpu::BindGroup),
    /// Whether the viewport's composite has the flat background behind it, not its backdrop
    /// ([`VolumeRenderer::prepare_behind`]).
    viewport_flat: bool,
    /// No light: the sky's shafts texture until there are shafts drawn apart.
    shafts_placeholder: wgpu::TextureView,
    clamp_sampler: wgpu::Sampler,
    repeat_sampler: wgpu::Sampler,
    textures: VolumeTextures,
    bind_group: Option<wgpu::BindGroup>,
    targets: [Option<Target>; TARGETS],
    light_pass: LightPass,
    /// The light volume: what it was computed for, its size, the texture.
    light: Option<LightVolume>,
    /// The light volume before it, kept: the viewport on a CPU adapter previews the light at
    /// less than the document's resolution while a PNG export draws it at the document's, and
    /// each would otherwise recompute it whenever the other had drawn.
    spare_light: Option<LightVolume>,
    /// Full transmittance, bound until a light volume exists.
    light_placeholder: wgpu::TextureView,
    /// Group 0 of the light pass (the slice group without the light texture).
    light_bind_group: Option<wgpu::BindGroup>,
    /// The marched slices' pass and its group 0, while the renderer marches the slices
    /// instead of rasterising them (see [`VolumeRenderer::set_marching`]).
    march: Option<(MarchPass, Option<wgpu::BindGroup>)>,
    /// The media probe's pipeline, created at its first use (tests only use it).
    probe: Option<super::probe::ProbePass>,
    /// The shafts of light outside the cloud's box on screen (the viewport's), drawn by
    /// [`VolumeRenderer::draw_outside_shafts`]: its first texture holds the light of the
    /// shells beyond the box alone ([`Shells::apart`]), its second that of every shell.
    outside: Option<Target>,
    /// Where a cropped target lies in the whole view, for its composite (xy + uv · zw).
    beyond_place: wgpu::Buffer,
    /// The composite group of a cropped target with the shafts beyond the box (see
    /// [`VolumeRenderer::prepare_cropped_composite`]).
    beyond: Option<BeyondComposite>,
}

/// A cropped target's composite group with the shafts beyond the box, and what it was made
/// for: made again only when one of these changes (not on every frame).
struct BeyondComposite {
    index: usize,
    crop: [f32; 4],
    /// The target's two textures and the outside shafts' first.
    views: [wgpu::TextureView; 3],
    group: wgpu::BindGroup,
}

/// The view behind the cloud in a texture of the viewport's size (or an image's), its group
/// for [`BackdropPass::draw`] and its group 1 for the composite.
struct Backdrop {
    size: [u32; 2],
    view: wgpu::TextureView,
    group: wgpu::BindGroup,
    behind: wgpu::BindGroup,
    /// What it was last drawn for ([`VolumeRenderer::draw_backdrop`]'s `key`).
    key: Option<u64>,
}

/// Draws a full-screen composite with `group` and `behind` (its group 1): the `transparent`
/// pipeline of the pair over a transparent image, else the `opaque` one.
fn lay(
    pass: &mut wgpu::RenderPass<'_>,
    [opaque, transparent_pipeline]: [&wgpu::RenderPipeline; 2],
    transparent: bool,
    group: &wgpu::BindGroup,
    behind: &wgpu::BindGroup,
) {
    pass.set_pipeline(if transparent {
        transparent_pipeline
    } else {
        opaque
    });
    pass.set_bind_group(0, group, &[]);
    pass.set_bind_group(1, behind, &[]);
    pass.draw(0..3, 0..1);
}

/// Begins a render pass into the one `target`, cleared to `colour` first.
fn clear_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    colour: wgpu::Color,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(colour),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// What lies behind an image's cloud ([`VolumeRenderer::prepare_image_behind`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum ImageBehind {
    /// Nothing: a transparent image.
    Nothing,
    /// The flat background, the image's clear colour.
    Flat(wgpu::Color),
    /// The image backdrop (sky, ground, shafts around the box).
    Backdrop,
}

/// Where an image cropped to `crop` (normalised device coordinates, x0, y0, x1, y1; y up) lies
/// in the whole view, as texture coordinates (y down): uv = xy + uv · zw.
fn place_of([x0, y0, x1, y1]: [f32; 4]) -> [f32; 4] {
    [
        0.5 * (x0 + 1.0),
        0.5 * (1.0 - y1),
        0.5 * (x1 - x0),
        0.5 * (y1 - y0),
    ]
}

/// The sky's `keep_out` (texture coordinates) for a target `size` pixels: none of it with
/// no shafts laid, else the box `crop` (pixels; none when out of view, and the shafts are
/// laid everywhere).
fn keep_out(shafts: bool, crop: Option<[u32; 4]>, [w, h]: [u32; 2]) -> [f32; 4] {
    match (shafts, crop) {
        (false, _) => SkyUniforms::NO_SHAFTS,
        (true, None) => [0.0; 4],
        (true, Some([x0, y0, x1, y1])) => {
            let (w, h) = (w.max(1) as f32, h.max(1) as f32);
            [x0 as f32 / w, y0 as f32 / h, x1 as f32 / w, y1 as f32 / h]
        }
    }
}

/// The light volume on the GPU. Each z-slice is rendered into `slice` (2D) and copied into
/// the 3D texture: wgpu's WebGPU backend drops a 3D attachment's depth slice, so rendering
/// into the 3D texture directly fails in browsers.
struct LightVolume {
    key: u64,
    dims: [u32; 3],
    texture: wgpu::Texture,
    /// A view of the 3D texture, sampled by the slices.
    view: wgpu::TextureView,
    /// One z-slice's render target.
    slice: wgpu::Texture,
    slice_view: wgpu::TextureView,
}

/// March steps of the light volume, at most.
const MAX_LIGHT_STEPS: u32 = 48;

/// The light grid for a density grid of `dims`: `resolution` texels along its longest side,
/// the others in proportion (at least 2, at most [`MAX_LIGHT_SLICES`]).
fn light_dims(dims: glam::UVec3, resolution: u32) -> [u32; 3] {
    let longest = dims.max_element().max(1) as f32;
    let res = resolution.clamp(2, MAX_LIGHT_SLICES) as f32;
    dims.to_array()
        .map(|d| ((d as f32 * res / longest).round() as u32).clamp(2, MAX_LIGHT_SLICES))
}

impl VolumeRenderer {
    /// Creates pipelines for compositing into `output_format`, accumulating in `accum_format`.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        output_format: wgpu::TextureFormat,
        accum_format: wgpu::TextureFormat,
    ) -> Self {
        let light_format = light_format(accum_format);
        // Full light from the sun and the sky, and no diffusion (its ratio 1, stored halved).
        let texel = [1.0f32, 1.0, 0.5, 1.0];
        let bytes: Vec<u8> = if light_format == LIGHT_FORMAT {
            texel
                .iter()
                .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
                .collect()
        } else {
            texel.iter().map(|&v| (v * 255.0).round() as u8).collect()
        };
        let placeholder = upload_3d(
            device,
            queue,
            "light placeholder",
            [1, 1, 1],
            light_format,
            &bytes,
        );
        let clamp_sampler = sampler(device, wgpu::AddressMode::ClampToEdge);
        let composite = CompositePass::new(device, output_format);
        let backdrop_pass = BackdropPass::new(device, output_format, &composite.layout);
        let shafts_placeholder = super::resources::render_texture(
            device,
            "no shafts, nothing behind",
            [1, 1],
            output_format,
        );
        let behind_buffer = || {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("what lies behind the cloud"),
                size: std::mem::size_of::<BehindUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let flat_buffer = behind_buffer();
        let flat_group = composite.behind_group(device, &shafts_placeholder, &flat_buffer);
        let flat_image_buffer = behind_buffer();
        let flat_image_group =
            composite.behind_group(device, &shafts_placeholder, &flat_image_buffer);
        // What a transparent image's composite reads (nothing behind): the accumulation's
        // light scale, which 8 bits need undone.
        let nothing =
            BehindUniforms::default().accumulated_at(accumulation_light_scale(accum_format));
        for buffer in [&flat_buffer, &flat_image_buffer] {
            queue.write_buffer(buffer, 0, bytemuck::bytes_of(&nothing));
        }
        Self {
            accum_format,
            output_format,
            slices: SlicePass::new(device, accum_format),
            sky: SkyPass::new(
                device,
                output_format,
                &placeholder,
                &shafts_placeholder,
                &clamp_sampler,
            ),
            composite,
            fill: FillPass::new(device, output_format),
            backdrop_pass,
            backdrop: None,
            image_backdrop: None,
            behind_uniforms: [behind_buffer(), behind_buffer()],
            flat_behind: (flat_buffer, flat_group),
            flat_image: (flat_image_buffer, flat_image_group),
            viewport_flat: true,
            shafts_placeholder,
            clamp_sampler,
            repeat_sampler: sampler(device, wgpu::AddressMode::Repeat),
            textures: VolumeTextures::new(),
            bind_group: None,
            targets: Default::default(),
            outside: None,
            beyond_place: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("where a cropped image lies in the view"),
                size: 16,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            beyond: None,
            light_pass: LightPass::new(device, light_format),
            light_format,
            light: None,
            spare_light: None,
            light_placeholder: placeholder,
            light_bind_group: None,
            march: None,
            probe: None,
        }
    }

    /// Marches the slices in a compute pass (`shaders/volume_march.wgsl`) instead of
    /// rasterising them, or goes back to rasterising: the same image either way. Only for
    /// devices that [`super::resources::can_march`].
    pub fn set_marching(&mut self, device: &wgpu::Device, on: bool) {
        if on == self.march.is_some() {
            return;
        }
        self.march = on.then(|| (MarchPass::new(device, self.accum_format), None));
        for target in self.targets.iter_mut().flatten() {
            target.marched = None;
        }
        self.rebuild_bind_groups(device);
    }

    /// Whether the slices are marched (see [`VolumeRenderer::set_marching`]).
    pub fn marching(&self) -> bool {
        self.march.is_some()
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
        self.rebuild_bind_groups(device);
    }

    /// The slice group (and the light pass's, which lacks the light texture) over the current
    /// textures.
    fn rebuild_bind_groups(&mut self, device: &wgpu::Device) {
        self.rebind_sky(device);
        let Some(entries) = self.volume_entries() else {
            return;
        };
        let group = |label, layout| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &entries,
            })
        };
        let slices = group("volume", &self.slices.layout);
        let march = self
            .march
            .as_ref()
            .map(|(pass, _)| group("marched slices: volume", &pass.layout));
        let light = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("light volume: volume"),
            layout: &self.light_pass.volume_layout,
            entries: &entries[..5],
        });
        self.bind_group = Some(slices);
        self.light_bind_group = Some(light);
        if let Some((_, group)) = &mut self.march {
            *group = march;
        }
    }

    /// Binds the sky to the current light volume and the shafts drawn apart.
    fn rebind_sky(&mut self, device: &wgpu::Device) {
        let light = self
            .light
            .as_ref()
            .map_or(&self.light_placeholder, |l| &l.view);
        let shafts = match &self.outside {
            Some(Target {
                shafts: Some((view, _)),
                ..
            }) => view,
            _ => &self.shafts_placeholder,
        };
        self.sky.bind(device, light, shafts, &self.clamp_sampler);
    }

    /// The slice group's entries over the current textures (none before both are uploaded).
    fn volume_entries(&self) -> Option<[wgpu::BindGroupEntry<'_>; 6]> {
        let t = &self.textures;
        let light = self
            .light
            .as_ref()
            .map_or(&self.light_placeholder, |l| &l.view);
        let (Some((_, volume)), Some((_, noise))) = (&t.volume, &t.noise) else {
            return None;
        };
        Some([
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
            wgpu::BindGroupEntry {
                binding: 5,
                resource: wgpu::BindingResource::TextureView(light),
            },
        ])
    }

    /// Records the media probe ([`super::probe`]) of `view`'s media over the uploaded volume
    /// at `probes` (world point, field value); returns the buffer to map for the densities, or
    /// `None` with nothing uploaded or no probes.
    pub fn probe_media(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        view: &View,
        probes: &[[f32; 4]],
    ) -> Option<wgpu::Buffer> {
        if probes.is_empty() {
            return None;
        }
        let volume = self.textures.density_volume.clone();
        let offset = self
            .slices
            .write(queue, &VolumeUniforms::new(view, &volume, 1, 0..1, None));
        if self.probe.is_none() {
            self.probe = Some(super::probe::ProbePass::new(device));
        }
        let pass = self.probe.as_ref()?;
        let entries = self.volume_entries()?;
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("media probe: volume"),
            layout: &pass.layout,
            entries: &entries,
        });
        Some(pass.record(device, encoder, &group, offset, probes))
    }

    /// Makes the next [`VolumeRenderer::update_light`] recompute the light volume (benchmarks).
    pub fn invalidate_light(&mut self) {
        for light in [&mut self.light, &mut self.spare_light]
            .into_iter()
            .flatten()
        {
            light.key = 0;
        }
    }

    /// Recomputes the light volume (transmittance toward the sun through the field and its
    /// noise) when anything it depends on changed: the field, the sun, the media, the scene
    /// time when the noise moves, the light's resolution or octaves. Call after
    /// [`VolumeRenderer::upload`], before the frame's slices. Returns whether it ran.
    pub fn update_light(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        view: &View,
    ) -> bool {
        let volume = self.textures.density_volume.clone();
        let Some((generation, _)) = &self.textures.volume else {
            return false;
        };
        if volume.is_empty() {
            return false;
        }
        let r = &view.render;
        let dims = light_dims(volume.dims, r.light_resolution);
        // Steps of a light texel across the box, at most [`MAX_LIGHT_STEPS`] (longer steps on a
        // fine grid): the pass must stay cheap on CPU adapters, where it holds up a frame.
        let diagonal = volume.size.length();
        let h = (volume.size / glam::UVec3::from_array(dims).as_vec3())
            .min_element()
            .max(diagonal / MAX_LIGHT_STEPS as f32);
        let steps = ((diagonal / h.max(1e-6)).ceil() as u32).clamp(1, MAX_LIGHT_STEPS);
        let mut uniforms = VolumeUniforms::new(view, &volume, 1, 0..1, None);
        uniforms.tier_filters[2] = self.textures.noise_means.get(r.noise_basis, r.noise_filter);
        let key = {
            use std::hash::{Hash, Hasher};
            let mut hasher = std::hash::DefaultHasher::new();
            let seed = self.textures.noise.as_ref().map(|n| n.0);
            (generation, seed, dims, steps, r.light_octaves).hash(&mut hasher);
            let octaves = (r.light_octaves as usize).min(uniforms.octaves.len());
            let parts: [&[u8]; 7] = [
                bytemuck::bytes_of(&uniforms.sun_dir),
                bytemuck::bytes_of(&uniforms.media),
                bytemuck::bytes_of(&uniforms.noise),
                bytemuck::cast_slice(&uniforms.octaves[..octaves]),
                bytemuck::bytes_of(&uniforms.tiers),
                bytemuck::bytes_of(&uniforms.tier_filters),
                bytemuck::cast_slice(&uniforms.tier_octaves),
            ];
            parts.hash(&mut hasher);
            hasher.finish()
        };
        if self.light.as_ref().is_some_and(|l| l.key == key) {
            return false;
        }
        if self.spare_light.as_ref().is_some_and(|l| l.key == key) {
            std::mem::swap(&mut self.light, &mut self.spare_light);
            self.rebuild_bind_groups(device);
            return false;
        }
        // Computed into the spare volume's textures where they fit (the current one is kept
        // as the spare), else into new ones.
        let previous = self.light.take();
        self.light = self.spare_light.take().filter(|l| l.dims == dims);
        self.spare_light = previous;
        if self.light.is_none() {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("light volume"),
                size: wgpu::Extent3d {
                    width: dims[0],
                    height: dims[1],
                    depth_or_array_layers: dims[2],
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D3,
                format: self.light_format,
                usage: wgpu::TextureUsages::COPY_DST
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let slice = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("light volume slice"),
                size: wgpu::Extent3d {
                    width: dims[0],
                    height: dims[1],
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.light_format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let slice_view = slice.create_view(&wgpu::TextureViewDescriptor::default());
            self.light = Some(LightVolume {
                key,
                dims,
                texture,
                view,
                slice,
                slice_view,
            });
        }
        // The current volume's textures changed either way.
        self.rebuild_bind_groups(device);
        let (Some(light), Some(group)) = (&mut self.light, &self.light_bind_group) else {
            return false;
        };
        light.key = key;
        let offset = self.slices.write(queue, &uniforms);
        let slices: Vec<LightSliceUniforms> = (0..dims[2])
            .map(|z| LightSliceUniforms {
                slice: [z, steps, r.light_octaves, 0],
                dims: [dims[0] as f32, dims[1] as f32, dims[2] as f32, h],
            })
            .collect();
        let offsets = self.light_pass.write(queue, &slices);
        for (z, slice_offset) in offsets.into_iter().enumerate() {
            let mut pass = clear_pass(
                encoder,
                "light volume slice",
                &light.slice_view,
                wgpu::Color::WHITE,
            );
            pass.set_pipeline(&self.light_pass.pipeline);
            pass.set_bind_group(0, group, &[offset]);
            pass.set_bind_group(1, &self.light_pass.slice_group, &[slice_offset]);
            pass.draw(0..3, 0..1);
            drop(pass);
            encoder.copy_texture_to_texture(
                light.slice.as_image_copy(),
                wgpu::TexelCopyTextureInfo {
                    texture: &light.texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: z as u32,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d {
                    width: dims[0],
                    height: dims[1],
                    depth_or_array_layers: 1,
                },
            );
        }
        true
    }

    /// Makes accumulation target `index` `size` pixels, with a shafts target beside it when
    /// `shafts`.
    fn ensure_target(&mut self, device: &wgpu::Device, index: usize, size: [u32; 2], shafts: bool) {
        let size = [size[0].max(1), size[1].max(1)];
        if self.targets[index].as_ref().is_none_or(|t| t.size != size) {
            let view = accumulation_texture(device, size, self.accum_format);
            let composite = self
                .composite
                .bind_group(device, &view, None, &self.clamp_sampler);
            self.targets[index] = Some(Target {
                size,
                view,
                composite,
                shafts: None,
                has_shafts: false,
                marched: None,
            });
        }
        if let (Some(target), Some((pass, _))) = (&mut self.targets[index], &self.march)
            && target.marched.is_none()
        {
            target.marched = Some(MarchImages::new(device, pass, size));
        }
        if let Some(target) = &mut self.targets[index]
            && shafts
            && target.shafts.is_none()
        {
            let view = accumulation_texture(device, size, self.accum_format);
            let group =
                self.composite
                    .bind_group(device, &target.view, Some(&view), &self.clamp_sampler);
            target.shafts = Some((view, group));
        }
    }

    /// The shafts of light where no cloud can lie in front of them: every shell of `view`'s
    /// image of `total` slices (as [`Shells::new`] counts them), with no slice among them, into
    /// a target of its own `size` pixels (the light is soft: a fraction of the view's size
    /// does). The viewport draws the cloud's box with its slices and shells interleaved, and
    /// the sky adds this over the rest of the view (`SkyUniforms::keep_out`; over a
    /// transparent image [`VolumeRenderer::composite_outside_shafts`] lays it), so
    /// shafts no longer make every slice cover the whole view. Returns whether there are
    /// shafts to lay.
    pub fn draw_outside_shafts(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        view: &View,
        total: u32,
        size: [u32; 2],
    ) -> bool {
        let volume = self.textures.density_volume.clone();
        let Some(shells) =
            Shells::new(view, &volume, total).map(|s| s.apart_beyond_the_box(view, &volume))
        else {
            self.outside = None;
            return false;
        };
        let size = [size[0].max(1), size[1].max(1)];
        if self.outside.as_ref().is_none_or(|t| t.size != size) {
            let cloud = accumulation_texture(device, size, self.accum_format);
            let light = accumulation_texture(device, size, self.accum_format);
            let composite = self
                .composite
                .bind_group(device, &cloud, None, &self.clamp_sampler);
            let group =
                self.composite
                    .bind_group(device, &cloud, Some(&light), &self.clamp_sampler);
            self.outside = Some(Target {
                size,
                view: cloud,
                composite,
                shafts: Some((light, group)),
                has_shafts: true,
                marched: None,
            });
            // The sky adds their light around the box.
            self.rebind_sky(device);
        }
        let (Some(target), Some(bind_group)) = (&self.outside, &self.bind_group) else {
            return false;
        };
        // No slice and one instance, a shell's triangle over the whole view, in which
        // fs_outside_shafts sums every shell's light.
        let mut uniforms = VolumeUniforms::new(view, &volume, total, 0..total, Some(&shells));
        uniforms.haze_light[3] = accumulation_light_scale(self.accum_format);
        uniforms.shells[0] = 0.0;
        uniforms.shells[1] = 1.0;
        uniforms.shells[2] = 0.0;
        let offset = self.slices.write(queue, &uniforms);
        let clear = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let Some((light, _)) = &target.shafts else {
            return false;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shafts outside the cloud"),
            color_attachments: &[clear(&target.view), clear(light)],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.slices.outside_pipeline);
        pass.set_bind_group(0, bind_group, &[offset]);
        pass.draw(0..6, 0..1);
        true
    }

    /// Lays the shafts of light [`VolumeRenderer::draw_outside_shafts`] drew over the current
    /// render pass's viewport of a transparent image, with alpha of their own (the whole view;
    /// its scissor keeps them off the cloud's box). Over a background the sky adds them.
    pub fn composite_outside_shafts(&self, pass: &mut wgpu::RenderPass<'_>) {
        if let Some(Target {
            shafts: Some((_, group)),
            ..
        }) = &self.outside
        {
            let c = &self.composite;
            lay(
                pass,
                [&c.shafts_pipeline, &c.shafts_transparent_pipeline],
                true,
                group,
                &self.flat_behind.1,
            );
        }
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
        let volume = self.textures.density_volume.clone();
        // The bench's baseline draws the plain slices alone.
        let shells = Shells::new(&job.view, &volume, plan.total)
            .filter(|_| pipeline.is_none())
            .map(|s| {
                if job.shells_apart {
                    s.apart_beyond_the_box(&job.view, &volume)
                } else {
                    s
                }
            });
        self.ensure_target(device, index, plan.size, shells.is_some());
        let (Some(target), Some(bind_group)) = (&mut self.targets[index], &self.bind_group) else {
            return;
        };
        // An image is drawn with shafts or without from its first chunk to its last.
        if plan.clear {
            target.has_shafts = shells.is_some();
        }
        let with_shafts = target.has_shafts && shells.is_some();
        let mut uniforms = VolumeUniforms::new(
            &job.view,
            &volume,
            plan.total,
            plan.range.clone(),
            shells.as_ref().filter(|_| with_shafts),
        );
        uniforms.haze_light[3] = accumulation_light_scale(self.accum_format);
        let offset = self.slices.write(queue, &uniforms);
        let load = if plan.clear {
            wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
        } else {
            wgpu::LoadOp::Load
        };
        let attachment = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let attachments = match (&target.shafts, with_shafts) {
            (Some((shafts, _)), true) => vec![attachment(&target.view), attachment(shafts)],
            _ => vec![attachment(&target.view)],
        };
        let count = plan.range.end.saturating_sub(plan.range.start);
        let empty = volume.is_empty() || count == 0;
        // Marched (not the bench's baseline): a compute pass writes the draw's images, then
        // the render pass lays them over the targets.
        let marched = match (pipeline, &self.march, &target.marched) {
            (None, Some((march, Some(group))), Some(images)) => Some((march, group, images)),
            _ => None,
        };
        if let Some((march, group, images)) = marched
            && !empty
        {
            let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("marched slices"),
                timestamp_writes: None,
            });
            compute.set_pipeline(&march.pipeline);
            compute.set_bind_group(0, group, &[offset]);
            compute.set_bind_group(1, &images.output, &[]);
            let [x, y] = plan.size.map(|side| side.div_ceil(MARCH_WORKGROUP));
            compute.dispatch_workgroups(x, y, 1);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("volume slices"),
            color_attachments: &attachments,
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if empty {
            return;
        }
        if let Some((march, _, images)) = marched {
            let blend = if with_shafts {
                &march.blend_shafts
            } else {
                &march.blend
            };
            pass.set_pipeline(blend);
            pass.set_bind_group(0, &images.blend, &[]);
            pass.draw(0..3, 0..1);
            return;
        }
        let (pipeline, shells) = match pipeline {
            Some(p) => (p, 0),
            None if with_shafts => (&self.slices.shafts_pipeline, uniforms.shells[1] as u32),
            None => (&self.slices.pipeline, 0),
        };
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[offset]);
        // Instances start at 0 (WebGL2 has no base instance); the first slice is a uniform.
        // The shafts' shells of this draw come among its slices (volume.wgsl's vs_main).
        pass.draw(0..6, 0..count + shells);
    }

    /// The format the composite and sky passes write.
    pub fn output_format(&self) -> wgpu::TextureFormat {
        self.output_format
    }

    /// Records a whole image of `job` into a new texture in the output format (copyable):
    /// the light volume when due, the slices, then the composite over `background` (with the
    /// view's sky gradient) or, without one, over transparency. `pipeline` replaces the slice
    /// pipeline (the bench's baseline). Offscreen renders and the app's captures both use it.
    pub fn render_image(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        job: &SliceJob,
        background: Option<[f32; 3]>,
        pipeline: Option<&wgpu::RenderPipeline>,
    ) -> wgpu::Texture {
        let output = self.output_texture(device, job.plan.size);
        let view = output.create_view(&wgpu::TextureViewDescriptor::default());
        self.update_light(device, queue, encoder, &job.view);
        self.draw_slices(device, queue, encoder, job, pipeline);
        // The shafts are among the slices over the whole image: none laid apart.
        let behind = self.prepare_image_behind(
            device,
            queue,
            encoder,
            &job.view,
            job.plan.size,
            background,
            [0.0, 0.0, 1.0, 1.0],
            None,
        );
        let mut pass = self.image_pass(encoder, &view, behind, "image composite");
        self.composite(
            &mut pass,
            job.plan.target,
            background.is_none(),
            self.image_behind(behind),
        );
        drop(pass);
        self.release_large_backdrop();
        output
    }

    /// The density's box (its lowest and highest corners), while there is one.
    pub fn density_box(&self) -> Option<(glam::Vec3, glam::Vec3)> {
        let volume = &self.textures.density_volume;
        (!volume.is_empty()).then(|| (volume.min, volume.min + volume.size))
    }

    /// Records `job`'s image (the whole view, full quality) as the viewport draws it: the
    /// slices, with the shafts of light's shells among them, over `crop` alone (the cloud's box
    /// on screen), the shafts elsewhere drawn apart at 1/`divisor` of the size and laid around
    /// it ([`VolumeRenderer::draw_outside_shafts`]), over `background` and its sky as
    /// [`VolumeRenderer::render_image`] lays them. The same image within the shafts' grain:
    /// `tests/render.rs` compares the two.
    pub fn render_image_cropped(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        job: &SliceJob,
        background: Option<[f32; 3]>,
        crop: &super::crop::PixelCrop,
        divisor: u32,
    ) -> wgpu::Texture {
        self.update_light(device, queue, encoder, &job.view);
        self.draw_slices(device, queue, encoder, &Self::cropped_job(job, crop), None);
        self.composite_image_cropped(device, queue, encoder, job, background, crop, divisor)
    }

    /// `job` (of the whole view) drawn over `crop` alone, with the shafts of light's shells
    /// among its slices: what [`VolumeRenderer::composite_image_cropped`] lays in the view.
    pub fn cropped_job(job: &SliceJob, crop: &super::crop::PixelCrop) -> SliceJob {
        SliceJob {
            plan: super::progressive::JobPlan {
                size: crop.size(),
                ..job.plan.clone()
            },
            view: View {
                crop: crop.ndc(job.plan.size),
                ..job.view.clone()
            },
            shells_apart: true,
        }
    }

    /// The image of `job`'s whole view from its target, drawn over `crop` by
    /// [`VolumeRenderer::cropped_job`]s: the shafts beyond the box drawn at 1/`divisor` of
    /// the size and laid around it, over `background` and its sky.
    #[allow(clippy::too_many_arguments)]
    pub fn composite_image_cropped(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        job: &SliceJob,
        background: Option<[f32; 3]>,
        crop: &super::crop::PixelCrop,
        divisor: u32,
    ) -> wgpu::Texture {
        let [width, height] = job.plan.size;
        let output = self.output_texture(device, job.plan.size);
        let view = output.create_view(&wgpu::TextureViewDescriptor::default());
        let outside = self.draw_outside_shafts(
            device,
            queue,
            encoder,
            &job.view,
            job.plan.total,
            job.plan.size.map(|v| v.div_ceil(divisor.max(1))),
        );
        // The shafts beyond the box are the viewport's too: it draws its own again.
        if let Some(backdrop) = &mut self.backdrop {
            backdrop.key = None;
        }
        let ndc = crop.ndc(job.plan.size);
        self.prepare_cropped_composite(device, queue, job.plan.target, ndc);
        // The sky with the shafts around the box in it, mapped once with them.
        let behind = self.prepare_image_behind(
            device,
            queue,
            encoder,
            &job.view,
            job.plan.size,
            background,
            place_of(ndc),
            outside.then(|| keep_out(true, Some(crop.px), job.plan.size)),
        );
        let mut pass = self.image_pass(encoder, &view, behind, "cropped image composite");
        let [x0, y0, x1, y1] = crop.px;
        if outside && background.is_none() {
            // Over transparency, the shafts' glow in the strips around the crop: above, below,
            // left, right.
            for [x, y, w, h] in [
                [0, 0, width, y0],
                [0, y1, width, height - y1],
                [0, y0, x0, y1 - y0],
                [x1, y0, width - x1, y1 - y0],
            ] {
                if w > 0 && h > 0 {
                    pass.set_scissor_rect(x, y, w, h);
                    self.composite_outside_shafts(&mut pass);
                }
            }
            pass.set_scissor_rect(0, 0, width, height);
        }
        pass.set_viewport(
            x0 as f32,
            y0 as f32,
            (x1 - x0) as f32,
            (y1 - y0) as f32,
            0.0,
            1.0,
        );
        self.composite_cropped(
            &mut pass,
            job.plan.target,
            background.is_none(),
            self.image_behind(behind),
        );
        drop(pass);
        self.release_large_backdrop();
        output
    }

    /// Readies what lies behind an image's cloud: nothing (no `background`: transparent), the
    /// flat background as the output's clear colour (no physical sky or gradient, no ground, no shafts
    /// laid apart: `shafts_keep_out` none), or the image backdrop, its sky drawn with the
    /// shafts outside `shafts_keep_out`. `place` is where the composited image lies in it.
    #[allow(clippy::too_many_arguments)]
    fn prepare_image_behind(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        view: &View,
        size: [u32; 2],
        background: Option<[f32; 3]>,
        place: [f32; 4],
        shafts_keep_out: Option<[f32; 4]>,
    ) -> ImageBehind {
        let Some(background) = background else {
            return ImageBehind::Nothing;
        };
        let light = &view.light;
        if !light.physical_sky && !light.sky_gradient && !light.ground && shafts_keep_out.is_none()
        {
            let shown = super::tone::background_display(background, light.exposure);
            let [r, g, b] = if super::passes::linear_output(self.output_format) {
                // A float target holds the light itself.
                (super::tone::light_of(background) * light.exposure.exp2()).to_array()
            } else {
                shown
            };
            queue.write_buffer(
                &self.flat_image.0,
                0,
                bytemuck::bytes_of(
                    &BehindUniforms::flat(place, shown)
                        .accumulated_at(accumulation_light_scale(self.accum_format)),
                ),
            );
            return ImageBehind::Flat(wgpu::Color {
                r: r.into(),
                g: g.into(),
                b: b.into(),
                a: 1.0,
            });
        }
        let mut slot = self.image_backdrop.take();
        self.draw_behind(
            device,
            queue,
            encoder,
            &mut slot,
            SkySlot::Image,
            view,
            size,
            background,
            shafts_keep_out.unwrap_or(SkyUniforms::NO_SHAFTS),
        );
        self.image_backdrop = slot;
        queue.write_buffer(
            &self.behind_uniforms[SkySlot::Image as usize],
            0,
            bytemuck::bytes_of(
                &BehindUniforms::backdrop(place)
                    .accumulated_at(accumulation_light_scale(self.accum_format)),
            ),
        );
        ImageBehind::Backdrop
    }

    /// Drops the image backdrop when it is large (an export's 8K image holds half a
    /// gigabyte of it); a smaller one is kept for the next image (a recording's frames).
    fn release_large_backdrop(&mut self) {
        if self
            .image_backdrop
            .as_ref()
            .is_some_and(|b| u64::from(b.size[0]) * u64::from(b.size[1]) > 1 << 22)
        {
            self.image_backdrop = None;
        }
    }

    /// The composite's group 1 for an image with `behind` it.
    fn image_behind(&self, behind: ImageBehind) -> &wgpu::BindGroup {
        match (behind, &self.image_backdrop) {
            (ImageBehind::Backdrop, Some(b)) => &b.behind,
            (ImageBehind::Flat(_), _) => &self.flat_image.1,
            _ => &self.flat_behind.1,
        }
    }

    /// Begins the render pass that lays an image over `target`: cleared to the flat
    /// background, or to transparency with the image's backdrop laid over it, or not.
    fn image_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        behind: ImageBehind,
        label: &str,
    ) -> wgpu::RenderPass<'e> {
        let clear = match behind {
            ImageBehind::Flat(colour) => colour,
            _ => wgpu::Color::TRANSPARENT,
        };
        let mut pass = clear_pass(encoder, label, target, clear);
        if let (ImageBehind::Backdrop, Some(b)) = (behind, &self.image_backdrop) {
            self.backdrop_pass.draw(&mut pass, &b.group);
        }
        pass
    }

    /// Draws the sky of `view` over `background` (sRGB-encoded, as picked) and the shafts drawn
    /// apart outside `keep_out` into `backdrop` (made `size` pixels), with the sky's `slot`.
    #[allow(clippy::too_many_arguments)]
    fn draw_behind(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        backdrop: &mut Option<Backdrop>,
        slot: SkySlot,
        view: &View,
        size: [u32; 2],
        background: [f32; 3],
        keep_out: [f32; 4],
    ) {
        let size = [size[0].max(1), size[1].max(1)];
        if backdrop.as_ref().is_none_or(|b| b.size != size) {
            let texture = super::resources::render_texture(
                device,
                "view behind the cloud",
                size,
                self.output_format,
            );
            let group = self
                .composite
                .bind_group(device, &texture, None, &self.clamp_sampler);
            let behind =
                self.composite
                    .behind_group(device, &texture, &self.behind_uniforms[slot as usize]);
            *backdrop = Some(Backdrop {
                size,
                view: texture,
                group,
                behind,
                key: None,
            });
        }
        let Some(backdrop) = backdrop else {
            return;
        };
        let mut light = view.light.clone();
        light.background = background;
        let mut uniforms = self.sky_uniforms(&View {
            light,
            ..view.clone()
        });
        uniforms.keep_out = keep_out;
        self.sky.write(queue, slot, &uniforms, &view.light);
        let mut pass = clear_pass(
            encoder,
            "view behind the cloud",
            &backdrop.view,
            wgpu::Color::BLACK,
        );
        self.sky.draw(&mut pass, slot);
    }

    /// A new output-format texture `size` pixels, to render into and copy from.
    fn output_texture(&self, device: &wgpu::Device, [width, height]: [u32; 2]) -> wgpu::Texture {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("image"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.output_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }

    /// The sky of `view`: its ground shaded through the light volume, which spans the
    /// density's box; no shafts.
    fn sky_uniforms(&self, view: &View) -> SkyUniforms {
        let volume = &self.textures.density_volume;
        let grid =
            (self.light.is_some() && !volume.is_empty()).then_some((volume.min, volume.size));
        SkyUniforms::new(&view.camera, &view.light, view.aspect, grid)
    }

    /// Draws the view behind the cloud into a texture `size` pixels (the viewport's), which
    /// [`VolumeRenderer::lay_backdrop`] then lays on every frame until it changes: `background`
    /// (sRGB-encoded, as picked) with `view`'s physical sky, sky gradient or ground, and the shafts of light
    /// [`VolumeRenderer::draw_outside_shafts`] drew (call it first) when `shafts`, added
    /// outside `crop` (the cloud's box in its pixels; none when out of view), all mapped by the
    /// one tone map; `key` is what it is drawn for ([`VolumeRenderer::backdrop_key`]). On CPU
    /// adapters the ground's shading and the shafts' lay took over half of each refining frame.
    #[allow(clippy::too_many_arguments)]
    pub fn draw_backdrop(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        view: &View,
        size: [u32; 2],
        background: [f32; 3],
        shafts: bool,
        crop: Option<[u32; 4]>,
        key: u64,
    ) {
        let size = [size[0].max(1), size[1].max(1)];
        let mut slot = self.backdrop.take();
        self.draw_behind(
            device,
            queue,
            encoder,
            &mut slot,
            SkySlot::Viewport,
            view,
            size,
            background,
            keep_out(shafts, crop, size),
        );
        self.backdrop = slot;
        if let Some(backdrop) = &mut self.backdrop {
            backdrop.key = Some(key);
        }
    }

    /// What the view behind the cloud was last drawn for ([`VolumeRenderer::draw_backdrop`]'s
    /// `key`; none before it is drawn).
    pub fn backdrop_key(&self) -> Option<u64> {
        self.backdrop.as_ref().and_then(|b| b.key)
    }

    /// Lays the view behind the cloud [`VolumeRenderer::draw_backdrop`] drew over the current
    /// render pass's viewport (nothing before it is drawn).
    pub fn lay_backdrop(&self, pass: &mut wgpu::RenderPass<'_>) {
        if let Some(b) = &self.backdrop {
            self.backdrop_pass.draw(pass, &b.group);
        }
    }

    /// Fills the current render pass's viewport with `colour` (the values the target stores).
    pub fn draw_fill(&self, pass: &mut wgpu::RenderPass<'_>, colour: wgpu::Color) {
        self.fill.draw(pass, colour);
    }

    /// Says what lies behind the viewport's cloud, cropped to `crop` (normalised device
    /// coordinates, x0, y0, x1, y1; y up): the flat background of display colour `flat`
    /// (the frame's clear colour, `tone::background_display`), or without one the backdrop
    /// [`VolumeRenderer::draw_backdrop`] drew. Call before [`VolumeRenderer::composite_cropped`]
    /// with [`VolumeRenderer::viewport_behind`].
    pub fn prepare_behind(&mut self, queue: &wgpu::Queue, crop: [f32; 4], flat: Option<[f32; 3]>) {
        self.viewport_flat = flat.is_some() || self.backdrop.is_none();
        let scale = accumulation_light_scale(self.accum_format);
        let (buffer, uniforms) = match flat {
            Some(shown) => (
                &self.flat_behind.0,
                BehindUniforms::flat(place_of(crop), shown).accumulated_at(scale),
            ),
            None => (
                &self.behind_uniforms[SkySlot::Viewport as usize],
                BehindUniforms::backdrop(place_of(crop)).accumulated_at(scale),
            ),
        };
        queue.write_buffer(buffer, 0, bytemuck::bytes_of(&uniforms));
    }

    /// The viewport composite's group 1, as [`VolumeRenderer::prepare_behind`] chose it.
    pub fn viewport_behind(&self) -> &wgpu::BindGroup {
        match &self.backdrop {
            Some(b) if !self.viewport_flat => &b.behind,
            _ => &self.flat_behind.1,
        }
    }

    /// Readies the composite of target `index`, drawn of a view cropped to `crop` (normalised
    /// device coordinates, x0, y0, x1, y1; y up), with the light of the shafts' shells beyond
    /// the clouds' box, which [`VolumeRenderer::draw_outside_shafts`] drew apart (call after
    /// it, before [`VolumeRenderer::composite_cropped`]).
    pub fn prepare_cropped_composite(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        index: usize,
        crop: [f32; 4],
    ) {
        let Some(Target { view: beyond, .. }) = &self.outside else {
            self.beyond = None;
            return;
        };
        let Some(Target {
            view: source,
            shafts: Some((shafts, _)),
            has_shafts: true,
            ..
        }) = self.targets.get(index).and_then(|t| t.as_ref())
        else {
            self.beyond = None;
            return;
        };
        let views = [source.clone(), shafts.clone(), beyond.clone()];
        if self
            .beyond
            .as_ref()
            .is_some_and(|b| b.index == index && b.crop == crop && b.views == views)
        {
            return;
        }
        queue.write_buffer(&self.beyond_place, 0, bytemuck::cast_slice(&place_of(crop)));
        let group = self.composite.beyond_bind_group(
            device,
            [source, shafts, beyond],
            &self.clamp_sampler,
            &self.beyond_place,
        );
        self.beyond = Some(BeyondComposite {
            index,
            crop,
            views,
            group,
        });
    }

    /// Draws accumulation target `index` of a cropped view as
    /// [`VolumeRenderer::composite`] does, with the light of the shafts' shells beyond the
    /// clouds' box seen through the cloud, where
    /// [`VolumeRenderer::prepare_cropped_composite`] readied it, over `behind`.
    pub fn composite_cropped(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        index: usize,
        transparent: bool,
        behind: &wgpu::BindGroup,
    ) {
        let c = &self.composite;
        match &self.beyond {
            Some(b) if b.index == index => lay(
                pass,
                [&c.beyond_pipeline, &c.beyond_transparent_pipeline],
                transparent,
                &b.group,
                behind,
            ),
            _ => self.composite(pass, index, transparent, behind),
        }
    }

    /// Draws accumulation target `index` over the current render pass's viewport, mapping its
    /// light with that of what lies `behind` it (the composite's group 1); over a
    /// `transparent` one the cloud alone, the shafts of light with alpha of their own.
    pub fn composite(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        index: usize,
        transparent: bool,
        behind: &wgpu::BindGroup,
    ) {
        let Some(target) = self.targets.get(index).and_then(|t| t.as_ref()) else {
            return;
        };
        let c = &self.composite;
        match &target.shafts {
            Some((_, group)) if target.has_shafts => lay(
                pass,
                [&c.shafts_pipeline, &c.shafts_transparent_pipeline],
                transparent,
                group,
                behind,
            ),
            _ => lay(
                pass,
                [&c.pipeline, &c.transparent_pipeline],
                transparent,
                &target.composite,
                behind,
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sky adds the shafts drawn apart at every pixel outside the cloud's box and at none
    /// inside it (where the box's composite adds its own), as `sky.wgsl` tests a pixel's centre.
    #[test]
    fn the_skys_shafts_cover_the_view_around_the_box_once() {
        let view = [40, 30];
        let inside =
            |[x0, y0, x1, y1]: [u32; 4], x: u32, y: u32| x >= x0 && x < x1 && y >= y0 && y < y1;
        for area in [
            None,
            Some([5, 7, 20, 25]),
            Some([0, 0, 40, 30]),
            Some([0, 3, 12, 30]),
            Some([30, 20, 60, 90]),
        ] {
            let k = keep_out(true, area, view);
            for y in 0..view[1] {
                for x in 0..view[0] {
                    let (u, v) = (
                        (x as f32 + 0.5) / view[0] as f32,
                        (y as f32 + 0.5) / view[1] as f32,
                    );
                    let added = u < k[0] || v < k[1] || u >= k[2] || v >= k[3];
                    let boxed = area.is_some_and(|a| inside(a, x, y));
                    assert_eq!(added, !boxed, "{area:?} at {x}, {y}");
                }
            }
        }
        let none = keep_out(false, Some([5, 7, 20, 25]), view);
        assert!(none[0] < 0.0 && none[1] < 0.0 && none[2] > 1.0 && none[3] > 1.0);
    }
}
