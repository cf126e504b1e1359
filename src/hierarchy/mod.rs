//! Volume-preserving decimation hierarchy (paper section 4.1) and moving between its levels.
//!
//! [`build_hierarchy`] runs the passes of `decimate` (one pass per level, see that module for
//! the cost, the independent set, the cone volume and the validity rules) and then stores the
//! result in a form where every level is cheap to reach:
//!
//! - Vertices are renumbered ("internal" ids) by the level at which they disappear, those that
//!   survive to the coarsest level first, those removed by the first pass last. The vertices of
//!   level `i` are then exactly the internal ids `0..V_i`, so the positions of level `i` are a
//!   prefix of one array and refining by a level appends the split vertices. Within a level's
//!   share they are in Morton order of their positions (as the decimation visits M0), so that
//!   every level's passes find a vertex's neighbours near it in memory.
//! - Faces are renumbered the same way, so the faces of level `i` are the first `F_i` faces
//!   (within a level's share, by their first corner in that Morton order).
//! - The collapse record of a removed vertex `v` is its target `k = target[v]` (an internal id
//!   of the next coarser level, so always smaller than `v`'s), the signed cone volume of the
//!   collapse, and (implicitly, through the face order) the faces it removed. The faces it
//!   rewrites need not be stored: a face's corner at level `i` is its M0 corner followed along
//!   `target` while it is not a vertex of level `i`. Coarsening by one level is one relabelling
//!   pass (`c -> target[c]` for the removed `c`) that drops the faces at the end of the level's
//!   range; refining (the vertex splits of a level) re-resolves the face range of the finer level
//!   from M0's corners. Both are exact: coarsening to the top and refining back gives M0's faces,
//!   in M0's order once mapped back through [`Hierarchy::original_vertex`].
//!
//! Creases ([`HierarchyOptions::creases`], off by default for now; not in the paper): M0's creases
//! are found as [`crate::fairing::detect_creases`] finds them (normals filtered as much as the
//! noise estimate asks; groups that wander are dropped only where their edges turn by more than
//! [`HIERARCHY_ZIGZAG_TURN`] unless the options say otherwise, since a coarse level keeps its shape
//! by those bends), corners never collapse and crease vertices collapse only along their crease
//! (see `decimate/`), so every level's creases are M0's feature edges with their ends followed
//! along `target` ([`Hierarchy::level_creases`]); multiresolution fairing fairs them as curves. The
//! detection costs a topology, the fan-ordered one-rings and one gather over them that gives the
//! noise estimate and the feature edges together (the guided normal filter only on a noisy mesh);
//! figures in `docs/measurements.md`.
//!
//! Loose triangles (not in the paper): on a mesh with non-manifold edges, the triangles a scan's
//! reconstruction left lying over a fan or hanging as fins ([`crate::mesh::loose_triangles`])
//! are left out of the levels ([`HierarchyOptions::leave_out_loose_triangles`]): level 0 is M0
//! without them, M0 itself stays whole, and `face_order` maps into M0's faces. Kept in, their
//! corners would be non-manifold and pinned with their neighbours in every level (a scan such as
//! the Stanford dragon would keep under half its vertices in its coarsest level).
//!
//! Storage per M0 vertex: target 4 bytes, cone volume 4, the vertex order both ways 8, and the
//! face order (about two faces per vertex) 8: 24 bytes, besides M0 itself in internal order.
//!
//! # Files
//! - `decimate`: the passes that remove the vertices, level by level.
//! - `order`: M0 numbered by level from the passes' output.

mod bytes;
mod decimate;
mod order;

use crate::fairing::creases::{
    detect_creases_with_estimate, CreaseOptions, Creases, FaceRingCache, FeatureClass,
    HIERARCHY_ZIGZAG_TURN,
};
use crate::mesh::{FanRings, Topology, TriMesh};
use crate::Progress;
pub use bytes::HierarchyBytesError;
use decimate::NEVER;
use order::in_level_order;
use std::borrow::Cow;
use std::sync::atomic::AtomicU64;

