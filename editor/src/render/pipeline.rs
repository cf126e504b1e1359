//! The mesh renderer: [`MeshRenderer`] owns the pipelines, the mesh's GPU buffers and an
//! offscreen colour + depth target it draws into. One file per concern beside it:
//! `pipeline/passes.rs` (the pipelines, `shaders/mesh.wgsl`, the uniforms, the target and the
//! render pass), `pipeline/buffers.rs` (a mesh's buffers and its wireframe edges),
//! `pipeline/upload.rs` (the upload thread for big meshes) and `pipeline/held.rs` (meshes kept
//! on the GPU besides the one on screen, keyed by what they show, so that showing one again
//! uploads nothing: [`MeshRenderer::show_held`]) and `pipeline/kept.rs` (each held mesh's last
//! complete image, so that showing it again with an unchanged view draws nothing either).
//!
//! Buffers are written only when the mesh changes ([`MeshRenderer::set_mesh`] for new
//! connectivity, [`MeshRenderer::set_positions`] when only the positions move; both recompute
//! the vertex normals smooth shading needs, `super::normals`, and where they split at sharp
//! edges: a move that splits them elsewhere gets new buffers, as a new mesh does), and the offscreen
//! image is redrawn only when the view, the mesh or the target size changed, so a large mesh costs
//! nothing per frame while nothing moves.
//!
//! New connectivity of a big mesh (4 MB of positions and triangles or more, ~170k faces) and its
//! wireframe edges are filled into buffers on the renderer's own upload thread: for a 1.2M-face
//! mesh that is ~30 ms of copying and page faults (positions, triangles) and ~20 ms (edges) that
//! would otherwise stall one UI frame. New positions of a big mesh get their normals there too
//! (20-40 ms for 1.2M faces with no sharp edge, the edges tested; about 100 ms when noise
//! splits many vertices, which then get new buffers too). The previous image stays until the upload lands.

mod buffers;
mod held;
mod kept;
mod passes;
mod upload;

pub use held::{HeldMesh, MeshKey, UploadCounts, MAX_HELD_MESHES};
pub use kept::ImageCounts;

use std::sync::Arc;
use std::time::Duration;

use super::appearance::Appearance;
use super::shading::{Lighting, Shading};
use buffers::MeshBuffers;
use kept::KeptImages;
use passes::{MaterialKit, Part, Pipelines, Target, Uniforms};
use upload::{InFlight, MoveJob, Moved, PendingMesh, UploadJob, Uploaded, Uploader};

/// Format of the image the mesh is drawn into (and that egui then samples).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Multisampling of the offscreen target (resolved before egui samples it).
const SAMPLE_COUNT: u32 = 4;

/// On a software renderer (lavapipe, llvmpipe: a CPU adapter), meshes with more faces than this
/// are drawn without multisampling: on the CPU, four samples cost several times the drawing of
/// one, and the window waits for the image.
pub const SOFTWARE_SINGLE_SAMPLE_FACES: usize = 400_000;

/// On a software renderer, a new image draws at most this many faces (or wireframe edges) per
/// frame: a bigger mesh's image is drawn over several frames into a second target while the
/// previous image stays on screen, then copied over it. A big mesh's image drawn in one frame
/// would keep the window from answering input until it is done; parts of this size keep each
/// frame short.
pub const SOFTWARE_FACES_PER_FRAME: usize = 50_000;

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
    /// Show the mask weights ([`MeshRenderer::set_mask`]): tinted over the base colour, or,
    /// over a heat map (whose colours must read as its legend says), as an outline.
    pub mask_tint: bool,
    /// Every surface in the clay colour, the file's materials, textures and vertex colours left
    /// out (to judge the shape alone).
    pub clay: bool,
    /// Target size in physical pixels.
    pub size: [u32; 2],
}

/// One drawn triangle as smooth shading lights it ([`MeshRenderer::read_back_corner_normals`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CornerNormals {
    /// Its corners' mesh vertices.
    pub vertices: [u32; 3],
    /// Its corners' unit normals.
    pub normals: [[f32; 3]; 3],
}

