//! The renderer's upload thread ([`Uploader`]): the jobs it takes ([`UploadJob`]: a big mesh's
//! buffers, its wireframe edges, new positions' normals, and new buffers when the positions
//! split the shading elsewhere), what comes back ([`Uploaded`]), and the upload in flight
//! ([`PendingMesh`]).

use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Mutex};

use super::buffers::{draw_normals, draw_triangles, line_buffer, DrawLayout, MeshBuffers};
use super::MeshSource;
use crate::render::appearance::Appearance;
use crate::render::normals::CornerTable;

/// Work for the upload thread.
pub(super) enum UploadJob {
    Mesh {
        generation: u64,
        source: Arc<dyn MeshSource>,
        with_lines: bool,
    },
    /// The wireframe's edges of the draw triangles of `look` (or the mesh's).
    Lines {
        generation: u64,
        source: Arc<dyn MeshSource>,
        look: Option<Arc<Appearance>>,
    },
    /// New positions for the mesh of `generation`, whose buffers have `layout`: their normals.
    Move(Box<MoveJob>),
}

/// New positions for the mesh of `generation` (drawn with `layout`, its welded triangles'
/// corners `corners`): their normals, and new buffers when the shading splits elsewhere now.
pub(super) struct MoveJob {
    pub(super) generation: u64,
    pub(super) serial: u64,
    pub(super) source: Arc<dyn MeshSource>,
    pub(super) corners: Arc<CornerTable>,
    pub(super) layout: Arc<DrawLayout>,
}

/// What a move gives: normals for the buffers' layout, or new buffers.
pub(super) enum Moved {
    Normals(Vec<[f32; 3]>),
    Rebuilt(Box<MeshBuffers>),
}

impl MoveJob {
    /// The move's normals, or new buffers (made on `device`) when its draw vertices changed.
    pub(super) fn run(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Moved {
        let drawn = draw_normals(self.source.as_ref(), &self.corners, Some(&self.layout));
        if Arc::ptr_eq(&drawn.layout, &self.layout) {
            return Moved::Normals(drawn.normals);
        }
        Moved::Rebuilt(Box::new(MeshBuffers::create_with(
            device,
            queue,
            self.source.clone(),
            self.corners.clone(),
            drawn,
            false,
            self.generation,
        )))
    }
}

impl UploadJob {
    fn generation(&self) -> u64 {
        match self {
            Self::Mesh { generation, .. } | Self::Lines { generation, .. } => *generation,
            Self::Move(job) => job.generation,
        }
    }

