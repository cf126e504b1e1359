//! Keeping the viewports' GPU buffers in step with what should be shown: which mesh each
//! viewport wants (the result, a level, the input mesh), uploading it when it changed, the heat
//! map's scalars and range, the draw parameters and fitting the camera.

use std::sync::Arc;

use crate::app::camera::OrbitCamera;
use crate::app::held_views::HeldView;
use crate::app::shown::{Shown, ShownMesh, Slot};
use crate::app::state::{
    self, CompareView, Document, HeatReference, HierarchyState, Settings, ViewMode,
};
use crate::app::App;
use crate::render::appearance::Appearance;
use crate::render::{CornerNormals, DrawParams, MeshSource, Viewport3d};
use fairmesh::hierarchy;
use fairmesh::TriMesh;

/// How one viewport's image is coloured, apart from the camera and the settings: the heat map's
/// range and the painted mask's tint (see [`App::slot_look`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(in crate::app) struct SlotLook {
    pub(in crate::app) scalar_range: Option<[f32; 2]>,
    pub(in crate::app) mask_tint: bool,
}

impl SlotLook {
    /// What a renderer is asked to draw with, for an image in `rect` seen by `camera`.
    pub(in crate::app) fn draw_params(
        self,
        camera: &OrbitCamera,
        settings: &Settings,
        rect: egui::Rect,
    ) -> DrawParams {
        let aspect = rect.width() / rect.height().max(1.0);
        DrawParams {
            view_proj: camera.view_proj(aspect).to_cols_array_2d(),
            eye: camera.eye().to_array(),
            light_dir: camera.light_dir().to_array(),
            fill_dir: camera.fill_dir().to_array(),
            up: camera.basis().1.to_array(),
            shading: settings.view.shading,
            lighting: settings.view.lighting,
            wireframe: settings.view.wireframe,
            scalar_range: self.scalar_range,
            mask_tint: self.mask_tint,
            clay: settings.view.clay,
            size: [0, 0],
        }
    }
}

/// The heat map's top: the 99th percentile of the distances above zero, so a few outliers do
/// not turn the rest of the mesh into the map's darkest colour (larger values take the top
/// colour), and a result faired under a small painted mask (the rest did not move) gets a
/// range from the part that moved.
pub(in crate::app) fn heat_map_top(distances: &[f32]) -> f32 {
    let mut finite: Vec<f32> = distances
        .iter()
        .copied()
        .filter(|d| d.is_finite() && *d > 0.0)
        .collect();
    if finite.is_empty() {
        return 0.0;
    }
    let rank = ((finite.len() - 1) as f64 * 0.99).round() as usize;
    let (_, value, _) = finite.select_nth_unstable_by(rank, f32::total_cmp);
    value.max(0.0)
}

/// The mesh `what` names, as a viewport takes it: its triangles (the hierarchy's M0 for a result
/// whose `base` does not match the document's mesh) and its positions. `None` when it is not
/// computed yet.
fn view_mesh(
    document: &Document,
    what: ShownMesh,
    base: Option<(Arc<hierarchy::Hierarchy>, bool)>,
    appearance: Option<Arc<Appearance>>,
) -> Option<ViewMesh> {
    Some(match what {
        ShownMesh::Original => ViewMesh {
            connectivity: SharedMesh::Mesh(document.original.clone()),
            positions: None,
            appearance,
        },
        ShownMesh::Faired { .. } => {
            let faired = document.faired.as_ref()?;
            // The file's colours need its triangles: M0 without its loose triangles has others.
            let (connectivity, appearance) = match base {
                Some((hierarchy, false)) => (SharedMesh::Base(hierarchy), None),
                _ => (SharedMesh::Mesh(document.original.clone()), appearance),
            };
            ViewMesh {
                connectivity,
                positions: Some(faired.positions.clone()),
                appearance,
            }
        }
        ShownMesh::Level { .. } => {
            let (_, mesh) = document.level_mesh.as_ref()?;
            ViewMesh {
                connectivity: SharedMesh::Mesh(mesh.clone()),
                positions: None,
                appearance: None,
            }
        }
    })
}

