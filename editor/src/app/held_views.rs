//! The meshes each viewport keeps on the GPU while they are current (the input mesh, the level
//! mesh, the faired result): switching between them picks other buffers on the GPU and uploads
//! nothing (see `render::pipeline` `held.rs`). Beside each held mesh the app keeps what it
//! uploaded with it (heat-map scalars, mask tint), so the colours shown with a held mesh are
//! always those written for that very mesh.

use crate::app::shown::{Shown, ShownMesh, Slot};
use crate::app::state::HierarchyState;
use crate::app::App;
use crate::render::{MeshKey, Viewport3d, MAX_HELD_MESHES};

/// A mesh a viewport holds on the GPU, and what was uploaded with it.
#[derive(Clone, Copy, Debug)]
pub(in crate::app) struct HeldView {
    pub(in crate::app) key: MeshKey,
    /// What its buffers show: the mesh, its heat map's reference, its mask tint.
    pub(in crate::app) shown: Shown,
    /// The top of its heat-map scalars.
    pub(in crate::app) heat_max: Option<f32>,
    /// Its vertex and face counts.
    pub(in crate::app) counts: (usize, usize),
}

/// The renderer's key for `shown`'s mesh: the family is the document and which of its meshes
/// (a result on the input's triangles and one on the hierarchy's base mesh have different
/// triangles, so they are two families); the version is the result's serial or the level.
pub(in crate::app) fn mesh_key(shown: Shown, base_matches_original: bool) -> MeshKey {
    let (which, version) = match shown.what {
        ShownMesh::Original => (0, 0),
        ShownMesh::Faired { serial } if base_matches_original => (1, serial),
        ShownMesh::Faired { serial } => (2, serial),
        ShownMesh::Level { level } => (3, level as u64),
    };
    MeshKey {
        family: shown.document.get() << 2 | which,
        version,
    }
}

/// The document a key's family belongs to.
fn document_of(key: MeshKey) -> u64 {
    key.family >> 2
}

impl App {
    /// The renderer's key for the mesh `shown` names, in the document now loaded.
    pub(in crate::app) fn held_key(&self, shown: Shown) -> MeshKey {
        let matches = self.document.as_ref().is_none_or(|d| match &d.hierarchy {
            HierarchyState::Ready {
                base_matches_original,
                ..
            } => *base_matches_original,
            _ => true,
        });
        mesh_key(shown, matches)
    }

    /// Shows `wanted`'s mesh from the GPU when the slot's renderer holds it: what was uploaded
    /// with it, or `None` (then it must be uploaded).
    pub(in crate::app) fn show_held(&mut self, slot: Slot, wanted: Shown) -> Option<HeldView> {
        let key = self.held_key(wanted);
        let views = &mut self.view.held_views[slot as usize];
        let index = views.iter().position(|h| h.key == key)?;
        let viewport = match slot {
            Slot::Main => self.view.viewport.as_ref(),
            Slot::Before => self.view.viewport_before.as_ref(),
        }?;
        if viewport.show_held(key) {
            Some(views[index])
        } else {
            views.remove(index);
            None
        }
    }

    /// Records what the slot's renderer now shows (it replaces its family's record) and forgets
    /// the meshes of other documents, here and on the GPU.
    pub(in crate::app) fn remember_view(&mut self, slot: Slot, view: HeldView) {
        let document = document_of(view.key);
        let views = &mut self.view.held_views[slot as usize];
        views.retain(|h| h.key.family != view.key.family && document_of(h.key) == document);
        views.insert(0, view);
        views.truncate(MAX_HELD_MESHES);
        let viewport = match slot {
            Slot::Main => self.view.viewport.as_ref(),
            Slot::Before => self.view.viewport_before.as_ref(),
        };
        if let Some(viewport) = viewport {
            viewport.retain_held(|key| document_of(key) == document);
        }
    }
}

impl App {
    /// What a viewport's renderer has written to the GPU so far (`None` without a renderer).
    pub fn gpu_uploads(&self, slot: Slot) -> Option<crate::render::UploadCounts> {
        self.slot_viewport(slot).map(|v| v.uploads())
    }

    /// The meshes a viewport's renderer holds on the GPU (the one on screen included) and the
    /// bytes they take (`None` without a renderer).
    pub fn held_meshes(&self, slot: Slot) -> Option<(usize, u64)> {
        self.slot_viewport(slot).map(|v| v.held_meshes())
    }

    /// What a viewport's renderer has put in its image so far: images drawn, parts of images
    /// drawn over several frames, held meshes' kept images shown again (`None` without a
    /// renderer).
    pub fn image_counts(&self, slot: Slot) -> Option<crate::render::ImageCounts> {
        self.slot_viewport(slot).map(|v| v.image_counts())
    }

    /// Bytes of the kept images (the held meshes' last complete images) of a viewport's
    /// renderer (`None` without a renderer).
    pub fn kept_image_bytes(&self, slot: Slot) -> Option<u64> {
        self.slot_viewport(slot).map(|v| v.image_bytes())
    }
}

/// One line of the Performance section's list of the meshes held on the GPU.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::app) struct HeldLine {
    /// The mesh as the toolbar names it ("Faired", "Level mesh M3", "Input mesh"), and the
    /// view holding it when that is the Before view.
    pub(in crate::app) name: String,
    /// Bytes of its buffers.
    pub(in crate::app) bytes: u64,
    /// Bytes of its kept image (0 without one).
    pub(in crate::app) image_bytes: u64,
    pub(in crate::app) on_screen: bool,
}

/// The meshes the viewports hold on the GPU (`views`: what the app recorded for each slot), the
/// main view's first and each view's mesh on screen first.
pub(in crate::app) fn held_lines(
    views: &[Vec<HeldView>; 2],
    viewports: [Option<&Viewport3d>; 2],
) -> Vec<HeldLine> {
    let mut lines = Vec::new();
    for (slot, viewport) in viewports.into_iter().enumerate() {
        let Some(viewport) = viewport else {
            continue;
        };
        for held in viewport.held_list() {
            let view = views[slot].iter().find(|v| Some(v.key) == held.key);
            let name = match view.map(|v| v.shown.what) {
                Some(ShownMesh::Original) => "Input mesh".to_owned(),
                Some(ShownMesh::Faired { .. }) => "Faired".to_owned(),
                Some(ShownMesh::Level { level }) => format!("Level mesh M{level}"),
                None => "A mesh being replaced".to_owned(),
            };
            lines.push(HeldLine {
                name: match slot == Slot::Before as usize {
                    true => format!("{name} (Before view)"),
                    false => name,
                },
                bytes: held.bytes,
                image_bytes: held.image_bytes,
                on_screen: held.on_screen,
            });
        }
    }
    lines
}