/// Options of [`build_hierarchy`]; build them with `HierarchyOptions::default()` and the
/// `with_*` setters.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct HierarchyOptions {
    /// Weight of the shortest incident edge in a vertex's removal cost (the paper's α).
    pub alpha: f64,
    /// Weight of the longest incident edge in a vertex's removal cost (the paper's β).
    pub beta: f64,
    /// Stop when a level has fewer vertices than this.
    pub min_vertices: usize,
    /// At most this many levels above M0.
    pub max_levels: usize,
    /// Never collapse boundary vertices.
    pub keep_boundary: bool,
    /// Keep sharp creases (found as [`crate::fairing::detect_creases`] finds them, with the
    /// normals filtered as much as the mesh's noise estimate asks): a crease vertex collapses only
    /// into one of its two neighbours along the crease, and corners never collapse, so every
    /// level keeps M0's creases and corners ([`Hierarchy::level_creases`]). `None`: no creases.
    pub creases: Option<CreaseOptions>,
    /// Decimate a non-manifold mesh without the triangles that lie loose at its non-manifold
    /// edges (overlays on a fan, fins; [`crate::mesh::loose_triangles`]), as the default fairing
    /// leaves them out; they stay in M0 ([`Hierarchy::loose_triangles`]). Otherwise their
    /// corners, being non-manifold, stay in every level with their neighbours.
    pub leave_out_loose_triangles: bool,
    /// Refuse a collapse that would turn a face of the coarser level against M0: a face whose
    /// normal points away from the sum of M0's vertex normals at its corners, or that folds over
    /// a neighbouring face of the collapse's fan (their normals more than 150° apart). Not in the
    /// paper, whose check looks only at the level being collapsed; off, the hierarchy is the
    /// paper's (the multiresolution recipe to the letter needs it off).
    pub keep_orientation: bool,
    /// How a level is cut into regions visited in parallel (tests make them small).
    regions: decimate::RegionSize,
}

with_setters!(HierarchyOptions {
    with_alpha => alpha: f64,
    with_beta => beta: f64,
    with_min_vertices => min_vertices: usize,
    with_max_levels => max_levels: usize,
    with_keep_boundary => keep_boundary: bool,
    with_creases => creases: Option<CreaseOptions>,
    with_leave_out_loose_triangles => leave_out_loose_triangles: bool,
    with_keep_orientation => keep_orientation: bool,
});

impl Default for HierarchyOptions {
    fn default() -> Self {
        Self {
            alpha: 1.0,
            beta: 0.01,
            min_vertices: 100,
            max_levels: 64,
            keep_boundary: false,
            creases: None,
            leave_out_loose_triangles: true,
            keep_orientation: true,
            regions: decimate::RegionSize::DEFAULT,
        }
    }
}

#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HierarchyError {
    #[error("hierarchy build cancelled")]
    Cancelled,
    #[error("cannot build a hierarchy: {0}")]
    Unsupported(String),
}

/// Size of one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelInfo {
    pub vertices: usize,
    pub faces: usize,
}

/// One half-edge collapse `vertex -> target` of a level, in internal (level-mesh) ids.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collapse {
    pub vertex: u32,
    pub target: u32,
    /// Signed cone volume: six times the volume the matching vertex split adds (on closed meshes
    /// the collapse changes the volume by minus a sixth of this).
    pub six_split_volume: f32,
}

static NEXT_HIERARCHY_ID: AtomicU64 = AtomicU64::new(1);

