//! The GPU side of drawing one image: the shader's uniforms ([`Uniforms`], made from the
//! [`DrawParams`]), the two pipelines (filled triangles and wireframe lines, `shaders/mesh.wgsl`)
//! with their uniform buffer ([`Pipelines`]), the offscreen colour + depth [`Target`], and the
//! render pass that draws a mesh into it.

use bytemuck::{Pod, Zeroable};
use std::ops::Range;

use super::buffers::MeshBuffers;
use super::{DrawParams, COLOR_FORMAT, DEPTH_FORMAT};
use std::borrow::Cow;

use crate::render::appearance::{
    Batch, MaterialLook, Mipmaps, Sampling, TextureImage, Wrap, UV_IDENTITY,
};
use crate::render::mipmaps::mip_chain;
use crate::render::shading::{Lighting, Shading};

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct Uniforms {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light_dir: [f32; 4],
    fill_dir: [f32; 4],
    up: [f32; 4],
    base_color: [f32; 4],
    wire_color: [f32; 4],
    scalar_range: [f32; 4],
    /// x: 1 for smooth shading, y: 1 for the studio lighting, z: 1 to draw the materials'
    /// colours (not clay), w: 1 when the vertex colours are there, 2 with texture coordinates
    /// too, 3 with texture coordinates alone.
    look: [f32; 4],
}

impl Uniforms {
    /// What the shader is told for `params`, for a mesh that shows its materials' colours or
    /// not (`materials`), with or without vertex colours and texture coordinates.
    pub(super) fn of(params: &DrawParams, materials: bool, colours: bool, uvs: bool) -> Self {
        Uniforms {
            view_proj: params.view_proj,
            eye: [params.eye[0], params.eye[1], params.eye[2], 1.0],
            light_dir: [
                params.light_dir[0],
                params.light_dir[1],
                params.light_dir[2],
                0.0,
            ],
            fill_dir: [
                params.fill_dir[0],
                params.fill_dir[1],
                params.fill_dir[2],
                0.0,
            ],
            up: [params.up[0], params.up[1], params.up[2], 0.0],
            base_color: [0.62, 0.56, 0.48, 1.0],
            wire_color: [0.02, 0.03, 0.05, 1.0],
            scalar_range: {
                let [lo, hi] = params.scalar_range.unwrap_or([0.0, 1.0]);
                let heat = f32::from(u8::from(params.scalar_range.is_some()));
                [lo, hi, heat, f32::from(u8::from(params.mask_tint))]
            },
            look: [
                f32::from(u8::from(params.shading == Shading::Smooth)),
                f32::from(u8::from(params.lighting == Lighting::Studio)),
                f32::from(u8::from(materials)),
                f32::from(u8::from(colours)) + 2.0 * f32::from(u8::from(uvs)),
            ],
        }
    }
}

/// The offscreen image a renderer draws into: multisampled colour and depth, resolved into a
/// single-sample colour texture that egui shows.
pub(super) struct Target {
    pub(super) size: [u32; 2],
    pub(super) samples: u32,
    /// The colour drawn into and resolved from; `None` with one sample (drawn into `resolved`).
    multisampled: Option<wgpu::TextureView>,
    pub(super) resolved: wgpu::TextureView,
    /// The texture behind `resolved` (an image drawn over several frames is copied into it).
    resolved_texture: wgpu::Texture,
    depth: wgpu::TextureView,
}

