//! Building the decimation hierarchy (paper section 4.1).
//!
//! One level is one pass over the current mesh's vertices in increasing
//! `cost(v) = alpha * min_edge(v) + beta * max_edge(v)` (edge lengths on the current level, ties
//! by vertex id). A vertex adjacent to one already removed in this pass is skipped, so the removed
//! vertices of a level form an independent set. A visited vertex `v` tries its neighbours `k` in
//! increasing `(|cone volume|, k)` and performs the first valid half-edge collapse `v -> k`:
//! `x_k` does not move, `v`'s faces that contain `k` disappear, `v` is replaced by `k` in the
//! others. Positions never change during the build.
//!
//! Interpretations (see `paper/NOTES.md`):
//! - Cone volume of `v -> k`: `sum over v's faces (v, a, b), in their own orientation, of
//!   ((x_a - x_k) x (x_b - x_k)) . (x_v - x_k)`; faces containing `k` add 0 (the paper's
//!   "⊗" is a cross product). The signed value is six times the volume the matching vertex split
//!   adds back, so on a closed mesh `|cone| = 6 |volume change|` of the collapse. It is kept
//!   (as f32) in the collapse record: the improved multiresolution fairing uses it.
//! - A collapse is refused when: the link condition fails (`N(v) ∩ N(k)` must be exactly the
//!   vertices opposite the edge `vk`); `v` has valence 3 and its other two neighbours already form
//!   a face with `k` (the tetrahedron case, which would leave two coincident faces); `v` is on a
//!   boundary and `vk` is not a boundary edge; `v` is a boundary vertex of a single triangle whose
//!   third edge is also a boundary edge (the loop would vanish); a surviving face would flip or
//!   degenerate (`n_old . n_new <= 0`). These keep every level an oriented 2-manifold with the
//!   Euler characteristic and the boundary loops of M0.
//! - `keep_boundary` leaves boundary vertices in place (interior vertices may still collapse
//!   into them, which does not move them).
//! - A pass stops removing once the level would drop below `min_vertices`; the build stops when a
//!   pass removes nothing, the level has at most `min_vertices` vertices, or `max_levels` is
//!   reached.
//!
//! - The input must be an oriented 2-manifold (checked on the first pass's fans: every vertex's
//!   faces form one consistently oriented fan); otherwise the build refuses with
//!   `HierarchyError::Unsupported` naming the vertex.
//!
//! Speed. The pass state is flat arrays: the faces' corners, the fans of the level in CSR form
//! (for every face `(v, a, b)` the pair `(a, b)` at `v`, built by a counting sort at the start of
//! the pass), and one stamp per vertex (locked / removed in this pass). No face is rewritten
//! during the pass: the removed vertices are independent, so their collapses touch disjoint face
//! sets and compose as one simultaneous relabelling `v -> target[v]`, done after the pass (faces
//! that degenerate are the removed ones). During the pass, a vertex that is not locked still has
//! exactly its pass-start fan; the current faces of a collapse target `k` are its pass-start fan
//! relabelled through this pass's removals (a face that degenerates is gone) plus the fans of the
//! vertices collapsed into it, chained in `absorbed` lists. Visiting vertices in cost order jumps
//! all over the mesh, so the build first renumbers vertices in Morton order of their positions
//! (faces by their first corner), which keeps a vertex's neighbours near it in memory; ties in
//! the visiting order and among equal cone volumes still go by M0's ids, so the result does not
//! depend on this renumbering.

use super::{HierarchyError, HierarchyOptions};
use crate::mesh::TriMesh;
use crate::Progress;
use glam::DVec3;
use rayon::prelude::*;
use std::time::Instant;

pub(super) const NEVER: u32 = u32::MAX;