/// M0 (the input) and the collapse records that lead to ever coarser levels M1..Mn.
#[derive(Clone, Debug, Default)]
pub struct Hierarchy {
    base: TriMesh,
    /// Identifies one build (clones share it): lets workspaces cache per-level data.
    id: u64,
    /// Internal id -> M0 vertex id.
    order: Vec<u32>,
    /// M0 vertex id -> internal id.
    rank: Vec<u32>,
    /// M0's positions in internal order: level `i`'s positions are the first `V_i`.
    positions: Vec<[f32; 3]>,
    /// M0's faces in internal order, with internal vertex ids.
    triangles: Vec<[u32; 3]>,
    /// Internal face id -> M0 face index.
    face_order: Vec<u32>,
    /// Collapse target of each internal vertex (`u32::MAX` for vertices of the coarsest level).
    target: Vec<u32>,
    six_split_volume: Vec<f32>,
    /// `V_i` and `F_i` per level, level 0 first.
    level_vertices: Vec<u32>,
    level_faces: Vec<u32>,
    /// Milliseconds the pass building level `i` took (`level_ms[0]` is the setup of M0).
    level_ms: Vec<f64>,
    /// M0's crease class of each internal vertex, and M0's feature edges in internal ids (both
    /// empty when the build kept no creases).
    feature_class: Vec<FeatureClass>,
    crease_edges: Vec<[u32; 2]>,
    /// M0 ids of the vertices whose faces are not one oriented fan (ascending).
    non_manifold: Vec<u32>,
    /// M0 faces left out of the levels (ascending; see [`Hierarchy::loose_triangles`]).
    loose: Vec<u32>,
}

