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
//! The state of the pass is flat arrays: the current corners of every face (indexed by M0's face
//! ids), a CSR of vertex-to-faces built at the start of the pass, and per-vertex stamps. Because
//! the removed vertices are independent, a vertex that is not locked still has exactly the faces
//! it had at the start of the pass; only a collapse target's face list grows, by the faces of the
//! vertices collapsed into it, which are chained in `absorbed` lists (never longer than one hop).

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
    let n = mesh.vertex_count();
    let face_count = mesh.face_count();
    let points: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
        .collect();
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

    let mut face_offsets = vec![0u32; n + 1];
    let mut vertex_faces: Vec<u32> = Vec::with_capacity(3 * face_count);
    let mut edge_min = vec![f32::INFINITY; n];
    let mut edge_max = vec![0f32; n];
    let mut keys: Vec<u64> = Vec::with_capacity(alive_vertices.len());
    let mut lock_stamp = vec![0u32; n];
    let mut absorbed_stamp = vec![0u32; n];
    let mut absorbed_head = vec![NEVER; n];
    let mut absorbed_next = vec![NEVER; n];
    let mut mark = vec![0u32; n];
    let mut mark_id = 0u32;
    let mut scratch = Scratch::default();

    let start_vertices = alive_vertices.len() as f64;
    let goal = (start_vertices - options.min_vertices as f64).max(1.0);
    let mut vertex_count = alive_vertices.len() + isolated;
    let mut visits = 0usize;

    for pass in 0..options.max_levels as u32 {
        if vertex_count <= options.min_vertices {
            break;
        }
        let started = Instant::now();
        let stamp = pass + 1;

        // Vertex -> faces CSR of the current level.
        face_offsets.fill(0);
        for &f in &alive_faces {
            for &c in &corners[f as usize] {
                face_offsets[c as usize + 1] += 1;
            }
        }
        for v in 0..n {
            face_offsets[v + 1] += face_offsets[v];
        }
        vertex_faces.clear();
        vertex_faces.resize(face_offsets[n] as usize, 0);
        {
            // Fill with a moving cursor kept in edge_max's bit pattern would be obscure; a second
            // pass over the offsets (shifted) is cheap and clear.
            let mut cursor: Vec<u32> = face_offsets[..n].to_vec();
            for &f in &alive_faces {
                for &c in &corners[f as usize] {
                    let slot = &mut cursor[c as usize];
                    vertex_faces[*slot as usize] = f;
                    *slot += 1;
                }
            }
        }

        if pass == 0 {
            if let Some(v) = first_non_manifold_vertex(&face_offsets, &vertex_faces, &corners) {
                return Err(HierarchyError::Unsupported(format!(
                    "the mesh is not an oriented 2-manifold at vertex {v}: its faces do not form \
                     one consistently oriented fan (an edge with more than two faces, two fans \
                     meeting at the vertex, or faces of opposite orientation)"
                )));
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
                let length = points[a].distance(points[b]) as f32;
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

        let mut removed = 0usize;
        for &key in &keys {
            visits += 1;
            if visits % REPORT_EVERY == 0 {
                let done = (start_vertices - vertex_count as f64 + isolated as f64) / goal;
                if !progress.report(done.clamp(0.0, 1.0) as f32) {
                    return Err(HierarchyError::Cancelled);
                }
            }
            if vertex_count <= options.min_vertices {
                break;
            }
            let v = key as u32;
            if lock_stamp[v as usize] == stamp {
                continue;
            }
            let faces = &vertex_faces
                [face_offsets[v as usize] as usize..face_offsets[v as usize + 1] as usize];
            let state = PassState {
                points: &points,
                corners: &corners,
                face_offsets: &face_offsets,
                vertex_faces: &vertex_faces,
                face_removed_in_pass: &out.face_removed_in_pass,
                absorbed_stamp: &absorbed_stamp,
                absorbed_head: &absorbed_head,
                absorbed_next: &absorbed_next,
                stamp,
            };
            mark_id = mark_id.wrapping_add(1);
            if mark_id == 0 {
                mark.fill(0);
                mark_id = 1;
            }
            let Some((k, six_volume)) =
                choose_collapse(v, faces, &state, options, &mut scratch, &mut mark, mark_id)
            else {
                continue;
            };

            // Perform v -> k.
            for &f in faces {
                let t = &mut corners[f as usize];
                if t.contains(&k) {
                    out.face_removed_in_pass[f as usize] = pass;
                } else {
                    for c in t.iter_mut() {
                        if *c == v {
                            *c = k;
                        }
                    }
                }
            }
            lock_stamp[v as usize] = stamp;
            for &x in &scratch.neighbors {
                lock_stamp[x as usize] = stamp;
            }
            if absorbed_stamp[k as usize] != stamp {
                absorbed_stamp[k as usize] = stamp;
                absorbed_head[k as usize] = NEVER;
            }
            absorbed_next[v as usize] = absorbed_head[k as usize];
            absorbed_head[k as usize] = v;
            out.removed_in_pass[v as usize] = pass;
            out.target[v as usize] = k;
            out.six_split_volume[v as usize] = six_volume as f32;
            vertex_count -= 1;
            removed += 1;
        }

        if removed == 0 {
            break;
        }
        alive_faces.retain(|&f| out.face_removed_in_pass[f as usize] == NEVER);
        alive_vertices.retain(|&v| out.removed_in_pass[v as usize] == NEVER);
        out.pass_ms.push(started.elapsed().as_secs_f64() * 1e3);
    }
    Ok(out)
}

/// A vertex whose faces are not a single consistently oriented fan, if any: with the faces
/// `(v, a, b)` of `v`, every `a` and every `b` must be distinct and following `a -> b` from the
/// fan's start (an `a` that is no `b`, or any `a` when the fan is closed) must visit every face.
fn first_non_manifold_vertex(
    face_offsets: &[u32],
    vertex_faces: &[u32],
    corners: &[[u32; 3]],
) -> Option<usize> {
    let n = face_offsets.len() - 1;
    (0..n).into_par_iter().find_first(|&v| {
        let faces = &vertex_faces[face_offsets[v] as usize..face_offsets[v + 1] as usize];
        if faces.is_empty() {
            return false;
        }
        let mut fan: Vec<(u32, u32)> = Vec::with_capacity(faces.len());
        for &f in faces {
            let t = corners[f as usize];
            let i = t.iter().position(|&c| c == v as u32).unwrap_or(0);
            fan.push((t[(i + 1) % 3], t[(i + 2) % 3]));
        }
        for i in 0..fan.len() {
            for j in i + 1..fan.len() {
                if fan[i].0 == fan[j].0 || fan[i].1 == fan[j].1 {
                    return true;
                }
            }
        }
        let start = fan
            .iter()
            .position(|&(a, _)| !fan.iter().any(|&(_, b)| b == a))
            .unwrap_or(0);
        let mut current = start;
        for step in 1..=fan.len() {
            let b = fan[current].1;
            match fan.iter().position(|&(a, _)| a == b) {
                Some(next) if next == start => return step != fan.len(),
                Some(next) => current = next,
                None => return step != fan.len(),
            }
        }
        true
    })
}

/// Read-only view of the pass state for choosing a collapse.
struct PassState<'a> {
    points: &'a [DVec3],
    corners: &'a [[u32; 3]],
    face_offsets: &'a [u32],
    vertex_faces: &'a [u32],
    face_removed_in_pass: &'a [u32],
    absorbed_stamp: &'a [u32],
    absorbed_head: &'a [u32],
    absorbed_next: &'a [u32],
    stamp: u32,
}