/// What the build found, in M0's vertex and face numbering.
pub(super) struct BuildOutput {
    /// Pass in which each vertex was removed (`NEVER` if it survives to the coarsest level).
    pub removed_in_pass: Vec<u32>,
    /// Collapse target of each removed vertex (`NEVER` otherwise).
    pub target: Vec<u32>,
    /// Signed cone volume (six times the volume its split adds back) of each removed vertex.
    pub six_split_volume: Vec<f32>,
    /// Pass in which each face disappeared (`NEVER` if it survives).
    pub face_removed_in_pass: Vec<u32>,
    /// Milliseconds each pass took.
    pub pass_ms: Vec<f64>,
}

/// Visits between two progress reports.
const REPORT_EVERY: usize = 4096;

pub(super) fn build(
    mesh: &TriMesh,
    options: &HierarchyOptions,
    progress: &mut dyn Progress,
) -> Result<BuildOutput, HierarchyError> {
    let (local, vertex_of_local, face_of_local) = spatially_ordered(mesh);
    let built =
        build_ordered(&local, &vertex_of_local, options, progress).map_err(|e| match e {
            BuildFailure::NonManifold(v) => HierarchyError::Unsupported(format!(
                "the mesh is not an oriented 2-manifold at vertex {}: its faces do not form one \
             consistently oriented fan (an edge with more than two faces, two fans meeting at \
             the vertex, or faces of opposite orientation)",
                vertex_of_local[v]
            )),
            BuildFailure::Cancelled => HierarchyError::Cancelled,
        })?;
    // Back to M0's numbering.
    let n = mesh.vertex_count();
    let mut out = BuildOutput {
        removed_in_pass: vec![NEVER; n],
        target: vec![NEVER; n],
        six_split_volume: vec![0.0; n],
        face_removed_in_pass: vec![NEVER; mesh.face_count()],
        pass_ms: built.pass_ms,
    };
    for (local_v, &v) in vertex_of_local.iter().enumerate() {
        let v = v as usize;
        out.removed_in_pass[v] = built.removed_in_pass[local_v];
        let k = built.target[local_v];
        out.target[v] = if k == NEVER {
            NEVER
        } else {
            vertex_of_local[k as usize]
        };
        out.six_split_volume[v] = built.six_split_volume[local_v];
    }
    for (local_f, &f) in face_of_local.iter().enumerate() {
        out.face_removed_in_pass[f as usize] = built.face_removed_in_pass[local_f];
    }
    Ok(out)
}

enum BuildFailure {
    NonManifold(usize),
    Cancelled,
}

/// The mesh with vertices in Morton order of their positions and faces in order of their first
/// corner, so that the neighbours of a vertex are near it in memory (the passes visit vertices in
/// cost order, which jumps all over the mesh). Returns it with the M0 ids of its vertices and
/// faces.
fn spatially_ordered(mesh: &TriMesh) -> (TriMesh, Vec<u32>, Vec<u32>) {
    let n = mesh.vertex_count();
    let (lo, hi) = crate::metrics::bounding_box(mesh).unwrap_or_default();
    let scale = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let spread = |x: u64| {
        // Spreads 10 bits to every third bit.
        let mut x = x & 0x3ff;
        x = (x | x << 16) & 0x030000ff;
        x = (x | x << 8) & 0x0300f00f;
        x = (x | x << 4) & 0x030c30c3;
        (x | x << 2) & 0x09249249
    };
    let mut keys: Vec<u64> = mesh
        .positions
        .par_iter()
        .enumerate()
        .map(|(v, p)| {
            let q = |c: usize| (((p[c] as f64 - lo[c]) / scale * 1023.0).clamp(0.0, 1023.0)) as u64;
            (spread(q(0)) | spread(q(1)) << 1 | spread(q(2)) << 2) << 32 | v as u64
        })
        .collect();
    keys.par_sort_unstable();
    let vertex_of_local: Vec<u32> = keys.iter().map(|&k| k as u32).collect();
    let mut local_of = vec![0u32; n];
    for (i, &v) in vertex_of_local.iter().enumerate() {
        local_of[v as usize] = i as u32;
    }
    let mut face_keys: Vec<u64> = mesh
        .triangles
        .par_iter()
        .enumerate()
        .map(|(f, t)| (local_of[t[0] as usize] as u64) << 32 | f as u64)
        .collect();
    face_keys.par_sort_unstable();
    let face_of_local: Vec<u32> = face_keys.iter().map(|&k| k as u32).collect();
    let local = TriMesh::new(
        vertex_of_local
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect(),
        face_of_local
            .iter()
            .map(|&f| mesh.triangles[f as usize].map(|c| local_of[c as usize]))
            .collect(),
    );
    (local, vertex_of_local, face_of_local)
}

