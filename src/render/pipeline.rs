//! The mesh renderer: wgpu pipelines (filled triangles and wireframe lines, `shaders/mesh.wgsl`),
//! the mesh's GPU buffers and an offscreen colour + depth target it draws into.
//!
//! Buffers are written only when the mesh changes ([`MeshRenderer::set_mesh`] for new
//! connectivity, [`MeshRenderer::set_positions`] when only the positions move; both recompute
//! the vertex normals smooth shading needs, `super::normals`), and the offscreen
//! image is redrawn only when the view, the mesh or the target size changed, so a large mesh costs
//! nothing per frame while nothing moves.
//!
//! New connectivity of a big mesh (4 MB of positions and triangles or more, ~170k faces) and its
//! wireframe edges are filled into buffers on the renderer's own upload thread: for a 1.2M-face
//! mesh that is ~30 ms of copying and page faults (positions, triangles) and ~20 ms (edges) that
//! would otherwise stall one UI frame. New positions of a big mesh get their normals there too
//! (~30 ms for 1.2M faces). The previous image stays until the upload lands.

use bytemuck::{Pod, Zeroable};
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};
use wgpu::util::DeviceExt;

use super::normals::vertex_normals;
use super::shading::{Lighting, Shading};

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
    /// Direction towards the studio lighting's fill light, world space.
    pub fill_dir: [f32; 3],
    /// The camera's up direction, world space (the studio's sky and rim come from there).
    pub up: [f32; 3],
    pub shading: Shading,
    pub lighting: Lighting,
    pub wireframe: bool,
    /// Scalars mapped to the heat map's two ends; `None` draws the plain base colour.
    pub scalar_range: Option<[f32; 2]>,
    /// Without a heat map: the scalars are a mask (0 to 1), tinted over the base colour.
    pub mask_tint: bool,
    /// Target size in physical pixels.
    pub size: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Uniforms {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light_dir: [f32; 4],
    fill_dir: [f32; 4],
    up: [f32; 4],
    base_color: [f32; 4],
    wire_color: [f32; 4],
    scalar_range: [f32; 4],
    /// x: 1 for smooth shading, y: 1 for the studio lighting.
    look: [f32; 4],
}

/// Mesh data the renderer may read on its upload thread (shared, never copied on the UI thread).
pub trait MeshSource: Send + Sync + 'static {
    fn positions(&self) -> &[[f32; 3]];
    fn triangles(&self) -> &[[u32; 3]];
}

/// Meshes whose positions and triangles take fewer bytes than this are uploaded in the calling
/// frame (under ~2 ms); larger ones on the renderer's upload thread, so that loading a 1M-face
/// mesh does not stall the UI for the ~30 ms its buffers take to fill.
pub const DEFAULT_ASYNC_UPLOAD_BYTES: usize = 4 << 20;

/// GPU copies of one mesh.
struct MeshBuffers {
    positions: wgpu::Buffer,
    /// Area-weighted unit vertex normals of the positions now in `positions`.
    normals: wgpu::Buffer,
    scalars: wgpu::Buffer,
    triangles: wgpu::Buffer,
    vertex_count: usize,
    index_count: u32,
    /// Edge list for the wireframe, built when first needed (on the upload thread for a big
    /// mesh) from `source`'s triangles.
    lines: Option<(wgpu::Buffer, u32)>,
    /// The mesh on screen: its triangles, and the positions last written.
    source: Arc<dyn MeshSource>,
    /// Which [`MeshRenderer::set_mesh`] call this mesh answers.
    generation: u64,
}

impl MeshBuffers {
    /// Writes new positions of the same connectivity and their normals.
    fn write_positions(
        &mut self,
        queue: &wgpu::Queue,
        source: Arc<dyn MeshSource>,
        normals: &[[f32; 3]],
    ) {
        queue.write_buffer(&self.positions, 0, bytemuck::cast_slice(source.positions()));
        queue.write_buffer(&self.normals, 0, bytemuck::cast_slice(normals));
        self.source = source;
    }

