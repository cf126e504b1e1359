//! Meshes a renderer keeps on the GPU besides the one on screen, so that showing one of them
//! again (the editor's switch between the input mesh, a level and the faired result) picks other
//! buffers: no upload, no normals, no work that grows with the mesh.
//!
//! The caller names what each mesh shows with a [`MeshKey`]: a *family* (which of its meshes:
//! for the editor a document and the input, the level or the result) and a *version* (which
//! content of that family: the level, the result's serial). A family holds one mesh: a new
//! version replaces the old one (new buffers, or the old ones with new positions). At most
//! [`MAX_HELD_MESHES`] meshes are kept, the one on screen included; the least recently shown
//! goes first.

use super::buffers::MeshBuffers;
use super::{DrawParams, MeshRenderer, MeshSource};
use egui_wgpu::wgpu;
use std::sync::Arc;

/// Meshes a renderer keeps on the GPU at most, the one on screen included (a new mesh on its way
/// from the upload thread comes on top until it lands): the editor's input mesh, level mesh and
/// faired result.
pub const MAX_HELD_MESHES: usize = 3;

/// What a mesh given to the renderer shows (see the module's documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshKey {
    pub family: u64,
    pub version: u64,
}

/// A mesh a renderer holds on the GPU ([`MeshRenderer::held_list`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HeldMesh {
    /// What the caller said it shows (`None`: a mesh given without a key, not held once
    /// another is shown).
    pub key: Option<MeshKey>,
    /// Bytes of its buffers.
    pub bytes: u64,
    /// Bytes of its kept image (its last complete image; 0 without one).
    pub image_bytes: u64,
    /// It is the mesh on screen.
    pub on_screen: bool,
}

/// What a renderer has written to the GPU: whole meshes and bytes of any kind (positions,
/// normals, triangles, scalars, mask weights).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UploadCounts {
    /// Meshes given new buffers ([`MeshRenderer::set_mesh`]).
    pub meshes: u64,
    /// New positions given to a mesh's buffers ([`MeshRenderer::set_positions`]).
    pub moves: u64,
    pub bytes: u64,
}

impl UploadCounts {
    pub(super) fn count_mesh(&mut self, vertices: usize, faces: usize) {
        self.meshes += 1;
        // Positions and normals, triangles; scalars and mask weights start at zero.
        self.bytes += (vertices * 24 + faces * 12) as u64;
    }

    pub(super) fn count_positions(&mut self, vertices: usize) {
        self.moves += 1;
        self.bytes += (vertices * 24) as u64;
    }

    pub(super) fn count_per_vertex(&mut self, values: usize) {
        self.bytes += (values * 4) as u64;
    }
}

impl MeshRenderer {
    /// Shows the mesh `key` names if the renderer holds it (or is uploading it): returns `true`,
    /// having uploaded nothing. `false`: give it with [`Self::set_mesh_keyed`] or
    /// [`Self::set_positions_keyed`].
    pub fn show_held(&mut self, queue: &wgpu::Queue, key: MeshKey) -> bool {
        self.poll_uploads(queue);
        if self
            .in_flight
            .pending
            .as_ref()
            .is_some_and(|p| p.key == Some(key))
        {
            return true;
        }
        let on_screen = self.mesh.as_ref().is_some_and(|m| m.key == Some(key));
        if on_screen && self.in_flight.pending_move.is_none() {
            // A mesh on its way would replace it when it lands: it is no longer wanted.
            self.in_flight.pending = None;
            return true;
        }
        let Some(index) = self.held.iter().position(|m| m.key == Some(key)) else {
            return false;
        };
        // The mesh on its way is no longer wanted (its upload is dropped when it lands).
        self.in_flight.pending = None;
        let mesh = self.held.remove(index);
        self.replace_current(mesh);
        true
    }