/// The passes on a mesh whose vertex `v` is M0's `original[v]` (ties in the visiting order and
/// among equal cone volumes are broken by M0's ids, as if the build ran on M0's numbering).
fn build_ordered(
    mesh: &TriMesh,
    original: &[u32],
    options: &HierarchyOptions,
    progress: &mut dyn Progress,
) -> Result<BuildOutput, BuildFailure> {
    let n = mesh.vertex_count();
    let face_count = mesh.face_count();
    let points: &[[f32; 3]] = &mesh.positions;
    let mut corners: Vec<[u32; 3]> = mesh.triangles.clone();

    let mut out = BuildOutput {
        removed_in_pass: vec![NEVER; n],
        target: vec![NEVER; n],
        six_split_volume: vec![0.0; n],
        face_removed_in_pass: vec![NEVER; face_count],
        pass_ms: Vec::new(),
    };
    let mut alive_faces: Vec<u32> = (0..face_count as u32).collect();
    let mut referenced = vec![false; n];
    for t in &mesh.triangles {
        for &c in t {
            referenced[c as usize] = true;
        }
    }
    let mut alive_vertices: Vec<u32> = (0..n as u32).filter(|&v| referenced[v as usize]).collect();
    drop(referenced);
    let isolated = n - alive_vertices.len();

    let mut fan_offsets = vec![0u32; n + 1];
    let mut fans: Vec<[u32; 2]> = Vec::with_capacity(3 * face_count);
    let mut cursor: Vec<u32> = vec![0; n];
    let mut edge_min = vec![f32::INFINITY; n];
    let mut edge_max = vec![0f32; n];
    let mut keys: Vec<u64> = Vec::with_capacity(alive_vertices.len());
    // `2 * stamp` while locked in the pass of that stamp, `2 * stamp + 1` once removed in it.
    let mut state = vec![0u32; n];
    let mut absorbed_head = vec![NEVER; n];
    let mut absorbed_next = vec![NEVER; n];
    let mut scratch = Scratch::default();

    let start_vertices = alive_vertices.len() as f64;
    let goal = (start_vertices - options.min_vertices as f64).max(1.0);
    let mut vertex_count = alive_vertices.len() + isolated;
    let mut visits = 0usize;

    for pass in 0..options.max_levels.max(1) as u32 {
        // Pass 0 always builds its fans, to check the input.
        if pass > 0 && (vertex_count <= options.min_vertices || pass as usize >= options.max_levels)
        {
            break;
        }
        let started = Instant::now();
        let stamp = pass + 1;

        // Fans of the current level in CSR form: for each face (v, a, b) the pair (a, b) at v.
        fan_offsets.fill(0);
        for &f in &alive_faces {
            for &c in &corners[f as usize] {
                fan_offsets[c as usize + 1] += 1;
            }
        }
        for v in 0..n {
            fan_offsets[v + 1] += fan_offsets[v];
        }
        fans.clear();
        fans.resize(fan_offsets[n] as usize, [0; 2]);
        cursor.copy_from_slice(&fan_offsets[..n]);
        for &f in &alive_faces {
            let [x, y, z] = corners[f as usize];
            for (v, pair) in [(x, [y, z]), (y, [z, x]), (z, [x, y])] {
                let slot = &mut cursor[v as usize];
                fans[*slot as usize] = pair;
                *slot += 1;
            }
        }
        if pass == 0 {
            if let Some(v) = first_non_manifold_vertex(&fan_offsets, &fans) {
                return Err(BuildFailure::NonManifold(v));
            }
            if vertex_count <= options.min_vertices || options.max_levels == 0 {
                break;
            }
        }

        // Costs on the current level.
        for &v in &alive_vertices {
            edge_min[v as usize] = f32::INFINITY;
            edge_max[v as usize] = 0.0;
        }
        for &f in &alive_faces {
            let t = corners[f as usize];
            for i in 0..3 {
                let (a, b) = (t[i] as usize, t[(i + 1) % 3] as usize);
                let length = point(points, a as u32).distance(point(points, b as u32)) as f32;
                edge_min[a] = edge_min[a].min(length);
                edge_max[a] = edge_max[a].max(length);
                edge_min[b] = edge_min[b].min(length);
                edge_max[b] = edge_max[b].max(length);
            }
        }
        keys.clear();
        keys.extend(alive_vertices.iter().map(|&v| {
            let cost = (options.alpha * edge_min[v as usize] as f64
                + options.beta * edge_max[v as usize] as f64) as f32;
            // Non-negative finite f32s order like their bit patterns.
            let bits = if cost.is_finite() && cost >= 0.0 {
                cost.to_bits()
            } else {
                f32::INFINITY.to_bits()
            };
            (bits as u64) << 32 | v as u64
        }));
        keys.par_sort_unstable();
        // Equal costs go by M0's vertex id.
        let mut run = 0;
        while run < keys.len() {
            let cost = keys[run] >> 32;
            let end = run + keys[run..].partition_point(|&k| k >> 32 == cost);
            if end - run > 1 {
                keys[run..end].sort_unstable_by_key(|&k| original[k as u32 as usize]);
            }
            run = end;
        }

        let locked = 2 * stamp;
        let removed_mark = 2 * stamp + 1;
        let mut removed = 0usize;
        for &key in &keys {
            visits += 1;
            if visits.is_multiple_of(REPORT_EVERY) {
                let done = (start_vertices - vertex_count as f64 + isolated as f64) / goal;
                if !progress.report(done.clamp(0.0, 1.0) as f32) {
                    return Err(BuildFailure::Cancelled);
                }
            }
            if vertex_count <= options.min_vertices {
                break;
            }
            let v = key as u32;
            if state[v as usize] >= locked {
                continue;
            }
            let view = PassView {
                points,
                fan_offsets: &fan_offsets,
                fans: &fans,
                state: &state,
                target: &out.target,
                absorbed_head: &absorbed_head,
                absorbed_next: &absorbed_next,
                locked,
            };
            let Some((k, six_volume)) = choose_collapse(v, &view, original, options, &mut scratch)
            else {
                continue;
            };

            // Perform v -> k: faces are relabelled after the pass (a pass's collapses touch
            // disjoint face sets, so they compose as one simultaneous relabelling).
            state[v as usize] = removed_mark;
            for &x in &scratch.neighbors {
                state[x as usize] = locked;
            }
            absorbed_next[v as usize] = absorbed_head[k as usize];
            absorbed_head[k as usize] = v;
            out.removed_in_pass[v as usize] = pass;
            out.target[v as usize] = k;
            out.six_split_volume[v as usize] = six_volume as f32;
            vertex_count -= 1;
            removed += 1;
        }

        // Clear the absorbed lists of this pass.
        for &key in &keys {
            absorbed_head[key as u32 as usize] = NEVER;
        }
        if removed == 0 {
            break;
        }
        // Relabel the faces of the removed vertices; those that degenerate disappear.
        let (removed_in_pass, target) = (&out.removed_in_pass, &out.target);
        let face_removed_in_pass = &mut out.face_removed_in_pass;
        alive_faces.retain(|&f| {
            let t = &mut corners[f as usize];
            for c in t.iter_mut() {
                if removed_in_pass[*c as usize] == pass {
                    *c = target[*c as usize];
                }
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                face_removed_in_pass[f as usize] = pass;
                false
            } else {
                true
            }
        });
        alive_vertices.retain(|&v| out.removed_in_pass[v as usize] == NEVER);
        out.pass_ms.push(started.elapsed().as_secs_f64() * 1e3);
    }
    Ok(out)
}