/// A mesh held by the document, shared with a worker or the renderer without copying it.
#[derive(Clone)]
pub(in crate::app) enum SharedMesh {
    /// The hierarchy's base mesh M0 (the connectivity faired results have).
    Base(Arc<hierarchy::Hierarchy>),
    Mesh(Arc<TriMesh>),
}

impl SharedMesh {
    pub(in crate::app) fn mesh(&self) -> &TriMesh {
        match self {
            Self::Base(hierarchy) => hierarchy.base_mesh(),
            Self::Mesh(mesh) => mesh,
        }
    }
}

/// What the viewport shows: a mesh's triangles with its own positions or other ones (a faired
/// result) over them.
pub(in crate::app) struct ViewMesh {
    pub(in crate::app) connectivity: SharedMesh,
    pub(in crate::app) positions: Option<Arc<Vec<[f32; 3]>>>,
    /// The file's colours over these triangles (the document's), when it has any.
    pub(in crate::app) appearance: Option<Arc<Appearance>>,
}

impl MeshSource for ViewMesh {
    fn positions(&self) -> &[[f32; 3]] {
        match &self.positions {
            Some(positions) => positions,
            None => &self.connectivity.mesh().positions,
        }
    }
    fn triangles(&self) -> &[[u32; 3]] {
        &self.connectivity.mesh().triangles
    }
    fn appearance(&self) -> Option<Arc<Appearance>> {
        self.appearance.clone()
    }
}

impl App {
    /// The heat map's reference now: `None` when it is off; the clean mesh only when there is one.
    pub(super) fn heat_reference(&self) -> Option<HeatReference> {
        if !self.settings.view.heat_map {
            return None;
        }
        let has_clean = self.document.as_ref().is_some_and(|d| d.clean.is_some());
        Some(match self.settings.view.heat_reference {
            HeatReference::Clean if has_clean => HeatReference::Clean,
            _ => HeatReference::Document,
        })
    }

    /// Whether the before viewport is on screen.
    pub(super) fn before_needed(&self) -> bool {
        self.settings.view.compare != CompareView::Single || self.view.show_before
    }

    /// What a viewport should show now: for the main one the view mode's mesh when it exists,
    /// otherwise the last good mesh of this document, otherwise the loaded mesh; for the before
    /// one the document's mesh. With the heat map on, a result whose distances are still being
    /// measured waits: the view keeps the picture before it, shape and colours together (see
    /// [`Self::main_view_behind`]).
    pub(super) fn wanted_mesh(&self, slot: Slot) -> Option<Shown> {
        let document = self.document.as_ref()?;
        let mask = self.mask_tint();
        let heat = self.heat_reference();
        if slot == Slot::Before {
            return Some(Shown {
                document: document.generation,
                what: ShownMesh::Original,
                heat,
                mask,
            });
        }
        let previous = self
            .view
            .shown
            .filter(|s| s.document == document.generation);
        let what = self.newest_mesh(document, previous.map(|s| s.what));
        // A level mesh has other vertices than the mask's.
        let mask = mask.filter(|_| !matches!(what, ShownMesh::Level { .. }));
        let mut wanted = Shown {
            document: document.generation,
            what,
            heat,
            mask,
        };
        if let Some(reference) = heat {
            if !matches!(what, ShownMesh::Level { .. })
                && self.heat_scalars(what, reference).is_none()
            {
                match previous {
                    // The picture on screen with its own colours, until these are measured.
                    Some(kept) if kept.heat == heat => wanted.what = kept.what,
                    _ => wanted.heat = None,
                }
            }
        }
        Some(wanted)
    }