impl Target {
    /// Textures of `size` (physical pixels) with `samples` per pixel on `device`.
    pub(super) fn new(device: &wgpu::Device, size: [u32; 2], samples: u32) -> Self {
        let extent = wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        };
        let texture = |label, format, samples, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: extent,
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let make = |label, format, samples, usage| {
            texture(label, format, samples, usage).create_view(&Default::default())
        };
        let resolved_texture = texture(
            "fairmesh colour",
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
        );
        Self {
            size,
            samples,
            multisampled: (samples > 1).then(|| {
                make(
                    "fairmesh colour (multisampled)",
                    COLOR_FORMAT,
                    samples,
                    wgpu::TextureUsages::RENDER_ATTACHMENT,
                )
            }),
            resolved: resolved_texture.create_view(&Default::default()),
            resolved_texture,
            depth: make(
                "fairmesh depth",
                DEPTH_FORMAT,
                samples,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            ),
        }
    }

    /// The resolved image's pixels (RGBA, rows top to bottom). Waits for the GPU.
    pub(super) fn read_back(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Vec<u8>> {
        let [width, height] = self.size;
        let row = width as usize * 4;
        let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fairmesh image read-back"),
            size: (padded * height as usize) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            self.resolved_texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(height),
                },
            },
            self.resolved_texture.size(),
        );
        queue.submit([encoder.finish()]);
        read_mapped(device, &staging, |bytes| {
            bytes
                .chunks(padded)
                .flat_map(|r| &r[..row])
                .copied()
                .collect()
        })
    }

    /// Records copying this target's image into `other`'s (the same size).
    pub(super) fn copy_image_to(&self, encoder: &mut wgpu::CommandEncoder, other: &Target) {
        self.copy_image_into(encoder, &other.resolved_texture);
    }

    /// A texture that can hold this target's image (a held mesh's kept image).
    pub(super) fn image_texture(&self, device: &wgpu::Device) -> wgpu::Texture {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("fairmesh kept image"),
            size: self.resolved_texture.size(),
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: COLOR_FORMAT,
            usage: wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        })
    }

    /// Records copying this target's image into `texture` (of [`Self::image_texture`]).
    pub(super) fn copy_image_into(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) {
        encoder.copy_texture_to_texture(
            self.resolved_texture.as_image_copy(),
            texture.as_image_copy(),
            self.resolved_texture.size(),
        );
    }

    /// Records copying `texture` (of [`Self::image_texture`]) into this target's image.
    pub(super) fn copy_image_from(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) {
        encoder.copy_texture_to_texture(
            texture.as_image_copy(),
            self.resolved_texture.as_image_copy(),
            self.resolved_texture.size(),
        );
    }
}

/// Maps `staging` (whose copy was submitted), waits for the GPU, and reads its bytes with `read`;
/// `None` when the GPU or the mapping fails. The read-backs of images and normals (tests) share it.
pub(super) fn read_mapped<T>(
    device: &wgpu::Device,
    staging: &wgpu::Buffer,
    read: impl FnOnce(&[u8]) -> T,
) -> Option<T> {
    let (tx, rx) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |result| {
        let _ = tx.send(result);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).ok()?;
    rx.recv().ok()?.ok()?;
    let view = staging.get_mapped_range(..).ok()?;
    let value = read(&view);
    drop(view);
    staging.unmap();
    Some(value)
}

/// A part of one image: the faces and wireframe edges one render pass draws. An image drawn in
/// one pass is one part with every face and edge; a software renderer draws a big mesh's image
/// in several (see `MeshRenderer::render`), each adding to what the earlier ones drew.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Part {
    /// Faces drawn (indices into the mesh's triangles).
    pub(super) faces: Range<u32>,
    /// Wireframe edges drawn (indices into the edge list), when the wireframe is on.
    pub(super) edges: Range<u32>,
    /// The first part clears the target; the others keep what is there.
    pub(super) first: bool,
}

impl Part {
    /// Every face of `mesh` and, with `wireframe`, every wireframe edge it has built.
    pub(super) fn whole(mesh: Option<&MeshBuffers>, wireframe: bool) -> Part {
        let edges = match mesh.and_then(|m| m.lines.as_ref()) {
            Some((_, count)) if wireframe => count / 2,
            _ => 0,
        };
        Part {
            faces: 0..mesh.map_or(0, |m| m.index_count / 3),
            edges: 0..edges,
            first: true,
        }
    }
}

/// What every material's bind group is made with (group 1 of the filled triangles): its layout,
/// and the group of "no material" (white, untextured), made when first drawn.
pub(super) struct MaterialKit {
    pub(super) layout: wgpu::BindGroupLayout,
    pub(super) plain: Option<wgpu::BindGroup>,
}

/// A material's uniform: its base colour factor, whether it has a texture (x of `flags`), and
/// the texture transform's two rows (xyz of `uv_u` and `uv_v`, times (u, v, 1)).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MaterialUniform {
    base_colour: [f32; 4],
    flags: [f32; 4],
    uv_u: [f32; 4],
    uv_v: [f32; 4],
}