/// Mesh data the renderer may read on its upload thread (shared, never copied on the UI thread).
pub trait MeshSource: Send + Sync + 'static {
    fn positions(&self) -> &[[f32; 3]];
    fn triangles(&self) -> &[[u32; 3]];
    /// The file's materials, texture coordinates and colours over these triangles, if shown.
    fn appearance(&self) -> Option<Arc<Appearance>> {
        None
    }
}

/// Meshes whose positions and triangles take fewer bytes than this are uploaded in the calling
/// frame (under ~2 ms); larger ones on the renderer's upload thread, so that loading a 1M-face
/// mesh does not stall the UI for the ~30 ms its buffers take to fill.
pub const DEFAULT_ASYNC_UPLOAD_BYTES: usize = 4 << 20;

/// An image drawn over several frames: what it shows and how far it got.
struct Progress {
    params: DrawParams,
    /// Faces, then wireframe edges, drawn so far.
    done: u32,
    /// CPU time spent recording its parts so far.
    recording: Duration,
}

/// What [`MeshRenderer::draw_next_part`] did.
enum PartDrawn {
    /// Nothing: there is no target to draw into.
    NoTarget,
    /// A part; the image needs more.
    MoreToDraw,
    /// The last part: the complete image is in the shown target.
    Complete,
}

/// Owns the pipelines, the mesh buffers and the offscreen target. Knows nothing of fairing.
///
/// Its state in parts: the device and what is made on it once (`DeviceKit`), the uploads in
/// flight (`InFlight`, `pipeline/upload.rs`), the image drawn over several frames
/// (`PartDrawing`), the held meshes' kept images (`KeptImages`, `pipeline/kept.rs`) and what
/// was drawn and written so far ([`ImageCounts`], [`UploadCounts`]).
pub struct MeshRenderer {
    /// The device, the pipelines and the materials' layout.
    gpu: DeviceKit,
    /// Faces of the mesh last given to [`Self::set_mesh`], uploaded or not: the target gets that
    /// mesh's sampling before its upload lands, so its first image is drawn once.
    newest_faces: usize,
    mesh: Option<MeshBuffers>,
    /// Meshes kept on the GPU besides the one on screen, to show again without uploading
    /// (see [`Self::show_held`]); at most [`MAX_HELD_MESHES`] with `mesh`.
    held: Vec<MeshBuffers>,
    /// What was written to the GPU so far (tests and the performance readout).
    pub uploads: UploadCounts,
    /// Uploads and moves on the upload thread, and what waits for them.
    in_flight: InFlight,
    target: Option<Target>,
    /// Parameters of the image now in the target; `None` forces a redraw.
    drawn: Option<DrawParams>,
    /// An image too big for one frame, drawn in parts.
    parts: PartDrawing,
    /// The target holds a complete image (it has since it was made): only then is a new image
    /// drawn over several frames, the old one staying on screen meanwhile. A new target (the
    /// view was resized) gets its first image at once rather than a blank view for a while.
    target_has_image: bool,
    /// Asks the UI for another frame (an image drawn over several frames needs them).
    repaint: Arc<dyn Fn() + Send + Sync>,
    /// Images drawn, parts drawn and images restored so far ([`Self::image_counts`]).
    counts: ImageCounts,
    /// The last complete image of each held mesh (and of the one on screen, when it has one).
    kept: KeptImages,
    /// Whether the last image had the wireframe (a big upload then builds its edges too).
    wireframe: bool,
    /// Why the last mesh set is not drawn (a buffer would exceed the device's `max_buffer_size`,
    /// or its upload failed).
    problem: Option<String>,
    /// Building the current mesh's wireframe failed (not tried again for this mesh).
    lines_failed: bool,
    /// CPU time of the last [`Self::render`] that drew (recording commands, building the
    /// wireframe's edges on first use).
    pub last_draw_time: Duration,
}

