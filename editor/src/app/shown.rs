//! What a viewport shows: which of the two viewports ([`Slot`]), which mesh ([`ShownMesh`]: the
//! input, a level, a result) and with which colours ([`Shown`]), the record the view syncing
//! ([`super::view_sync`]) and the meshes held on the GPU ([`super::held_views`]) both keep.

use crate::app::generation::GenerationId;
use crate::app::state::HeatReference;

/// What a viewport has uploaded, to know when to upload again: one record per viewport, so
/// that its shape, its heat map and its mask tint are always of one result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::app) struct Shown {
    pub(in crate::app) document: GenerationId,
    pub(in crate::app) what: ShownMesh,
    /// The heat map's reference, when the scalars on the GPU are `what`'s own distances from
    /// it (never another result's).
    pub(in crate::app) heat: Option<HeatReference>,
    /// The painted mask's revision, when its weights are tinted over the mesh.
    pub(in crate::app) mask: Option<u64>,
}

/// The two viewports: the main one (the view mode's mesh: the result, a level, the original)
/// and the "before" one (the document's mesh) for the toggle, split and side-by-side views.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    Main = 0,
    Before = 1,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::app) enum ShownMesh {
    Original,
    Faired { serial: u64 },
    Level { level: usize },
}