impl Hierarchy {
    /// Number of levels including M0 (so the coarsest is `level_count() - 1`).
    pub fn level_count(&self) -> usize {
        self.level_vertices.len().max(1)
    }
    /// The coarsest level's index.
    pub fn coarsest_level(&self) -> usize {
        self.level_count() - 1
    }
    pub fn level_info(&self, level: usize) -> LevelInfo {
        if self.level_vertices.is_empty() {
            return LevelInfo {
                vertices: self.base.vertex_count(),
                faces: self.base.face_count(),
            };
        }
        let level = level.min(self.coarsest_level());
        LevelInfo {
            vertices: self.level_vertices[level] as usize,
            faces: self.level_faces[level] as usize,
        }
    }
    /// Milliseconds spent building `level` (its decimation pass; for level 0 the set-up).
    pub fn level_build_ms(&self, level: usize) -> f64 {
        self.level_ms.get(level).copied().unwrap_or(0.0)
    }
    /// M0, the mesh the hierarchy was built from (all of it: level 0 leaves out its
    /// [`Hierarchy::loose_triangles`], when it has any).
    pub fn base_mesh(&self) -> &TriMesh {
        &self.base
    }
    /// The mesh of one level, compacted: its vertex `j` is internal vertex `j`, M0's vertex
    /// [`Hierarchy::original_vertex`]`(j)`, at its M0 position.
    pub fn level_mesh(&self, level: usize) -> TriMesh {
        if self.level_vertices.is_empty() {
            return self.base.clone();
        }
        TriMesh::new(
            self.level_positions(level).to_vec(),
            self.level_triangles(level),
        )
    }
    /// Where [`Hierarchy::level_mesh`]`(level)` comes from in M0: per vertex the M0 vertex, per
    /// triangle the M0 triangle it is what is left of (for keeping a file's UVs, colours and
    /// materials on a coarse level, see `io::save_derived_with_source`).
    pub fn level_origins(&self, level: usize) -> (Vec<u32>, Vec<u32>) {
        if self.level_vertices.is_empty() {
            return (
                (0..self.base.vertex_count() as u32).collect(),
                (0..self.base.face_count() as u32).collect(),
            );
        }
        let info = self.level_info(level);
        (
            self.order[..info.vertices].to_vec(),
            self.face_order[..info.faces].to_vec(),
        )
    }
    /// A level as a file should hold it: [`Hierarchy::level_mesh`] without the vertices none of
    /// its faces uses (the tips of fins left out as loose triangles, which never collapse), its
    /// vertices and faces in M0's order (so level 0 is M0 as it came in, less loose triangles,
    /// and a file does not depend on the internal order), and its origins to match: per vertex
    /// its M0 vertex and per face its M0 face, both ascending ([`Hierarchy::level_origins`] in
    /// that order).
    pub fn level_for_export(&self, level: usize) -> (TriMesh, Vec<u32>, Vec<u32>) {
        let internal = self.level_mesh(level);
        let (vertex_origin, face_origin) = self.level_origins(level);
        let by_origin = |origin: &[u32]| {
            let mut ids: Vec<u32> = (0..origin.len() as u32).collect();
            ids.sort_unstable_by_key(|&i| origin[i as usize]);
            ids
        };
        let (vertices, faces) = (by_origin(&vertex_origin), by_origin(&face_origin));
        let place = crate::mesh::inverse_permutation(&vertices);
        let mut mesh = TriMesh::new(
            vertices
                .iter()
                .map(|&v| internal.positions[v as usize])
                .collect(),
            faces
                .iter()
                .map(|&f| internal.triangles[f as usize].map(|c| place[c as usize]))
                .collect(),
        );
        let vertex_origin: Vec<u32> = vertices
            .iter()
            .map(|&v| vertex_origin[v as usize])
            .collect();
        let face_origin: Vec<u32> = faces.iter().map(|&f| face_origin[f as usize]).collect();
        let faces = mesh.face_count();
        // A level has no face that repeats a vertex, so only vertices go.
        let (_, map) = crate::mesh::clean_with_map_but_repeats(&mut mesh);
        debug_assert_eq!(mesh.face_count(), faces);
        let vertex_origin = match map {
            Some(map) => vertex_origin
                .iter()
                .zip(&map)
                .filter(|&(_, &to)| to != u32::MAX)
                .map(|(&from, _)| from)
                .collect(),
            None => vertex_origin,
        };
        (mesh, vertex_origin, face_origin)
    }
    /// M0 positions of the vertices of `level`, in internal order.
    pub fn level_positions(&self, level: usize) -> &[[f32; 3]] {
        &self.positions[..self.level_info(level).vertices]
    }
    /// Faces of `level` in internal vertex ids (the order is that of [`Hierarchy::level_mesh`]).
    pub fn level_triangles(&self, level: usize) -> Vec<[u32; 3]> {
        let info = self.level_info(level);
        let mut triangles = Vec::new();
        self.resolve_faces(0..info.faces, info.vertices as u32, &mut triangles);
        triangles
    }
    /// M0 vertex id of internal vertex `v`.
    pub fn original_vertex(&self, v: u32) -> u32 {
        self.order[v as usize]
    }
    /// Internal id of M0 vertex `v`.
    pub fn internal_vertex(&self, v: u32) -> u32 {
        self.rank[v as usize]
    }
    /// M0 face index of internal face `f`.
    pub fn original_face(&self, f: u32) -> u32 {
        self.face_order[f as usize]
    }
    /// Internal id -> M0 vertex id for every vertex (level `i`'s vertices are the first `V_i`).
    pub fn vertex_order(&self) -> &[u32] {
        &self.order
    }
    /// The collapses that lead from `level` to `level + 1` (empty for the coarsest level).
    pub fn collapses(&self, level: usize) -> impl Iterator<Item = Collapse> + '_ {
        let range = if level + 1 < self.level_count() {
            self.level_vertices[level + 1]..self.level_vertices[level]
        } else {
            0..0
        };
        range.map(move |v| Collapse {
            vertex: v,
            target: self.target[v as usize],
            six_split_volume: self.six_split_volume[v as usize],
        })
    }
    /// Collapse target (internal id) of internal vertex `v`, `None` on the coarsest level.
    pub fn collapse_target(&self, v: u32) -> Option<u32> {
        let k = self.target[v as usize];
        (k != NEVER).then_some(k)
    }
    /// Six times the signed volume the split of internal vertex `v` adds (0 if never removed).
    pub fn six_split_volume(&self, v: u32) -> f32 {
        self.six_split_volume[v as usize]
    }
    /// The creases of `level` in its internal ids (`None` when the build kept none): M0's
    /// feature edges with each end followed along its collapses to the level (a crease vertex
    /// only ever collapses along its crease, so these are the level's own crease edges), and M0's
    /// classes of the level's vertices.
    pub fn level_creases(&self, level: usize) -> Option<Creases> {
        if self.crease_edges.is_empty() {
            return None;
        }
        let vertex_count = self.level_info(level).vertices as u32;
        let resolve = |mut c: u32| {
            while c >= vertex_count {
                c = self.target[c as usize];
            }
            c
        };
        let mut edges: Vec<[u32; 2]> = self
            .crease_edges
            .iter()
            .filter_map(|&[a, b]| {
                let (a, b) = (resolve(a), resolve(b));
                (a != b).then(|| [a.min(b), a.max(b)])
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let class = self.feature_class[..vertex_count as usize].to_vec();
        Some(Creases::from_classified(edges, class))
    }
    /// The vertices of M0 (the input mesh's ids, ascending) whose faces are not one consistently
    /// oriented fan: they and their neighbours stay in every level.
    pub fn non_manifold_vertices(&self) -> &[u32] {
        &self.non_manifold
    }

    /// M0's faces (ascending indices) that lie loose at its non-manifold edges
    /// ([`crate::mesh::loose_triangles`]) and were left out of the levels
    /// ([`HierarchyOptions::leave_out_loose_triangles`]): level 0 is M0 without them, and the
    /// result of multiresolution fairing, on M0's triangles, has them following their corners
    /// (a corner only they use stays where it is).
    pub fn loose_triangles(&self) -> &[u32] {
        &self.loose
    }

    /// What a level written to a file lacks of M0, as a warning (`None` when nothing): the
    /// [`Hierarchy::loose_triangles`], which no level has.
    pub fn levels_warning(&self) -> Option<String> {
        (!self.loose.is_empty()).then(|| {
            format!(
                "{} triangles lying loose at non-manifold edges (over other triangles, or fins) \
                 are in no level, M0 included: the levels are built without them",
                self.loose.len()
            )
        })
    }

    /// M0's feature edges the build kept, in M0's own vertex ids (the input mesh's), lower id
    /// first; empty without creases.
    pub fn crease_edges(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = self
            .crease_edges
            .iter()
            .map(|&[a, b]| {
                let (a, b) = (self.original_vertex(a), self.original_vertex(b));
                [a.min(b), a.max(b)]
            })
            .collect();
        edges.sort_unstable();
        edges
    }
    /// Number of M0's feature edges the build kept (0 without creases).
    pub fn crease_edge_count(&self) -> usize {
        self.crease_edges.len()
    }
    /// Heap bytes of the collapse records (targets, cone volumes, vertex and face orders, the
    /// loose triangles' indices).
    pub fn record_bytes(&self) -> usize {
        4 * (self.target.len() + self.six_split_volume.len())
            + 4 * (self.order.len() + self.rank.len())
            + 4 * self.face_order.len()
            + self.feature_class.len() * std::mem::size_of::<FeatureClass>()
            + 8 * self.crease_edges.len()
            + 4 * self.loose.len()
    }
    pub(crate) fn id(&self) -> u64 {
        self.id
    }

    /// Appends the faces `range` with their corners resolved to a level with `vertex_count`
    /// vertices.
    fn resolve_faces(
        &self,
        range: std::ops::Range<usize>,
        vertex_count: u32,
        out: &mut Vec<[u32; 3]>,
    ) {
        let resolve = |mut c: u32| {
            while c >= vertex_count {
                c = self.target[c as usize];
            }
            c
        };
        out.extend(self.triangles[range].iter().map(|t| t.map(resolve)));
    }
}

/// A level's connectivity, to move up and down the hierarchy by whole levels.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LevelCursor {
    pub level: usize,
    /// The faces of `level`, internal ids (vertices `0..V_level`).
    pub triangles: Vec<[u32; 3]>,
}

