//! Sharp creases: which edges are feature edges, which vertices lie on them, and the chains they
//! form, so that fairing can treat a crease like the paper treats a boundary (section 3.3).
//!
//! Not in the paper, which fairs every interior vertex alike and so rounds every sharp edge of a
//! CAD part. The reading here: a crease is a boundary between two surface patches. Each patch is
//! faired with the crease as its boundary (a triangle with one crease corner is solved with that
//! corner held, its other two keeping their midpoint; one with two is not solved, as a triangle
//! touching the boundary is not: [`super::constrained`]), each chain of crease edges is faired
//! as a curve with the paper's edge-centre constraints of section 3.3 (open chains between two
//! fixed ends, closed loops like boundary loops), and the corners stay where they are.
//!
//! Detection:
//! - A feature edge is an edge with exactly two faces whose normals differ by more than
//!   [`CreaseOptions::angle_degrees`]. On a noisy mesh the faces' own normals scatter by tens of
//!   degrees, so they are first filtered ([`CreaseOptions::normal_filtering`] passes, chosen from
//!   the noise estimate when fairing picks its own strength): a guided bilateral filter, read from
//!   Zhang et al., "Guided Mesh Normal Filtering" (2015). Each pass gives every face a guidance
//!   normal, the mean normal of the most consistent patch (the faces sharing a vertex with some
//!   face) among the patches that contain it, so a face beside a crease is guided by a patch on
//!   its own side; then each face averages the normals of the faces sharing a vertex with it,
//!   weighted by area and by exp(−|g_f − g_g|² / 2σ²) of the guidance normals
//!   (σ = [`CreaseOptions::normal_sigma`]). Noise averages out within each side, while across a
//!   crease the weights vanish. A plain bilateral filter (weights from the noisy normals
//!   themselves) was tried first: on a cube with noise of 0.3 edge lengths it found six times
//!   too many crease edges, and thousands on the noisy bunny, which has none.
//! - Feature edges that form small groups (fewer than [`CreaseOptions::min_edges`] edges joined at
//!   their ends) are dropped, and so are groups that zigzag (more than one corner per two edges):
//!   noise and single spikes of a scan make those, while a crease runs straight between a few
//!   corners. For this test a corner is where the edges themselves turn by more than
//!   [`CreaseOptions::zigzag_turn_degrees`] ([`ZIGZAG_TURN`], 55°, lower than the classes'
//!   70°): the bends of a coarse scan that the filter sharpens into feature edges wander, and
//!   fairing them as creases costs the scan more than it keeps. The hierarchy keeps them
//!   ([`HIERARCHY_ZIGZAG_TURN`], 70°): there they hold a coarse level's shape
//!   (`docs/measurements.md`, "Wandering groups are no creases").
//! - Edges the input file marks as sharp ([`CreaseOptions::file_edges`]: split normals, material
//!   boundaries, from [`crate::io::Source::hard_edges`]) are feature edges whatever
//!   their angle, and are never dropped as a small or zigzagging group: the file's author said so.
//! - A crease vertex has exactly two feature edges whose crease directions (the cross product of
//!   each edge's two filtered face normals: on a noisy crease the vertices zigzag, the faces on
//!   either side do not) turn by less than [`CreaseOptions::corner_turn_degrees`]; any other vertex with feature edges is a corner (the
//!   end of a crease, three or more creases meeting, a sharp turn, or a crease meeting the
//!   boundary) and is held fixed.
//!
//! Speed (issue 12: detection and the noise estimate should add at most 10 % to a default round):
//! constrained fairing and the hierarchy detect through `detect_creases_with_estimate`, whose
//! one gather over the fan-ordered one-rings gives the noise estimate and the feature edges of the
//! faces' own normals at once, so a clean mesh reads no face and never runs the filter. The
//! filter (noisy meshes) works in f32 on a face-around-face list built once for all passes.
//! Every vertex and face is computed by the same operations whatever the thread count.

use super::constrained::FanRings;
use super::strength::{area_normal, normal_filtering_for, scan_fans};
use crate::mesh::{Topology, TriMesh};
use glam::{Mat4, Vec3A, Vec4};
use rayon::prelude::*;
use std::collections::HashMap;

/// Angle scale of the normal filter (length of the difference of unit normals; 0.5 is about 29
/// degrees).
pub const NORMAL_SIGMA: f64 = 0.5;

/// Options of [`detect_creases`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct CreaseOptions {
    /// An edge is a feature edge when its two faces' (filtered) normals differ by more than this.
    pub angle_degrees: f64,
    /// Passes of the guided normal filter before the angles are taken (0: the faces' own
    /// normals).
    pub normal_filtering: usize,
    /// Angle scale of the normal filter: the length of the difference of two unit normals at
    /// which a neighbour's weight falls to e^(−1/2) (0.5 is about 29 degrees).
    pub normal_sigma: f64,
    /// Groups of joined feature edges with fewer edges than this are not creases.
    pub min_edges: usize,
    /// A vertex whose two feature edges turn by more than this is a corner.
    pub corner_turn_degrees: f64,
    /// For dropping groups that zigzag: a vertex whose two feature edges' positions turn by more
    /// than this counts as a corner, and a group with more than one such corner per two edges is
    /// no crease. `None` (the default): the angle of the use, [`ZIGZAG_TURN`] for fairing and
    /// [`detect_creases`], [`HIERARCHY_ZIGZAG_TURN`] for the hierarchy.
    pub zigzag_turn_degrees: Option<f64>,
    /// Edges the input file marks as sharp (its normals split there, or two of its materials
    /// meet: [`crate::io::Source::hard_edges`]), each `[a, b]` with `a < b`: feature edges
    /// whatever their angle, never dropped as a small or zigzagging group. Empty: none.
    pub file_edges: std::sync::Arc<[[u32; 2]]>,
}

with_setters!(CreaseOptions {
    with_angle_degrees => angle_degrees: f64,
    with_normal_filtering => normal_filtering: usize,
    with_normal_sigma => normal_sigma: f64,
    with_min_edges => min_edges: usize,
    with_corner_turn_degrees => corner_turn_degrees: f64,
    with_zigzag_turn_degrees => zigzag_turn_degrees: Option<f64>,
});

impl Default for CreaseOptions {
    fn default() -> Self {
        Self {
            angle_degrees: DEFAULT_CREASE_ANGLE,
            normal_filtering: 0,
            normal_sigma: NORMAL_SIGMA,
            min_edges: 8,
            corner_turn_degrees: 70.0,
            zigzag_turn_degrees: None,
            file_edges: std::sync::Arc::from([]),
        }
    }
}

/// [`CreaseOptions::zigzag_turn_degrees`] for fairing (where it is `None`): holding the wandering
/// bends a coarse scan's filtered normals show costs its fairing more than it keeps.
pub const ZIGZAG_TURN: f64 = 55.0;

