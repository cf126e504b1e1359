//! Not in the paper: the folds a multiresolution run leaves. Refining from a coarse level
//! places each split vertex from its coarse neighbours, and where a coarse level's fairing bent
//! a thin part or a sharp edge, a few of those placements fall on the wrong side of their
//! neighbours: a triangle then faces away from the surface of M0 under it, and two triangles
//! fold over their shared edge by more than a right angle (the noisy 1.2M-face bunny from level
//! 14: 78 faces turned against the clean mesh). So, last, every face of the result turned by more
//! than 90° against the same face of M0 (the mesh the hierarchy was built on, `fair`'s result in
//! the editor), and every edge folded beyond 90° where M0 was not bent to within 5° of a right
//! angle (a box's edges are features), is undone in steps, each for what the one before left:
//!
//! 1. The corners of each (an edge: its two ends and its faces' third corners) move to the mean
//!    of their neighbours (Jacobi, a few sweeps), and those of faces and edges still turned or
//!    folded join them, until none is left or [`UNFOLD_PASSES`] have run. A crease vertex moves
//!    along its crease (to the mean of its two neighbours on it); corners of creases and
//!    boundary vertices stay. From the middle levels down this is all most runs need.
//! 2. **Tangential relaxation** around what is left (16 rings, [`TANGENT_SWEEPS`] sweeps): every
//!    vertex moves towards the mean of its neighbours, less the part along its normal, and 1.
//!    runs again; then, around what that leaves, once more, 32 rings out and 40 sweeps long
//!    ([`TANGENT_REACH`]). Most folds of a coarse run are triangles squeezed past each other on
//!    a surface that is smooth, and this spreads them out again without changing the shape.
//!    Crease and boundary vertices stay. From the coarsest levels the folds lie many edge
//!    lengths from M0, where 3.-5. would bring M0's detail back into the smooth result: the
//!    second, wider round leaves them far fewer (a 150k-face bunny, noise 0.3, from level 20 of
//!    24: 0.2 % of the result put back where M0 has it, 4.7 % with the first round alone).
//! 3. **The displacement from M0 smoothed** around what is still left: the corners that lie far
//!    from M0 (more than half their edge length there, [`FAR_FROM_M0`]) and the vertices up to k
//!    rings around them get a displacement that is the mean of their neighbours' (harmonic,
//!    solved by conjugate gradients), the vertices outside held; k grows round by round
//!    ([`DISPLACEMENT_RINGS`]). A face whose corners are displaced alike is M0's face moved,
//!    neither turned nor folded. Corners nearer M0 are left to 4.: put back, they fold little,
//!    and smoothing M0's displacement would bring M0's noise back where the hierarchy was built
//!    on a noisy mesh (`--denoise off`).
//! 4. What that cannot undo has its corners put back where M0 has them and held there, and the
//!    displacement around them smoothed again, so that it ramps from zero at those corners to
//!    the result's a few rings out ([`RAMP_ROUNDS`] times). Putting a corner back alone would
//!    make a spike as high as the coarse result lies from M0 (several edge lengths on the coarse
//!    half of the slider), fold its neighbours and spread over most of the mesh: the bundled
//!    bunny from level 16 ended 87 % `fair`'s result, a patchwork with seams.
//! 5. Whatever is still turned or folded then has its corners, boundary vertices included, put
//!    back where M0 has them, until none is: a face whose corners are all M0's is M0's face, so
//!    this ends, at the latest with the whole mesh back to M0.
//!
//! **The budget.** From the coarsest levels of a large mesh (a 150k-face bunny from level 22 of
//! 24), steps 4 and 5 cascade: a corner put back from many edge lengths away folds its
//! neighbours, they go back in turn, and the result becomes a patchwork of the smooth result
//! and M0 with seams between them (a third of the mesh at M0), far worse to look at than the
//! specks it undoes. So when steps 4 and 5 have put back more than [`PUT_BACK_BUDGET`] of the
//! vertices from farther than [`PUT_BACK_FAR`] edge lengths, steps 3-5 are taken back where
//! they went over: what they moved is cut into parts (connected through M0's edges), a part
//! with nothing left turned or folded keeps what they did (the cheapest first, as long as the
//! vertices they put back from far fit the budget together), and the rest is what steps 1 and
//! 2 left. The cascade is mostly in one place: the noisy 1.2M-face bunny from level 20 of 29
//! kept eleven small parts, leaving 12 faces and edges of the one cascade over 56k vertices
//! where taking everything back left 200 (from level 24: 243 against 416). Around what is then
//! left, the widest relaxation ([`LAST_REACH`], 64 rings and 80 sweeps) spreads the squeezed
//! triangles out, the means run again, and steps 3-5 once more (its figures there). What is
//! still turned or folded is counted ([`Unfolded::left`]) for the caller to say so. Within the
//! budget (every level of the quality set's meshes), no result has a face turned or an edge
//! folded that M0 does not have.
//!
//! The faces and edges are looked at once whole (a pass over the faces and one over the edges);
//! after that only those around the vertices that moved, so that a run pays for its folds, not
//! for M0's size. A run with no fold changes nothing.
//!
//! With the improved variant, M0's volume is given back before 1. and after 5. (every vertex
//! offset along its normal, one distance per connected part), on every run from a coarser
//! level. Before 1. it reads M0 whole (four passes); after 5. only the faces around what 1.-5.
//! moved or put back, whose terms of the volume are taken out as they were and put in as they
//! are, and it offsets along the first offset's normals (`VolumeKeeper::restore_again`: the
//! volume is as exact, and a slider step on a 1.2M-face scan no longer reads M0 whole twice
//! more, 90-110 ms a time). That offset can turn a face again on a thin part, so 1.-5. run once
//! more after it, holding the vertices put back (3.-5. alone put the coarsest levels' new folds
//! back to M0, far from where the result lies).

use super::NONE;
use crate::fairing::creases::Creases;
use crate::fairing::volume::{Redo, VolumeKeeper};
use crate::mesh::{Topology, TriMesh};
use glam::Vec3A;
use rayon::prelude::*;

/// What [`unfold`] reads of M0: its connectivity, its creases and, per vertex, its two
/// neighbours along its crease or boundary loop (`NONE` for others; empty when M0 has neither).
pub(super) struct Level<'a> {
    pub(super) mesh: &'a TriMesh,
    pub(super) topology: &'a Topology,
    pub(super) creases: Option<&'a Creases>,
    pub(super) loop_neighbors: &'a [[u32; 2]],
    /// Give M0's volume back first (the improved variant's promise).
    pub(super) keep_volume: bool,
    /// The share of the vertices steps 4 and 5 may put back from far from M0
    /// ([`PUT_BACK_BUDGET`]).
    pub(super) put_back_budget: f32,
}

/// At most this many rounds of finding the folds and smoothing their corners.
pub const UNFOLD_PASSES: usize = 8;

/// Sweeps of the tangential relaxation's first round (step 2 of the module docs).
pub const TANGENT_SWEEPS: usize = 10;

/// The tangential relaxation's rounds (step 2 of the module docs): how far around the folds
/// each reaches, in rings, and its sweeps. The second runs only on what the first and the
/// neighbour means after it leave.
const TANGENT_REACH: [[usize; 2]; 2] = [[16, TANGENT_SWEEPS], [32, 40]];

/// The widest tangential relaxation (rings, sweeps), only around what steps 3-5 leave where
/// they went over [`PUT_BACK_BUDGET`]; they then run once more, with the budget again (as they
/// do after each volume offset), so that a run puts back at most a few times the budget from
/// far, and only in parts that nothing is left folded in. The noisy 1.2M-face bunny,
/// faired, from level 20 / 22 / 24 / 26 of 29: 12 / 397 / 243 / 327 faces and edges left
/// without it, 0 / 3 / 27 / 245 with it, for 0.1 / 1.7 / 1.4 / 3.6 s more (regions of 23k to
/// 228k vertices).
const LAST_REACH: [usize; 2] = [64, 80];