impl MaterialKit {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty,
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fairmesh material"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                entry(
                    1,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    2,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
            ],
        });
        Self {
            layout,
            plain: None,
        }
    }

    /// The bind group of `material` (`None`: no material, white): its base colour factor and
    /// texture transform, its texture uploaded (sRGB, with its mipmaps unless its sampler
    /// wants none) with its sampler's filters and wrapping, or a white texel.
    pub(super) fn group(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        material: Option<&MaterialLook>,
    ) -> wgpu::BindGroup {
        let white = TextureImage {
            width: 1,
            height: 1,
            rgba: vec![255; 4],
            sampling: Sampling::default(),
        };
        let texture = material.and_then(|m| m.texture.as_ref());
        let image = texture.unwrap_or(&white);
        let [uv_u, uv_v] = material.map_or(UV_IDENTITY, |m| m.uv_transform);
        let uniform = MaterialUniform {
            base_colour: material.map_or([1.0; 4], |m| m.base_colour),
            flags: [f32::from(u8::from(texture.is_some())), 0.0, 0.0, 0.0],
            uv_u: [uv_u[0], uv_u[1], uv_u[2], 0.0],
            uv_v: [uv_v[0], uv_v[1], uv_v[2], 0.0],
        };
        let buffer = super::buffers::filled_buffer(
            device,
            queue,
            "fairmesh material",
            bytemuck::bytes_of(&uniform),
            wgpu::BufferUsages::UNIFORM,
        );
        let sampling = image.sampling;
        let levels = texture_levels(image, device.limits().max_texture_dimension_2d);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("fairmesh base colour"),
            size: wgpu::Extent3d {
                width: levels[0].0,
                height: levels[0].1,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (level, (width, height, rgba)) in levels.iter().enumerate() {
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: level as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                rgba,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(width * 4),
                    rows_per_image: Some(*height),
                },
                wgpu::Extent3d {
                    width: *width,
                    height: *height,
                    depth_or_array_layers: 1,
                },
            );
        }
        let filter = |linear| match linear {
            true => wgpu::FilterMode::Linear,
            false => wgpu::FilterMode::Nearest,
        };
        let address = |wrap| match wrap {
            Wrap::Repeat => wgpu::AddressMode::Repeat,
            Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
            Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("fairmesh base colour"),
            address_mode_u: address(sampling.wrap[0]),
            address_mode_v: address(sampling.wrap[1]),
            mag_filter: filter(sampling.mag_linear),
            min_filter: filter(sampling.min_linear),
            mipmap_filter: match sampling.mipmaps {
                Mipmaps::Linear => wgpu::MipmapFilterMode::Linear,
                Mipmaps::Nearest | Mipmaps::Off => wgpu::MipmapFilterMode::Nearest,
            },
            ..Default::default()
        });
        let view = texture.create_view(&Default::default());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fairmesh material"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        })
    }
}

/// The levels a texture is uploaded with (width, height, sRGB RGBA rows): the image and its
/// mipmaps, or the image alone when its sampler wants none; levels wider or taller than the
/// device allows (`max_side`) are left out, so a too-big texture shows at the largest size the
/// GPU takes.
fn texture_levels(image: &TextureImage, max_side: u32) -> Vec<(u32, u32, Cow<'_, [u8]>)> {
    let fits = |w: u32, h: u32| w <= max_side && h <= max_side;
    let wanted = image.sampling.mipmaps != Mipmaps::Off;
    let mut levels = vec![(image.width, image.height, Cow::Borrowed(&image.rgba[..]))];
    if wanted || !fits(image.width, image.height) {
        let chain = mip_chain(image.width, image.height, &image.rgba);
        levels.extend(
            chain
                .into_iter()
                .map(|l| (l.width, l.height, Cow::Owned(l.rgba))),
        );
    }
    let first = levels
        .iter()
        .position(|(w, h, _)| fits(*w, *h))
        .unwrap_or(levels.len() - 1);
    levels.drain(..first);
    if !wanted {
        levels.truncate(1);
    }
    levels
}

