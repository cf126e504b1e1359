//! The mesh renderer: wgpu pipelines (filled triangles and wireframe lines, `shaders/mesh.wgsl`),
//! the mesh's GPU buffers and an offscreen colour + depth target it draws into.
//!
//! Buffers are written only when the mesh changes ([`MeshRenderer::set_mesh`] for new
//! connectivity, [`MeshRenderer::set_positions`] when only the positions move), and the offscreen
//! image is redrawn only when the view, the mesh or the target size changed, so a large mesh costs
//! nothing per frame while nothing moves.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

/// Format of the image the mesh is drawn into (and that egui then samples).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Multisampling of the offscreen target (resolved before egui samples it).
const SAMPLE_COUNT: u32 = 4;

/// Everything that decides what one rendered image looks like, apart from the mesh itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawParams {
    /// Projection times view, column major (glam's `Mat4::to_cols_array_2d`).
    pub view_proj: [[f32; 4]; 4],
    /// Camera position in world space.
    pub eye: [f32; 3],
    /// Direction towards the key light, world space.
    pub light_dir: [f32; 3],
    pub wireframe: bool,
    /// Scalars mapped to the heat map's two ends; `None` draws the plain base colour.
    pub scalar_range: Option<[f32; 2]>,
    /// Target size in physical pixels.
    pub size: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Uniforms {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light_dir: [f32; 4],
    base_color: [f32; 4],
    wire_color: [f32; 4],
    scalar_range: [f32; 4],
}

/// GPU copies of one mesh.
struct MeshBuffers {
    positions: wgpu::Buffer,
    scalars: wgpu::Buffer,
    triangles: wgpu::Buffer,
    vertex_count: usize,
    index_count: u32,
    /// Edge list for the wireframe, built on first use from `triangles_cpu`.
    lines: Option<(wgpu::Buffer, u32)>,
    triangles_cpu: Vec<[u32; 3]>,
}

struct Target {
    size: [u32; 2],
    multisampled: wgpu::TextureView,
    resolved: wgpu::TextureView,
    depth: wgpu::TextureView,
}

/// Owns the pipelines, the mesh buffers and the offscreen target. Knows nothing of fairing.
pub struct MeshRenderer {
    fill_pipeline: wgpu::RenderPipeline,
    line_pipeline: wgpu::RenderPipeline,
    uniform_buffer: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    mesh: Option<MeshBuffers>,
    target: Option<Target>,
    /// Parameters of the image now in the target; `None` forces a redraw.
    drawn: Option<DrawParams>,
    /// Offscreen images drawn so far (for tests and the performance readout).
    pub images_drawn: u64,
}

impl MeshRenderer {
    pub fn new(device: &wgpu::Device) -> Self {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("fairmesh mesh shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/mesh.wgsl").into()),
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