/// Ring counts of the rounds of smoothing the displacement from M0 (step 3); a round runs at
/// most [`DISPLACEMENT_ITERATIONS_PER_RING`] iterations per ring.
const DISPLACEMENT_RINGS: [usize; 8] = [1, 2, 3, 4, 6, 8, 12, 16];

/// At most this many conjugate-gradient iterations per ring of a round of smoothing the
/// displacement ([`make_harmonic`]); it stops sooner once [`HARMONIC_TOLERANCE`] is reached.
const DISPLACEMENT_ITERATIONS_PER_RING: usize = 16;

/// How far each residual of the displacement's solve must come down (against where the round
/// started) for the round to stop ([`make_harmonic`]). A 150k-face bunny's coarse levels: about
/// 10 iterations for a round of 1 ring, 74 for one of 16 (at most 256), where as many Jacobi
/// sweeps of the neighbours' mean, all 256, still left the wider ramps short of harmonic.
const HARMONIC_TOLERANCE: f32 = 1e-3;

/// How far from M0, in its edge lengths there, a vertex must lie for the displacement around it
/// to be smoothed (steps 3 and 4): one put back from nearer folds little around it.
const FAR_FROM_M0: f32 = 0.5;

/// At most this many times the corners of what is left go back to M0 with the displacement
/// ramped around them (step 4) before only putting back remains.
const RAMP_ROUNDS: usize = 8;

/// At most this many times the volume is given back after the unfolding (each time holding the
/// vertices put back to M0, and undoing what it turned again).
const VOLUME_PASSES: usize = 3;

/// How far from M0 (in its edge lengths there) a vertex put back by steps 4 and 5 counts
/// against [`PUT_BACK_BUDGET`]: put back, it leaves a step at least that tall in the result.
pub const PUT_BACK_FAR: f32 = 4.0;

/// The share of M0's vertices steps 4 and 5 may put back from farther than [`PUT_BACK_FAR`].
/// Beyond it the putting back has become a cascade (each corner put back from far away folds
/// its neighbours, which go back in turn), and the result a patchwork of the smooth result and
/// M0 with seams between them, worse to look at than the specks it undoes: steps 3-5 are then
/// taken back where they went over, and the folds there are left (and counted). A 150k-face noisy
/// bunny put back 0.24 % of its vertices from that far from level 20 of 24, and 19 % from
/// level 22; the tests' noisy box and elephant 0.14 % and none.
pub const PUT_BACK_BUDGET: f32 = 0.02;

/// Umbrella sweeps over the folds' corners in each pass.
const SWEEPS: usize = 3;

/// How close to a right angle an edge of M0 may bend and still be a feature
/// ([`FoldEdges::new`]).
pub const RIGHT_ANGLE_MARGIN_DEGREES: f32 = 5.0;

/// Area normal of the triangle `corners` with `positions`.
#[inline]
fn area_normal(positions: &[[f32; 3]], corners: [u32; 3]) -> Vec3A {
    let [a, b, c] = corners.map(|v| Vec3A::from_array(positions[v as usize]));
    (b - a).cross(c - a)
}

/// Every face's area normal with `positions`, into `normals`.
fn face_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]], normals: &mut Vec<Vec3A>) {
    triangles
        .par_iter()
        .with_min_len(super::PARALLEL_GRAIN)
        .map(|&t| area_normal(positions, t))
        .collect_into_vec(normals);
}

/// An edge with two faces, and what a run ([`FoldState`]) marks on it, together: a run that
/// looks at the edges around what moved reads one record per edge, not five arrays. That look
/// waits on memory (the edges are numbered apart from their faces): on a 1.2M-face scan it is
/// about half of a pass of neighbour means (8-11 ms for the edges of 30k faces).
#[derive(Clone, Copy, Debug)]
struct Edge {
    /// Its two ends and its two faces.
    ends: [u32; 4],
    /// [`FoldState::moved`]'s stamp of the last call that looked at it.
    stamp: u32,
    /// It bends to within [`RIGHT_ANGLE_MARGIN_DEGREES`] of a right angle or beyond on M0.
    reference: bool,
    /// Folded now (beyond a right angle, and not `reference`).
    folded: bool,
    /// On the run's list of edges that may be folded ([`FoldState`]'s `edges`).
    watched: bool,
}

/// A face of M0 and what a run ([`FoldState`]) marks on it, together in half a cache line: the
/// look at the faces around what moved reads one record a face and its two normals, where five
/// arrays (corners, edges, stamp and two flags) were each a cache miss on a large mesh, whose
/// faces around a vertex lie apart in memory. The normals stay in arrays of their own: the look
/// at every edge after a full pass reads two of them an edge, and a 16-byte array of them stays
/// in the cache where 64-byte records with them did not (that pass took half as long again).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Face {
    corners: [u32; 3],
    /// The indices in [`FoldEdges`]' `edges` of its edges (`NONE` for an edge without two
    /// faces).
    edges: [u32; 3],
    /// [`FoldState::faces_around`]'s stamp of the last call that reached it.
    stamp: u32,
    /// Turned by more than 90° against M0 now.
    turned: bool,
    /// On the run's list of faces that may be turned ([`FoldState`]'s `faces`).
    watched: bool,
}

/// What [`unfold`] keeps of M0 from run to run: its faces with their edges and normals, its edges
/// with two faces, and which of those bend to within [`RIGHT_ANGLE_MARGIN_DEGREES`] of a right
/// angle or beyond on M0 itself (features, left alone even when the levels bend them a little
/// further).
pub(super) struct FoldEdges {
    edges: Vec<Edge>,
    faces: Vec<Face>,
    /// M0's face normals (area-weighted).
    m0_normals: Vec<Vec3A>,
    /// The result's face normals, kept up to date while a run unfolds.
    normals: Vec<Vec3A>,
    /// M0's volumes, and a mesh to offset (built by the first run that gives the volume back).
    volume: Option<(VolumeKeeper, TriMesh)>,
}

impl FoldEdges {
    pub(super) fn new(mesh: &TriMesh) -> Self {
        let edges = crate::mesh::two_face_edges(&mesh.triangles);
        let mut m0_normals = Vec::new();
        face_normals(&mesh.positions, &mesh.triangles, &mut m0_normals);
        let cosine = RIGHT_ANGLE_MARGIN_DEGREES.to_radians().sin();
        let reference = edges
            .par_iter()
            .with_min_len(super::PARALLEL_GRAIN)
            .map(|&[_, _, f, g]| {
                let (n, m) = (m0_normals[f as usize], m0_normals[g as usize]);
                n.dot(m) < cosine * (n.length() * m.length())
            })
            .collect();
        Self::with_reference(mesh, edges, reference, m0_normals)
    }

    /// M0's volumes, to give them back ([`unfold`] with `keep_volume`), and a mesh to offset:
    /// made by the first call, kept for the next runs.
    pub(super) fn keep_volume_of(&mut self, mesh: &TriMesh, topology: &Topology) {
        if self.volume.is_none() {
            self.volume = Some((
                VolumeKeeper::new(mesh, topology, &[]),
                TriMesh::new(Vec::new(), mesh.triangles.clone()),
            ));
        }
    }

    /// Whether M0's volumes are made ([`Self::keep_volume_of`]).
    #[cfg(test)]
    pub(super) fn has_volume(&self) -> bool {
        self.volume.is_some()
    }

    /// Whether each edge bends on M0 itself as [`Self::new`] reads it (a feature).
    #[cfg(test)]
    fn reference(&self) -> Vec<bool> {
        self.edges.iter().map(|e| e.reference).collect()
    }