    fn run(self, device: &wgpu::Device, queue: &wgpu::Queue) -> Uploaded {
        match self {
            UploadJob::Mesh {
                generation,
                source,
                with_lines,
            } => Uploaded::Mesh(Box::new(MeshBuffers::create(
                device, queue, source, with_lines, generation,
            ))),
            UploadJob::Lines {
                generation,
                source,
                look,
            } => Uploaded::Lines {
                generation,
                lines: line_buffer(
                    device,
                    queue,
                    draw_triangles(source.as_ref(), look.as_deref()),
                ),
                look,
            },
            UploadJob::Move(job) => Uploaded::Moved {
                generation: job.generation,
                serial: job.serial,
                moved: job.run(device, queue),
                source: job.source,
            },
        }
    }
}

pub(super) enum Uploaded {
    Mesh(Box<MeshBuffers>),
    /// Filling the buffers of `generation` panicked inside wgpu.
    Failed {
        generation: u64,
    },
    /// Edges of the draw triangles of `look` (dropped if the mesh is drawn with other ones).
    Lines {
        generation: u64,
        look: Option<Arc<Appearance>>,
        lines: (wgpu::Buffer, u32),
    },
    Moved {
        generation: u64,
        serial: u64,
        source: Arc<dyn MeshSource>,
        moved: Moved,
    },
}

/// The renderer's upload thread: fills buffers for big meshes off the UI thread. Only the newest
/// generation's jobs in the queue are done; older ones are superseded.
pub(super) struct Uploader {
    jobs: Option<Sender<UploadJob>>,
    /// In a mutex only because egui_wgpu's callback resources must be `Sync`.
    pub(super) done: Mutex<Receiver<Uploaded>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Uploader {
    pub(super) fn spawn(
        device: wgpu::Device,
        queue: wgpu::Queue,
        on_done: Arc<dyn Fn() + Send + Sync>,
    ) -> Option<Self> {
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
                        .rposition(|job| matches!(job, UploadJob::Move(_)));
                    for (index, job) in batch.into_iter().enumerate() {
                        let old_move =
                            matches!(job, UploadJob::Move(_)) && Some(index) != last_move;
                        if Some(job.generation()) != newest || old_move {
                            continue;
                        }
                        let generation = job.generation();
                        let upload = std::panic::AssertUnwindSafe(|| job.run(&device, &queue));
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
    pub(super) fn send(&self, job: UploadJob) -> Result<(), UploadJob> {
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

/// A mesh whose buffers the upload thread is filling.
pub(super) struct PendingMesh {
    pub(super) generation: u64,
    /// What the mesh shows (kept as the buffers' key when it lands).
    pub(super) key: Option<super::MeshKey>,
    pub(super) vertex_count: usize,
    /// Scalars set while the upload was in flight, written once it lands.
    pub(super) scalars: Option<Vec<f32>>,
    /// Mask weights set while the upload was in flight, written once it lands.
    pub(super) mask: Option<Vec<f32>>,
}

/// What the renderer has on the upload thread, and what waits for it to land.
pub(super) struct InFlight {
    /// The upload thread (`None`: it failed to start; every upload happens in the calling
    /// frame).
    pub(super) uploader: Option<Uploader>,
    /// Counts `MeshRenderer::set_mesh` calls; an upload that lands for an older one is dropped.
    pub(super) generation: u64,
    /// The upload in flight on the upload thread (the previous mesh stays on screen meanwhile).
    pub(super) pending: Option<PendingMesh>,
    /// Generation of the mesh whose wireframe edges the upload thread is building.
    pub(super) lines_requested: Option<u64>,
    /// Counts `MeshRenderer::set_positions` calls; normals that land for an older one are
    /// dropped.
    pub(super) move_serial: u64,
    /// The newest positions whose normals the upload thread is computing (the mesh on screen
    /// keeps its positions until they land, so positions and normals always match).
    pub(super) pending_move: Option<u64>,
    /// Scalars and mask weights set while those positions are on their way: they belong to
    /// the new positions (a heat map of the new result), so they are written with them.
    pub(super) move_scalars: Option<Vec<f32>>,
    pub(super) move_mask: Option<Vec<f32>>,
    /// Meshes of at least this many bytes (positions + triangles) upload on the upload thread.
    pub(super) async_upload_bytes: usize,
}

impl InFlight {
    pub(super) fn new(uploader: Option<Uploader>) -> Self {
        Self {
            uploader,
            generation: 0,
            pending: None,
            lines_requested: None,
            move_serial: 0,
            pending_move: None,
            move_scalars: None,
            move_mask: None,
            async_upload_bytes: super::DEFAULT_ASYNC_UPLOAD_BYTES,
        }
    }

    /// A new mesh is set (its generation counted): whatever was on its way for the one before
    /// is no longer wanted.
    pub(super) fn next_mesh(&mut self) {
        self.generation += 1;
        self.pending = None;
        self.pending_move = None;
        self.move_scalars = None;
        self.move_mask = None;
        self.lines_requested = None;
    }

    /// The mesh on screen is replaced: new positions on their way for it and its wireframe's
    /// edges no longer apply. Returns whether positions were on their way.
    pub(super) fn screen_replaced(&mut self) -> bool {
        let moving = self.pending_move.take().is_some();
        self.move_scalars = None;
        self.move_mask = None;
        self.lines_requested = None;
        moving
    }

    /// Whether anything is still on its way.
    pub(super) fn any(&self) -> bool {
        self.pending.is_some() || self.lines_requested.is_some() || self.pending_move.is_some()
    }
}

/// The wireframe's edges, made when first drawn.
impl super::MeshRenderer {
    /// Builds the wireframe's edges of the mesh on screen when they are missing and fit: a big
    /// mesh's on the upload thread (the image shows the mesh without them meanwhile), a small
    /// one's here.
    pub(super) fn ensure_lines(&mut self, device: &wgpu::Device, queue: &wgpu::Queue) {
        if let Some(mesh) = &mut self.mesh {
            let faces = mesh.index_count as usize / 3;
            let fits = faces as u64 * 24 <= self.gpu.max_buffer_size;
            if fits
                && !self.lines_failed
                && mesh.lines.is_none()
                && self.in_flight.lines_requested != Some(mesh.generation)
            {
                // A big mesh's edges are built on the upload thread (the image shows the
                // mesh without them meanwhile); a small one's here.
                let bytes = (mesh.vertex_count + faces) * 12;
                let job = UploadJob::Lines {
                    generation: mesh.generation,
                    source: mesh.source.clone(),
                    look: mesh.appearance.clone(),
                };
                let sent = match &self.in_flight.uploader {
                    Some(uploader) if bytes >= self.in_flight.async_upload_bytes => {
                        uploader.send(job).is_ok()
                    }
                    _ => false,
                };
                if sent {
                    self.in_flight.lines_requested = Some(mesh.generation);
                } else {
                    let triangles =
                        draw_triangles(mesh.source.as_ref(), mesh.appearance.as_deref());
                    mesh.lines = Some(line_buffer(device, queue, triangles));
                }
            }
        }
    }
}
