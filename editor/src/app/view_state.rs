//! What the 3D views show: the two viewports' renderers, the camera, the record of what each
//! viewport has uploaded and holds on the GPU, the file's colours as the viewport draws them,
//! and the state of "Save image".

use std::sync::Arc;

use crate::render::appearance::Appearance;
use crate::render::Viewport3d;

use super::camera::OrbitCamera;
use super::held_views::HeldView;
use super::shown::Shown;

/// The views' state, apart from the document they show.
#[derive(Default)]
pub(in crate::app) struct ViewState {
    pub(in crate::app) viewport: Option<Viewport3d>,
    pub(in crate::app) viewport_before: Option<Viewport3d>,
    pub(in crate::app) camera: OrbitCamera,
    /// The camera as the last fit left it: while the user has not moved it since, switching to
    /// or from the side-by-side view fits it again (the halves are narrower than tall).
    pub(in crate::app) fitted_camera: Option<OrbitCamera>,
    pub(in crate::app) shown: Option<Shown>,
    pub(in crate::app) shown_before: Option<Shown>,
    /// Per slot, the meshes its renderer holds on the GPU and what was uploaded with them.
    pub(in crate::app) held_views: [Vec<HeldView>; 2],
    /// Largest heat-map scalar uploaded per slot (the legend's and the colour map's top).
    pub(in crate::app) heat_max: [Option<f32>; 2],
    /// The file's colours as the viewport draws them, made once per loaded file (keyed by its
    /// [`fairmesh::io::Source`], held so that it is never mistaken for another); `None` inside
    /// when the file has none.
    pub(in crate::app) appearance: Option<(Arc<fairmesh::io::Source>, Option<Arc<Appearance>>)>,
    /// What could not be shown of the file's colours (a texture that did not decode), said in
    /// the Mesh section; made with [`Self::appearance`].
    pub(in crate::app) appearance_warnings: Vec<String>,
    /// The single view shows "before" instead of "after" (toggled with B).
    pub(in crate::app) show_before: bool,
    pub(in crate::app) shown_counts: (usize, usize),
    /// Where the viewport was drawn in the last frame (points).
    pub(in crate::app) viewport_rect: Option<egui::Rect>,
    /// Draw the kept sharp edges over the mesh until then (their controls are hovered or were
    /// just changed).
    pub(in crate::app) sharp_edges_shown_until: Option<web_time::Instant>,
    pub(in crate::app) sharp_edges_drawn: usize,
    /// "Save image" was asked for: the next frame is drawn without the mouse hints and captured.
    pub(in crate::app) capture_next_frame: bool,
    /// This frame is the one captured for "Save image".
    pub(in crate::app) capturing_view: bool,
}

impl ViewState {
    /// The views of a new window: a renderer per viewport when there is a wgpu render state.
    pub(in crate::app) fn new(cc: &eframe::CreationContext<'_>) -> Self {
        let viewport =
            || (cc.wgpu_render_state.as_ref()).map(|state| Viewport3d::new(state, &cc.egui_ctx));
        Self {
            viewport: viewport(),
            viewport_before: viewport(),
            ..Self::default()
        }
    }

    /// The viewports there are (none without a wgpu render state).
    pub(in crate::app) fn viewports(&self) -> impl Iterator<Item = &Viewport3d> {
        [&self.viewport, &self.viewport_before]
            .into_iter()
            .flatten()
    }
}