    /// [`Self::new`] with the edges and the reference flags given.
    fn with_reference(
        mesh: &TriMesh,
        ends: Vec<[u32; 4]>,
        reference: Vec<bool>,
        m0_normals: Vec<Vec3A>,
    ) -> Self {
        let mut faces: Vec<Face> = mesh
            .triangles
            .iter()
            .map(|&corners| Face {
                corners,
                edges: [NONE; 3],
                stamp: 0,
                turned: false,
                watched: false,
            })
            .collect();
        for (e, &[a, b, f, g]) in ends.iter().enumerate() {
            for face in [f, g] {
                let face = &mut faces[face as usize];
                let t = face.corners;
                let slot = (0..3)
                    .find(|&k| {
                        let (x, y) = (t[k], t[(k + 1) % 3]);
                        (x == a && y == b) || (x == b && y == a)
                    })
                    .expect("an edge's face has the edge");
                face.edges[slot] = e as u32;
            }
        }
        let edges = ends
            .into_iter()
            .zip(reference)
            .map(|(ends, reference)| Edge {
                ends,
                stamp: 0,
                reference,
                folded: false,
                watched: false,
            })
            .collect();
        Self {
            edges,
            faces,
            m0_normals,
            normals: Vec::new(),
            volume: None,
        }
    }
}

/// Which faces are turned against M0 and which edges newly folded, kept up to date as vertices
/// move: after one pass over everything, only the faces around moved vertices and their edges
/// are looked at again.
struct FoldState<'a> {
    topology: &'a Topology,
    folds: &'a mut FoldEdges,
    /// The faces and edges that may be turned or folded now: those that were at the full pass or
    /// at the last [`Self::corners`], and every one looked at since (their `watched` flags).
    faces: Vec<u32>,
    edges: Vec<u32>,
    /// [`Self::moved`]'s mark of the faces and edges it has looked at in this call (their
    /// `stamp`), and its buffers of those faces and their normals.
    stamp: u32,
    touched: Vec<u32>,
    touched_normals: Vec<Vec3A>,
}

impl<'a> FoldState<'a> {
    /// Every face and edge looked at.
    fn new(positions: &[[f32; 3]], topology: &'a Topology, folds: &'a mut FoldEdges) -> Self {
        let FoldEdges {
            edges,
            faces,
            m0_normals,
            normals,
            ..
        } = folds;
        normals.resize(faces.len(), Vec3A::ZERO);
        faces
            .par_iter_mut()
            .zip(normals.par_iter_mut())
            .zip(m0_normals.par_iter())
            .with_min_len(super::PARALLEL_GRAIN)
            .for_each(|((face, normal), m0_normal)| {
                *normal = area_normal(positions, face.corners);
                face.turned = normal.dot(*m0_normal) < 0.0;
                face.watched = face.turned;
                face.stamp = 0;
            });
        let normals: &[Vec3A] = normals;
        edges
            .par_iter_mut()
            .with_min_len(super::PARALLEL_GRAIN)
            .for_each(|edge| {
                let [_, _, f, g] = edge.ends;
                let (n, m) = (normals[f as usize], normals[g as usize]);
                edge.folded = !edge.reference && n.dot(m) < 0.0;
                edge.watched = edge.folded;
                edge.stamp = 0;
            });
        let faces: Vec<u32> = (0..folds.faces.len() as u32)
            .filter(|&f| folds.faces[f as usize].turned)
            .collect();
        let edges: Vec<u32> = (0..folds.edges.len() as u32)
            .filter(|&e| folds.edges[e as usize].folded)
            .collect();
        Self {
            topology,
            folds,
            faces,
            edges,
            stamp: 0,
            touched: Vec::new(),
            touched_normals: Vec::new(),
        }
    }

    /// The faces around `vertices`, each once, into `faces` (cleared first), under a new
    /// stamp: [`Self::moved`] marks their edges with the same one.
    fn faces_around(&mut self, vertices: &[u32], faces: &mut Vec<u32>) {
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            for face in &mut self.folds.faces {
                face.stamp = 0;
            }
            for edge in &mut self.folds.edges {
                edge.stamp = 0;
            }
            self.stamp = 1;
        }
        let stamp = self.stamp;
        faces.clear();
        for &v in vertices {
            for &f in self.topology.faces_of(v) {
                let face = &mut self.folds.faces[f as usize];
                if face.stamp != stamp {
                    face.stamp = stamp;
                    faces.push(f);
                }
            }
        }
    }

    /// The faces around `moved` and their edges looked at again, each once however many of its
    /// corners moved (a face has three, an edge is on two faces): the normals in parallel.
    fn moved(&mut self, positions: &[[f32; 3]], moved: &[u32]) {
        let mut faces = std::mem::take(&mut self.touched);
        self.faces_around(moved, &mut faces);
        let stamp = self.stamp;
        let mut normals = std::mem::take(&mut self.touched_normals);
        let records = &self.folds.faces;
        faces
            .par_iter()
            .with_min_len(super::PARALLEL_GRAIN)
            .map(|&f| area_normal(positions, records[f as usize].corners))
            .collect_into_vec(&mut normals);
        for (&f, &n) in faces.iter().zip(&normals) {
            self.folds.normals[f as usize] = n;
            let face = &mut self.folds.faces[f as usize];
            face.turned = n.dot(self.folds.m0_normals[f as usize]) < 0.0;
            if !face.watched {
                face.watched = true;
                self.faces.push(f);
            }
        }
        for &f in &faces {
            for e in self.folds.faces[f as usize].edges {
                if e == NONE {
                    continue;
                }
                let edge = &mut self.folds.edges[e as usize];
                if edge.stamp == stamp {
                    continue;
                }
                edge.stamp = stamp;
                let [_, _, f, g] = edge.ends;
                let normals = &self.folds.normals;
                let (n, m) = (normals[f as usize], normals[g as usize]);
                edge.folded = !edge.reference && n.dot(m) < 0.0;
                if !edge.watched {
                    edge.watched = true;
                    self.edges.push(e);
                }
            }
        }
        self.touched = faces;
        self.touched_normals = normals;
    }

    /// The corners of every face turned and every edge folded now (repeats possible); empty
    /// when there is none. The faces and edges no longer turned or folded leave the watched
    /// lists (only a move of one of their corners can turn them again, and [`Self::moved`]
    /// watches them then), so that the repeated calls of a run cost what is still folded.
    fn corners(&mut self) -> Vec<u32> {
        let mut corners = Vec::new();
        let records = &mut self.folds.faces;
        self.faces.retain(|&f| {
            let face = &mut records[f as usize];
            face.watched = face.turned;
            face.turned
        });
        for &f in &self.faces {
            corners.extend(records[f as usize].corners);
        }
        let edges = &mut self.folds.edges;
        self.edges.retain(|&e| {
            let edge = &mut edges[e as usize];
            edge.watched = edge.folded;
            edge.folded
        });
        for &e in &self.edges {
            let [a, b, f, g] = self.folds.edges[e as usize].ends;
            let third = |face: u32| {
                let t = self.folds.faces[face as usize].corners;
                t[0] ^ t[1] ^ t[2] ^ a ^ b
            };
            corners.extend([a, b, third(f), third(g)]);
        }
        corners
    }
}

/// The vertices up to `rings` rings around `seeds`, each once and in the mesh's vertex order,
/// leaving out those `skip` names. `mark` is all false on entry and again on return. The order
/// is for the sweeps over them: in the order the rings reach them, their neighbours lie all over
/// memory, and a sweep of the wide relaxation took 2-3 times as long.
fn grow(
    seeds: impl IntoIterator<Item = u32>,
    rings: usize,
    topology: &Topology,
    mark: &mut [bool],
    skip: impl Fn(u32) -> bool,
) -> Vec<u32> {
    let mut reached = Vec::new();
    for v in seeds {
        if !mark[v as usize] && !skip(v) {
            mark[v as usize] = true;
            reached.push(v);
        }
    }
    let mut start = 0;
    for _ in 0..rings {
        let end = reached.len();
        for i in start..end {
            for &u in topology.neighbors(reached[i]) {
                if !mark[u as usize] && !skip(u) {
                    mark[u as usize] = true;
                    reached.push(u);
                }
            }
        }
        start = end;
    }
    for &v in &reached {
        mark[v as usize] = false;
    }
    reached.sort_unstable();
    reached
}