impl PassState<'_> {
    /// Calls `visit` with the current corners of every live face of `k`: its faces at the start of
    /// the pass plus those of the vertices collapsed into it during this pass.
    #[inline]
    fn for_each_face_of(&self, k: u32, mut visit: impl FnMut([u32; 3])) {
        let mut owner = k;
        loop {
            let range = self.face_offsets[owner as usize] as usize
                ..self.face_offsets[owner as usize + 1] as usize;
            for &f in &self.vertex_faces[range] {
                if self.face_removed_in_pass[f as usize] == NEVER {
                    visit(self.corners[f as usize]);
                }
            }
            owner = if owner == k {
                if self.absorbed_stamp[k as usize] == self.stamp {
                    self.absorbed_head[k as usize]
                } else {
                    NEVER
                }
            } else {
                self.absorbed_next[owner as usize]
            };
            if owner == NEVER {
                break;
            }
        }
    }
}

#[derive(Default)]
struct Scratch {
    /// `(a, b)` for each face `(v, a, b)` of the vertex being tried, in the face's orientation.
    fan: Vec<(u32, u32)>,
    neighbors: Vec<u32>,
    /// `(|cone|, k, signed cone)`.
    candidates: Vec<(f64, u32, f64)>,
}

/// The first valid collapse target of `v` in increasing cone volume, with its signed cone volume.
fn choose_collapse(
    v: u32,
    faces: &[u32],
    state: &PassState,
    options: &HierarchyOptions,
    scratch: &mut Scratch,
    mark: &mut [u32],
    mark_id: u32,
) -> Option<(u32, f64)> {
    if faces.is_empty() {
        return None;
    }
    let p = state.points;
    scratch.fan.clear();
    for &f in faces {
        let t = state.corners[f as usize];
        let (a, b) = if t[0] == v {
            (t[1], t[2])
        } else if t[1] == v {
            (t[2], t[0])
        } else {
            (t[0], t[1])
        };
        scratch.fan.push((a, b));
    }
    // Boundary: a fan edge v-a (a first in its face) that no face has as v-b closes the fan.
    let mut fan_start = NEVER;
    let mut fan_end = NEVER;
    for &(a, _) in &scratch.fan {
        if !scratch.fan.iter().any(|&(_, b)| b == a) {
            fan_start = a;
        }
    }
    for &(_, b) in &scratch.fan {
        if !scratch.fan.iter().any(|&(a, _)| a == b) {
            fan_end = b;
        }
    }
    let on_boundary = fan_start != NEVER;
    if on_boundary && options.keep_boundary {
        return None;
    }
    scratch.neighbors.clear();
    for &(a, _) in &scratch.fan {
        scratch.neighbors.push(a);
    }
    if on_boundary {
        scratch.neighbors.push(fan_end);
    }
    let xv = p[v as usize];

    scratch.candidates.clear();
    for &k in &scratch.neighbors {
        if on_boundary && k != fan_start && k != fan_end {
            continue;
        }
        let xk = p[k as usize];
        let mut cone = 0.0;
        for &(a, b) in &scratch.fan {
            if a != k && b != k {
                cone += (p[a as usize] - xk).cross(p[b as usize] - xk).dot(xv - xk);
            }
        }
        scratch.candidates.push((cone.abs(), k, cone));
    }
    scratch
        .candidates
        .sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));

    'candidate: for &(_, k, cone) in &scratch.candidates {
        let xk = p[k as usize];
        // No surviving face may flip or degenerate.
        let mut opposite = [NEVER; 2];
        for &(a, b) in &scratch.fan {
            if a == k {
                opposite[0] = b;
                continue;
            }
            if b == k {
                opposite[1] = a;
                continue;
            }
            let (xa, xb) = (p[a as usize], p[b as usize]);
            let old = (xa - xv).cross(xb - xv);
            let new = (xa - xk).cross(xb - xk);
            if old.dot(new) <= 0.0 {
                continue 'candidate;
            }
        }
        // Link condition: apart from the opposite vertices, no neighbour of v may be one of k.
        for &x in &scratch.neighbors {
            mark[x as usize] = mark_id;
        }
        for o in opposite {
            if o != NEVER {
                mark[o as usize] = mark_id.wrapping_sub(1);
            }
        }
        mark[k as usize] = mark_id.wrapping_sub(1);
        let mut link_ok = true;
        let valence = scratch.neighbors.len();
        let tetrahedron_check = !on_boundary && valence == 3;
        let single_triangle = on_boundary && valence == 2;
        let third = if opposite[0] != NEVER {
            opposite[0]
        } else {
            opposite[1]
        };
        let mut faces_on_third_edge = 0;
        state.for_each_face_of(k, |t| {
            for c in t {
                if c != k && mark[c as usize] == mark_id {
                    link_ok = false;
                }
            }
            if tetrahedron_check
                && !t.contains(&v)
                && t.contains(&opposite[0])
                && t.contains(&opposite[1])
            {
                link_ok = false;
            }
            if single_triangle && t.contains(&third) {
                faces_on_third_edge += 1;
            }
        });
        // Restore the marks of the opposite vertices for later candidates.
        for &x in &scratch.neighbors {
            mark[x as usize] = mark_id;
        }
        if !link_ok || (single_triangle && faces_on_third_edge < 2) {
            continue;
        }
        return Some((k, cone));
    }
    None
}