        let position_layout = wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &[wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x3,
                offset: 0,
                shader_location: 0,
            }],
        };
        let scalar_layout = wgpu::VertexBufferLayout {
            array_stride: 4,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &[wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32,
                offset: 0,
                shader_location: 1,
            }],
        };
        let targets = [Some(wgpu::ColorTargetState {
            format: COLOR_FORMAT,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let multisample = wgpu::MultisampleState {
            count: SAMPLE_COUNT,
            ..Default::default()
        };

        let fill_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("fairmesh triangles"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_mesh"),
                compilation_options: Default::default(),
                buffers: &[Some(position_layout.clone()), Some(scalar_layout)],
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
            multisample,
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_mesh"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });
        let line_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("fairmesh wireframe"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
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
            multisample,
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_line"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });

        Self {
            fill_pipeline,
            line_pipeline,
            uniform_buffer,
            bind_group,
            mesh: None,
            target: None,
            drawn: None,
            images_drawn: 0,
        }
    }

    /// Uploads a mesh with new connectivity. `scalars`, when given, has one value per vertex.
    pub fn set_mesh(
        &mut self,
        device: &wgpu::Device,
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        scalars: Option<&[f32]>,
    ) {
        self.drawn = None;
        if positions.is_empty() || triangles.is_empty() {
            self.mesh = None;
            return;
        }
        let positions_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh positions"),
            contents: bytemuck::cast_slice(positions),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        let zeros;
        let scalars = match scalars {
            Some(s) if s.len() == positions.len() => s,
            _ => {
                zeros = vec![0.0f32; positions.len()];
                &zeros
            }
        };
        let scalars_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh scalars"),
            contents: bytemuck::cast_slice(scalars),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        let triangles_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh triangles"),
            contents: bytemuck::cast_slice(triangles),
            usage: wgpu::BufferUsages::INDEX,
        });
        self.mesh = Some(MeshBuffers {
            positions: positions_buffer,
            scalars: scalars_buffer,
            triangles: triangles_buffer,
            vertex_count: positions.len(),
            index_count: (triangles.len() * 3) as u32,
            lines: None,
            triangles_cpu: triangles.to_vec(),
        });
    }

    /// Moves the vertices of the current mesh; returns `false` (and changes nothing) when the
    /// vertex count differs from the uploaded mesh's, in which case call [`Self::set_mesh`].
    pub fn set_positions(&mut self, queue: &wgpu::Queue, positions: &[[f32; 3]]) -> bool {
        match &self.mesh {
            Some(mesh) if mesh.vertex_count == positions.len() => {
                queue.write_buffer(&mesh.positions, 0, bytemuck::cast_slice(positions));
                self.drawn = None;
                true
            }
            _ => false,
        }
    }

    /// Replaces the per-vertex scalars (one per vertex); `false` when the count does not match.
    pub fn set_scalars(&mut self, queue: &wgpu::Queue, scalars: &[f32]) -> bool {
        match &self.mesh {
            Some(mesh) if mesh.vertex_count == scalars.len() => {
                queue.write_buffer(&mesh.scalars, 0, bytemuck::cast_slice(scalars));
                self.drawn = None;
                true
            }
            _ => false,
        }
    }

    pub fn has_mesh(&self) -> bool {
        self.mesh.is_some()
    }

    /// Makes sure the offscreen target has `size` (physical pixels, each at least 1); returns
    /// `true` when it was (re)created, after which the egui texture must point at
    /// [`Self::color_view`] again.
    pub fn ensure_target(&mut self, device: &wgpu::Device, size: [u32; 2]) -> bool {
        let size = [size[0].clamp(1, 8192), size[1].clamp(1, 8192)];
        if self.target.as_ref().is_some_and(|t| t.size == size) {
            return false;
        }
        let extent = wgpu::Extent3d {
            width: size[0],
            height: size[1],
            depth_or_array_layers: 1,
        };
        let make = |label, format, samples, usage| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: extent,
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        self.target = Some(Target {
            size,
            multisampled: make(
                "fairmesh colour (multisampled)",
                COLOR_FORMAT,
                SAMPLE_COUNT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            ),
            resolved: make(
                "fairmesh colour",
                COLOR_FORMAT,
                1,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            ),
            depth: make(
                "fairmesh depth",
                DEPTH_FORMAT,
                SAMPLE_COUNT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            ),
        });
        self.drawn = None;
        true
    }

    /// The image the mesh is drawn into, once [`Self::ensure_target`] made one.
    pub fn color_view(&self) -> Option<&wgpu::TextureView> {
        self.target.as_ref().map(|t| &t.resolved)
    }

    /// Records the drawing of the mesh into the offscreen target, unless the image there already
    /// shows exactly this. Returns whether it drew.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        params: &DrawParams,
    ) -> bool {
        let Some(target) = &self.target else {
            return false;
        };
        if self.drawn.as_ref() == Some(params) || target.size != params.size {
            return false;
        }
        let uniforms = Uniforms {
            view_proj: params.view_proj,
            eye: [params.eye[0], params.eye[1], params.eye[2], 1.0],
            light_dir: [
                params.light_dir[0],
                params.light_dir[1],
                params.light_dir[2],
                0.0,
            ],
            base_color: [0.62, 0.56, 0.48, 1.0],
            wire_color: [0.02, 0.03, 0.05, 1.0],
            scalar_range: match params.scalar_range {
                Some([lo, hi]) => [lo, hi, 1.0, 0.0],
                None => [0.0, 1.0, 0.0, 0.0],
            },
        };
        queue.write_buffer(&self.uniform_buffer, 0, bytemuck::bytes_of(&uniforms));

        if params.wireframe {
            if let Some(mesh) = &mut self.mesh {
                if mesh.lines.is_none() {
                    let edges: Vec<u32> = mesh
                        .triangles_cpu
                        .iter()
                        .flat_map(|&[a, b, c]| [a, b, b, c, c, a])
                        .collect();
                    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("fairmesh wireframe edges"),
                        contents: bytemuck::cast_slice(&edges),
                        usage: wgpu::BufferUsages::INDEX,
                    });
                    mesh.lines = Some((buffer, edges.len() as u32));
                }
            }
        }

        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("fairmesh viewport"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target.multisampled,
                    depth_slice: None,
                    resolve_target: Some(&target.resolved),
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: 0.018,
                            g: 0.021,
                            b: 0.026,
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Discard,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if let Some(mesh) = &self.mesh {
                pass.set_bind_group(0, &self.bind_group, &[]);
                pass.set_pipeline(&self.fill_pipeline);
                pass.set_vertex_buffer(0, mesh.positions.slice(..));
                pass.set_vertex_buffer(1, mesh.scalars.slice(..));
                pass.set_index_buffer(mesh.triangles.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.index_count, 0, 0..1);
                if params.wireframe {
                    if let Some((lines, count)) = &mesh.lines {
                        pass.set_pipeline(&self.line_pipeline);
                        pass.set_vertex_buffer(0, mesh.positions.slice(..));
                        pass.set_index_buffer(lines.slice(..), wgpu::IndexFormat::Uint32);
                        pass.draw_indexed(0..*count, 0, 0..1);
                    }
                }
            }
        }
        self.drawn = Some(*params);
        self.images_drawn += 1;
        true
    }
}