/// Step 2 of the module docs: the vertices up to `rings` rings around `seeds` (the corners of
/// what is turned or folded), but those `stays` names, moved `sweeps` times towards the
/// mean of their neighbours, less the part along their normal (Jacobi: each sweep reads the
/// last one's positions).
///
/// The sweeps run on a copy of the region ([`Patch`]): its vertices, their neighbours and the
/// faces around it, numbered anew, so that a sweep reads a few megabytes that stay in cache
/// instead of gathering its neighbours' positions and its faces' normals from all over M0's
/// arrays (a 1.2M-face scan's level 16: a region of 71k vertices, 40 sweeps in 70 ms instead
/// of about 900). The sums run in the same order as over M0's arrays, so the positions are the
/// same to the bit.
fn relax_tangentially(
    positions: &mut [[f32; 3]],
    triangles: &[[u32; 3]],
    topology: &Topology,
    state: &mut FoldState,
    stays: impl Fn(u32) -> bool,
    seeds: Vec<u32>,
    [rings, sweeps]: [usize; 2],
) {
    let mut mark = vec![false; positions.len()];
    let region = grow(seeds, rings, topology, &mut mark, stays);
    let mut faces = Vec::new();
    state.faces_around(&region, &mut faces);
    faces.sort_unstable();
    let mut patch = Patch::new(positions, triangles, topology, &region, &faces);
    patch.relax(sweeps);
    for (&v, &p) in region.iter().zip(&patch.points) {
        positions[v as usize] = p;
    }
    // The faces around the region get their normals from the positions the sweeps left.
    state.moved(positions, &region);
}

/// A region of the mesh copied out for [`relax_tangentially`]'s sweeps: the region's vertices
/// first (in the region's order), then the other corners of the faces around it, each with its
/// position; those faces by their local corners; and per region vertex its neighbours and its
/// faces by local index, in the topology's order.
struct Patch {
    /// The region's vertices, then the corners outside it (held).
    points: Vec<[f32; 3]>,
    /// How many of `points` move (the region's vertices).
    moving: usize,
    triangles: Vec<[u32; 3]>,
    /// Per moving vertex i, its neighbours are `neighbors[neighbor_start[i]..neighbor_start[i
    /// + 1]]` and its faces `faces_of[face_start[i]..face_start[i + 1]]`, by local index.
    neighbor_start: Vec<u32>,
    neighbors: Vec<u32>,
    face_start: Vec<u32>,
    faces_of: Vec<u32>,
}

impl Patch {
    fn new(
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        topology: &Topology,
        region: &[u32],
        faces: &[u32],
    ) -> Self {
        // Local index by M0's (NONE: not in the patch yet).
        let mut local = vec![NONE; positions.len()];
        let mut points = Vec::with_capacity(region.len() * 2);
        let mut index = |v: u32, points: &mut Vec<[f32; 3]>| -> u32 {
            let slot = &mut local[v as usize];
            if *slot == NONE {
                *slot = points.len() as u32;
                points.push(positions[v as usize]);
            }
            *slot
        };
        for &v in region {
            index(v, &mut points);
        }
        let mut face_index = vec![NONE; triangles.len()];
        for (i, &f) in faces.iter().enumerate() {
            face_index[f as usize] = i as u32;
        }
        let local_triangles = faces
            .iter()
            .map(|&f| triangles[f as usize].map(|v| index(v, &mut points)))
            .collect();
        let (mut neighbor_start, mut neighbors) = (vec![0], Vec::new());
        let (mut face_start, mut faces_of) = (vec![0], Vec::new());
        for &v in region {
            for &u in topology.neighbors(v) {
                neighbors.push(index(u, &mut points));
            }
            neighbor_start.push(neighbors.len() as u32);
            faces_of.extend(topology.faces_of(v).iter().map(|&f| face_index[f as usize]));
            face_start.push(faces_of.len() as u32);
        }
        Self {
            points,
            moving: region.len(),
            triangles: local_triangles,
            neighbor_start,
            neighbors,
            face_start,
            faces_of,
        }
    }

    /// `sweeps` Jacobi sweeps of the tangential step over the moving vertices: each face's
    /// area normal once a sweep, then each vertex moved by the step to its neighbours' mean less
    /// the step's part along the sum of its faces' normals.
    fn relax(&mut self, sweeps: usize) {
        let mut normals = Vec::new();
        let mut moved = Vec::new();
        for _ in 0..sweeps {
            face_normals(&self.points, &self.triangles, &mut normals);
            let (points, normals): (&[[f32; 3]], &[Vec3A]) = (&self.points, &normals);
            (0..self.moving)
                .into_par_iter()
                .with_min_len(super::PARALLEL_GRAIN)
                .map(|i| {
                    let p = Vec3A::from_array(points[i]);
                    let faces = &self.faces_of
                        [self.face_start[i] as usize..self.face_start[i + 1] as usize];
                    let normal = faces
                        .iter()
                        .fold(Vec3A::ZERO, |n, &f| n + normals[f as usize])
                        .normalize_or_zero();
                    let ring = &self.neighbors
                        [self.neighbor_start[i] as usize..self.neighbor_start[i + 1] as usize];
                    let sum = ring.iter().fold(Vec3A::ZERO, |sum, &u| {
                        sum + Vec3A::from_array(points[u as usize])
                    });
                    let step = sum / ring.len().max(1) as f32 - p;
                    (p + step - normal * step.dot(normal)).to_array()
                })
                .collect_into_vec(&mut moved);
            self.points[..self.moving].copy_from_slice(&moved);
        }
    }
}

/// Steps 3 and 4 of the module docs: the displacement from M0 smoothed around what `state`
/// finds turned or folded, over the rings `rings` names round by round. The vertices `back`
/// (put back to M0) and boundary vertices are held.
fn smooth_displacement(
    positions: &mut [[f32; 3]],
    mesh: &TriMesh,
    topology: &Topology,
    state: &mut FoldState,
    back: &[bool],
    rings: &[usize],
) {
    let mut mark = vec![false; positions.len()];
    for &rings in rings {
        let corners = state.corners();
        if corners.is_empty() {
            return;
        }
        let held = |v: u32| back[v as usize] || topology.is_boundary_vertex(v);
        let far = |v: &u32| far_from_m0(positions, mesh, topology, *v);
        let seeds: Vec<u32> = corners.into_iter().filter(far).collect();
        if seeds.is_empty() {
            return;
        }
        let region = grow(seeds, rings, topology, &mut mark, held);
        make_harmonic(
            positions,
            mesh,
            topology,
            &region,
            DISPLACEMENT_ITERATIONS_PER_RING * rings,
        );
        state.moved(positions, &region);
    }
}

/// Sum of `terms` over fixed chunks added in order: the same bits whatever the number of
/// threads.
fn ordered_sum(terms: impl IndexedParallelIterator<Item = Vec3A>) -> Vec3A {
    let chunks: Vec<Vec3A> = terms
        .chunks(super::PARALLEL_GRAIN)
        .map(|chunk| chunk.into_iter().fold(Vec3A::ZERO, |sum, t| sum + t))
        .collect();
    chunks.into_iter().fold(Vec3A::ZERO, |sum, t| sum + t)
}