    /// The mesh the main view's mode asks for, as far as it is computed: the newest result, the
    /// level mesh (or `previous` until one exists), the input mesh.
    fn newest_mesh(&self, document: &Document, previous: Option<ShownMesh>) -> ShownMesh {
        match self.settings.view.view_mode {
            ViewMode::Original => ShownMesh::Original,
            ViewMode::Faired => match &document.faired {
                Some(faired) => ShownMesh::Faired {
                    serial: faired.serial,
                },
                None => ShownMesh::Original,
            },
            ViewMode::Level => match &document.level_mesh {
                Some((level, _)) => ShownMesh::Level { level: *level },
                None => previous.unwrap_or(ShownMesh::Original),
            },
        }
    }

    /// Whether the main view shows an older picture than the one being computed (the input
    /// while the first result is computed, the previous result while the next one is faired or
    /// measured for the heat map, the previous level): its caption says "computing…".
    pub(super) fn main_view_behind(&self) -> bool {
        let Some(document) = &self.document else {
            return false;
        };
        let shown = self
            .view
            .shown
            .filter(|s| s.document == document.generation);
        match self.settings.view.view_mode {
            ViewMode::Original => shown.is_none_or(|s| s.what != ShownMesh::Original),
            ViewMode::Level => {
                matches!(document.hierarchy, HierarchyState::Building)
                    || document.level_mesh.as_ref().is_none_or(|(level, _)| {
                        *level != document.level
                            || shown.is_none_or(|s| s.what != ShownMesh::Level { level: *level })
                    })
            }
            ViewMode::Faired => {
                let newest = self.newest_mesh(document, None);
                let heat_waits = self.heat_reference().is_some()
                    && shown.is_some_and(|s| s.heat != self.heat_reference());
                self.work.fair_in_flight
                    || matches!(document.hierarchy, HierarchyState::Building)
                    || shown.is_none_or(|s| s.what != newest)
                    || heat_waits
            }
        }
    }

    /// Distance of each vertex of `what` from the heat map's reference (`None`: no heat map for
    /// that mesh, as for level meshes, or not measured yet: a result's distances are its own or
    /// none, never the previous result's).
    pub(super) fn heat_scalars(
        &self,
        what: ShownMesh,
        reference: HeatReference,
    ) -> Option<Arc<Vec<f32>>> {
        let document = self.document.as_ref()?;
        match what {
            ShownMesh::Faired { serial } => {
                let faired = document
                    .faired
                    .as_ref()
                    .filter(|f| f.serial == serial && !f.measures_pending)?;
                let measures = match reference {
                    HeatReference::Clean => faired.against_clean.as_ref(),
                    HeatReference::Document => faired.against_document.as_ref(),
                }?;
                Some(measures.vertex_distances.clone())
            }
            ShownMesh::Original => match reference {
                HeatReference::Clean => document
                    .against_clean
                    .as_ref()
                    .map(|m| m.vertex_distances.clone()),
                // The document's mesh is its own reference: zero everywhere.
                HeatReference::Document => {
                    Some(Arc::new(vec![0.0; document.original.vertex_count()]))
                }
            },
            ShownMesh::Level { .. } => None,
        }
    }

    pub(super) fn sync_viewport(&mut self) {
        self.sync_slot(Slot::Main);
        if self.before_needed() {
            self.sync_slot(Slot::Before);
        }
    }