#[inline]
fn point(points: &[[f32; 3]], v: u32) -> DVec3 {
    let p = points[v as usize];
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// A vertex whose faces are not a single consistently oriented fan, if any: with the faces
/// `(v, a, b)` of `v`, every `a` and every `b` must be distinct and following `a -> b` from the
/// fan's start (an `a` that is no `b`, or any `a` when the fan is closed) must visit every face.
fn first_non_manifold_vertex(fan_offsets: &[u32], fans: &[[u32; 2]]) -> Option<usize> {
    let n = fan_offsets.len() - 1;
    (0..n).into_par_iter().find_first(|&v| {
        let fan = &fans[fan_offsets[v] as usize..fan_offsets[v + 1] as usize];
        if fan.is_empty() {
            return false;
        }
        for i in 0..fan.len() {
            for j in i + 1..fan.len() {
                if fan[i][0] == fan[j][0] || fan[i][1] == fan[j][1] {
                    return true;
                }
            }
        }
        let start = fan
            .iter()
            .position(|&[a, _]| !fan.iter().any(|&[_, b]| b == a))
            .unwrap_or(0);
        let mut current = start;
        for step in 1..=fan.len() {
            let b = fan[current][1];
            match fan.iter().position(|&[a, _]| a == b) {
                Some(next) if next == start => return step != fan.len(),
                Some(next) => current = next,
                None => return step != fan.len(),
            }
        }
        true
    })
}

/// Read-only view of the pass state for choosing a collapse.
struct PassView<'a> {
    points: &'a [[f32; 3]],
    fan_offsets: &'a [u32],
    fans: &'a [[u32; 2]],
    state: &'a [u32],
    target: &'a [u32],
    absorbed_head: &'a [u32],
    absorbed_next: &'a [u32],
    locked: u32,
}