/// [`CreaseOptions::zigzag_turn_degrees`] for the hierarchy (where it is `None`): there the same
/// bends keep a coarse level's shape (multires from level 9 of the noisy
/// elephant ends 0.35 edge lengths from the clean surface with them, 0.44 without them).
pub const HIERARCHY_ZIGZAG_TURN: f64 = 70.0;

impl CreaseOptions {
    /// `self` with [`file_edges`](Self::file_edges) set to `edges`.
    #[must_use]
    pub fn with_file_edges(mut self, edges: Vec<[u32; 2]>) -> Self {
        self.file_edges = edges.into();
        self
    }
}

/// The default crease angle (degrees): see `docs/measurements.md` for how it was chosen.
pub const DEFAULT_CREASE_ANGLE: f64 = 40.0;

/// What a vertex is with respect to the creases.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FeatureClass {
    /// On no feature edge.
    #[default]
    Smooth,
    /// Inside a chain of feature edges: faired along the chain.
    Crease,
    /// Where chains end, meet or turn sharply: kept in place.
    Corner,
}

/// A run of feature edges: `vertices[k]`–`vertices[k + 1]` are feature edges. An open chain starts
/// and ends at corners; a closed one has only crease vertices (the last joins the first).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chain {
    pub vertices: Vec<u32>,
    pub closed: bool,
}

/// The creases of a mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Creases {
    /// One class per vertex.
    pub class: Vec<FeatureClass>,
    /// The feature edges, lower index first.
    pub edges: Vec<[u32; 2]>,
    pub chains: Vec<Chain>,
}