impl LevelCursor {
    /// The cursor at M0.
    pub fn new(hierarchy: &Hierarchy) -> Self {
        Self::at(hierarchy, 0)
    }
    pub fn at(hierarchy: &Hierarchy, level: usize) -> Self {
        let level = level.min(hierarchy.coarsest_level());
        Self {
            level,
            triangles: hierarchy.level_triangles(level),
        }
    }
    /// Applies the collapses of the current level (one relabelling pass). False at the top.
    pub fn coarsen(&mut self, hierarchy: &Hierarchy) -> bool {
        if self.level >= hierarchy.coarsest_level() {
            return false;
        }
        let next = hierarchy.level_info(self.level + 1);
        let vertex_count = next.vertices as u32;
        self.triangles.truncate(next.faces);
        for t in &mut self.triangles {
            for c in t.iter_mut() {
                if *c >= vertex_count {
                    *c = hierarchy.target[*c as usize];
                }
            }
        }
        self.level += 1;
        true
    }
    /// Applies the vertex splits that undo the collapses of the next finer level. False at M0.
    pub fn refine(&mut self, hierarchy: &Hierarchy) -> bool {
        if self.level == 0 {
            return false;
        }
        let finer = hierarchy.level_info(self.level - 1);
        let vertex_count = finer.vertices as u32;
        // A face keeps its corners unless one of them is the target of a split vertex whose M0
        // corner chain passes through it: re-resolve every face from M0 (chains are short).
        self.triangles.clear();
        hierarchy.resolve_faces(0..finer.faces, vertex_count, &mut self.triangles);
        self.level -= 1;
        true
    }
    /// The level's faces in M0 vertex ids.
    pub fn original_triangles(&self, hierarchy: &Hierarchy) -> Vec<[u32; 3]> {
        self.triangles
            .iter()
            .map(|t| t.map(|c| hierarchy.order[c as usize]))
            .collect()
    }
}