/// The device the renderer draws with and what it makes there once.
struct DeviceKit {
    /// The device the buffers are made on (a move may need new ones), and the queue that
    /// fills them.
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// The materials' bind group layout (shared by both samplings' pipelines) and the group of
    /// "no material".
    materials: MaterialKit,
    pipelines: Pipelines,
    /// The same pipelines for a target without multisampling (made when first needed).
    single_sample: Option<Pipelines>,
    /// The adapter is a CPU (a software renderer): big meshes are drawn with one sample.
    software: bool,
    /// On a software renderer, meshes with more faces than this are drawn with one sample
    /// ([`SOFTWARE_SINGLE_SAMPLE_FACES`], or 0 in the web page: every mesh).
    single_sample_faces: usize,
    /// The biggest buffer the renderer makes (the device's limit, or less: tests).
    max_buffer_size: u64,
}

/// An image too big for one frame, drawn in parts into a second target.
struct PartDrawing {
    /// Faces (or edges) a new image draws per frame at most; more take several frames.
    faces_per_frame: usize,
    /// The image being drawn over several frames, if one is.
    progress: Option<Progress>,
    /// Where that image is drawn (the target's size and sampling; kept between images).
    work: Option<Target>,
}

impl MeshRenderer {
    /// Pipelines on `device` (buffers filled through `queue`), and an upload thread for big
    /// meshes that calls `on_upload_done` (from that thread) whenever an upload lands, so the
    /// UI can repaint.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        on_upload_done: Arc<dyn Fn() + Send + Sync>,
    ) -> Self {
        let materials = MaterialKit::new(device);
        Self {
            gpu: DeviceKit {
                device: device.clone(),
                queue: queue.clone(),
                pipelines: Pipelines::new(device, SAMPLE_COUNT, &materials),
                materials,
                single_sample: None,
                software: false,
                single_sample_faces: SOFTWARE_SINGLE_SAMPLE_FACES,
                max_buffer_size: device.limits().max_buffer_size,
            },
            newest_faces: 0,
            mesh: None,
            held: Vec::new(),
            uploads: UploadCounts::default(),
            // Without the thread (it failed to start) every upload happens in the calling frame.
            in_flight: InFlight::new(Uploader::spawn(
                device.clone(),
                queue.clone(),
                on_upload_done.clone(),
            )),
            target: None,
            drawn: None,
            parts: PartDrawing {
                faces_per_frame: usize::MAX,
                progress: None,
                work: None,
            },
            target_has_image: false,
            repaint: on_upload_done,
            counts: ImageCounts::default(),
            kept: KeptImages::default(),
            last_draw_time: Duration::ZERO,
            wireframe: false,
            problem: None,
            lines_failed: false,
        }
    }

    /// Uses at most `bytes` per buffer, or the device's limit if that is lower (to see what a
    /// smaller GPU would do; tests).
    pub fn cap_buffer_size(&mut self, device: &wgpu::Device, bytes: u64) {
        self.gpu.max_buffer_size = bytes.min(device.limits().max_buffer_size);
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
        (bytes as u64 > self.gpu.max_buffer_size).then(|| {
            format!(
                "{what} of {faces} faces needs a {} buffer; this GPU allows {}",
                megabytes(bytes as u64),
                megabytes(self.gpu.max_buffer_size)
            )
        })
    }

    /// Meshes of at least `bytes` (positions + triangles) upload on the upload thread; 0 sends
    /// every mesh there, `usize::MAX` none.
    pub fn set_async_upload_bytes(&mut self, bytes: usize) {
        self.in_flight.async_upload_bytes = bytes;
    }

    /// Shows a mesh with new connectivity (its scalars zero until [`Self::set_scalars`]).
    ///
    /// A small mesh is uploaded here; a big one on the upload thread, while the previous mesh
    /// stays on screen (it appears in the first frame after the upload lands; see
    /// [`Self::upload_pending`]).
    pub fn set_mesh(&mut self, device: &wgpu::Device, source: Arc<dyn MeshSource>) {
        self.set_mesh_keyed(device, source, None);
    }

    /// [`Self::set_mesh`] for a mesh the renderer keeps on the GPU while `key`'s family is
    /// current (it replaces that family's mesh; see [`Self::show_held`]).
    pub fn set_mesh_keyed(
        &mut self,
        device: &wgpu::Device,
        source: Arc<dyn MeshSource>,
        key: Option<MeshKey>,
    ) {
        self.drop_family(key);
        self.in_flight.next_mesh();
        self.lines_failed = false;
        let (vertex_count, face_count) = (source.positions().len(), source.triangles().len());
        self.newest_faces = face_count;
        // Positions and triangles take 12 bytes per vertex and per face.
        self.problem = self.too_big("the mesh", vertex_count.max(face_count) * 12, face_count);
        if vertex_count == 0 || face_count == 0 || self.problem.is_some() {
            self.mesh = None;
            self.redraw();
            return;
        }
        self.uploads.count_mesh(vertex_count, face_count);
        let generation = self.in_flight.generation;
        let mut source = source;
        if (vertex_count + face_count) * 12 >= self.in_flight.async_upload_bytes {
            if let Some(uploader) = &self.in_flight.uploader {
                let job = UploadJob::Mesh {
                    generation,
                    source,
                    with_lines: self.wireframe
                        && face_count as u64 * 24 <= self.gpu.max_buffer_size,
                };
                match uploader.send(job) {
                    Ok(()) => {
                        self.in_flight.pending = Some(PendingMesh {
                            generation,
                            key,
                            vertex_count,
                            scalars: None,
                            mask: None,
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
        let mut buffers = MeshBuffers::create(device, &self.gpu.queue, source, false, generation);
        buffers.key = key;
        self.replace_current(buffers);
    }

    /// Takes in the uploads that landed since the last call (a stale one is dropped).
    fn poll_uploads(&mut self, queue: &wgpu::Queue) {
        let Some(uploader) = &self.in_flight.uploader else {
            return;
        };
        let landed: Vec<Uploaded> = match uploader.done.lock() {
            Ok(done) => done.try_iter().collect(),
            Err(poisoned) => poisoned.into_inner().try_iter().collect(),
        };
        for uploaded in landed {
            match uploaded {
                Uploaded::Mesh(mut buffers) => {
                    if self
                        .in_flight
                        .pending
                        .as_ref()
                        .is_some_and(|p| p.generation == buffers.generation)
                    {
                        if let Some(pending) = self.in_flight.pending.take() {
                            buffers.key = pending.key;
                            if let Some(scalars) = pending.scalars {
                                buffers.write_per_vertex(queue, &scalars, false);
                            }
                            if let Some(mask) = pending.mask {
                                buffers.write_per_vertex(queue, &mask, true);
                            }
                        }
                        self.replace_current(*buffers);
                    }
                }
                Uploaded::Failed { generation } => {
                    if self
                        .in_flight
                        .pending
                        .as_ref()
                        .is_some_and(|p| p.generation == generation)
                    {
                        self.in_flight.pending = None;
                        self.mesh = None;
                        self.redraw();
                        self.problem = Some("the GPU could not take the mesh's buffers".into());
                    }
                    if self.in_flight.lines_requested == Some(generation) {
                        self.in_flight.lines_requested = None;
                        self.lines_failed = true;
                        self.redraw();
                    }
                    if self
                        .mesh
                        .as_ref()
                        .is_some_and(|m| m.generation == generation)
                    {
                        // A move's normals failed: the mesh keeps its last positions.
                        self.in_flight.pending_move = None;
                        self.write_move_tints(queue);
                    }
                }
                Uploaded::Moved {
                    generation,
                    serial,
                    source,
                    moved,
                } => {
                    if self.in_flight.pending_move != Some(serial) {
                        continue;
                    }
                    self.in_flight.pending_move = None;
                    if self
                        .mesh
                        .as_ref()
                        .is_some_and(|m| m.generation == generation)
                    {
                        self.apply_move(queue, source, moved);
                    }
                    self.write_move_tints(queue);
                }
                Uploaded::Lines {
                    generation,
                    look,
                    lines,
                } => {
                    if self.in_flight.lines_requested == Some(generation) {
                        self.in_flight.lines_requested = None;
                    }
                    let same_look = |m: &&mut MeshBuffers| match (&m.appearance, &look) {
                        (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                        (a, b) => a.is_none() && b.is_none(),
                    };
                    if let Some(mesh) = (self.mesh.as_mut())
                        .filter(|m| m.generation == generation)
                        .filter(same_look)
                    {
                        mesh.lines = Some(lines);
                        self.redraw();
                    }
                }
            }
        }
    }

    /// Whether an upload is still in flight (takes in those that landed first).
    pub fn upload_pending(&mut self, queue: &wgpu::Queue) -> bool {
        self.poll_uploads(queue);
        self.in_flight.any()
    }

    /// Moves the vertices of the current mesh to `source`'s positions (its triangles must be the
    /// mesh's), with new normals; returns `false` (and changes nothing) when the vertex count
    /// differs from the uploaded mesh's or a new mesh is still uploading, in which case call
    /// [`Self::set_mesh`]. A big mesh's normals are computed on the upload thread: the mesh
    /// moves once they land.
    pub fn set_positions(&mut self, queue: &wgpu::Queue, source: Arc<dyn MeshSource>) -> bool {
        self.poll_uploads(queue);
        if self.in_flight.pending.is_some() {
            return false;
        }
        let Some(mesh) = self.mesh.as_mut() else {
            return false;
        };
        let vertex_count = source.positions().len();
        if mesh.vertex_count != vertex_count {
            return false;
        }
        self.in_flight.move_serial += 1;
        self.uploads.count_positions(vertex_count);
        // The mesh is about to move: its kept image shows where it was.
        kept::forget_image(&mut self.kept.images, mesh.generation);
        let faces = mesh.index_count as usize / 3;
        let job = MoveJob {
            generation: mesh.generation,
            serial: self.in_flight.move_serial,
            source: source.clone(),
            corners: mesh.corners.clone(),
            layout: mesh.layout.clone(),
        };
        let mut job = Box::new(job);
        if (vertex_count + faces) * 12 >= self.in_flight.async_upload_bytes {
            if let Some(uploader) = &self.in_flight.uploader {
                match uploader.send(UploadJob::Move(job)) {
                    Ok(()) => {
                        self.in_flight.pending_move = Some(self.in_flight.move_serial);
                        return true;
                    }
                    // The thread is gone: the move is made here.
                    Err(UploadJob::Move(back)) => job = back,
                    Err(_) => return false, // `send` gives back the job it was given
                }
            }
        }
        self.in_flight.pending_move = None;
        let moved = job.run(&self.gpu.device, queue);
        self.apply_move(queue, source, moved);
        self.write_move_tints(queue);
        true
    }

    /// Shows the mesh on screen at `source`'s positions: their normals written into its
    /// buffers, or its new buffers in their place (the shading splits elsewhere now; the
    /// wireframe's edges are then built again).
    fn apply_move(&mut self, queue: &wgpu::Queue, source: Arc<dyn MeshSource>, moved: Moved) {
        let Some(mesh) = self.mesh.as_mut() else {
            return;
        };
        match moved {
            Moved::Normals(normals) => mesh.write_positions(queue, source, &normals),
            Moved::Rebuilt(mut buffers) => {
                buffers.take_place_of(queue, mesh);
                *mesh = *buffers;
                self.in_flight.lines_requested = None;
                self.lines_failed = false;
            }
        }
        self.redraw();
    }

    /// Writes the scalars and mask weights that waited for a move's positions.
    fn write_move_tints(&mut self, queue: &wgpu::Queue) {
        let (scalars, mask) = (
            self.in_flight.move_scalars.take(),
            self.in_flight.move_mask.take(),
        );
        if let Some(mesh) = &mut self.mesh {
            if let Some(scalars) = scalars.filter(|s| s.len() == mesh.vertex_count) {
                mesh.write_per_vertex(queue, &scalars, false);
            }
            if let Some(mask) = mask.filter(|m| m.len() == mesh.vertex_count) {
                mesh.write_per_vertex(queue, &mask, true);
            }
            self.redraw();
        }
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
        let size = (mesh.draw_count * 12) as u64;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fairmesh normals read-back"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&mesh.normals, 0, &staging, 0, size);
        queue.submit([encoder.finish()]);
        passes::read_mapped(device, &staging, |bytes| {
            bytemuck::cast_slice::<u8, [f32; 3]>(bytes).to_vec()
        })
    }

    /// Reads back the normals each drawn triangle's corners are lit with (tests: where smooth
    /// shading splits), with the triangle's mesh vertices; in draw order (the mesh's own order
    /// for a mesh without an appearance). Waits for the GPU.
    pub fn read_back_corner_normals(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Option<Vec<CornerNormals>> {
        let normals = self.read_back_normals(device, queue)?;
        let mesh = self.mesh.as_ref()?;
        let look = mesh.appearance.as_deref();
        let triangles = buffers::draw_triangles(mesh.source.as_ref(), look);
        let vertex_of = |d: u32| {
            look.and_then(|l| l.vertex_of.as_ref())
                .map_or(d, |m| m[d as usize])
        };
        Some(
            triangles
                .iter()
                .map(|t| CornerNormals {
                    vertices: t.map(vertex_of),
                    normals: t.map(|d| normals[d as usize]),
                })
                .collect(),
        )
    }

    /// Reads back the image in the target (RGBA, sRGB, rows top to bottom; tests). Waits for
    /// the GPU.
    pub fn read_back_image(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Vec<u8>> {
        self.target.as_ref()?.read_back(device, queue)
    }

    /// Replaces the per-vertex scalars (one per vertex) of the mesh on screen or, while one
    /// uploads, of that one; `false` when the count does not match. While new positions are on
    /// their way (a big mesh's normals on the upload thread) they are written with them, so a
    /// heat map never colours the positions it was not measured on.
    pub fn set_scalars(&mut self, queue: &wgpu::Queue, scalars: &[f32]) -> bool {
        self.set_per_vertex(queue, scalars, false)
    }

    /// Replaces the painted mask's weights (0 to 1, one per vertex), like [`Self::set_scalars`].
    pub fn set_mask(&mut self, queue: &wgpu::Queue, weights: &[f32]) -> bool {
        self.set_per_vertex(queue, weights, true)
    }

    fn set_per_vertex(&mut self, queue: &wgpu::Queue, values: &[f32], mask: bool) -> bool {
        self.poll_uploads(queue);
        if let Some(pending) = &mut self.in_flight.pending {
            if pending.vertex_count != values.len() {
                return false;
            }
            match mask {
                true => pending.mask = Some(values.to_vec()),
                false => pending.scalars = Some(values.to_vec()),
            }
            self.uploads.count_per_vertex(values.len());
            return true;
        }
        let Some(mesh) = self
            .mesh
            .as_mut()
            .filter(|m| m.vertex_count == values.len())
        else {
            return false;
        };
        if self.in_flight.pending_move.is_some() {
            match mask {
                true => self.in_flight.move_mask = Some(values.to_vec()),
                false => self.in_flight.move_scalars = Some(values.to_vec()),
            }
            self.uploads.count_per_vertex(values.len());
            return true;
        }
        mesh.write_per_vertex(queue, values, mask);
        self.uploads.count_per_vertex(values.len());
        self.redraw();
        true
    }

    pub fn has_mesh(&self) -> bool {
        self.mesh.is_some()
    }

    /// Tells the renderer that its device is a software renderer (a CPU adapter): meshes over
    /// [`SOFTWARE_SINGLE_SAMPLE_FACES`] faces are then drawn without multisampling.
    pub fn set_software_adapter(&mut self, software: bool) {
        self.gpu.software = software;
        self.set_faces_per_frame(if software {
            SOFTWARE_FACES_PER_FRAME
        } else {
            usize::MAX
        });
    }

    /// Marks the device as a software renderer whose meshes are all drawn with one sample (no
    /// anti-aliasing), whatever their size: the web page on a software renderer (SwiftShader),
    /// where the four samples' drawing and resolving is most of a frame's time. Unlike
    /// [`Self::set_software_adapter`], images are still drawn whole in one frame.
    pub fn set_single_sampled(&mut self) {
        self.gpu.software = true;
        self.gpu.single_sample_faces = 0;
        self.redraw();
    }

    /// A new image draws at most `faces` faces (or wireframe edges) per [`Self::render`]; a
    /// bigger mesh's image takes several calls, the previous image staying in the target until
    /// the new one is complete. Software renderers get [`SOFTWARE_FACES_PER_FRAME`]; GPUs draw
    /// every image at once.
    pub fn set_faces_per_frame(&mut self, faces: usize) {
        self.parts.faces_per_frame = faces.max(1);
        self.redraw();
    }

    /// Whether an image is being drawn over several frames (the target still shows the one
    /// before it).
    pub fn drawing(&self) -> bool {
        self.parts.progress.is_some()
    }

    /// The image in the target no longer shows the mesh as it is: draw it again, drop an
    /// image half drawn from the old buffers, and forget the mesh's kept image.
    fn redraw(&mut self) {
        self.drawn = None;
        self.parts.progress = None;
        self.forget_current_image();
    }

    /// Samples per pixel the newest mesh is drawn with (4, or 1 for a big mesh on a software
    /// renderer, or for every mesh after [`Self::set_single_sampled`]).
    pub fn samples(&self) -> u32 {
        if self.gpu.software && self.newest_faces > self.gpu.single_sample_faces {
            1
        } else {
            SAMPLE_COUNT
        }
    }

    /// Makes sure the offscreen target has `size` (physical pixels, each at least 1) and the
    /// current mesh's [`Self::samples`]; returns `true` when it was (re)created, after which the
    /// egui texture must point at [`Self::color_view`] again.
    pub fn ensure_target(&mut self, device: &wgpu::Device, size: [u32; 2]) -> bool {
        let size = [size[0].clamp(1, 8192), size[1].clamp(1, 8192)];
        let samples = self.samples();
        if self
            .target
            .as_ref()
            .is_some_and(|t| t.size == size && t.samples == samples)
        {
            return false;
        }
        if samples != SAMPLE_COUNT && self.gpu.single_sample.is_none() {
            self.gpu.single_sample = Some(Pipelines::new(device, samples, &self.gpu.materials));
        }
        self.target = Some(Target::new(device, size, samples));
        self.target_has_image = false;
        // The image in the old target is gone (the meshes and their kept images are as they
        // were: a kept image of this size is shown again).
        self.drawn = None;
        self.parts.progress = None;
        self.kept.request = None;
        true
    }

    /// The image the mesh is drawn into, once [`Self::ensure_target`] made one.
    pub fn color_view(&self) -> Option<&wgpu::TextureView> {
        self.target.as_ref().map(|t| &t.resolved)
    }

    /// Records the drawing of the mesh into the offscreen target, unless the image there already
    /// shows exactly this. Returns whether it drew.
    ///
    /// When the image has more faces (plus wireframe edges) than [`Self::set_faces_per_frame`]
    /// allows, each call draws the next part of it into a second target instead, and the
    /// complete image is copied into the shown target by the call that draws its last part. An
    /// image being drawn is finished before one with newer parameters begins (an orbit shows
    /// complete images, each a few frames late); a new mesh or new positions drop it.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        params: &DrawParams,
    ) -> bool {
        self.poll_uploads(queue);
        let wrong_size = self.target.as_ref().is_none_or(|t| t.size != params.size);
        if wrong_size {
            return false;
        }
        // The image of the mesh that just left the screen, before anything is drawn over it.
        self.keep_outgoing_image(device, encoder);
        self.prune_images();
        if self.parts.progress.is_none() && self.drawn.as_ref() == Some(params) {
            return false;
        }
        // The mesh's kept image, when it shows exactly this (an image half drawn with older
        // parameters is dropped for it).
        if self.drawn.as_ref() != Some(params) && self.restore_kept_image(encoder, params) {
            return true;
        }
        let params = match &self.parts.progress {
            Some(progress) => progress.params,
            None => *params,
        };
        self.wireframe = params.wireframe;
        let started = web_time::Instant::now();
        self.ensure_materials(device, queue);
        let (materials, colours, uvs) = self.mesh.as_ref().map_or((false, false, false), |m| {
            let look = m.appearance.as_deref();
            (
                !params.clay && look.is_some_and(|l| !l.is_plain()),
                look.is_some_and(|l| l.colours.is_some()),
                look.is_some_and(|l| l.uvs.is_some()),
            )
        });
        let uniforms = Uniforms::of(&params, materials, colours, uvs);
        if params.wireframe {
            self.ensure_lines(device, queue);
        }
        let Some(pipelines) = self.pipelines() else {
            return false;
        };
        queue.write_buffer(&pipelines.uniform_buffer, 0, bytemuck::bytes_of(&uniforms));
        let Some(target) = &self.target else {
            return false;
        };
        let mesh = self.mesh.as_ref();
        let whole = Part::whole(mesh, params.wireframe);
        let (faces, edges) = (whole.faces.end, whole.edges.end);
        let total = faces as usize + edges as usize;
        let at_once = total <= self.parts.faces_per_frame || !self.target_has_image;
        if at_once {
            let plain = self.gpu.materials.plain.as_ref();
            pipelines.draw(encoder, target, (mesh, plain), params.wireframe);
            self.last_draw_time = started.elapsed();
        } else {
            match self.draw_next_part(device, encoder, params, (faces, total), started) {
                PartDrawn::NoTarget => return false,
                PartDrawn::MoreToDraw => return true,
                PartDrawn::Complete => {}
            }
        }
        self.target_has_image = true;
        self.drawn = Some(params);
        self.counts.drawn += 1;
        true
    }

    /// The pipelines that match the target's sampling (the mesh may have changed since the
    /// target was made: it is made again in the next frame's `ensure_target`); `None` without a
    /// target, or without the single-sample pipelines it needs.
    fn pipelines(&self) -> Option<&Pipelines> {
        match (&self.target, &self.gpu.single_sample) {
            (Some(target), _) if target.samples == SAMPLE_COUNT => Some(&self.gpu.pipelines),
            (Some(_), Some(single)) => Some(single),
            _ => None,
        }
    }

    /// Draws the next part of an image too big for one frame (of `faces` faces and `total` faces
    /// and wireframe edges) into the work target; the part that completes it is copied into the
    /// shown target. `started` is when this frame's recording began.
    fn draw_next_part(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        params: DrawParams,
        (faces, total): (u32, usize),
        started: web_time::Instant,
    ) -> PartDrawn {
        let Some((size, samples)) = self.target.as_ref().map(|t| (t.size, t.samples)) else {
            return PartDrawn::NoTarget;
        };
        if self
            .parts
            .work
            .as_ref()
            .is_none_or(|w| w.size != size || w.samples != samples)
        {
            self.parts.work = Some(Target::new(device, size, samples));
        }
        let (Some(pipelines), Some(target), Some(work)) =
            (self.pipelines(), &self.target, &self.parts.work)
        else {
            return PartDrawn::NoTarget;
        };
        let start = self.parts.progress.as_ref().map_or(0, |p| p.done);
        let end = (start as usize + self.parts.faces_per_frame).min(total) as u32;
        let part = Part {
            faces: start.min(faces)..end.min(faces),
            edges: start.saturating_sub(faces)..end.saturating_sub(faces),
            first: start == 0,
        };
        let last = end as usize == total;
        pipelines.draw_part(
            encoder,
            work,
            (self.mesh.as_ref(), self.gpu.materials.plain.as_ref()),
            params.wireframe,
            &part,
            last,
        );
        self.counts.parts += 1;
        let recording = self
            .parts
            .progress
            .as_ref()
            .map_or(Duration::ZERO, |p| p.recording)
            + started.elapsed();
        if !last {
            self.parts.progress = Some(Progress {
                params,
                done: end,
                recording,
            });
            (self.repaint)();
            return PartDrawn::MoreToDraw;
        }
        work.copy_image_to(encoder, target);
        self.parts.progress = None;
        self.last_draw_time = recording;
        PartDrawn::Complete
    }
}