impl Creases {
    /// Whether vertex `v` is on a crease (a crease vertex or a corner).
    pub fn is_feature(&self, v: u32) -> bool {
        self.class
            .get(v as usize)
            .is_some_and(|&c| c != FeatureClass::Smooth)
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Number of vertices of each class: (crease, corner).
    pub fn counts(&self) -> (usize, usize) {
        let crease = self
            .class
            .iter()
            .filter(|&&c| c == FeatureClass::Crease)
            .count();
        let corner = self
            .class
            .iter()
            .filter(|&&c| c == FeatureClass::Corner)
            .count();
        (crease, corner)
    }
}

/// Unit face normals, filtered `passes` times (see the module docs): each pass takes, for every
/// face, a guidance normal (the mean normal of the most consistent patch that contains it), then
/// averages the normals of the faces around it weighted by area and by how close their guidance
/// normals are to its own.
pub fn filtered_face_normals(
    mesh: &TriMesh,
    topology: &Topology,
    passes: usize,
    sigma: f64,
) -> Vec<Vec3A> {
    filter_face_normals(mesh, topology, passes, sigma, &mut FaceRingCache::default())
        .into_par_iter()
        .with_min_len(4096)
        .map(xyz)
        .collect()
}

/// The faces around each face, built the first time the guided filter runs and kept for later
/// detections on the same connectivity (constrained fairing finds the creases again before every
/// round: the lists stay, only the normals change).
#[derive(Default)]
pub(crate) struct FaceRingCache {
    rings: Option<FaceRings>,
    /// Keep the mesh's own face order (no Morton order): the mesh is numbered for locality.
    mesh_order: bool,
}

impl FaceRingCache {
    /// A cache for a mesh already numbered for locality (constrained fairing's rounds run on
    /// a copy numbered breadth-first, faces by their lowest corner): the filter keeps its face
    /// order instead of sorting the faces in Morton order. 1.2M-face bunny so numbered, 5
    /// passes: lists built in 56 instead of 105 ms, a pass 98 instead of 111 ms, the same
    /// normals bit for bit.
    pub(crate) fn in_mesh_order() -> FaceRingCache {
        FaceRingCache {
            rings: None,
            mesh_order: true,
        }
    }
}

/// [`filtered_face_normals`], each unit normal with its face's doubled area in w (the area of
/// the input's face), by face id.
///
/// How it is computed: in f32 (normals are directions; a pass averages a dozen of them), with the
/// faces around each face (those sharing a vertex with it, each with the number of vertices it
/// shares) listed once, before the passes, in blocks of faces ([`FaceRings`]). A pass is then
/// three parallel gathers over the faces: every patch's mean and spread (once per face), every
/// face's guidance (the least spread among the patches around it), the filtered normal. The first
/// and the last take the faces around four at a time (their x, y, z and area in four lanes, the
/// weights' exponentials by [`exp_of_negative`]): on the noisy 1.2M-face bunny a pass went from
/// 90 to ~68 ms (2 threads), with the same creases on every mesh of `fairing_default`'s table.
/// Each face is computed by the same operations whatever the thread count. No pass (a clean
/// mesh) builds nothing: the normals are the faces' own. Three arrays of the faces' size are
/// written (the normals, the patches and then the filtered normals over them, the guidance);
/// there were six, and a detection's first touch of their pages cost ~30 ms on 1.2M faces.
fn filter_face_normals(
    mesh: &TriMesh,
    topology: &Topology,
    passes: usize,
    sigma: f64,
    cache: &mut FaceRingCache,
) -> Vec<Vec4> {
    // Unit normal and area (twice the area: only ratios matter) of face f.
    let unit = |f: u32| {
        let n = area_normal(mesh, f);
        let length = n.length();
        if length > 0.0 && length.is_finite() {
            (n / length).extend(length)
        } else {
            Vec4::ZERO
        }
    };
    let face_count = mesh.triangles.len();
    if passes == 0 {
        return (0..face_count as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(unit)
            .collect();
    }
    let mesh_order = cache.mesh_order;
    let rings = cache
        .rings
        .get_or_insert_with(|| FaceRings::build(mesh, topology, mesh_order));
    // The passes' arrays are in the rings' order of the faces.
    let mut current: Vec<Vec4> = match &rings.order {
        Some(order) => order
            .par_iter()
            .with_min_len(4096)
            .map(|&f| unit(f))
            .collect(),
        None => (0..face_count as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(unit)
            .collect(),
    };
    let inverse = (1.0 / (2.0 * sigma * sigma)) as f32;
    // Three arrays: the patches are no longer read once the guidance is taken, so the filtered
    // normals are written over them.
    let mut patches = vec![Vec4::ZERO; face_count];
    let mut guidance = vec![Vec4::ZERO; face_count];
    for _ in 0..passes {
        // Each patch (the faces around a face, with their multiplicities): its area-weighted
        // mean normal and how much its normals disagree (the largest squared difference from
        // the mean), as (mean, spread).
        rings.for_each_face(&mut patches, |f, around, shared, patch| {
            let own = xyz(current[f]);
            let mut sum = [Vec4::ZERO; 3];
            for k in (0..around.len()).step_by(4) {
                let ([n], m) = four([&current], around, shared, k, f);
                let weight = n.w_axis * m;
                for (s, n) in sum.iter_mut().zip([n.x_axis, n.y_axis, n.z_axis]) {
                    *s += n * weight;
                }
            }
            let sum = Vec3A::new(
                sum[0].element_sum(),
                sum[1].element_sum(),
                sum[2].element_sum(),
            );
            let mean = sum.try_normalize().unwrap_or(own);
            let mut spread = Vec4::ZERO;
            for k in (0..around.len()).step_by(4) {
                let ([n], _) = four([&current], around, shared, k, f);
                let d = [(n.x_axis, mean.x), (n.y_axis, mean.y), (n.z_axis, mean.z)]
                    .map(|(n, m)| n - Vec4::splat(m));
                spread = spread.max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            }
            *patch = mean.extend(spread.max_element());
        });
        // Guidance: the mean of the most consistent patch among those containing f (the
        // first of the least spread, in the order of the list).
        rings.for_each_face(&mut guidance, |f, around, _, guide| {
            let mut best = xyz(current[f]).extend(f32::INFINITY);
            for &g in around {
                let patch = patches[g as usize];
                if patch.w < best.w {
                    best = patch;
                }
            }
            *guide = xyz(best).extend(0.0);
        });
        let next = &mut patches;
        rings.for_each_face(next, |f, around, shared, out| {
            let own = guidance[f];
            let mut sum = [Vec4::ZERO; 3];
            for k in (0..around.len()).step_by(4) {
                let ([g, n], m) = four([&guidance, &current], around, shared, k, f);
                let d = [(g.x_axis, own.x), (g.y_axis, own.y), (g.z_axis, own.z)]
                    .map(|(g, o)| g - Vec4::splat(o));
                let d = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let weight = n.w_axis * m * exp_of_negative(d * inverse);
                for (s, n) in sum.iter_mut().zip([n.x_axis, n.y_axis, n.z_axis]) {
                    *s += n * weight;
                }
            }
            let sum = Vec3A::new(
                sum[0].element_sum(),
                sum[1].element_sum(),
                sum[2].element_sum(),
            );
            let area = current[f].w;
            *out = sum.try_normalize().unwrap_or(xyz(current[f])).extend(area);
        });
        std::mem::swap(&mut current, next);
    }
    match &rings.order {
        Some(order) => {
            let mut normals = vec![Vec4::ZERO; current.len()];
            for (&f, n) in order.iter().zip(&current) {
                normals[f as usize] = *n;
            }
            normals
        }
        None => current,
    }
}

/// For each array of `values`, its four values at `around[k..k + 4]` as the columns of a matrix,
/// transposed (so its x axis holds their x, and so on), and their shared-vertex counts; past the
/// end of the list, face `own` (always in its own list) with a count of 0.
#[inline(always)]
fn four<const N: usize>(
    values: [&[Vec4]; N],
    around: &[u32],
    shared: &[u8],
    k: usize,
    own: usize,
) -> ([Mat4; N], Vec4) {
    let (faces, counts) = match (around.get(k..k + 4), shared.get(k..k + 4)) {
        (Some(&[a, b, c, d]), Some(&[ma, mb, mc, md])) => (
            [a, b, c, d].map(|g| g as usize),
            [ma, mb, mc, md].map(f32::from),
        ),
        _ => {
            let at = |i: usize| match around.get(k + i) {
                Some(&g) => (g as usize, f32::from(shared[k + i])),
                None => (own, 0.0),
            };
            let [(a, ma), (b, mb), (c, mc), (d, md)] = [at(0), at(1), at(2), at(3)];
            ([a, b, c, d], [ma, mb, mc, md])
        }
    };
    let [a, b, c, d] = faces;
    (
        values
            .map(|values| Mat4::from_cols(values[a], values[b], values[c], values[d]).transpose()),
        Vec4::from_array(counts),
    )
}

/// e^(−x) for each x ≥ 0: (e^(−x/16))^16, e^(−y) by its Taylor series to degree 7, so all four
/// lanes at once in a few multiplications (x is clamped to 16, where e^(−x) is 1e-7: the weights
/// it gives are to other weights as 1e-7 is to 1, and a face's own weight is 1). Relative error
/// below 5e-6 for x ≤ 8 (unit normals and σ = 0.5 give x ≤ 8; 3.8e-6 at worst, near 8): the
/// polynomial's few ulps of f32 rounding and the series' 1e-7 at y = 1/2, each doubled by every
/// squaring; well under what the weights' sum of a dozen f32 terms carries anyway.
#[inline(always)]
fn exp_of_negative(x: Vec4) -> Vec4 {
    let y = -x.min(Vec4::splat(16.0)) * (1.0 / 16.0);
    let mut e = Vec4::splat(1.0 / 5040.0);
    for c in [
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        e = e * y + Vec4::splat(c);
    }
    for _ in 0..4 {
        e *= e;
    }
    e
}

/// The x, y, z of a normal stored with its face's area in w.
#[inline]
fn xyz(v: Vec4) -> Vec3A {
    Vec3A::from_vec4(v)
}

/// Faces per block of [`FaceRings`].
const FACE_BLOCK: usize = 4096;

/// For every face, the faces sharing a vertex with it (itself included), in ascending order of
/// their ids, each once with the number of vertices it shares (3 for the face itself, 2 across an
/// edge, 1 across a vertex): the union, with multiplicities, of its corners' face lists, which is
/// what the guided filter averages over. Kept in blocks of [`FACE_BLOCK`] faces, built and read in
/// parallel.
///
/// The faces are numbered here in Morton order of their centroids (`order`), and the lists hold
/// these numbers, so that the faces around a face are near it in the passes' arrays whatever the
/// file's face order: the passes are gathers, bound by the memory's latency. A mesh already
/// numbered for locality keeps its own order (`order` is `None`;
/// [`FaceRingCache::in_mesh_order`]). The lists keep the
/// order of the faces' ids, so every face's sums and choices are made in the same order as with
/// the file's numbering, and the filtered normals are the same bit for bit. (1.2M-face bunny, 5
/// passes: 1.14-1.24 s in the subdivided file's order, 0.77-0.81 s in Morton order, 3.4-3.9 s
/// with its faces shuffled.)
struct FaceRings {
    /// `order[i]`: the id of the face numbered `i` (`None`: face `i`, the mesh's own order).
    order: Option<Vec<u32>>,
    blocks: Vec<FaceRingBlock>,
}

struct FaceRingBlock {
    /// `faces[offsets[i]..offsets[i + 1]]` are around the block's face `i`.
    offsets: Vec<u32>,
    faces: Vec<u32>,
    /// How many vertices each listed face shares with the block's face.
    shared: Vec<u8>,
}

impl FaceRings {
    /// The lists in Morton order of the faces, or in the mesh's own order with `mesh_order`.
    fn build(mesh: &TriMesh, topology: &Topology, mesh_order: bool) -> FaceRings {
        let face_count = mesh.triangles.len();
        let order = (!mesh_order).then(|| morton_face_order(mesh));
        let number = order.as_deref().map(crate::mesh::inverse_permutation);
        let blocks = (0..face_count.div_ceil(FACE_BLOCK))
            .into_par_iter()
            .map(|index| {
                let faces = index * FACE_BLOCK..face_count.min((index + 1) * FACE_BLOCK);
                let block = faces.map(|i| order.as_ref().map_or(i as u32, |order| order[i]));
                let mut ring = FaceRingBlock {
                    offsets: Vec::with_capacity(block.len() + 1),
                    faces: Vec::with_capacity(14 * block.len()),
                    shared: Vec::with_capacity(14 * block.len()),
                };
                ring.offsets.push(0);
                for f in block {
                    let [a, b, c] = mesh.triangles[f as usize];
                    let start = ring.faces.len();
                    merge_face_lists(
                        [
                            topology.faces_of(a),
                            topology.faces_of(b),
                            topology.faces_of(c),
                        ],
                        &mut ring.faces,
                        &mut ring.shared,
                    );
                    if let Some(number) = &number {
                        for g in &mut ring.faces[start..] {
                            *g = number[*g as usize];
                        }
                    }
                    ring.offsets.push(ring.faces.len() as u32);
                }
                ring
            })
            .collect();
        FaceRings { order, blocks }
    }

    /// Calls `visit(f, faces around f, their shared-vertex counts, &mut out[f])` for every face,
    /// in parallel over blocks.
    fn for_each_face<T: Send>(
        &self,
        out: &mut [T],
        visit: impl Fn(usize, &[u32], &[u8], &mut T) + Sync,
    ) {
        out.par_chunks_mut(FACE_BLOCK)
            .zip(&self.blocks)
            .enumerate()
            .for_each(|(b, (out, ring))| {
                for (i, slot) in out.iter_mut().enumerate() {
                    let (start, end) = (ring.offsets[i] as usize, ring.offsets[i + 1] as usize);
                    visit(
                        b * FACE_BLOCK + i,
                        &ring.faces[start..end],
                        &ring.shared[start..end],
                        slot,
                    );
                }
            });
    }
}

/// The faces' ids in Morton order of their centroids (quantized to 10 bits per axis in the
/// bounding box of the vertices; ties by id, so the order is the same on any thread count).
fn morton_face_order(mesh: &TriMesh) -> Vec<u32> {
    let (lo, hi) = crate::metrics::bounding_box(mesh).unwrap_or_default();
    let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let mut keys: Vec<u64> = mesh
        .triangles
        .par_iter()
        .with_min_len(4096)
        .enumerate()
        .map(|(f, t)| {
            let centre = t
                .iter()
                .map(|&v| glam::DVec3::from(mesh.positions[v as usize].map(f64::from)))
                .sum::<glam::DVec3>()
                / 3.0;
            crate::mesh::morton_code(centre, lo, extent) << 32 | f as u64
        })
        .collect();
    keys.par_sort_unstable();
    keys.into_iter().map(|k| k as u32).collect()
}

/// Appends the union of three ascending face lists, each face once with the number of lists
/// holding it.
fn merge_face_lists(lists: [&[u32]; 3], faces: &mut Vec<u32>, shared: &mut Vec<u8>) {
    let [mut a, mut b, mut c] = lists;
    loop {
        let head = |l: &[u32]| l.first().copied().unwrap_or(u32::MAX);
        let (x, y, z) = (head(a), head(b), head(c));
        let m = x.min(y).min(z);
        if m == u32::MAX {
            break;
        }
        faces.push(m);
        shared.push((x == m) as u8 + (y == m) as u8 + (z == m) as u8);
        a = &a[(x == m) as usize..];
        b = &b[(y == m) as usize..];
        c = &c[(z == m) as usize..];
    }
}

/// Finds the creases of `mesh` (`topology` built from it).
pub fn detect_creases(mesh: &TriMesh, topology: &Topology, options: &CreaseOptions) -> Creases {
    detect_creases_cached(mesh, topology, options, &mut FaceRingCache::default())
}

/// [`detect_creases`] keeping the faces around each face in `cache` for the next detection on
/// the same connectivity.
pub(crate) fn detect_creases_cached(
    mesh: &TriMesh,
    topology: &Topology,
    options: &CreaseOptions,
    cache: &mut FaceRingCache,
) -> Creases {
    let normals = filter_face_normals(
        mesh,
        topology,
        options.normal_filtering,
        options.normal_sigma,
        cache,
    );
    finish(
        mesh,
        topology,
        feature_edges(mesh, topology, &normals, options),
        options,
    )
}

/// The noise estimate and the creases, with the normals filtered at least as much as the
/// estimate asks for ([`super::strength::normal_filtering_for`]), for a caller that has the
/// fan-ordered one-rings (constrained fairing builds them anyway; the hierarchy builds them for
/// this). The estimate's gather finds the feature edges of the faces' own normals at once
/// ([`super::strength::scan_fans`]); when the estimate says the mesh is clean (no filtering),
/// those are the creases' edges, and the guided filter is skipped entirely. Without `estimate`
/// no estimate is made (`None`) and the normals are filtered as `options` say: for a caller that
/// has read the mesh clean and only smooths it further.
pub(crate) fn detect_creases_with_estimate(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    options: &CreaseOptions,
    cache: &mut FaceRingCache,
    estimate: bool,
) -> (Option<f64>, Creases) {
    let scan = scan_fans(mesh, topology, fans, options.angle_degrees, estimate);
    let mut options = options.clone();
    options.normal_filtering = options
        .normal_filtering
        .max(scan.noise.map_or(0, normal_filtering_for));
    let creases = if options.normal_filtering == 0 {
        finish(mesh, topology, scan.edges, &options)
    } else {
        detect_creases_cached(mesh, topology, &options, cache)
    };
    (scan.noise, creases)
}

/// A feature edge `[v, u]` (v < u) with its crease direction (unit, either sign).
pub(crate) type FeatureEdge = ([u32; 2], Vec3A);

/// Every feature edge `[v, u]` (v < u, ascending by v then u) with the direction its two faces'
/// normals give it (n_a × n_b, along the crease however noisy the vertex positions are); in
/// parallel over the vertices, each edge found from its lower end.
fn feature_edges(
    mesh: &TriMesh,
    topology: &Topology,
    normals: &[Vec4],
    options: &CreaseOptions,
) -> Vec<FeatureEdge> {
    let threshold = options.angle_degrees.to_radians().cos() as f32;
    (0..mesh.positions.len() as u32)
        .into_par_iter()
        .with_min_len(1024)
        .flat_map_iter(|v| {
            let mut edges = Vec::new();
            vertex_feature_edges(
                mesh,
                topology,
                v,
                |f| xyz(normals[f as usize]),
                threshold,
                &mut edges,
            );
            edges
        })
        .collect()
}

/// Appends the feature edges `[v, u]` with u > v, ascending by u, with `normal(f)` a normal of
/// face f (of any length): the edges with exactly two faces whose normals' angle has its cosine
/// below `threshold` (the cosine of the crease angle). The faces of an edge v–u are among v's own, so
/// no other vertex's list is searched, and v's triangles are read once.
pub(crate) fn vertex_feature_edges(
    mesh: &TriMesh,
    topology: &Topology,
    v: u32,
    normal: impl Fn(u32) -> Vec3A,
    threshold: f32,
    edges: &mut Vec<FeatureEdge>,
) {
    let faces_v = topology.faces_of(v);
    // Every (u, i) with u > v a corner of v's i-th face (each face once per u), sorted: the
    // faces of an edge v–u are then side by side, in the order of v's list.
    let mut buffer = [(0u32, 0u32); 64];
    let mut heap = Vec::new();
    let pairs: &mut [(u32, u32)] = if 2 * faces_v.len() <= buffer.len() {
        let mut count = 0;
        for (i, &f) in faces_v.iter().enumerate() {
            let [a, b, c] = mesh.triangles[f as usize];
            // (Each face of v's list has v for a corner, so at most two others.)
            for (u, repeated) in [(a, false), (b, b == a), (c, c == a || c == b)] {
                if u > v && !repeated {
                    buffer[count] = (u, i as u32);
                    count += 1;
                }
            }
        }
        &mut buffer[..count]
    } else {
        for (i, &f) in faces_v.iter().enumerate() {
            let [a, b, c] = mesh.triangles[f as usize];
            for (u, repeated) in [(a, false), (b, b == a), (c, c == a || c == b)] {
                if u > v && !repeated {
                    heap.push((u, i as u32));
                }
            }
        }
        &mut heap
    };
    pairs.sort_unstable();
    // An edge with other than two faces is no feature edge.
    let mut rest = &*pairs;
    while let Some(&(u, i)) = rest.first() {
        let run = rest.iter().take_while(|&&(w, _)| w == u).count();
        if run == 2 {
            let j = rest[1].1;
            let (fi, fj) = (faces_v[i as usize], faces_v[j as usize]);
            if let Some(direction) = feature(normal(fi), normal(fj), threshold) {
                edges.push(([v, u], direction));
            }
        }
        rest = &rest[run..];
    }
}

/// [`vertex_feature_edges`] for a vertex with a closed fan, from its ring (`ring[k]` = x_k, at
/// most 64) and its faces' area normals (`faces[k]` = (x_(k−1) − x_v) × (x_k − x_v), the normal
/// of face (v, x_(k−1), x_k), which the noise estimate sums anyway): edge v–x_k lies on faces k
/// and k + 1, so no face is read.
pub(crate) fn fan_feature_edges(
    v: u32,
    ring: &[u32],
    faces: &[Vec3A],
    threshold: f32,
    edges: &mut Vec<FeatureEdge>,
) {
    let first = edges.len();
    edges.extend(
        fan_feature_neighbors(v, ring, faces, threshold)
            .map(|(u, [a, b])| ([v, u], a.cross(b).normalize_or_zero())),
    );
    edges[first..].sort_unstable_by_key(|&([_, u], _)| u);
}

/// The neighbours u > v of [`fan_feature_edges`] (in the ring's order), each with the normals of
/// its edge's two faces.
pub(crate) fn fan_feature_neighbors<'a>(
    v: u32,
    ring: &'a [u32],
    faces: &'a [Vec3A],
    threshold: f32,
) -> impl Iterator<Item = (u32, [Vec3A; 2])> + 'a {
    let n = ring.len();
    ring.iter().enumerate().filter_map(move |(k, &u)| {
        let pair = [faces[k], faces[(k + 1) % n]];
        (u > v && is_feature(pair[0], pair[1], threshold)).then_some((u, pair))
    })
}

/// The crease direction of an edge whose faces have the normals `na` and `nb` (of any length),
/// when it is a feature edge (the cosine of their angle below `threshold`; a face without a
/// normal makes none).
#[inline]
fn feature(na: Vec3A, nb: Vec3A, threshold: f32) -> Option<Vec3A> {
    is_feature(na, nb, threshold).then(|| na.cross(nb).normalize_or_zero())
}

/// Whether an edge whose faces have the normals `na` and `nb` is a feature edge ([`feature`]
/// without the direction).
#[inline]
fn is_feature(na: Vec3A, nb: Vec3A, threshold: f32) -> bool {
    let (la, lb) = (na.length(), nb.length());
    la > 0.0 && lb > 0.0 && (la * lb).is_finite() && na.dot(nb) < threshold * la * lb
}

/// The creases from the feature edges: small and zigzagging groups dropped, vertices classified,
/// chains walked.
fn finish(
    mesh: &TriMesh,
    topology: &Topology,
    found: Vec<FeatureEdge>,
    options: &CreaseOptions,
) -> Creases {
    let vertex_count = mesh.positions.len();
    if found.is_empty() && options.file_edges.is_empty() {
        return Creases {
            class: vec![FeatureClass::Smooth; vertex_count],
            ..Creases::default()
        };
    }
    let edges: Vec<[u32; 2]> = found.iter().map(|&(e, _)| e).collect();
    let mut directions: HashMap<[u32; 2], Vec3A> = found.into_iter().collect();
    // Small groups are noise or spikes; so are groups that zigzag (more corners than one per two
    // edges: a true crease, even a noisy one, runs straight between few corners).
    let max_turn = options.corner_turn_degrees.to_radians().cos();
    let min_edges = options.min_edges;
    let edges = keep_groups(edges, vertex_count, None, |edges, _| edges >= min_edges);
    // The zigzag test turns by the edges' positions: noise that lines up into a fake crease
    // zigzags there, while the faces' crease directions may still agree.
    let zigzag_turn = options
        .zigzag_turn_degrees
        .unwrap_or(ZIGZAG_TURN)
        .to_radians()
        .cos();
    let class = classify(topology, &edges, Turn::Positions(mesh), zigzag_turn);
    let mut edges = keep_groups(edges, vertex_count, Some(&class), |edges, corners| {
        2 * corners <= edges
    });
    // The file's own sharp edges join whatever their angle and length; their crease direction is
    // the edge's own (a crease direction lies along its edge).
    if !options.file_edges.is_empty() {
        for &[a, b] in options.file_edges.iter() {
            if a < b && (b as usize) < vertex_count && topology.neighbors(a).contains(&b) {
                edges.push([a, b]);
                directions.entry([a, b]).or_insert_with(|| {
                    let point = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
                    (point(b) - point(a)).normalize_or_zero()
                });
            }
        }
        edges.sort_unstable();
        edges.dedup();
    }
    let class = classify(topology, &edges, Turn::Directions(&directions), max_turn);
    Creases::from_classified(edges, class)
}

impl Creases {
    /// The creases given by their feature edges (each once, lower index first) and every
    /// vertex's class: the chains are walked from the corners along the feature edges, then the
    /// closed loops of crease vertices that remain. A vertex classed `Crease` must have exactly
    /// two feature edges (one with another number is taken as a corner).
    pub fn from_classified(edges: Vec<[u32; 2]>, mut class: Vec<FeatureClass>) -> Creases {
        let graph = FeatureGraph::new(&edges, class.len());
        let feature_neighbors = |v: u32| graph.neighbors(v);
        // A vertex with no feature edge is smooth; one with two may be a crease vertex; any
        // other is a corner.
        for (v, c) in class.iter_mut().enumerate() {
            if *c != FeatureClass::Smooth && graph.index(v as u32).is_none() {
                *c = FeatureClass::Smooth;
            }
        }
        for (i, &v) in graph.vertices.list.iter().enumerate() {
            let c = &mut class[v as usize];
            *c = match (*c, graph.neighbors_at(i).len()) {
                (FeatureClass::Crease, 2) => FeatureClass::Crease,
                _ => FeatureClass::Corner,
            };
        }
        let mut used = vec![false; graph.adjacent.len()];
        let slot = |from: u32, to: u32| -> usize {
            let i = graph.index(from).expect("a feature edge's end is listed");
            graph.offsets[i] as usize
                + graph
                    .neighbors_at(i)
                    .iter()
                    .position(|&u| u == to)
                    .expect("a feature edge is listed at both ends")
        };
        let walk = |start: u32, first: u32, used: &mut Vec<bool>| -> Option<Chain> {
            if used[slot(start, first)] {
                return None;
            }
            let mut vertices = vec![start];
            let (mut previous, mut current) = (start, first);
            loop {
                used[slot(previous, current)] = true;
                used[slot(current, previous)] = true;
                if current == start {
                    return Some(Chain {
                        vertices,
                        closed: true,
                    });
                }
                vertices.push(current);
                if class[current as usize] != FeatureClass::Crease {
                    return Some(Chain {
                        vertices,
                        closed: false,
                    });
                }
                let next = feature_neighbors(current)
                    .iter()
                    .copied()
                    .find(|&u| u != previous)
                    .expect("a crease vertex has two feature edges");
                (previous, current) = (current, next);
            }
        };
        let mut chains = Vec::new();
        for (i, &v) in graph.vertices.list.iter().enumerate() {
            if class[v as usize] == FeatureClass::Corner {
                for &u in graph.neighbors_at(i) {
                    chains.extend(walk(v, u, &mut used));
                }
            }
        }
        for (i, &v) in graph.vertices.list.iter().enumerate() {
            if class[v as usize] == FeatureClass::Crease {
                let first = graph.neighbors_at(i)[0];
                chains.extend(walk(v, first, &mut used));
            }
        }
        // A closed crease of a few vertices is no curve the section 3.3 constraints can fair (in
        // multires from coarse levels its vertices were seen to run together, leaving faces with
        // no area): it is held in place, as corners are, and its edges become chains between them.
        if chains
            .iter()
            .any(|c| c.closed && c.vertices.len() < MIN_FAIRED_LOOP)
        {
            for chain in chains
                .iter()
                .filter(|c| c.closed && c.vertices.len() < MIN_FAIRED_LOOP)
            {
                for &v in &chain.vertices {
                    class[v as usize] = FeatureClass::Corner;
                }
            }
            return Creases::from_classified(edges, class);
        }
        Creases {
            class,
            edges,
            chains,
        }
    }
}

/// Closed creases with fewer vertices than this are held in place.
pub const MIN_FAIRED_LOOP: usize = 8;

/// The vertices on feature edges, each with a place of its own (0, 1, …), so that what is kept
/// per vertex need not be of the mesh's size (a detection on a mesh of 600k vertices with a
/// hundred feature edges touches a few hundred entries).
struct FeatureVertices {
    /// The vertices with a feature edge, ascending: `list[place]`.
    list: Vec<u32>,
    /// With many edges, every vertex's place (`u32::MAX`: none).
    table: Option<Vec<u32>>,
}

impl FeatureVertices {
    /// The ends of `edges`, between vertices numbered below `vertex_count`.
    fn new(edges: &[[u32; 2]], vertex_count: usize) -> FeatureVertices {
        // Few edges (a detection on a clean or faired mesh): the vertices sorted, found by
        // bisection. Many (the faces' own normals of a noisy scan make an edge of a quarter of
        // its edges): a table of the mesh's size finds them at once.
        if 32 * edges.len() < vertex_count {
            let mut list: Vec<u32> = edges.iter().flatten().copied().collect();
            list.sort_unstable();
            list.dedup();
            FeatureVertices { list, table: None }
        } else {
            let mut table = vec![u32::MAX; vertex_count];
            for &v in edges.iter().flatten() {
                table[v as usize] = 0;
            }
            let mut list = Vec::new();
            for (v, place) in table.iter_mut().enumerate() {
                if *place == 0 {
                    *place = list.len() as u32;
                    list.push(v as u32);
                }
            }
            FeatureVertices {
                list,
                table: Some(table),
            }
        }
    }