/// Builds the decimation hierarchy of `mesh` (section 4.1): M0 is `mesh`, each further level
/// removes an independent set of vertices by volume-preserving half-edge collapses. `progress`
/// may cancel the build ([`HierarchyError::Cancelled`]). Triangles lying loose at non-manifold
/// edges (a scan's overlays and fins) are left out of the levels by default
/// ([`Hierarchy::loose_triangles`]); where the rest is still not an oriented 2-manifold, those
/// vertices and their neighbours stay in every level ([`Hierarchy::non_manifold_vertices`]).
///
/// ```
/// use fairmesh::hierarchy::{build_hierarchy, HierarchyOptions};
///
/// let mesh = fairmesh::bundled::load_bunny(&Default::default())?.mesh;
/// let hierarchy = build_hierarchy(&mesh, &HierarchyOptions::default(), &mut fairmesh::NoProgress)?;
/// assert_eq!(hierarchy.level_info(0).vertices, mesh.vertex_count());
/// let coarsest = hierarchy.level_info(hierarchy.coarsest_level());
/// assert!(coarsest.vertices < mesh.vertex_count() / 20);
/// // Every level is a closed mesh again: V − E + F = 2, so F = 2V − 4.
/// assert_eq!(coarsest.faces, 2 * coarsest.vertices - 4);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn build_hierarchy(
    mesh: &TriMesh,
    options: &HierarchyOptions,
    progress: &mut dyn Progress,
) -> Result<Hierarchy, HierarchyError> {
    build(mesh, None, options, progress)
}

/// [`build_hierarchy`] for a caller that has the mesh's connectivity already (`topology`, built
/// from `mesh`'s triangles, as loading gives it): keeping creases reads it, and building it again
/// is about a fifth of the whole build on large meshes. Without creases it is not read. A
/// topology of another mesh (other vertex or corner counts) is not used; one is built instead.
pub fn build_hierarchy_with_topology(
    mesh: &TriMesh,
    topology: &Topology,
    options: &HierarchyOptions,
    progress: &mut dyn Progress,
) -> Result<Hierarchy, HierarchyError> {
    let fits = topology.vertex_count() == mesh.vertex_count()
        && topology.face_csr().1.len() == 3 * mesh.face_count();
    build(mesh, fits.then_some(topology), options, progress)
}