    fn create(
        device: &wgpu::Device,
        source: Arc<dyn MeshSource>,
        with_lines: bool,
        generation: u64,
    ) -> Self {
        let positions = source.positions();
        let triangles = source.triangles();
        let positions_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh positions"),
            contents: bytemuck::cast_slice(positions),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        let normals_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh normals"),
            contents: bytemuck::cast_slice(&vertex_normals(positions, triangles)),
            // COPY_SRC: tests read back what was uploaded.
            usage: wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        });
        // Scalars come later through `set_scalars`; wgpu zero-fills a buffer that is not mapped
        // at creation.
        let scalars_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fairmesh scalars"),
            size: (positions.len() * 4) as u64,
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let triangles_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fairmesh triangles"),
            contents: bytemuck::cast_slice(triangles),
            usage: wgpu::BufferUsages::INDEX,
        });
        let lines = with_lines.then(|| line_buffer(device, triangles));
        Self {
            positions: positions_buffer,
            normals: normals_buffer,
            scalars: scalars_buffer,
            triangles: triangles_buffer,
            vertex_count: positions.len(),
            index_count: (triangles.len() * 3) as u32,
            lines,
            source,
            generation,
        }
    }
}

/// The wireframe's index buffer: each triangle's three edges as line segments (an edge shared by
/// two triangles is drawn twice, which looks the same and needs no edge map).
fn line_buffer(device: &wgpu::Device, triangles: &[[u32; 3]]) -> (wgpu::Buffer, u32) {
    const BLOCK: usize = 4096;
    let count = triangles.len() * 6;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("fairmesh wireframe edges"),
        size: (count * 4) as u64,
        usage: wgpu::BufferUsages::INDEX,
        mapped_at_creation: true,
    });
    // The mapping is write-only (it may be write-combining memory): edges are built a block of
    // triangles at a time in a small scratch array and copied in, with no full-size temporary.
    let mut scratch = vec![0u32; BLOCK * 6];
    match buffer.slice(..).get_mapped_range_mut() {
        Ok(mut view) => {
            for (block_index, block) in triangles.chunks(BLOCK).enumerate() {
                let edges = &mut scratch[..block.len() * 6];
                for (edge, &[a, b, c]) in edges.chunks_exact_mut(6).zip(block) {
                    edge.copy_from_slice(&[a, b, b, c, c, a]);
                }
                let start = block_index * BLOCK * 6 * 4;
                view.slice(start..start + edges.len() * 4)
                    .copy_from_slice(bytemuck::cast_slice(edges));
            }
        }
        // Cannot happen for a buffer mapped at creation; the wireframe is then just not drawn.
        Err(_) => {
            buffer.unmap();
            return (buffer, 0);
        }
    }
    buffer.unmap();
    (buffer, count as u32)
}

/// Work for the upload thread.
enum UploadJob {
    Mesh {
        generation: u64,
        source: Arc<dyn MeshSource>,
        with_lines: bool,
    },
    Lines {
        generation: u64,
        source: Arc<dyn MeshSource>,
    },
    /// New positions for the mesh of `generation`: their normals.
    Move {
        generation: u64,
        serial: u64,
        source: Arc<dyn MeshSource>,
    },
}

impl UploadJob {
    fn generation(&self) -> u64 {
        match self {
            Self::Mesh { generation, .. }
            | Self::Lines { generation, .. }
            | Self::Move { generation, .. } => *generation,
        }
    }

    fn run(self, device: &wgpu::Device) -> Uploaded {
        match self {
            UploadJob::Mesh {
                generation,
                source,
                with_lines,
            } => Uploaded::Mesh(MeshBuffers::create(device, source, with_lines, generation)),
            UploadJob::Lines { generation, source } => Uploaded::Lines {
                generation,
                lines: line_buffer(device, source.triangles()),
            },
            UploadJob::Move {
                generation,
                serial,
                source,
            } => Uploaded::Moved {
                generation,
                serial,
                normals: vertex_normals(source.positions(), source.triangles()),
                source,
            },
        }
    }
}