impl PassView<'_> {
    #[inline]
    fn fan(&self, v: u32) -> &[[u32; 2]] {
        &self.fans[self.fan_offsets[v as usize] as usize..self.fan_offsets[v as usize + 1] as usize]
    }

    /// The current label of a vertex of the level's start: its target if removed in this pass.
    #[inline]
    fn current(&self, c: u32) -> u32 {
        if self.state[c as usize] == self.locked + 1 {
            self.target[c as usize]
        } else {
            c
        }
    }

    /// Calls `visit` with the two other corners of every live face of `k`: its faces at the start
    /// of the pass, relabelled by this pass's collapses (a face that degenerates is gone), and
    /// those of the vertices collapsed into it during this pass.
    #[inline]
    fn for_each_face_of(&self, k: u32, mut visit: impl FnMut(u32, u32)) {
        for &[a, b] in self.fan(k) {
            let (a, b) = (self.current(a), self.current(b));
            if a != b && a != k && b != k {
                visit(a, b);
            }
        }
        let mut absorbed = self.absorbed_head[k as usize];
        while absorbed != NEVER {
            for &[a, b] in self.fan(absorbed) {
                // The absorbed vertex's neighbours were locked when it went: they are unchanged.
                if a != k && b != k {
                    visit(a, b);
                }
            }
            absorbed = self.absorbed_next[absorbed as usize];
        }
    }
}