    /// The place of vertex `v`, if it has a feature edge.
    fn place(&self, v: u32) -> Option<usize> {
        match &self.table {
            Some(table) => table
                .get(v as usize)
                .filter(|&&place| place != u32::MAX)
                .map(|&place| place as usize),
            None => self.list.binary_search(&v).ok(),
        }
    }

    /// The places of both ends of an edge whose ends are listed.
    fn ends(&self, [a, b]: [u32; 2]) -> [usize; 2] {
        [a, b].map(|v| self.place(v).expect("an edge's ends are listed"))
    }
}

/// The vertices on feature edges and their feature neighbours.
struct FeatureGraph {
    vertices: FeatureVertices,
    /// `adjacent[offsets[i]..offsets[i + 1]]`: the feature neighbours of the vertex at place i,
    /// in the order of the edges.
    offsets: Vec<u32>,
    adjacent: Vec<u32>,
}

impl FeatureGraph {
    /// The graph of `edges` between vertices numbered below `vertex_count`.
    fn new(edges: &[[u32; 2]], vertex_count: usize) -> FeatureGraph {
        let vertices = FeatureVertices::new(edges, vertex_count);
        let mut offsets = vec![0u32; vertices.list.len() + 1];
        for &e in edges {
            for end in vertices.ends(e) {
                offsets[end + 1] += 1;
            }
        }
        for i in 0..vertices.list.len() {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut adjacent = vec![0; 2 * edges.len()];
        for &[a, b] in edges {
            let [ia, ib] = vertices.ends([a, b]);
            adjacent[fill[ia] as usize] = b;
            fill[ia] += 1;
            adjacent[fill[ib] as usize] = a;
            fill[ib] += 1;
        }
        FeatureGraph {
            vertices,
            offsets,
            adjacent,
        }
    }

    /// The place of vertex `v`, if it has a feature edge.
    fn index(&self, v: u32) -> Option<usize> {
        self.vertices.place(v)
    }

    /// The feature neighbours of the `i`-th listed vertex.
    fn neighbors_at(&self, i: usize) -> &[u32] {
        &self.adjacent[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// The feature neighbours of vertex `v` (none if it has no feature edge).
    fn neighbors(&self, v: u32) -> &[u32] {
        self.index(v).map_or(&[], |i| self.neighbors_at(i))
    }
}

/// How the turn at a vertex with two feature edges is measured.
enum Turn<'a> {
    /// Between the edges themselves (from the vertex positions).
    Positions(&'a TriMesh),
    /// Between the edges' crease directions (from their faces' filtered normals).
    Directions(&'a HashMap<[u32; 2], Vec3A>),
}

/// Every vertex's class, from its feature edges.
fn classify(
    topology: &Topology,
    edges: &[[u32; 2]],
    turn: Turn,
    max_turn: f64,
) -> Vec<FeatureClass> {
    let graph = FeatureGraph::new(edges, topology.vertex_count());
    let mut class = vec![FeatureClass::Smooth; topology.vertex_count()];
    for (i, &v) in graph.vertices.list.iter().enumerate() {
        class[v as usize] = match graph.neighbors_at(i) {
            _ if topology.is_boundary_vertex(v) => FeatureClass::Corner,
            &[a, b] => {
                let straight = match &turn {
                    Turn::Positions(mesh) => {
                        let x = mesh.point(v);
                        let incoming = (x - mesh.point(a)).normalize_or_zero();
                        let outgoing = (mesh.point(b) - x).normalize_or_zero();
                        incoming.dot(outgoing)
                    }
                    // The signs of crease directions are arbitrary.
                    Turn::Directions(directions) => {
                        let key = |u: u32| [u.min(v), u.max(v)];
                        directions[&key(a)].dot(directions[&key(b)]).abs() as f64
                    }
                };
                if straight >= max_turn {
                    FeatureClass::Crease
                } else {
                    FeatureClass::Corner
                }
            }
            _ => FeatureClass::Corner,
        };
    }
    class
}

/// The feature edges whose group (edges joined at shared vertices) `keep(edges, corners)` accepts;
/// corners are counted from `class` when given.
fn keep_groups(
    edges: Vec<[u32; 2]>,
    vertex_count: usize,
    class: Option<&[FeatureClass]>,
    keep: impl Fn(usize, usize) -> bool,
) -> Vec<[u32; 2]> {
    if edges.is_empty() {
        return edges;
    }
    // Union-find over the feature vertices' places.
    let vertices = FeatureVertices::new(&edges, vertex_count);
    let mut parent: Vec<u32> = (0..vertices.list.len() as u32).collect();
    fn root(parent: &mut [u32], mut v: usize) -> usize {
        while parent[v] as usize != v {
            parent[v] = parent[parent[v] as usize];
            v = parent[v] as usize;
        }
        v
    }
    let mut roots = Vec::with_capacity(edges.len());
    for &e in &edges {
        let [a, b] = vertices.ends(e);
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb) as u32;
        }
        roots.push(a);
    }
    let mut edge_count = vec![0u32; vertices.list.len()];
    let mut corner_count = vec![0u32; vertices.list.len()];
    for r in &mut roots {
        *r = root(&mut parent, *r);
        edge_count[*r] += 1;
    }
    if let Some(class) = class {
        for (i, &v) in vertices.list.iter().enumerate() {
            if class[v as usize] == FeatureClass::Corner {
                corner_count[root(&mut parent, i)] += 1;
            }
        }
    }
    edges
        .into_iter()
        .zip(roots)
        .filter(|&(_, r)| keep(edge_count[r] as usize, corner_count[r] as usize))
        .map(|(e, _)| e)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes::{cuboid, cylinder};

    #[test]
    fn the_filters_exponential_is_within_its_stated_error() {
        // Relative error below 5e-6 where unit normals and σ = 0.5 put the weights (x ≤ 8),
        // and no weight larger than e^(−16) beyond 16 (a face's own weight is 1).
        for i in 0..=8000 {
            let x = i as f32 * 0.001;
            let lanes = exp_of_negative(Vec4::new(x, x * 0.5, x * 0.25, 0.0));
            for (k, scale) in [1.0f32, 0.5, 0.25].into_iter().enumerate() {
                let exact = (-(f64::from(x * scale))).exp();
                let error = (f64::from(lanes[k]) - exact).abs() / exact;
                assert!(error < 5e-6, "x = {x}: {} against {exact}", lanes[k]);
            }
            assert_eq!(lanes[3], 1.0);
        }
        for x in [16.0f32, 20.0, 1e3, f32::MAX] {
            let e = exp_of_negative(Vec4::splat(x))[0];
            assert!((0.0..=1.2e-7).contains(&e), "x = {x}: {e}");
        }
    }

    /// The feature edges against every edge's faces counted over the whole mesh: an edge with
    /// three faces (a non-manifold spine) is none however sharp, a folded edge with two is one.
    #[test]
    fn feature_edges_are_the_sharp_edges_with_exactly_two_faces() {
        // Vertices 0-1 the spine; pages to 2, 3, 4 (three faces on the spine); page 0-1-2 folds
        // sharply onto face 1-2-5 along 1-2.
        let mesh = TriMesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, 1.0, 0.0],
                [0.5, -1.0, 0.0],
                [0.5, 0.0, 1.0],
                [1.5, 1.0, 0.9],
            ],
            triangles: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]],
        };
        let topology = Topology::build(&mesh);
        let normals: Vec<Vec4> = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(f, _)| area_normal(&mesh, f as u32).normalize().extend(1.0))
            .collect();
        let options = CreaseOptions::default().with_angle_degrees(30.0);
        let found: Vec<[u32; 2]> = feature_edges(&mesh, &topology, &normals, &options)
            .into_iter()
            .map(|(e, _)| e)
            .collect();
        // By brute force: each edge's faces, over all faces.
        let threshold = options.angle_degrees.to_radians().cos() as f32;
        let mut expected = Vec::new();
        for v in 0..6u32 {
            for &u in topology.neighbors(v).iter().filter(|&&u| u > v) {
                let faces: Vec<usize> = (0..mesh.triangles.len())
                    .filter(|&f| mesh.triangles[f].contains(&v) && mesh.triangles[f].contains(&u))
                    .collect();
                if let [a, b] = faces[..] {
                    if xyz(normals[a]).dot(xyz(normals[b])) < threshold {
                        expected.push([v, u]);
                    }
                }
            }
        }
        assert_eq!(found, expected);
        assert_eq!(found, vec![[1, 2]], "the fold, not the spine");
    }

    #[test]
    fn a_box_has_twelve_creases_between_eight_corners() {
        let mesh = cuboid([2.0, 1.0, 0.5], 0.1);
        let topology = Topology::build(&mesh);
        let creases = detect_creases(&mesh, &topology, &CreaseOptions::default());
        let (crease, corner) = creases.counts();
        assert_eq!(corner, 8);
        assert_eq!(creases.chains.len(), 12);
        assert!(creases.chains.iter().all(|c| !c.closed));
        // 4·(20 + 10 + 5) edges along the box's edges, their inner vertices crease vertices.
        assert_eq!(creases.edges.len(), 4 * 35);
        assert_eq!(crease, 4 * 35 - 12);
    }

    /// The filter in the mesh's own face order (a mesh numbered for locality) gives the normals
    /// of the Morton order bit for bit, for every face: each face's sums run over its
    /// neighbours in the order of their ids either way.
    #[test]
    fn the_filter_in_the_meshs_own_face_order_gives_the_same_normals() {
        use crate::noise::{add_noise, NoiseOptions};
        let mut mesh = cuboid([1.0, 1.0, 1.0], 0.05);
        add_noise(&mut mesh, &NoiseOptions::default().with_sigma(0.3));
        let topology = Topology::build(&mesh);
        let filter =
            |cache: &mut FaceRingCache| filter_face_normals(&mesh, &topology, 3, 0.5, cache);
        let (mut morton, mut own) = (FaceRingCache::default(), FaceRingCache::in_mesh_order());
        let expected = filter(&mut morton);
        assert!(morton.rings.as_ref().unwrap().order.is_some());
        assert!(own.rings.is_none());
        let got = filter(&mut own);
        assert!(own.rings.as_ref().unwrap().order.is_none());
        assert_eq!(got, expected);
        // The filter moved the normals (a pass that did nothing would pass the comparison).
        let raw = filter_face_normals(&mesh, &topology, 0, 0.5, &mut own);
        assert!(raw.iter().zip(&got).filter(|(a, b)| a != b).count() > raw.len() / 2);
    }

    /// The path constrained fairing and the hierarchy take (the estimate's gather over the fans
    /// finds the feature edges of the faces' own normals, and the guided filter is skipped on a
    /// clean mesh) gives the creases the general path gives, and filters like it on a noisy one.
    #[test]
    fn the_fan_scan_finds_the_creases_the_general_path_finds() {
        use crate::fairing::strength::{estimate_noise, normal_filtering_for};
        use crate::noise::{add_noise, NoiseOptions};
        let mut noisy = cuboid([1.0, 1.0, 1.0], 0.05);
        add_noise(&mut noisy, &NoiseOptions::default().with_sigma(0.3));
        for mesh in [cuboid([2.0, 1.0, 0.5], 0.1), cylinder(1.0, 1.0, 0.1), noisy] {
            let topology = Topology::build(&mesh);
            let fans = FanRings::new(&mesh.triangles, &topology);
            let options = CreaseOptions::default();
            let (estimate, creases) = detect_creases_with_estimate(
                &mesh,
                &topology,
                &fans,
                &options,
                &mut FaceRingCache::default(),
                true,
            );
            let general_estimate = estimate_noise(&mesh, &topology).unwrap();
            let estimate = estimate.unwrap();
            assert!(
                (estimate - general_estimate).abs() < 1e-5,
                "{estimate} {general_estimate}"
            );
            let filtering = normal_filtering_for(estimate);
            let general = detect_creases(
                &mesh,
                &topology,
                &options.clone().with_normal_filtering(filtering),
            );
            assert!(!creases.is_empty());
            assert_eq!(creases, general, "filtering {filtering}");
            // And without filtering the scan's raw edges are the general path's.
            let raw = scan_fans(&mesh, &topology, &fans, options.angle_degrees, true).edges;
            // The same without the estimate.
            let alone = scan_fans(&mesh, &topology, &fans, options.angle_degrees, false);
            assert_eq!(alone.noise, None);
            assert_eq!(alone.edges, raw);
            let general: Vec<[u32; 2]> = {
                let unit =
                    filter_face_normals(&mesh, &topology, 0, 0.5, &mut FaceRingCache::default());
                feature_edges(&mesh, &topology, &unit, &options)
                    .into_iter()
                    .map(|(e, _)| e)
                    .collect()
            };
            assert_eq!(raw.into_iter().map(|(e, _)| e).collect::<Vec<_>>(), general);
        }
    }

    #[test]
    fn a_cylinder_has_two_closed_creases_and_no_corner() {
        let mesh = cylinder(1.0, 1.0, 0.1);
        let topology = Topology::build(&mesh);
        let creases = detect_creases(&mesh, &topology, &CreaseOptions::default());
        assert_eq!(creases.counts().1, 0);
        assert_eq!(creases.chains.len(), 2);
        assert!(creases
            .chains
            .iter()
            .all(|c| c.closed && c.vertices.len() == 63));
        // The side's own edges turn by 360/63 degrees: smooth.
        let sharper = CreaseOptions::default().with_angle_degrees(3.0);
        assert!(detect_creases(&mesh, &topology, &sharper).edges.len() > 2 * 63);
    }

    /// A group of feature edges that turns by 60° at every vertex (a bend of a coarse scan that
    /// the filter sharpened wanders so) is no crease, while a straight one beside it is; with
    /// the classes' 70° as the zigzag test's corner turn, the wandering group would be kept.
    #[test]
    fn a_group_that_turns_sixty_degrees_at_every_vertex_is_no_crease() {
        // A flat lattice of equilateral triangles: the grid fixture sheared (its diagonals from
        // (x, y) to (x + 1, y + 1) then have unit length too).
        let n = 16;
        let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
        let mut mesh = crate::mesh::fixtures::grid(n);
        for p in &mut mesh.positions {
            p[0] -= 0.5 * p[1];
            p[1] *= 3f32.sqrt() / 2.0;
        }
        let topology = Topology::build(&mesh);
        // Straight: along row 2, 12 edges. Wandering: up from (8, 4), alternately to (x, y + 1)
        // (at 120°) and (x + 1, y + 1) (at 60°), 12 edges, each turning 60° from the last.
        let straight: Vec<u32> = (2..=14).map(|x| at(x, 2)).collect();
        let mut wandering = vec![at(8, 4)];
        let (mut x, mut y) = (8, 4);
        for step in 0..12 {
            if step % 2 == 1 {
                x += 1;
            }
            y += 1;
            wandering.push(at(x, y));
        }
        let point = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
        let mut found: Vec<FeatureEdge> = [&straight, &wandering]
            .iter()
            .flat_map(|path| path.windows(2))
            .map(|w| {
                assert!(topology.neighbors(w[0]).contains(&w[1]));
                let direction = (point(w[1]) - point(w[0])).normalize();
                ([w[0].min(w[1]), w[0].max(w[1])], direction)
            })
            .collect();
        found.sort_unstable_by_key(|&(e, _)| e);
        let on = |creases: &Creases, path: &[u32]| {
            path.windows(2)
                .filter(|w| creases.edges.contains(&[w[0].min(w[1]), w[0].max(w[1])]))
                .count()
        };
        let options = CreaseOptions::default();
        let creases = finish(&mesh, &topology, found.clone(), &options);
        assert_eq!(on(&creases, &straight), 12);
        assert_eq!(on(&creases, &wandering), 0);
        let seventy = options.with_zigzag_turn_degrees(Some(70.0));
        let creases = finish(&mesh, &topology, found, &seventy);
        assert_eq!(on(&creases, &straight), 12);
        assert_eq!(on(&creases, &wandering), 12);
    }
}