/// Step 3's solve: the displacement from M0 of the vertices of `region` (sorted) made harmonic,
/// each the mean of its neighbours' (uniform weights), those of the vertices outside held.
/// Conjugate gradients on the graph Laplacian restricted to the region, one system a coordinate,
/// from the displacement the region has, until each residual is down to
/// [`HARMONIC_TOLERANCE`] of where it started or `limit` iterations have run. An isolated
/// vertex's displacement becomes zero (the mean of none).
fn make_harmonic(
    positions: &mut [[f32; 3]],
    mesh: &TriMesh,
    topology: &Topology,
    region: &[u32],
    limit: usize,
) {
    let m0 = |u: u32| Vec3A::from_array(mesh.positions[u as usize]);
    let displacement = |u: u32| Vec3A::from_array(positions[u as usize]) - m0(u);
    // The system, row by row: each vertex's valence, its neighbours inside the region (by rank
    // in it) and the sum of the held displacements of those outside.
    let mut offsets = Vec::with_capacity(region.len() + 1);
    offsets.push(0u32);
    let mut inside: Vec<u32> = Vec::new();
    let mut held: Vec<Vec3A> = Vec::with_capacity(region.len());
    let mut valence: Vec<f32> = Vec::with_capacity(region.len());
    for &v in region {
        let ring = topology.neighbors(v);
        let mut sum = Vec3A::ZERO;
        for &u in ring {
            match region.binary_search(&u) {
                Ok(rank) => inside.push(rank as u32),
                Err(_) => sum += displacement(u),
            }
        }
        offsets.push(inside.len() as u32);
        held.push(sum);
        valence.push(ring.len().max(1) as f32);
    }
    let apply = |x: &[Vec3A], out: &mut Vec<Vec3A>| {
        (0..x.len())
            .into_par_iter()
            .with_min_len(super::PARALLEL_GRAIN)
            .map(|i| {
                let row = &inside[offsets[i] as usize..offsets[i + 1] as usize];
                x[i] * valence[i] - row.iter().fold(Vec3A::ZERO, |s, &j| s + x[j as usize])
            })
            .collect_into_vec(out);
    };
    let dot = |x: &[Vec3A], y: &[Vec3A]| ordered_sum(x.par_iter().zip(y).map(|(a, b)| *a * *b));
    let mut x: Vec<Vec3A> = region.iter().map(|&v| displacement(v)).collect();
    let mut product = Vec::new();
    apply(&x, &mut product);
    let mut residual: Vec<Vec3A> = held.iter().zip(&product).map(|(b, a)| *b - *a).collect();
    let mut direction = residual.clone();
    let mut squared = dot(&residual, &residual);
    let stop = squared * (HARMONIC_TOLERANCE * HARMONIC_TOLERANCE);
    for _ in 0..limit {
        if squared.cmple(stop).all() {
            break;
        }
        apply(&direction, &mut product);
        let curvature = dot(&direction, &product);
        let alpha = Vec3A::select(
            curvature.cmpgt(Vec3A::ZERO),
            squared / curvature,
            Vec3A::ZERO,
        );
        x.par_iter_mut()
            .zip(&direction)
            .with_min_len(super::PARALLEL_GRAIN)
            .for_each(|(x, d)| *x += alpha * *d);
        residual
            .par_iter_mut()
            .zip(&product)
            .with_min_len(super::PARALLEL_GRAIN)
            .for_each(|(r, p)| *r -= alpha * *p);
        let next = dot(&residual, &residual);
        let beta = Vec3A::select(squared.cmpgt(Vec3A::ZERO), next / squared, Vec3A::ZERO);
        squared = next;
        direction
            .par_iter_mut()
            .zip(&residual)
            .with_min_len(super::PARALLEL_GRAIN)
            .for_each(|(d, r)| *d = *r + beta * *d);
    }
    for (&v, d) in region.iter().zip(&x) {
        positions[v as usize] = (m0(v) + *d).to_array();
    }
}

/// Whether vertex `v` lies farther from where M0 has it than [`FAR_FROM_M0`] times the mean
/// length of its edges on M0: put back alone, it would fold its neighbours.
fn far_from_m0(positions: &[[f32; 3]], mesh: &TriMesh, topology: &Topology, v: u32) -> bool {
    distance_from_m0(positions, mesh, topology, v) > FAR_FROM_M0
}

/// How far vertex `v` lies from where M0 has it, in the mean length of its edges on M0.
fn distance_from_m0(positions: &[[f32; 3]], mesh: &TriMesh, topology: &Topology, v: u32) -> f32 {
    let m0 = |u: u32| Vec3A::from_array(mesh.positions[u as usize]);
    let ring = topology.neighbors(v);
    let length =
        ring.iter().map(|&u| m0(u).distance(m0(v))).sum::<f32>() / ring.len().max(1) as f32;
    m0(v).distance(Vec3A::from_array(positions[v as usize])) / length.max(f32::MIN_POSITIVE)
}

/// Steps 3-5 of the module docs, for what `state` finds turned or folded. Where they put more
/// than `budget` vertices back from farther than [`PUT_BACK_FAR`], what they did is kept only
/// in the parts that fit ([`keep_what_fits`]); the others are taken back to what steps 1 and 2
/// left. True when nothing is left turned or folded.
fn undo_what_is_left(
    positions: &mut [[f32; 3]],
    mesh: &TriMesh,
    topology: &Topology,
    state: &mut FoldState,
    back: &mut [bool],
    budget: usize,
) -> bool {
    if state.corners().is_empty() {
        return true;
    }
    let before = positions.to_vec();
    let back_before = back.to_vec();
    // The vertices put back from farther than PUT_BACK_FAR.
    let mut far = Vec::new();
    let undone = 'steps: {
        smooth_displacement(positions, mesh, topology, state, back, &DISPLACEMENT_RINGS);
        for _ in 0..RAMP_ROUNDS {
            let still: Vec<u32> = state
                .corners()
                .into_iter()
                .filter(|&v| !topology.is_boundary_vertex(v) && !back[v as usize])
                .collect();
            if still.is_empty() {
                break;
            }
            put_at_m0(positions, mesh, state, back, &still, &mut far);
            if far.len() > budget {
                break 'steps false;
            }
            smooth_displacement(positions, mesh, topology, state, back, &DISPLACEMENT_RINGS);
        }
        put_back(positions, mesh, state, back, budget, &mut far)
    };
    if undone {
        return true;
    }
    let before = Before {
        positions: &before,
        back: &back_before,
    };
    keep_what_fits(positions, topology, state, back, before, &far, budget)
}

/// What steps 1 and 2 left, for [`keep_what_fits`] to take back to.
#[derive(Clone, Copy)]
struct Before<'a> {
    positions: &'a [[f32; 3]],
    back: &'a [bool],
}

/// Steps 3-5 went over the budget: most of the time in one place, where putting corners back
/// cascaded, while elsewhere they undid a few folds near M0 (the module docs' figures). So what
/// they moved is cut into parts (connected through M0's edges): a part with nothing turned or
/// folded left at its vertices keeps what they did, the parts with the fewest vertices put back
/// from far (`far`) first, as long as those fit `budget` together; the others are taken back to
/// `before` (their `back` marks too). True when nothing is left turned or folded.
fn keep_what_fits(
    positions: &mut [[f32; 3]],
    topology: &Topology,
    state: &mut FoldState,
    back: &mut [bool],
    before: Before,
    far: &[u32],
    budget: usize,
) -> bool {
    let count = positions.len();
    let changed = |v: u32| positions[v as usize] != before.positions[v as usize];
    let mut is_far = vec![false; count];
    for &v in far {
        is_far[v as usize] = true;
    }
    let mut is_corner = vec![false; count];
    for v in state.corners() {
        is_corner[v as usize] = true;
    }
    // Each part: whether something is left at it, its vertices put back from far, its vertices.
    let mut parts: Vec<(bool, usize, Vec<u32>)> = Vec::new();
    let mut seen = vec![false; count];
    for v in 0..count as u32 {
        if seen[v as usize] || !changed(v) {
            continue;
        }
        seen[v as usize] = true;
        let mut members = vec![v];
        let mut next = 0;
        while let Some(&u) = members.get(next) {
            next += 1;
            for &w in topology.neighbors(u) {
                if !seen[w as usize] && changed(w) {
                    seen[w as usize] = true;
                    members.push(w);
                }
            }
        }
        let folded = members.iter().any(|&u| is_corner[u as usize]);
        let far = members.iter().filter(|&&u| is_far[u as usize]).count();
        parts.push((folded, far, members));
    }
    // Stable: parts that cost the same keep the order of their lowest vertex.
    parts.sort_by_key(|&(folded, far, _)| (folded, far));
    let mut spent = 0;
    let mut taken_back = Vec::new();
    for (folded, far, members) in parts {
        if !folded && spent + far <= budget {
            spent += far;
            continue;
        }
        for &u in &members {
            positions[u as usize] = before.positions[u as usize];
            back[u as usize] = before.back[u as usize];
        }
        taken_back.extend(members);
    }
    state.moved(positions, &taken_back);
    state.corners().is_empty()
}