#[derive(Default)]
struct Scratch {
    neighbors: Vec<u32>,
    /// Positions of `a` and `b` for each face `(v, a, b)` of the vertex being tried.
    positions: Vec<[DVec3; 2]>,
    /// `(|cone|, k, signed cone)`.
    candidates: Vec<(f64, u32, f64)>,
}

/// The first valid collapse target of `v` in increasing cone volume, with its signed cone volume.
fn choose_collapse(
    v: u32,
    view: &PassView,
    original: &[u32],
    options: &HierarchyOptions,
    scratch: &mut Scratch,
) -> Option<(u32, f64)> {
    let fan = view.fan(v);
    if fan.is_empty() {
        return None;
    }
    let p = |c: u32| point(view.points, c);
    // Boundary: a fan edge v-a (a first in its face) that no face has as v-b opens the fan.
    let mut fan_start = NEVER;
    let mut fan_end = NEVER;
    for &[a, _] in fan {
        if !fan.iter().any(|&[_, b]| b == a) {
            fan_start = a;
        }
    }
    for &[_, b] in fan {
        if !fan.iter().any(|&[a, _]| a == b) {
            fan_end = b;
        }
    }
    let on_boundary = fan_start != NEVER;
    if on_boundary && options.keep_boundary {
        return None;
    }
    scratch.neighbors.clear();
    scratch.positions.clear();
    for &[a, b] in fan {
        scratch.neighbors.push(a);
        scratch.positions.push([p(a), p(b)]);
    }
    if on_boundary {
        scratch.neighbors.push(fan_end);
    }
    let xv = p(v);

    scratch.candidates.clear();
    for &k in &scratch.neighbors {
        if on_boundary && k != fan_start && k != fan_end {
            continue;
        }
        let xk = p(k);
        let mut cone = 0.0;
        for (&[a, b], &[xa, xb]) in fan.iter().zip(&scratch.positions) {
            if a != k && b != k {
                cone += (xa - xk).cross(xb - xk).dot(xv - xk);
            }
        }
        scratch.candidates.push((cone.abs(), k, cone));
    }
    scratch.candidates.sort_unstable_by(|x, y| {
        x.0.total_cmp(&y.0)
            .then_with(|| original[x.1 as usize].cmp(&original[y.1 as usize]))
    });

    let valence = scratch.neighbors.len();
    'candidate: for &(_, k, cone) in &scratch.candidates {
        let xk = p(k);
        // No surviving face may flip or degenerate.
        let mut opposite = [NEVER; 2];
        for (&[a, b], &[xa, xb]) in fan.iter().zip(&scratch.positions) {
            if a == k {
                opposite[0] = b;
                continue;
            }
            if b == k {
                opposite[1] = a;
                continue;
            }
            let old = (xa - xv).cross(xb - xv);
            let new = (xa - xk).cross(xb - xk);
            if old.dot(new) <= 0.0 {
                continue 'candidate;
            }
        }
        // Link condition: apart from the opposite vertices, no neighbour of v may be one of k.
        let neighbors = &scratch.neighbors;
        let shared = |x: u32| x != opposite[0] && x != opposite[1] && neighbors.contains(&x);
        let mut link_ok = true;
        let tetrahedron_check = !on_boundary && valence == 3;
        let single_triangle = on_boundary && valence == 2;
        let third = if opposite[0] != NEVER {
            opposite[0]
        } else {
            opposite[1]
        };
        let mut faces_on_third_edge = 0;
        view.for_each_face_of(k, |a, b| {
            if shared(a) || shared(b) {
                link_ok = false;
            }
            // The tetrahedron case: k's other faces already hold both opposite vertices.
            if tetrahedron_check
                && (a == opposite[0] && b == opposite[1] || a == opposite[1] && b == opposite[0])
            {
                link_ok = false;
            }
            if single_triangle && (a == third || b == third) {
                faces_on_third_edge += 1;
            }
        });
        if !link_ok || (single_triangle && faces_on_third_edge < 2) {
            continue;
        }
        return Some((k, cone));
    }
    None
}