/// The pipelines and their uniforms, made once per renderer.
pub(super) struct Pipelines {
    fill: wgpu::RenderPipeline,
    line: wgpu::RenderPipeline,
    pub(super) uniform_buffer: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl Pipelines {
    /// Pipelines drawing into targets with `samples` per pixel.
    pub(super) fn new(device: &wgpu::Device, samples: u32, materials: &MaterialKit) -> Self {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("fairmesh mesh shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../../../shaders/mesh.wgsl").into()),
        });
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fairmesh uniforms"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("fairmesh pipeline layout"),
            bind_group_layouts: &[Some(&bind_group_layout), Some(&materials.layout)],
            immediate_size: 0,
        });
        let line_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("fairmesh wireframe layout"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let uniform_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fairmesh uniforms"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fairmesh uniforms"),
            layout: &bind_group_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform_buffer.as_entire_binding(),
            }],
        });

        Self {
            fill: fill_pipeline(device, &layout, &shader, samples),
            line: line_pipeline(device, &line_layout, &shader, samples),
            uniform_buffer,
            bind_group,
        }
    }

    /// Records the pass that clears `target` and draws `mesh` into it (with its wireframe edges
    /// when `wireframe` and they are built).
    pub(super) fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        (mesh, plain): (Option<&MeshBuffers>, Option<&wgpu::BindGroup>),
        wireframe: bool,
    ) {
        let whole = Part::whole(mesh, wireframe);
        self.draw_part(encoder, target, (mesh, plain), wireframe, &whole, true);
    }

    /// Records the pass that draws `part` of the image into `target`: the first part clears
    /// it. With `last`, the multisampled colour and the depth are not kept after the pass
    /// (the resolved image is); parts drawn later need them.
    pub(super) fn draw_part(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        (mesh, plain): (Option<&MeshBuffers>, Option<&wgpu::BindGroup>),
        wireframe: bool,
        part: &Part,
        last: bool,
    ) {
        let background = wgpu::Color {
            r: 0.018,
            g: 0.021,
            b: 0.026,
            a: 1.0,
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("fairmesh viewport"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target.multisampled.as_ref().unwrap_or(&target.resolved),
                depth_slice: None,
                resolve_target: target.multisampled.as_ref().map(|_| &target.resolved),
                ops: wgpu::Operations {
                    load: if part.first {
                        wgpu::LoadOp::Clear(background)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    // The multisampled colour is resolved; a single-sample one is the image.
                    store: if target.multisampled.is_some() && last {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth,
                depth_ops: Some(wgpu::Operations {
                    load: if part.first {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: if last {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some(mesh) = mesh {
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.set_pipeline(&self.fill);
            pass.set_vertex_buffer(0, mesh.positions.slice(..));
            pass.set_vertex_buffer(1, mesh.scalars.slice(..));
            pass.set_vertex_buffer(2, mesh.normals.slice(..));
            pass.set_vertex_buffer(3, mesh.mask.slice(..));
            pass.set_vertex_buffer(4, mesh.uvs.slice(..));
            pass.set_vertex_buffer(5, mesh.colours.slice(..));
            pass.set_index_buffer(mesh.triangles.slice(..), wgpu::IndexFormat::Uint32);
            let face_count = mesh.index_count / 3;
            let faces = part.faces.start.min(face_count)..part.faces.end.min(face_count);
            // Each material's run of triangles with its own group; without materials, one run.
            let whole = [Batch {
                material: None,
                first: 0,
                end: face_count,
            }];
            let batches = match (&mesh.appearance, &mesh.materials) {
                (Some(look), Some(_)) if !look.batches.is_empty() => look.batches.as_slice(),
                _ => &whole,
            };
            for batch in batches {
                let run = faces.start.max(batch.first)..faces.end.min(batch.end);
                if run.is_empty() {
                    continue;
                }
                let group = match (batch.material, &mesh.materials) {
                    (Some(m), Some(groups)) => groups.get(m).map(|g| &g.bind_group),
                    _ => None,
                };
                let Some(group) = group.or(plain) else {
                    continue;
                };
                pass.set_bind_group(1, group, &[]);
                pass.draw_indexed(run.start * 3..run.end * 3, 0, 0..1);
            }
            if wireframe {
                if let Some((lines, count)) = &mesh.lines {
                    let edges = part.edges.start.min(count / 2)..part.edges.end.min(count / 2);
                    if !edges.is_empty() {
                        pass.set_pipeline(&self.line);
                        pass.set_vertex_buffer(0, mesh.positions.slice(..));
                        pass.set_index_buffer(lines.slice(..), wgpu::IndexFormat::Uint32);
                        pass.draw_indexed(edges.start * 2..edges.end * 2, 0, 0..1);
                    }
                }
            }
        }
    }
}

/// One attribute per vertex buffer, at the shader locations the layouts below give them.
const POSITION: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];
const SCALAR: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![1 => Float32];
const NORMAL: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![2 => Float32x3];
const MASK: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![3 => Float32];
const UV: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![4 => Float32x2];
const COLOUR: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![5 => Float32x4];

/// A vertex buffer holding `attribute` alone, tightly packed.
fn per_vertex(attribute: &'static [wgpu::VertexAttribute; 1]) -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: attribute[0].format.size(),
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: attribute,
    }
}

/// The vertex buffers' layouts: positions (location 0), scalars (1), normals (2), mask
/// weights (3), texture coordinates (4), colours (5).
fn vertex_layouts() -> [wgpu::VertexBufferLayout<'static>; 6] {
    [
        per_vertex(&POSITION),
        per_vertex(&SCALAR),
        per_vertex(&NORMAL),
        per_vertex(&MASK),
        per_vertex(&UV),
        per_vertex(&COLOUR),
    ]
}

/// The colour target both pipelines draw into.
fn color_targets() -> [Option<wgpu::ColorTargetState>; 1] {
    [Some(wgpu::ColorTargetState {
        format: COLOR_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    })]
}

/// The target's multisampling, for both pipelines.
fn multisample(samples: u32) -> wgpu::MultisampleState {
    wgpu::MultisampleState {
        count: samples,
        ..Default::default()
    }
}

/// Filled triangles, pushed back a little in depth so the wireframe on them wins.
fn fill_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    samples: u32,
) -> wgpu::RenderPipeline {
    let [position_layout, scalar_layout, normal_layout, mask_layout, uv_layout, colour_layout] =
        vertex_layouts();
    let targets = color_targets();
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("fairmesh triangles"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs_mesh"),
            compilation_options: Default::default(),
            buffers: &[
                Some(position_layout),
                Some(scalar_layout),
                Some(normal_layout),
                Some(mask_layout),
                Some(uv_layout),
                Some(colour_layout),
            ],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            // Push triangles back a little so the wireframe lines on them win the depth test.
            bias: wgpu::DepthBiasState {
                constant: 2,
                slope_scale: 1.0,
                clamp: 0.0,
            },
        }),
        multisample: multisample(samples),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs_mesh"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The wireframe's lines, over the triangles.
fn line_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    samples: u32,
) -> wgpu::RenderPipeline {
    let [position_layout, ..] = vertex_layouts();
    let targets = color_targets();
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("fairmesh wireframe"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs_line"),
            compilation_options: Default::default(),
            buffers: &[Some(position_layout)],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::LineList,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: multisample(samples),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs_line"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(width: u32, height: u32, mipmaps: Mipmaps) -> TextureImage {
        TextureImage {
            width,
            height,
            rgba: vec![128; (width * height * 4) as usize],
            sampling: Sampling {
                mipmaps,
                ..Sampling::default()
            },
        }
    }

    fn sizes(levels: &[(u32, u32, Cow<'_, [u8]>)]) -> Vec<(u32, u32)> {
        levels.iter().map(|(w, h, _)| (*w, *h)).collect()
    }

    #[test]
    fn a_texture_is_uploaded_with_its_mipmaps_unless_its_sampler_wants_none() {
        let mipmapped = image(8, 4, Mipmaps::Linear);
        let all = [(8, 4), (4, 2), (2, 1), (1, 1)];
        assert_eq!(sizes(&texture_levels(&mipmapped, 8192)), all);
        let nearest = image(8, 4, Mipmaps::Nearest);
        assert_eq!(sizes(&texture_levels(&nearest, 8192)), all);
        let alone = image(8, 4, Mipmaps::Off);
        assert_eq!(sizes(&texture_levels(&alone, 8192)), [(8, 4)]);
    }

    #[test]
    fn a_texture_too_big_for_the_gpu_starts_at_the_largest_level_that_fits() {
        let mipmapped = image(8, 4, Mipmaps::Linear);
        assert_eq!(
            sizes(&texture_levels(&mipmapped, 4)),
            [(4, 2), (2, 1), (1, 1)]
        );
        let alone = image(8, 4, Mipmaps::Off);
        assert_eq!(sizes(&texture_levels(&alone, 2)), [(2, 1)]);
    }
}