/// Puts the corners of what `state` finds turned or folded back where M0 has them, until
/// nothing is (marking them in `back`; true), or until more than `budget` vertices lay farther
/// than [`PUT_BACK_FAR`] from M0 when put back, counting those `far` holds already (false).
fn put_back(
    positions: &mut [[f32; 3]],
    mesh: &TriMesh,
    state: &mut FoldState,
    back: &mut [bool],
    budget: usize,
    far: &mut Vec<u32>,
) -> bool {
    loop {
        let still: Vec<u32> = state
            .corners()
            .into_iter()
            .filter(|&v| positions[v as usize] != mesh.positions[v as usize])
            .collect();
        if still.is_empty() {
            return true;
        }
        put_at_m0(positions, mesh, state, back, &still, far);
        if far.len() > budget {
            return false;
        }
    }
}

/// Puts `vertices` where M0 has them, marks them in `back` and tells `state` they moved. Those
/// that lay farther than [`PUT_BACK_FAR`] from M0 join `far`.
fn put_at_m0(
    positions: &mut [[f32; 3]],
    mesh: &TriMesh,
    state: &mut FoldState,
    back: &mut [bool],
    vertices: &[u32],
    far: &mut Vec<u32>,
) {
    for &v in vertices {
        if distance_from_m0(positions, mesh, state.topology, v) > PUT_BACK_FAR {
            far.push(v);
        }
        positions[v as usize] = mesh.positions[v as usize];
        back[v as usize] = true;
    }
    state.moved(positions, vertices);
}

/// What [`unfold`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Unfolded {
    /// How many vertices moved.
    pub(super) moved: usize,
    /// How many faces it left turned against M0 and edges folded where M0 is not: none, but
    /// in the places where undoing them went over [`PUT_BACK_BUDGET`] (it would have put more
    /// of the vertices back from far from M0).
    pub(super) left: usize,
}