    /// Shows the wanted mesh: from the GPU when the viewport holds it, otherwise uploaded (and
    /// its heat-map scalars and mask weights when they differ from what is on the GPU).
    pub(super) fn sync_slot(&mut self, slot: Slot) {
        let Some(wanted) = self.wanted_mesh(slot) else {
            return;
        };
        let mut shown = match slot {
            Slot::Main => self.view.shown,
            Slot::Before => self.view.shown_before,
        };
        if shown == Some(wanted) || self.document.is_none() {
            return;
        }
        let mut mesh_changed =
            shown.is_none_or(|s| (s.document, s.what) != (wanted.document, wanted.what));
        let mut counts = None;
        if mesh_changed {
            if let Some(held) = self.show_held(slot, wanted) {
                // Its scalars and weights are on the GPU with it: written again only if the
                // wanted ones differ.
                shown = Some(held.shown);
                self.view.heat_max[slot as usize] = held.heat_max;
                counts = Some(held.counts);
                mesh_changed = false;
            } else {
                self.make_appearance();
                let Some(uploaded) = self.upload_mesh(slot, wanted) else {
                    return;
                };
                counts = Some(uploaded);
            }
        }
        // New buffers start with zero scalars and weights: both are written again.
        let mut uploaded = wanted;
        if mesh_changed || shown.is_none_or(|s| s.heat != wanted.heat) {
            self.view.heat_max[slot as usize] = self.upload_heat(slot, wanted);
            // Scalars that are not there yet are asked for again next frame.
            if self.view.heat_max[slot as usize].is_none() {
                uploaded.heat = None;
            }
        }
        if mesh_changed || shown.is_none_or(|s| s.mask != wanted.mask) {
            self.upload_mask(slot, wanted);
        }
        let counts = counts.unwrap_or(self.view.shown_counts);
        match slot {
            Slot::Main => {
                self.view.shown_counts = counts;
                self.view.shown = Some(uploaded);
            }
            Slot::Before => self.view.shown_before = Some(uploaded),
        }
        let view = HeldView {
            key: self.held_key(uploaded),
            shown: uploaded,
            heat_max: self.view.heat_max[slot as usize],
            counts,
        };
        self.remember_view(slot, view);
    }

    /// Makes the document's file's colours for the viewport, once per loaded file.
    fn make_appearance(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        if (self.view.appearance.as_ref()).is_some_and(|(s, _)| Arc::ptr_eq(s, &document.source)) {
            return;
        }
        let file = document.path.file_name().map_or_else(
            || document.path.display().to_string(),
            |name| name.to_string_lossy().into_owned(),
        );
        let (appearance, warnings) =
            super::appearance::appearance_of(&document.source, &document.original, &file);
        self.view.appearance = Some((document.source.clone(), appearance.map(Arc::new)));
        self.view.appearance_warnings = warnings;
    }

    /// The slot's renderer handle, when there is a wgpu renderer.
    pub(super) fn slot_viewport(&self, slot: Slot) -> Option<&Viewport3d> {
        match slot {
            Slot::Main => self.view.viewport.as_ref(),
            Slot::Before => self.view.viewport_before.as_ref(),
        }
    }

    /// Uploads the wanted mesh to the slot's viewport (only its positions when the GPU holds an
    /// older version of it, such as the previous result); its vertex and face counts, or `None`
    /// when that mesh is not there (yet).
    fn upload_mesh(&self, slot: Slot, wanted: Shown) -> Option<(usize, usize)> {
        let document = self.document.as_ref()?;
        let base = match &document.hierarchy {
            HierarchyState::Ready {
                hierarchy,
                base_matches_original,
                ..
            } => Some((hierarchy.clone(), *base_matches_original)),
            _ => None,
        };
        let key = self.held_key(wanted);
        let appearance = self.view.appearance.as_ref().and_then(|(_, a)| a.clone());
        let source = view_mesh(document, wanted.what, base, appearance)?;
        let counts = (source.positions().len(), source.triangles().len());
        if let Some(viewport) = self.slot_viewport(slot) {
            let source: Arc<dyn MeshSource> = Arc::new(source);
            if !viewport.set_positions_keyed(source.clone(), key) {
                viewport.set_mesh_keyed(source, key);
            }
        }
        Some(counts)
    }

    /// Uploads the wanted view's heat-map scalars (the shown mesh's own distances); the heat
    /// map's top, or `None` when there is no heat map or its scalars are not there yet.
    fn upload_heat(&self, slot: Slot, wanted: Shown) -> Option<f32> {
        let viewport = self.slot_viewport(slot);
        let scalars = self.heat_scalars(wanted.what, wanted.heat?)?;
        viewport
            .is_none_or(|v| v.set_scalars(&scalars))
            .then(|| heat_map_top(&scalars))
    }