enum Uploaded {
    Mesh(MeshBuffers),
    /// Filling the buffers of `generation` panicked inside wgpu.
    Failed {
        generation: u64,
    },
    Lines {
        generation: u64,
        lines: (wgpu::Buffer, u32),
    },
    Moved {
        generation: u64,
        serial: u64,
        source: Arc<dyn MeshSource>,
        normals: Vec<[f32; 3]>,
    },
}

/// The renderer's upload thread: fills buffers for big meshes off the UI thread. Only the newest
/// generation's jobs in the queue are done; older ones are superseded.
struct Uploader {
    jobs: Option<Sender<UploadJob>>,
    /// In a mutex only because egui_wgpu's callback resources must be `Sync`.
    done: Mutex<Receiver<Uploaded>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Uploader {
    fn spawn(device: wgpu::Device, on_done: Arc<dyn Fn() + Send + Sync>) -> Option<Self> {
        let (jobs_tx, jobs_rx) = mpsc::channel::<UploadJob>();
        let (done_tx, done_rx) = mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("fairmesh-upload".into())
            .spawn(move || {
                while let Ok(first) = jobs_rx.recv() {
                    let mut batch = vec![first];
                    batch.extend(jobs_rx.try_iter());
                    let newest = batch.iter().map(UploadJob::generation).max();
                    // Only the last move counts: the positions before it are already old.
                    let last_move = batch
                        .iter()
                        .rposition(|job| matches!(job, UploadJob::Move { .. }));
                    for (index, job) in batch.into_iter().enumerate() {
                        let old_move =
                            matches!(job, UploadJob::Move { .. }) && Some(index) != last_move;
                        if Some(job.generation()) != newest || old_move {
                            continue;
                        }
                        let generation = job.generation();
                        let upload = std::panic::AssertUnwindSafe(|| job.run(&device));
                        // wgpu reports an error it cannot return (out of memory, say) by
                        // panicking: the upload fails, the thread and the app go on.
                        let uploaded = std::panic::catch_unwind(upload)
                            .unwrap_or(Uploaded::Failed { generation });
                        if done_tx.send(uploaded).is_err() {
                            return;
                        }
                        on_done();
                    }
                }
            })
            .ok()?;
        Some(Self {
            jobs: Some(jobs_tx),
            done: Mutex::new(done_rx),
            thread: Some(thread),
        })
    }

    /// Queues a job; gives it back when the thread is gone.
    fn send(&self, job: UploadJob) -> Result<(), UploadJob> {
        match &self.jobs {
            Some(jobs) => jobs.send(job).map_err(|e| e.0),
            None => Err(job),
        }
    }
}

impl Drop for Uploader {
    fn drop(&mut self) {
        // Closing the queue ends the thread after the job in hand.
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

struct PendingMesh {
    generation: u64,
    vertex_count: usize,
    /// Scalars set while the upload was in flight, written once it lands.
    scalars: Option<Vec<f32>>,
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
    uploader: Option<Uploader>,
    /// Counts [`Self::set_mesh`] calls; an upload that lands for an older one is dropped.
    generation: u64,
    /// The upload in flight on the upload thread (the previous mesh stays on screen meanwhile).
    pending: Option<PendingMesh>,
    /// Generation of the mesh whose wireframe edges the upload thread is building.
    lines_requested: Option<u64>,
    /// Counts [`Self::set_positions`] calls; normals that land for an older one are dropped.
    move_serial: u64,
    /// The newest positions whose normals the upload thread is computing (the mesh on screen
    /// keeps its positions until they land, so positions and normals always match).
    pending_move: Option<u64>,
    /// Whether the last image had the wireframe (a big upload then builds its edges too).
    wireframe: bool,
    /// Meshes of at least this many bytes (positions + triangles) upload on the upload thread.
    async_upload_bytes: usize,
    /// Why the last mesh set is not drawn (a buffer would exceed the device's `max_buffer_size`,
    /// or its upload failed).
    problem: Option<String>,
    /// Building the current mesh's wireframe failed (not tried again for this mesh).
    lines_failed: bool,
    max_buffer_size: u64,
    /// CPU time of the last [`Self::render`] that drew (recording commands, building the
    /// wireframe's edges on first use).
    pub last_draw_time: std::time::Duration,
}

impl MeshRenderer {
    /// Pipelines on `device`, and an upload thread for big meshes that calls `on_upload_done`
    /// (from that thread) whenever an upload lands, so the UI can repaint.
    pub fn new(device: &wgpu::Device, on_upload_done: Arc<dyn Fn() + Send + Sync>) -> Self {
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
        let normal_layout = wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &[wgpu::VertexAttribute {
                format: wgpu::VertexFormat::Float32x3,
                offset: 0,
                shader_location: 2,
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
                buffers: &[
                    Some(position_layout.clone()),
                    Some(scalar_layout),
                    Some(normal_layout),
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
            last_draw_time: std::time::Duration::ZERO,
            // Without the thread (it failed to start) every upload happens in the calling frame.
            uploader: Uploader::spawn(device.clone(), on_upload_done),
            generation: 0,
            pending: None,
            lines_requested: None,
            move_serial: 0,
            pending_move: None,
            wireframe: false,
            async_upload_bytes: DEFAULT_ASYNC_UPLOAD_BYTES,
            problem: None,
            lines_failed: false,
            max_buffer_size: device.limits().max_buffer_size,
        }
    }

    /// Uses at most `bytes` per buffer, or the device's limit if that is lower (to see what a
    /// smaller GPU would do; tests).
    pub fn cap_buffer_size(&mut self, device: &wgpu::Device, bytes: u64) {
        self.max_buffer_size = bytes.min(device.limits().max_buffer_size);
    }

    /// Why the mesh, or its wireframe when `wireframe` is on, is not shown (too big for the
    /// device's buffers), if so.
    pub fn problem(&self, wireframe: bool) -> Option<String> {
        if self.problem.is_some() {
            return self.problem.clone();
        }
        let faces = self.mesh.as_ref()?.index_count as usize / 3;
        if !wireframe {
            None
        } else if self.lines_failed {
            Some("the GPU could not take the wireframe's buffer".into())
        } else {
            self.too_big("the wireframe", faces * 24, faces)
        }
    }

    /// `None` when a buffer of `bytes` fits the device, else the sentence saying it does not.
    fn too_big(&self, what: &str, bytes: usize, faces: usize) -> Option<String> {
        let megabytes = |bytes: u64| {
            let mb = bytes as f64 / 1e6;
            if mb < 10.0 {
                format!("{mb:.1} MB")
            } else {
                format!("{mb:.0} MB")
            }
        };
        (bytes as u64 > self.max_buffer_size).then(|| {
            format!(
                "{what} of {faces} faces needs a {} buffer; this GPU allows {}",
                megabytes(bytes as u64),
                megabytes(self.max_buffer_size)
            )
        })
    }

    /// Meshes of at least `bytes` (positions + triangles) upload on the upload thread; 0 sends
    /// every mesh there, `usize::MAX` none.
    pub fn set_async_upload_bytes(&mut self, bytes: usize) {
        self.async_upload_bytes = bytes;
    }

    /// Shows a mesh with new connectivity (its scalars zero until [`Self::set_scalars`]).
    ///
    /// A small mesh is uploaded here; a big one on the upload thread, while the previous mesh
    /// stays on screen (it appears in the first frame after the upload lands; see
    /// [`Self::upload_pending`]).
    pub fn set_mesh(&mut self, device: &wgpu::Device, source: Arc<dyn MeshSource>) {
        self.generation += 1;
        self.pending = None;
        self.pending_move = None;
        self.lines_requested = None;
        self.lines_failed = false;
        let (vertex_count, face_count) = (source.positions().len(), source.triangles().len());
        // Positions and triangles take 12 bytes per vertex and per face.
        self.problem = self.too_big("the mesh", vertex_count.max(face_count) * 12, face_count);
        if vertex_count == 0 || face_count == 0 || self.problem.is_some() {
            self.mesh = None;
            self.drawn = None;
            return;
        }
        let generation = self.generation;
        let mut source = source;
        if (vertex_count + face_count) * 12 >= self.async_upload_bytes {
            if let Some(uploader) = &self.uploader {
                let job = UploadJob::Mesh {
                    generation,
                    source,
                    with_lines: self.wireframe && face_count as u64 * 24 <= self.max_buffer_size,
                };
                match uploader.send(job) {
                    Ok(()) => {
                        self.pending = Some(PendingMesh {
                            generation,
                            vertex_count,
                            scalars: None,
                        });
                        return;
                    }
                    // The thread is gone (it panicked): upload here instead.
                    Err(job) => {
                        let UploadJob::Mesh { source: back, .. } = job else {
                            return; // `send` gives back the job it was given: a mesh job
                        };
                        source = back;
                    }
                }
            }
        }
        self.mesh = Some(MeshBuffers::create(device, source, false, generation));
        self.drawn = None;
    }

    /// Takes in the uploads that landed since the last call (a stale one is dropped).
    fn poll_uploads(&mut self, queue: &wgpu::Queue) {
        let Some(uploader) = &self.uploader else {
            return;
        };
        let landed: Vec<Uploaded> = match uploader.done.lock() {
            Ok(done) => done.try_iter().collect(),
            Err(poisoned) => poisoned.into_inner().try_iter().collect(),
        };
        for uploaded in landed {
            match uploaded {
                Uploaded::Mesh(buffers) => {
                    if self
                        .pending
                        .as_ref()
                        .is_some_and(|p| p.generation == buffers.generation)
                    {
                        if let Some(scalars) = self.pending.take().and_then(|p| p.scalars) {
                            queue.write_buffer(&buffers.scalars, 0, bytemuck::cast_slice(&scalars));
                        }
                        self.mesh = Some(buffers);
                        self.drawn = None;
                    }
                }
                Uploaded::Failed { generation } => {
                    if self
                        .pending
                        .as_ref()
                        .is_some_and(|p| p.generation == generation)
                    {
                        self.pending = None;
                        self.mesh = None;
                        self.drawn = None;
                        self.problem = Some("the GPU could not take the mesh's buffers".into());
                    }
                    if self.lines_requested == Some(generation) {
                        self.lines_requested = None;
                        self.lines_failed = true;
                        self.drawn = None;
                    }
                    if self
                        .mesh
                        .as_ref()
                        .is_some_and(|m| m.generation == generation)
                    {
                        // A move's normals failed: the mesh keeps its last positions.
                        self.pending_move = None;
                    }
                }
                Uploaded::Moved {
                    generation,
                    serial,
                    source,
                    normals,
                } => {
                    if self.pending_move != Some(serial) {
                        continue;
                    }
                    self.pending_move = None;
                    if let Some(mesh) = self.mesh.as_mut().filter(|m| m.generation == generation) {
                        mesh.write_positions(queue, source, &normals);
                        self.drawn = None;
                    }
                }
                Uploaded::Lines { generation, lines } => {
                    if self.lines_requested == Some(generation) {
                        self.lines_requested = None;
                    }
                    if let Some(mesh) = self.mesh.as_mut().filter(|m| m.generation == generation) {
                        mesh.lines = Some(lines);
                        self.drawn = None;
                    }
                }
            }
        }
    }

    /// Whether an upload is still in flight (takes in those that landed first).
    pub fn upload_pending(&mut self, queue: &wgpu::Queue) -> bool {
        self.poll_uploads(queue);
        self.pending.is_some() || self.lines_requested.is_some() || self.pending_move.is_some()
    }

    /// Moves the vertices of the current mesh to `source`'s positions (its triangles must be the
    /// mesh's), with new normals; returns `false` (and changes nothing) when the vertex count
    /// differs from the uploaded mesh's or a new mesh is still uploading, in which case call
    /// [`Self::set_mesh`]. A big mesh's normals are computed on the upload thread: the mesh
    /// moves once they land.
    pub fn set_positions(&mut self, queue: &wgpu::Queue, source: Arc<dyn MeshSource>) -> bool {
        self.poll_uploads(queue);
        if self.pending.is_some() {
            return false;
        }
        let Some(mesh) = self.mesh.as_mut() else {
            return false;
        };
        let vertex_count = source.positions().len();
        if mesh.vertex_count != vertex_count {
            return false;
        }
        self.move_serial += 1;
        let faces = mesh.index_count as usize / 3;
        if (vertex_count + faces) * 12 >= self.async_upload_bytes {
            if let Some(uploader) = &self.uploader {
                let job = UploadJob::Move {
                    generation: mesh.generation,
                    serial: self.move_serial,
                    source: source.clone(),
                };
                if uploader.send(job).is_ok() {
                    self.pending_move = Some(self.move_serial);
                    return true;
                }
            }
        }
        self.pending_move = None;
        let normals = vertex_normals(source.positions(), source.triangles());
        mesh.write_positions(queue, source, &normals);
        self.drawn = None;
        true
    }

    /// Reads back the vertex normals in the GPU buffer of the mesh on screen (tests: what
    /// smooth shading is drawn with). Waits for the GPU.
    pub fn read_back_normals(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Option<Vec<[f32; 3]>> {
        self.poll_uploads(queue);
        let mesh = self.mesh.as_ref()?;
        let size = (mesh.vertex_count * 12) as u64;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fairmesh normals read-back"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&mesh.normals, 0, &staging, 0, size);
        queue.submit([encoder.finish()]);
        let (tx, rx) = mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |result| {
            let _ = tx.send(result);
        });
        device.poll(wgpu::PollType::wait_indefinitely()).ok()?;
        rx.recv().ok()?.ok()?;
        let view = staging.get_mapped_range(..).ok()?;
        let normals = bytemuck::cast_slice::<u8, [f32; 3]>(&view).to_vec();
        drop(view);
        staging.unmap();
        Some(normals)
    }

    /// Replaces the per-vertex scalars (one per vertex) of the mesh on screen or, while one
    /// uploads, of that one; `false` when the count does not match.
    pub fn set_scalars(&mut self, queue: &wgpu::Queue, scalars: &[f32]) -> bool {
        self.poll_uploads(queue);
        if let Some(pending) = &mut self.pending {
            if pending.vertex_count != scalars.len() {
                return false;
            }
            pending.scalars = Some(scalars.to_vec());
            return true;
        }
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
        self.poll_uploads(queue);
        self.wireframe = params.wireframe;
        let Some(target) = &self.target else {
            return false;
        };
        if self.drawn.as_ref() == Some(params) || target.size != params.size {
            return false;
        }
        let started = std::time::Instant::now();
        let uniforms = Uniforms {
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
            scalar_range: match (params.scalar_range, params.mask_tint) {
                (Some([lo, hi]), _) => [lo, hi, 1.0, 0.0],
                (None, true) => [0.0, 1.0, 2.0, 0.0],
                (None, false) => [0.0, 1.0, 0.0, 0.0],
            },
            look: [
                f32::from(u8::from(params.shading == Shading::Smooth)),
                f32::from(u8::from(params.lighting == Lighting::Studio)),
                0.0,
                0.0,
            ],
        };
        queue.write_buffer(&self.uniform_buffer, 0, bytemuck::bytes_of(&uniforms));

        if params.wireframe {
            if let Some(mesh) = &mut self.mesh {
                let faces = mesh.index_count as usize / 3;
                let fits = faces as u64 * 24 <= self.max_buffer_size;
                if fits
                    && !self.lines_failed
                    && mesh.lines.is_none()
                    && self.lines_requested != Some(mesh.generation)
                {
                    // A big mesh's edges are built on the upload thread (the image shows the
                    // mesh without them meanwhile); a small one's here.
                    let bytes = (mesh.vertex_count + faces) * 12;
                    let job = UploadJob::Lines {
                        generation: mesh.generation,
                        source: mesh.source.clone(),
                    };
                    let sent = match &self.uploader {
                        Some(uploader) if bytes >= self.async_upload_bytes => {
                            uploader.send(job).is_ok()
                        }
                        _ => false,
                    };
                    if sent {
                        self.lines_requested = Some(mesh.generation);
                    } else {
                        mesh.lines = Some(line_buffer(device, mesh.source.triangles()));
                    }
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
                pass.set_vertex_buffer(2, mesh.normals.slice(..));
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
        self.last_draw_time = started.elapsed();
        true
    }
}