/// Moves the corners of the faces turned against M0 and the edges folded where M0 is not
/// (`folds`, made by [`FoldEdges::new`] from M0) as the module docs say.
pub(super) fn unfold(positions: &mut [[f32; 3]], level: &Level, folds: &mut FoldEdges) -> Unfolded {
    let Level {
        mesh,
        topology,
        creases,
        loop_neighbors,
        keep_volume,
        put_back_budget,
    } = *level;
    let budget = (put_back_budget * positions.len() as f32) as usize;
    // M0's volume given back before and after the unfolding (the improved variant), as
    // constrained fairing gives it back after a round: every vertex offset along its normal, one
    // distance per connected part. Before, for the levels' own drift (a coarse level's result can
    // hold a percent or two more); after, for what the means and the vertices put back to M0
    // changed (clean elephant from its coarsest level: +1.9 % without it).
    if keep_volume {
        folds.keep_volume_of(mesh, topology);
    }
    let mut volume = folds.volume.take().filter(|_| keep_volume);
    // The first offset reads the whole mesh; the later ones only the faces around what the
    // unfolding moved or put back since (`VolumeKeeper::restore_again`), along the first one's
    // normals. The vertices `held` (put back to M0) stay where they are.
    let mut redo = None;
    if let Some((keeper, result)) = &mut volume {
        result.positions.clear();
        result.positions.extend_from_slice(positions);
        redo = Some(keeper.restore_to_redo(result, topology, &[]));
        positions.copy_from_slice(&result.positions);
    }
    let restore_again = |positions: &mut [[f32; 3]], redo: &mut Option<Redo>, held: &[bool]| {
        if let (Some((keeper, _)), Some(redo)) = (&volume, redo) {
            keeper.restore_again(redo, positions, topology, &mesh.triangles, held);
        }
    };
    let mut state = FoldState::new(positions, topology, folds);
    if state.faces.is_empty() && state.edges.is_empty() {
        drop(state);
        folds.volume = volume;
        return Unfolded::default();
    }
    // A crease vertex moves along its crease (to the mean of its two neighbours on it); a corner
    // and a boundary vertex stay.
    let on_crease = |v: u32| {
        loop_neighbors
            .get(v as usize)
            .filter(|pair| pair[0] != NONE && pair[1] != NONE)
            .copied()
    };
    let stays = |v: u32| {
        topology.is_boundary_vertex(v)
            || (creases.is_some_and(|c| c.is_feature(v)) && on_crease(v).is_none())
    };
    let at_rest = positions.to_vec();
    let mut moving = vec![false; positions.len()];
    let mut region: Vec<u32> = Vec::new();
    // The vertices put back to M0 (below), which stay there.
    let mut back = vec![false; positions.len()];
    let passes = |positions: &mut [[f32; 3]],
                  state: &mut FoldState,
                  region: &mut Vec<u32>,
                  moving: &mut [bool],
                  back: &[bool]| {
        for _ in 0..UNFOLD_PASSES {
            let corners = state.corners();
            if corners.is_empty() {
                return;
            }
            for v in corners {
                if !moving[v as usize] && !stays(v) {
                    moving[v as usize] = true;
                    region.push(v);
                }
            }
            for _ in 0..SWEEPS {
                let means: Vec<[f32; 3]> = region
                    .par_iter()
                    .with_min_len(super::PARALLEL_GRAIN)
                    .map(|&v| {
                        if back[v as usize] {
                            return positions[v as usize];
                        }
                        if let Some([p, n]) = on_crease(v) {
                            let [p, n] = [p, n].map(|u| Vec3A::from_array(positions[u as usize]));
                            return ((p + n) * 0.5).to_array();
                        }
                        let ring = topology.neighbors(v);
                        let sum = ring.iter().fold(Vec3A::ZERO, |sum, &u| {
                            sum + Vec3A::from_array(positions[u as usize])
                        });
                        (sum / ring.len().max(1) as f32).to_array()
                    })
                    .collect();
                for (&v, mean) in region.iter().zip(means) {
                    positions[v as usize] = mean;
                }
            }
            state.moved(positions, region);
        }
    };
    // What the means leave, relaxed along the surface around it and passed over again, then
    // what that leaves relaxed again, farther out and longer (the coarsest levels' folds lie
    // many edge lengths from M0, where putting corners back would spread M0 over the result).
    // Crease vertices too stay in the relaxation: moved along their faces' mean plane they
    // would leave the crease. Last, what the neighbours' means cannot undo (a fold whose corners
    // all stay, or one the levels pressed in too deep), with the displacement from M0, and
    // what is left goes back to M0.
    let relax_stays = |v: u32| {
        topology.is_boundary_vertex(v)
            || topology.neighbors(v).is_empty()
            || creases.is_some_and(|c| c.is_feature(v))
    };
    let mut all_steps = |positions: &mut [[f32; 3]], state: &mut FoldState, back: &mut [bool]| {
        passes(positions, state, &mut region, &mut moving, back);
        // The relaxation's rounds, then steps 3-5; where those went over the budget (only the
        // coarsest levels of a large mesh), the widest round around what they left, and 3-5
        // once more.
        for reaches in [&TANGENT_REACH[..], &[LAST_REACH]] {
            for &reach in reaches {
                let seeds = state.corners();
                if seeds.is_empty() {
                    break;
                }
                relax_tangentially(
                    positions,
                    &mesh.triangles,
                    topology,
                    state,
                    relax_stays,
                    seeds,
                    reach,
                );
                passes(positions, state, &mut region, &mut moving, back);
            }
            if undo_what_is_left(positions, mesh, topology, state, back, budget) {
                return true;
            }
        }
        false
    };
    let mut undone = all_steps(positions, &mut state, &mut back);
    drop(state);
    // The offset holds the vertices put back; what it turns again is undone as above, and the
    // offset made again, until it turns nothing (a few times at most: after the last, the
    // volume is off by what that undoing moved).
    for _ in 0..VOLUME_PASSES {
        if volume.is_none() {
            break;
        }
        restore_again(positions, &mut redo, &back);
        if !undone {
            // Steps 3-5 went over the budget (only then is something left): steps 1 and 2 would
            // only run again around the folds left, and what the offset turned, a few faces, is
            // counted with them.
            break;
        }
        let mut state = FoldState::new(positions, topology, folds);
        if state.faces.is_empty() && state.edges.is_empty() {
            undone = true;
            break;
        }
        undone = all_steps(positions, &mut state, &mut back);
    }
    if keep_volume {
        folds.volume = volume;
    }
    let left = if undone {
        0
    } else {
        let state = FoldState::new(positions, topology, folds);
        state.faces.len() + state.edges.len()
    };
    Unfolded {
        moved: positions
            .iter()
            .zip(&at_rest)
            .filter(|(now, was)| now != was)
            .count(),
        left,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::grid;
    use crate::mesh::two_face_edges;

    fn fold_edges(mesh: &TriMesh, edges: &[[u32; 4]], reference: &[bool]) -> FoldEdges {
        let mut m0_normals = Vec::new();
        face_normals(&mesh.positions, &mesh.triangles, &mut m0_normals);
        FoldEdges::with_reference(mesh, edges.to_vec(), reference.to_vec(), m0_normals)
    }

    /// Whether each of `edges` folds beyond 90° with `positions`.
    fn folded(positions: &[[f32; 3]], mesh: &TriMesh, edges: &[[u32; 4]]) -> Vec<bool> {
        let mut normals = Vec::new();
        face_normals(positions, &mesh.triangles, &mut normals);
        edges
            .iter()
            .map(|&[_, _, f, g]| normals[f as usize].dot(normals[g as usize]) < 0.0)
            .collect()
    }

    /// Edges of `edges` folded beyond 90° with `positions` that `reference` does not fold.
    fn new_folds(
        positions: &[[f32; 3]],
        mesh: &TriMesh,
        edges: &[[u32; 4]],
        reference: &[bool],
    ) -> usize {
        folded(positions, mesh, edges)
            .iter()
            .zip(reference)
            .filter(|(&now, &was)| now && !was)
            .count()
    }

    /// A flat grid of `n` by `n` squares of side `side`, its topology, its edges between two
    /// faces and their fold flags (none folded).
    fn flat_grid(n: usize, side: f32) -> (TriMesh, Topology, Vec<[u32; 4]>, Vec<bool>) {
        let mut mesh = grid(n);
        for p in &mut mesh.positions {
            *p = p.map(|x| x * side);
        }
        let topology = Topology::build(&mesh);
        let edges = two_face_edges(&mesh.triangles);
        let reference = folded(&mesh.positions, &mesh, &edges);
        (mesh, topology, edges, reference)
    }

    /// [`unfold`] on `mesh` with no crease and `budget`, `edges` folding nothing on `mesh`.
    fn unfold_with_budget(
        positions: &mut [[f32; 3]],
        mesh: &TriMesh,
        topology: &Topology,
        edges: &[[u32; 4]],
        budget: f32,
    ) -> Unfolded {
        let level = Level {
            put_back_budget: budget,
            ..level(mesh, topology)
        };
        let reference = vec![false; edges.len()];
        unfold(positions, &level, &mut fold_edges(mesh, edges, &reference))
    }

    fn level<'a>(mesh: &'a TriMesh, topology: &'a Topology) -> Level<'a> {
        Level {
            mesh,
            topology,
            creases: None,
            loop_neighbors: &[],
            keep_volume: false,
            put_back_budget: 1.0,
        }
    }

    #[test]
    fn the_displacement_inside_a_region_is_made_the_mean_of_its_neighbours() {
        // On the regular grid every inner vertex has its six neighbours in three opposite
        // pairs, so a displacement linear in position is the mean of its neighbours': harmonic,
        // and the only harmonic one with its values around the region. Held on the vertices
        // outside a square and scrambled inside, the solve gives it back.
        let n = 16;
        let mesh = grid(n);
        let topology = Topology::build(&mesh);
        let linear = |[x, y, _]: [f32; 3]| Vec3A::new(0.02 * y, -0.01 * x, 0.1 * x + 0.05 * y);
        let inside =
            |v: usize| (4..=12).contains(&(v % (n + 1))) && (4..=12).contains(&(v / (n + 1)));
        let region: Vec<u32> = (0..mesh.vertex_count() as u32)
            .filter(|&v| inside(v as usize))
            .collect();
        let mut positions: Vec<[f32; 3]> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(v, &p)| {
                // Up to one edge length off, a different amount at each vertex.
                let scramble = if inside(v) {
                    let k = v as f32;
                    Vec3A::new((k * 0.7).sin(), (k * 1.3).cos(), (k * 2.9).sin())
                } else {
                    Vec3A::ZERO
                };
                (Vec3A::from_array(p) + linear(p) + scramble).to_array()
            })
            .collect();
        let outside_before: Vec<[f32; 3]> = positions.clone();
        make_harmonic(&mut positions, &mesh, &topology, &region, 1000);
        let mut largest = 0.0f32;
        for (v, (now, &m0)) in positions.iter().zip(&mesh.positions).enumerate() {
            if inside(v) {
                let off = Vec3A::from_array(*now) - Vec3A::from_array(m0) - linear(m0);
                largest = largest.max(off.length());
            } else {
                assert_eq!(
                    *now, outside_before[v],
                    "vertex {v} outside the region is held"
                );
            }
        }
        // From up to one edge length off to a hundredth of one.
        assert!(largest < 0.01, "{largest} from the harmonic displacement");
    }

    #[test]
    fn a_vertex_pushed_through_its_neighbours_is_put_back_and_the_rest_stays() {
        // A flat grid (no fold) with one inner vertex moved far across its neighbours, in the
        // plane: its triangles flip over their edges.
        let n = 24;
        let mesh = grid(n);
        let topology = Topology::build(&mesh);
        let edges = two_face_edges(&mesh.triangles);
        let reference = folded(&mesh.positions, &mesh, &edges);
        assert!(reference.iter().all(|&f| !f), "the flat grid folds nothing");
        let (row, column) = (n / 2, n / 2);
        let v = row * (n + 1) + column;
        let mut positions = mesh.positions.clone();
        positions[v][0] += 1.6;
        let flipped = folded(&positions, &mesh, &edges);
        assert!(flipped.iter().any(|&f| f), "the push folds edges");
        let moved = unfold(
            &mut positions,
            &level(&mesh, &topology),
            &mut fold_edges(&mesh, &edges, &reference),
        )
        .moved;
        assert!(folded(&positions, &mesh, &edges).iter().all(|&f| !f));
        // The vertex is back near its place. The passes move the folds' corners only, and every
        // sweep of the relaxation's first round, if it runs, reaches one ring further (on a
        // regular grid a vertex is the mean of its neighbours, so only the push moves
        // anything): the vertices more than TANGENT_SWEEPS rings away did not move (so the
        // wider second round did not run either), and those that did stayed in the plane.
        assert!((positions[v][0] - mesh.positions[v][0]).abs() < 0.5);
        let mut near = 0;
        for (u, (now, was)) in positions.iter().zip(&mesh.positions).enumerate() {
            let rings = (u / (n + 1))
                .abs_diff(row)
                .max((u % (n + 1)).abs_diff(column));
            if rings > TANGENT_SWEEPS {
                assert_eq!(now, was, "vertex {u}, {rings} rings away");
            } else {
                near += 1;
            }
            assert_eq!(now[2], was[2], "vertex {u} left the plane");
        }
        assert!((1..=near).contains(&moved), "{moved} vertices moved");
    }

    #[test]
    fn a_fold_between_corners_that_stay_is_undone_next_to_m0() {
        // A cube's corner (a crease corner: it stays in the relaxation and the passes) pushed
        // through the cube, past the centre: the neighbours' means cannot unfold its edges, the
        // displacement from M0 smoothed around it can: nothing stays folded, and the corner is
        // next to where M0 has it, displaced as its neighbours are.
        let mesh = crate::mesh::shapes::cuboid([1.0, 1.0, 1.0], 0.25);
        let topology = Topology::build(&mesh);
        let creases = crate::fairing::detect_creases(&mesh, &topology, &Default::default());
        let edges = two_face_edges(&mesh.triangles);
        let mut folds = FoldEdges::new(&mesh);
        let reference = folds.reference();
        let sum = |p: &[f32; 3]| p[0] + p[1] + p[2];
        let corner = (0..mesh.positions.len())
            .max_by(|&a, &b| sum(&mesh.positions[a]).total_cmp(&sum(&mesh.positions[b])))
            .unwrap();
        let n = mesh.positions.len() as f32;
        let centre = mesh
            .positions
            .iter()
            .fold([0.0f32; 3], |s, p| [0, 1, 2].map(|i| s[i] + p[i] / n));
        let mut positions = mesh.positions.clone();
        positions[corner] = [0, 1, 2].map(|i| centre[i] - 0.3 * (positions[corner][i] - centre[i]));
        let new_folds = |positions: &[[f32; 3]]| {
            folded(positions, &mesh, &edges)
                .iter()
                .zip(&reference)
                .filter(|(&now, &was)| now && !was)
                .count()
        };
        assert!(new_folds(&positions) > 0, "the push folds edges");
        let level = Level {
            mesh: &mesh,
            topology: &topology,
            creases: Some(&creases),
            loop_neighbors: &[],
            keep_volume: false,
            put_back_budget: 1.0,
        };
        let moved = unfold(&mut positions, &level, &mut folds).moved;
        assert!(moved >= 1);
        assert_eq!(new_folds(&positions), 0);
        // Next to where M0 has it (the side is 1, the push moved it by 1.1), and no face
        // turned against M0.
        let off = Vec3A::from_array(positions[corner])
            .distance(Vec3A::from_array(mesh.positions[corner]));
        assert!(off < 0.05, "{off} from M0");
        let result = TriMesh::new(positions.clone(), mesh.triangles.clone());
        for t in 0..mesh.face_count() {
            assert!(
                result.face_normal(t).dot(mesh.face_normal(t)) >= 0.0,
                "face {t}"
            );
        }
    }

    #[test]
    fn a_fold_only_putting_back_undoes_is_left_and_counted_when_that_is_over_budget() {
        // A boundary vertex of a flat grid of squares of side 0.25 pushed into it: its faces
        // turn over. A boundary vertex stays in the means, the relaxation and the
        // displacement's smoothing, so only putting it back where M0 has it undoes them. The
        // budget counts only what goes back from farther than PUT_BACK_FAR edge lengths (not
        // model units: the side is not 1).
        let (n, side) = (12, 0.25);
        let (mesh, topology, edges, reference) = flat_grid(n, side);
        let v = n / 2;
        let turned = |positions: &[[f32; 3]]| {
            let result = TriMesh::new(positions.to_vec(), mesh.triangles.clone());
            (0..mesh.face_count())
                .filter(|&t| result.face_normal(t).dot(mesh.face_normal(t)) < 0.0)
                .count()
        };
        let run = |rows: f32, budget: f32| {
            let mut positions = mesh.positions.clone();
            positions[v][1] += rows * side;
            assert!(turned(&positions) > 0, "the push turns faces");
            let pushed = positions[v];
            let done = unfold_with_budget(&mut positions, &mesh, &topology, &edges, budget);
            (positions, pushed, done)
        };
        // Pushed six rows (six edge lengths): within the budget (the whole mesh may go back), it
        // goes back and nothing is left.
        let (positions, _, done) = run(6.0, 1.0);
        assert_eq!(positions[v], mesh.positions[v]);
        assert_eq!(turned(&positions), 0);
        assert_eq!(done.left, 0);
        // With no budget, it stays where it was pushed, and what is left is counted: the faces
        // turned against M0 and the edges folded (each once).
        let (positions, pushed, done) = run(6.0, 0.0);
        assert_eq!(positions[v], pushed);
        let left_turned = turned(&positions);
        let left_folded = new_folds(&positions, &mesh, &edges, &reference);
        assert!(left_turned > 0);
        assert_eq!(done.left, left_turned + left_folded);
        // Pushed two rows, nearer than PUT_BACK_FAR: it goes back even with no budget.
        let (positions, _, done) = run(2.0, 0.0);
        assert_eq!(positions[v], mesh.positions[v]);
        assert_eq!(turned(&positions), 0);
        assert_eq!(done.left, 0);
    }

    #[test]
    fn over_budget_only_the_place_that_went_over_is_taken_back() {
        // Two boundary vertices of a flat grid of squares of side 0.25 pushed into it, at
        // opposite sides: one six rows deep (putting it back counts against the budget), one two
        // rows (it does not). With no budget the last steps go over it at the deep push, and
        // what they did there is taken back; at the shallow push, 38 rows away, it is kept: the
        // faces left turned and the edges left folded all lie in the half of the deep push.
        let (n, side) = (40, 0.25);
        let (mesh, topology, edges, reference) = flat_grid(n, side);
        let (deep, shallow) = (n / 2, n * (n + 1) + n / 2);
        // Faces turned against M0, by half of the grid: [the deep push's, the shallow one's].
        let turned = |positions: &[[f32; 3]]| {
            let result = TriMesh::new(positions.to_vec(), mesh.triangles.clone());
            let mut halves = [0; 2];
            for (t, corners) in mesh.triangles.iter().enumerate() {
                if result.face_normal(t).dot(mesh.face_normal(t)) < 0.0 {
                    let y = corners
                        .iter()
                        .map(|&v| mesh.positions[v as usize][1])
                        .sum::<f32>();
                    halves[usize::from(y / 3.0 > 0.5 * n as f32 * side)] += 1;
                }
            }
            halves
        };
        let run = |budget: f32| {
            let mut positions = mesh.positions.clone();
            positions[deep][1] += 6.0 * side;
            positions[shallow][1] -= 2.0 * side;
            let pushed = turned(&positions);
            assert!(
                pushed[0] > 0 && pushed[1] > 0,
                "both pushes turn faces: {pushed:?}"
            );
            let done = unfold_with_budget(&mut positions, &mesh, &topology, &edges, budget);
            (positions, done)
        };
        let (positions, done) = run(1.0);
        assert_eq!(turned(&positions), [0, 0]);
        assert_eq!(done.left, 0);
        let (positions, done) = run(0.0);
        let [at_deep, at_shallow] = turned(&positions);
        assert!(at_deep > 0, "the deep push is left turned");
        assert_eq!(at_shallow, 0, "the shallow push is undone");
        let left_folded = new_folds(&positions, &mesh, &edges, &reference);
        assert_eq!(done.left, at_deep + left_folded);
    }

    #[test]
    fn folds_the_reference_has_are_kept() {
        // The same push, but in M0 itself: nothing is new, nothing moves.
        let mut mesh = grid(6);
        mesh.positions[3 * 7 + 3][0] += 1.6;
        let topology = Topology::build(&mesh);
        let edges = two_face_edges(&mesh.triangles);
        let mut positions = mesh.positions.clone();
        let reference = folded(&positions, &mesh, &edges);
        let before = positions.clone();
        assert_eq!(
            unfold(
                &mut positions,
                &level(&mesh, &topology),
                &mut fold_edges(&mesh, &edges, &reference)
            ),
            Unfolded::default()
        );
        assert_eq!(positions, before);
    }
}