/// [`build_hierarchy`] with the topology, when one is at hand: checks the mesh, finds the
/// creases, decimates, then numbers M0 by level.
fn build(
    mesh: &TriMesh,
    topology: Option<&Topology>,
    options: &HierarchyOptions,
    progress: &mut dyn Progress,
) -> Result<Hierarchy, HierarchyError> {
    let started = crate::clock::Instant::now();
    check_supported(mesh)?;
    // A non-manifold scan is decimated without the triangles its reconstruction left lying loose
    // at its non-manifold edges (`crate::mesh::loose_triangles`, as the default fairing leaves
    // them out): they would pin their corners and neighbours in every level, and the levels of a
    // scan such as the Stanford dragon would stop at under half its vertices. They stay in M0;
    // the levels are those of the mesh without them. With a topology at hand (given, or needed
    // for the creases) they are looked for at once; otherwise only when the first pass finds a
    // non-manifold vertex, so a manifold mesh pays nothing.
    let mut topology = topology.map(Cow::Borrowed);
    if options.creases.is_some() && topology.is_none() {
        topology = Some(Cow::Owned(Topology::build(mesh)));
    }
    let mut loose_out = match &topology {
        Some(topology) if options.leave_out_loose_triangles => {
            crate::mesh::without_loose_triangles(mesh, topology)
        }
        _ => None,
    };
    let creases = options.creases.as_ref().and_then(|crease_options| {
        let (levels_mesh, levels_topology) = match &loose_out {
            Some((_, kept, kept_topology)) => (kept, kept_topology),
            None => (
                mesh,
                topology.as_deref().expect("built above for the creases"),
            ),
        };
        levels_creases(levels_mesh, levels_topology, crease_options)
    });
    let setup_ms = started.elapsed().as_secs_f64() * 1e3;

    let look_later = options.leave_out_loose_triangles && topology.is_none();
    let levels_mesh = loose_out.as_ref().map_or(mesh, |(_, kept, _)| kept);
    let built = match decimate::build(levels_mesh, creases.as_ref(), options, look_later, progress)?
    {
        Some(built) => built,
        None => {
            // Non-manifold, and no topology was at hand (nor creases asked for).
            loose_out = crate::mesh::without_loose_triangles(mesh, &Topology::build(mesh));
            let levels_mesh = loose_out.as_ref().map_or(mesh, |(_, kept, _)| kept);
            decimate::build(levels_mesh, None, options, false, progress)?
                .expect("only asked to stop when told to")
        }
    };
    drop(topology);
    let (loose, levels_mesh) = match loose_out {
        Some((loose, kept, _)) => (loose, Cow::Owned(kept)),
        None => (Vec::new(), Cow::Borrowed(mesh)),
    };
    Ok(in_level_order(
        mesh,
        &levels_mesh,
        loose,
        built,
        creases,
        setup_ms,
    ))
}

/// An error for a mesh the hierarchy cannot number or decimate: too many vertices, a non-finite
/// coordinate, or a face that repeats a vertex or refers to a missing one.
fn check_supported(mesh: &TriMesh) -> Result<(), HierarchyError> {
    let n = mesh.vertex_count();
    if n >= u32::MAX as usize / 2 {
        return Err(HierarchyError::Unsupported(format!(
            "{n} vertices is more than this hierarchy can number"
        )));
    }
    if let Some(v) = mesh.first_non_finite_vertex() {
        return Err(HierarchyError::Unsupported(format!(
            "vertex {v} has a non-finite coordinate"
        )));
    }
    if let Some((f, t)) = mesh.triangles.iter().enumerate().find(|(_, t)| {
        t.iter().any(|&c| c as usize >= n) || t[0] == t[1] || t[1] == t[2] || t[0] == t[2]
    }) {
        return Err(HierarchyError::Unsupported(format!(
            "face {f} {t:?} repeats a vertex or refers to a missing one"
        )));
    }
    Ok(())
}

/// The creases the levels keep, found on the mesh that is decimated (`None` when there are
/// none); groups that wander are kept unless `crease_options` say otherwise
/// ([`HIERARCHY_ZIGZAG_TURN`]).
fn levels_creases(
    levels_mesh: &TriMesh,
    levels_topology: &Topology,
    crease_options: &CreaseOptions,
) -> Option<Creases> {
    let fans = FanRings::new(&levels_mesh.triangles, levels_topology);
    let crease_options = CreaseOptions {
        zigzag_turn_degrees: Some(
            crease_options
                .zigzag_turn_degrees
                .unwrap_or(HIERARCHY_ZIGZAG_TURN),
        ),
        ..crease_options.clone()
    };
    let (_, creases) = detect_creases_with_estimate(
        levels_mesh,
        levels_topology,
        &fans,
        &crease_options,
        &mut FaceRingCache::default(),
        true,
    );
    (!creases.is_empty()).then_some(creases)
}

#[cfg(test)]
mod tests;