    /// Moves the vertices of `key`'s family's mesh (on screen or held) to `source`'s positions and
    /// shows it, as [`Self::set_positions`] does; `false` when the renderer holds no mesh of that
    /// family with `source`'s vertex count.
    pub fn set_positions_keyed(
        &mut self,
        queue: &wgpu::Queue,
        source: Arc<dyn MeshSource>,
        key: MeshKey,
    ) -> bool {
        self.poll_uploads(queue);
        if self.in_flight.pending.is_some() {
            return false;
        }
        let vertices = source.positions().len();
        let of_family = |m: &MeshBuffers| {
            m.key.is_some_and(|k| k.family == key.family) && m.vertex_count == vertices
        };
        if !self.mesh.as_ref().is_some_and(of_family) {
            let Some(index) = self.held.iter().position(of_family) else {
                return false;
            };
            let mesh = self.held.remove(index);
            self.replace_current(mesh);
        }
        if let Some(mesh) = &mut self.mesh {
            mesh.key = Some(key);
        }
        self.set_positions(queue, source)
    }

    /// Keeps only the held meshes whose key `keep` accepts (the one on screen stays).
    pub fn retain_held(&mut self, keep: impl Fn(MeshKey) -> bool) {
        self.held.retain(|m| m.key.is_some_and(&keep));
        self.prune_images();
    }

    /// Bytes of GPU memory the meshes take: the one on screen and the held ones.
    pub fn mesh_bytes(&self) -> u64 {
        let held: u64 = self.held.iter().map(MeshBuffers::gpu_bytes).sum();
        held + self.mesh.as_ref().map_or(0, MeshBuffers::gpu_bytes)
    }

    /// Meshes held on the GPU, the one on screen included.
    pub fn meshes_held(&self) -> usize {
        self.held.len() + usize::from(self.mesh.is_some())
    }

    /// The meshes held on the GPU, the one on screen first, with their bytes and their kept
    /// images' bytes.
    pub fn held_list(&self) -> Vec<HeldMesh> {
        let entry = |mesh: &MeshBuffers, on_screen| HeldMesh {
            key: mesh.key,
            bytes: mesh.gpu_bytes(),
            image_bytes: self.image_bytes_of(mesh.generation),
            on_screen,
        };
        let current = self.mesh.iter().map(|m| entry(m, true));
        current
            .chain(self.held.iter().map(|m| entry(m, false)))
            .collect()
    }

    /// Puts `mesh` on screen; the mesh there is held unless it is of `mesh`'s family (replaced)
    /// or has no key, or its new positions are still on their way (its buffers do not show
    /// its key's version yet). A held mesh keeps the complete image of it the target holds
    /// (`kept.rs`); `mesh`'s own kept image, if any, is shown again when the view is unchanged.
    pub(super) fn replace_current(&mut self, mesh: MeshBuffers) {
        let moving = self.in_flight.screen_replaced();
        self.lines_failed = false;
        self.problem = None;
        self.newest_faces = mesh.index_count as usize / 3;
        // The target's complete image shows the mesh leaving (an image half drawn is dropped).
        let image = self.drawn.take();
        self.parts.progress = None;
        let family = mesh.key.map(|k| k.family);
        let generation = mesh.generation;
        if let Some(old) = self.mesh.replace(mesh) {
            let old_family = old.key.map(|k| k.family);
            if !moving && old_family.is_some() && old_family != family {
                // An image drawn with the wireframe on before its edges were built lacks them.
                let complete = |p: &DrawParams| !p.wireframe || old.lines.is_some();
                if let Some(params) = image.filter(complete) {
                    self.keep_image_of(old.generation, params);
                }
                self.held.insert(0, old);
            }
        }
        self.held.truncate(MAX_HELD_MESHES - 1);
        // Back before anything was drawn since it left: its image is still in the target.
        self.drawn = self.image_still_in_target(generation);
        self.prune_images();
    }

    /// Drops the held mesh of `key`'s family: a new version replaces it.
    pub(super) fn drop_family(&mut self, key: Option<MeshKey>) {
        // The mesh on screen is about to be replaced: if its new positions are still on their
        // way, its buffers are not its key's version, so it is not kept.
        if self.in_flight.pending_move.is_some() {
            if let Some(mesh) = &mut self.mesh {
                mesh.key = None;
            }
        }
        if let Some(key) = key {
            self.held
                .retain(|m| m.key.is_none_or(|k| k.family != key.family));
        }
        self.prune_images();
    }
}