    /// Uploads the painted mask's weights when the wanted view tints them.
    fn upload_mask(&self, slot: Slot, wanted: Shown) {
        if wanted.mask.is_none() {
            return;
        }
        let mask = self.document.as_ref().and_then(|d| d.mask.as_ref());
        if let (Some(mask), Some(viewport)) = (mask, self.slot_viewport(slot)) {
            viewport.set_mask(mask.weights());
        }
    }

    /// The heat map's top value for the slots on screen (shared, so the colours compare).
    pub(super) fn heat_top(&self) -> Option<f32> {
        self.heat_reference()?;
        let main = self.view.heat_max[Slot::Main as usize];
        let before = self
            .before_needed()
            .then(|| self.view.heat_max[Slot::Before as usize])
            .flatten();
        match (main, before) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
        .map(|top| top.max(f32::MIN_POSITIVE))
    }

    /// What the main viewport's renderer is asked to draw with now (tests).
    pub fn main_draw_params(&self) -> Option<DrawParams> {
        Some(self.draw_params(self.view.viewport_rect?, Slot::Main))
    }

    /// The vertex normals uploaded to a viewport's GPU buffer for the mesh it shows, one per
    /// draw vertex (the mesh's vertices unless the file's appearance or a split at sharp edges
    /// gives others; tests; waits for the GPU).
    pub fn uploaded_normals(&self, slot: Slot) -> Option<Vec<[f32; 3]>> {
        match slot {
            Slot::Main => self.view.viewport.as_ref(),
            Slot::Before => self.view.viewport_before.as_ref(),
        }?
        .read_back_normals()
    }

    /// Each drawn triangle's mesh vertices and the normals its corners are lit with in smooth
    /// shading, read back from a viewport's GPU buffer (tests; waits for the GPU).
    pub fn uploaded_corner_normals(&self, slot: Slot) -> Option<Vec<CornerNormals>> {
        match slot {
            Slot::Main => self.view.viewport.as_ref(),
            Slot::Before => self.view.viewport_before.as_ref(),
        }?
        .read_back_corner_normals()
    }

    pub(super) fn draw_params(&self, rect: egui::Rect, slot: Slot) -> DrawParams {
        self.slot_look(slot)
            .draw_params(&self.view.camera, &self.settings, rect)
    }

    /// How a viewport's image is coloured now (the heat map's range, the mask's tint): from
    /// what the viewport has uploaded, so the colours are always those of the shape shown.
    pub(super) fn slot_look(&self, slot: Slot) -> SlotLook {
        let top = self.heat_top();
        let scalar_range = self.view.heat_max[slot as usize]
            .and(top)
            .map(|top| [0.0, top]);
        let shown = match slot {
            Slot::Main => self.view.shown,
            Slot::Before => self.view.shown_before,
        };
        let mask_tint = shown.is_some_and(|s| s.mask.is_some());
        SlotLook {
            scalar_range,
            mask_tint,
        }
    }

    pub(super) fn fit_view(&mut self) {
        let Some(document) = &self.document else {
            return;
        };
        let (lo, hi) = match (self.settings.view.view_mode, &document.level_mesh) {
            (ViewMode::Level, Some((_, mesh))) => state::bounds_of(&mesh.positions),
            _ => document.bounds,
        };
        // Each side-by-side half is half the view's width.
        let aspect = self.view.viewport_rect.map_or(1.0, |rect| {
            let width = match self.settings.view.compare {
                CompareView::SideBySide => rect.width() * 0.5,
                CompareView::Single | CompareView::Split => rect.width(),
            };
            width / rect.height().max(1.0)
        });
        self.view.camera.fit(
            glam::Vec3::from_array(lo),
            glam::Vec3::from_array(hi),
            aspect,
        );
        self.view.fitted_camera = Some(self.view.camera);
    }
}
