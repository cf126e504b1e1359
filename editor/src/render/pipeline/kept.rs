//! The last complete image of each mesh the renderer holds ([`KeptImage`]), so that showing a
//! held mesh again with the same [`DrawParams`] (camera, size, shading, lighting, wireframe,
//! heat map, mask tint, clay) copies its image into the target instead of drawing it: one frame
//! even where drawing a big mesh takes many (a software renderer draws it in parts).
//!
//! When a mesh leaves the screen with a complete image of it in the target, that image is copied
//! into the mesh's own texture by the next [`MeshRenderer::render`], before anything else is
//! drawn into the target. An image is used again only if the mesh's buffers did not change since
//! (every change calls `MeshRenderer::redraw`, which forgets the image of the mesh on screen; a
//! held mesh's buffers never change) and only for exactly the parameters it was drawn with;
//! anything else is drawn as before. A kept image is the target's size in RGBA (4 bytes a pixel):
//! 2.9 MB for the 970×738-pixel view of a 1280×800 window. There is at most one per mesh the
//! renderer holds (the one on screen keeps its texture to reuse), so at most
//! [`super::MAX_HELD_MESHES`] per renderer; an image goes with its mesh.

use super::{DrawParams, MeshRenderer};

/// The held meshes' kept images, and the image of a mesh that left the screen still to copy.
#[derive(Default)]
pub(super) struct KeptImages {
    pub(super) images: Vec<KeptImage>,
    /// A mesh that left the screen (its generation) whose complete image, drawn with these
    /// parameters, is still in the target: the next render copies it into its kept image.
    pub(super) request: Option<(u64, DrawParams)>,
}

/// A held mesh's last complete image.
pub(super) struct KeptImage {
    /// The mesh's `MeshBuffers::generation` (which `set_mesh` call made its buffers).
    generation: u64,
    texture: wgpu::Texture,
    /// What the image shows; `None` once the mesh's buffers changed (the texture stays, to be
    /// written again).
    params: Option<DrawParams>,
}

impl KeptImage {
    fn bytes(&self) -> u64 {
        let size = self.texture.size();
        u64::from(size.width) * u64::from(size.height) * 4
    }
}

/// What a renderer has put in its target so far (tests and the performance readout).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ImageCounts {
    /// Complete images drawn.
    pub drawn: u64,
    /// Parts drawn of images drawn over several frames (a big mesh on a software renderer).
    pub parts: u64,
    /// Images shown again from a held mesh's kept image, with nothing drawn.
    pub restored: u64,
}

impl MeshRenderer {
    pub fn image_counts(&self) -> ImageCounts {
        self.counts
    }

    /// The mesh of `generation` leaves the screen, the target holding its complete image drawn
    /// with `params`: keep that image (copied by the next `render`, unless the mesh's kept
    /// image is that one already).
    pub(super) fn keep_image_of(&mut self, generation: u64, params: DrawParams) {
        self.kept.request = Some((generation, params));
    }

    /// `generation`'s mesh comes back on screen before the target was drawn into since it left:
    /// the target still holds its image (returns the parameters it was drawn with).
    pub(super) fn image_still_in_target(&mut self, generation: u64) -> Option<DrawParams> {
        let (requested, params) = self.kept.request?;
        (requested == generation).then(|| {
            self.kept.request = None;
            params
        })
    }

    /// Copies the image of the mesh that left the screen into its kept texture (recorded before
    /// anything is drawn into the target).
    pub(super) fn keep_outgoing_image(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        let Some((generation, params)) = self.kept.request.take() else {
            return;
        };
        let Some(target) = self.target.as_ref().filter(|t| t.size == params.size) else {
            return;
        };
        if !self.held.iter().any(|m| m.generation == generation) {
            return;
        }
        let index = match self
            .kept
            .images
            .iter()
            .position(|k| k.generation == generation)
        {
            Some(index) if self.kept.images[index].params == Some(params) => return,
            Some(index) => index,
            None => {
                self.kept.images.push(KeptImage {
                    generation,
                    texture: target.image_texture(device),
                    params: None,
                });
                self.kept.images.len() - 1
            }
        };
        let kept = &mut self.kept.images[index];
        let size = kept.texture.size();
        if [size.width, size.height] != target.size {
            kept.texture = target.image_texture(device);
        }
        target.copy_image_into(encoder, &kept.texture);
        kept.params = Some(params);
    }

    /// Copies the mesh on screen's kept image into the target when it shows exactly `params`:
    /// returns whether it did (the target then holds that complete image).
    pub(super) fn restore_kept_image(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        params: &DrawParams,
    ) -> bool {
        let (Some(mesh), Some(target)) = (&self.mesh, &self.target) else {
            return false;
        };
        let Some(kept) = self
            .kept
            .images
            .iter()
            .find(|k| k.generation == mesh.generation && k.params.as_ref() == Some(params))
        else {
            return false;
        };
        target.copy_image_from(encoder, &kept.texture);
        self.drawn = Some(*params);
        self.parts.progress = None;
        self.wireframe = params.wireframe;
        self.target_has_image = true;
        self.counts.restored += 1;
        // The frame after shows (and logs) the image, as it does after a drawn one.
        (self.repaint)();
        true
    }

    /// The mesh on screen changed: its kept image no longer shows it.
    pub(super) fn forget_current_image(&mut self) {
        if let Some(mesh) = &self.mesh {
            forget_image(&mut self.kept.images, mesh.generation);
        }
    }

    /// Drops the kept images of meshes the renderer no longer holds.
    pub(super) fn prune_images(&mut self) {
        let on_screen = self.mesh.as_ref().map(|m| m.generation);
        let held = &self.held;
        self.kept.images.retain(|k| {
            on_screen == Some(k.generation) || held.iter().any(|m| m.generation == k.generation)
        });
    }

    /// Bytes of GPU memory the kept images take.
    pub fn image_bytes(&self) -> u64 {
        self.kept.images.iter().map(KeptImage::bytes).sum()
    }

    /// Bytes of the kept image of the mesh of `generation` (0 without one).
    pub(super) fn image_bytes_of(&self, generation: u64) -> u64 {
        self.kept
            .images
            .iter()
            .filter(|k| k.generation == generation)
            .map(KeptImage::bytes)
            .sum()
    }
}

/// The buffers of the mesh of `generation` changed: its kept image no longer shows it.
pub(super) fn forget_image(kept: &mut [KeptImage], generation: u64) {
    for image in kept.iter_mut().filter(|k| k.generation == generation) {
        image.params = None;
    }
}
