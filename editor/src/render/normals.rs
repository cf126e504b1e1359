//! Per-vertex normals for smooth shading, split at sharp edges.
//!
//! [`vertex_normals`]: each vertex gets the sum of the normals of the triangles around it, each
//! weighted by its triangle's area (the unnormalised cross product is twice the area long, so
//! summing cross products weights by area), then made unit length. A fair surface, and a noisy
//! scan, shade smooth with these.
//!
//! [`sharp_split`] finds where they must not be shared: at an edge whose two faces' normals turn
//! by more than [`SHARP_EDGE_ANGLE`] (a CAD part's rim, a box's edge), shading averaged across it
//! makes the whole part look like a soft blob. Around each vertex the triangles joined across
//! edges that are not sharp form its smoothing groups (walking its fan and stopping at sharp
//! edges, as Blender's smoothing by angle does); a vertex with two groups or more is split, one
//! shading vertex per group, and each corner is shaded with its group's normal
//! ([`SharpSplit::normals`]). A vertex with one sharp edge in a closed fan is not split (the walk
//! goes round the other way), nor is any vertex of a mesh with no sharp edge: such a mesh gets
//! [`vertex_normals`] exactly, and nothing else changes in what is drawn.
//!
//! A split vertex's groups weight their faces by the faces' angles at the vertex, not by area:
//! the meshes that split are mostly CAD exports, whose triangulation has nothing to do with the
//! surface (a side quad cut into two triangles gives the vertex two faces on one side and one on
//! the other; a cap is a fan of slivers), and area weights would tilt the normal towards the
//! side with more triangles (1.9° on a 32-sided cylinder's rim, a visibly twisted highlight),
//! where angle weights (Thürmer and Wüthrich's mean) give the surface's own normal. Vertices that
//! do not split keep the area weights, so the smooth parts of a mesh shade as before.
//!
//! The split is found again whenever the positions change (a fairing result, a level, noise),
//! as the shading must show the surface on screen: a noisy CAD part's rims crisp once faired, a
//! rim rounded off by a coarse level smooth. [`shading_normals`] does both at once, reading each
//! face's normal once; with the mesh's [`CornerTable`] kept from one move to the next (the
//! connectivity does not change: it lists the faces around each vertex and the two faces of
//! each edge), a mesh with no sharp edge costs one test per edge on top of [`vertex_normals`]
//! (1.6-2× on the 1.2M-face mesh, see docs/measurements.md), and only the ends of sharp edges
//! are walked.
//!
//! Computed on the CPU whenever the displayed mesh changes (a new mesh or new positions), on the
//! renderer's upload thread for big meshes. Face normals are computed in parallel with rayon
//! when the mesh is big; summing them into the vertices is one serial pass (a parallel scatter
//! would need a vertex-to-face table or one accumulator per thread, both costing more memory
//! than the pass costs time). Finding the split needs the corners around each vertex
//! ([`CornerTable`]), built once per connectivity.
//!
//! Never NaN: a degenerate triangle (zero area, or a corner that is not finite) adds nothing and
//! joins the faces beside it, a triangle naming a vertex out of range is skipped (and a mesh
//! with one is not split), and a vertex with no usable triangle gets the zero vector, which the
//! shader reads as "use the face normal".

use rayon::prelude::*;

/// Below this many triangles one thread is faster than handing work to rayon.
const PARALLEL_TRIANGLES: usize = 50_000;

/// Two faces whose normals turn by more than this many degrees meet at a sharp edge, which
/// smooth shading keeps crisp. A CAD part's rims turn by 90°; noise of 0.3 mean edge lengths
/// along the normals turns one edge in seven by more than 60° and one in twenty by more than
/// 80°: at 60° the noisy bunny's split vertices (27 %) show as dark flakes, at 80° (8 %) it looks
/// as unsplit. Edges of 60-80° (a hexagonal prism's sides) shade smooth. See
/// docs/measurements.md, "Smooth shading's sharp edges".
pub const SHARP_EDGE_ANGLE: f32 = 80.0;

/// Area-weighted unit vertex normals, one per position; `[0, 0, 0]` for a vertex that no
/// triangle with an area touches.
pub fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let faces = face_normals(positions, triangles, |v| v as usize);
    area_weighted(positions.len(), triangles, &faces)
}

/// The unit sums of the `faces`' normals (area vectors, one per triangle) at each of `vertices`.
fn area_weighted(vertices: usize, triangles: &[[u32; 3]], faces: &[[f32; 3]]) -> Vec<[f32; 3]> {
    let mut sums = vec![[0.0f32; 3]; vertices];
    for (t, n) in triangles.iter().zip(faces) {
        if *n == [0.0; 3] {
            continue;
        }
        for &v in t {
            // face_normal gave zero for triangles with a vertex out of range.
            let sum = &mut sums[v as usize];
            for k in 0..3 {
                sum[k] += n[k];
            }
        }
    }
    make_unit(&mut sums);
    sums
}

fn make_unit(sums: &mut [[f32; 3]]) {
    let unit = |n: &mut [f32; 3]| *n = normalized(*n);
    if sums.len() >= PARALLEL_TRIANGLES {
        sums.par_iter_mut().for_each(unit);
    } else {
        sums.iter_mut().for_each(unit);
    }
}

/// Smooth shading's normals of `triangles` over `positions`, split at edges sharper than
/// `angle_degrees`: `(None, normals per vertex)`, exactly [`vertex_normals`], when no vertex
/// splits; otherwise the split and the normals of its shading vertices ([`SharpSplit::normals`]).
/// `corners` is [`CornerTable::new`] of the same triangles, when the caller keeps one.
pub fn shading_normals(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    corners: Option<&CornerTable>,
    angle_degrees: f32,
) -> (Option<SharpSplit>, Vec<[f32; 3]>) {
    let faces = face_normals(positions, triangles, |v| v as usize);
    match find_split(positions.len(), triangles, &faces, corners, angle_degrees) {
        Some(split) => {
            let normals = split.sum_normals(positions, &faces);
            (Some(split), normals)
        }
        None => (None, area_weighted(positions.len(), triangles, &faces)),
    }
}

/// Every triangle's unnormalised normal ([`face_normal`]), its corners' positions taken at
/// `vertex(corner)`; in parallel for a big mesh.
fn face_normals(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    vertex: impl Fn(u32) -> usize + Sync,
) -> Vec<[f32; 3]> {
    let face = |t: &[u32; 3]| face_normal(positions, &t.map(|c| vertex(c) as u32));
    if triangles.len() >= PARALLEL_TRIANGLES {
        triangles.par_iter().map(face).collect()
    } else {
        triangles.iter().map(face).collect()
    }
}

/// Where smooth shading's normals split at the sharp edges of one triangle list: its shading
/// vertices (the mesh's own vertices first, each standing for its first smoothing group, then
/// one more per further group of a split vertex) and the triangles over them. Made by
/// [`sharp_split`] or [`shading_normals`] for one set of positions; two splits are equal when
/// they split the same corners the same way.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SharpSplit {
    /// The mesh vertex each shading vertex stands on (`vertex_of[v] == v` for the mesh's own).
    vertex_of: Vec<u32>,
    /// The triangles given to [`sharp_split`], in their order, each corner on its shading
    /// vertex.
    triangles: Vec<[u32; 3]>,
    /// Per mesh vertex: it is split (its corners are weighted by angle).
    split: Vec<bool>,
}

impl SharpSplit {
    /// The mesh vertex of each shading vertex.
    pub fn vertex_of(&self) -> &[u32] {
        &self.vertex_of
    }

    /// The triangles over the shading vertices (those given to [`sharp_split`], in order).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// How many mesh vertices are split.
    pub fn split_vertex_count(&self) -> usize {
        self.split.iter().filter(|&&s| s).count()
    }

    fn is_split(&self, shading: u32) -> bool {
        self.split.get(shading as usize).copied().unwrap_or(true)
    }

    /// Unit normals of the shading vertices for `positions` (per mesh vertex): a split vertex's
    /// groups averaged by their faces' angles at it, every other vertex as [`vertex_normals`]
    /// has it. Meant for the positions the split was found on (other positions keep this
    /// split's groups, sharp or not).
    pub fn normals(&self, positions: &[[f32; 3]]) -> Vec<[f32; 3]> {
        let vertex_of = &self.vertex_of;
        // A position out of range makes the face's normal zero (it adds nothing).
        let faces = face_normals(positions, &self.triangles, |s| {
            vertex_of
                .get(s as usize)
                .map_or(usize::MAX, |&v| v as usize)
        });
        self.sum_normals(positions, &faces)
    }

    /// [`Self::normals`] from the faces' area normals.
    fn sum_normals(&self, positions: &[[f32; 3]], faces: &[[f32; 3]]) -> Vec<[f32; 3]> {
        let vertex_of = &self.vertex_of;
        let mut sums = vec![[0.0f32; 3]; vertex_of.len()];
        for (t, n) in self.triangles.iter().zip(faces) {
            if *n == [0.0; 3] {
                continue;
            }
            if !t.iter().any(|&s| self.is_split(s)) {
                for &s in t {
                    let sum = &mut sums[s as usize];
                    for k in 0..3 {
                        sum[k] += n[k];
                    }
                }
                continue;
            }
            let corners = t.map(|s| positions[vertex_of[s as usize] as usize]);
            let angles = corner_angles(corners, *n);
            let unit = normalized(*n);
            for (k, &s) in t.iter().enumerate() {
                let add = match self.is_split(s) {
                    true => unit.map(|c| c * angles[k]),
                    false => *n,
                };
                let sum = &mut sums[s as usize];
                for i in 0..3 {
                    sum[i] += add[i];
                }
            }
        }
        make_unit(&mut sums);
        sums
    }
}

/// The root of `s` in a union-find forest whose roots are their groups' smallest members.
fn root(roots: &[u32], mut s: u32) -> u32 {
    while roots[s as usize] != s {
        s = roots[s as usize];
    }
    s
}

/// The corners (3 × triangle + corner) around each vertex of a triangle list and the pairs of
/// faces that share an edge: what finding the split reads. It depends on the connectivity alone,
/// so a caller that moves a mesh keeps it: a move then tests each edge's pair once and walks
/// only the vertices of sharp edges.
#[derive(Clone, Debug)]
pub struct CornerTable {
    /// Per vertex, where its corners start in `corners` (one more entry than vertices).
    offsets: Vec<u32>,
    corners: Vec<u32>,
    /// Every two faces that share an edge (each pair of an edge with more than two faces).
    pairs: Vec<[u32; 2]>,
}

impl CornerTable {
    /// The table of `triangles` over `vertices` vertices; corners naming a vertex out of range
    /// are left out.
    pub fn new(vertices: usize, triangles: &[[u32; 3]]) -> Self {
        let mut offsets = vec![0u32; vertices + 1];
        for &v in triangles.iter().flatten() {
            if let Some(count) = offsets.get_mut(v as usize + 1) {
                *count += 1;
            }
        }
        for v in 0..vertices {
            offsets[v + 1] += offsets[v];
        }
        let mut next = offsets.clone();
        let mut corners = vec![0u32; offsets[vertices] as usize];
        for (c, &v) in triangles.iter().flatten().enumerate() {
            if let Some(at) = next.get_mut(v as usize).filter(|_| (v as usize) < vertices) {
                corners[*at as usize] = c as u32;
                *at += 1;
            }
        }
        let mut table = Self {
            offsets,
            corners,
            pairs: Vec::new(),
        };
        // Each edge v–u once, from its lower end v.
        let pairs_at = |mut out: Vec<[u32; 2]>, v: usize, ends: &mut Vec<(u32, u32)>| {
            table.ends(v as u32, triangles, ends);
            for run in ends
                .chunk_by(|a, b| a.0 == b.0)
                .filter(|run| run[0].0 > v as u32)
            {
                for (a, &(_, i)) in run.iter().enumerate() {
                    for &(_, j) in &run[a + 1..] {
                        let around = table.around(v);
                        let (f, g) = (around[i as usize] / 3, around[j as usize] / 3);
                        if f != g {
                            out.push([f, g]);
                        }
                    }
                }
            }
            out
        };
        let pairs = if triangles.len() >= PARALLEL_TRIANGLES {
            (0..vertices)
                .into_par_iter()
                .with_min_len(4096)
                .fold(
                    || (Vec::new(), Vec::new()),
                    |(out, mut ends), v| (pairs_at(out, v, &mut ends), ends),
                )
                .map(|(out, _)| out)
                .reduce(Vec::new, |mut a, b| {
                    a.extend(b);
                    a
                })
        } else {
            let mut ends = Vec::new();
            (0..vertices).fold(Vec::new(), |out, v| pairs_at(out, v, &mut ends))
        };
        table.pairs = pairs;
        table
    }

    /// The other ends of the edges at `v`'s corners, each with the index (in `around(v)`) of
    /// the corner whose face has that edge, sorted: the faces of one edge side by side.
    fn ends(&self, v: u32, triangles: &[[u32; 3]], ends: &mut Vec<(u32, u32)>) {
        ends.clear();
        for (i, &c) in self.around(v as usize).iter().enumerate() {
            let t = triangles[c as usize / 3];
            let k = c as usize % 3;
            let (next, prev) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            if next != v {
                ends.push((next, i as u32));
            }
            if prev != v && prev != next {
                ends.push((prev, i as u32));
            }
        }
        ends.sort_unstable();
    }

    fn vertices(&self) -> usize {
        self.offsets.len() - 1
    }

    fn around(&self, v: usize) -> &[u32] {
        &self.corners[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// Bytes it takes.
    pub fn bytes(&self) -> usize {
        (self.offsets.len() + self.corners.len() + 2 * self.pairs.len()) * 4
    }
}

/// Where the smooth shading of `triangles` (over `positions`) must split: `None` when no vertex
/// has two smoothing groups or more at `angle_degrees` (the mesh shades with
/// [`vertex_normals`]), or when a triangle names a vertex out of range.
pub fn sharp_split(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    angle_degrees: f32,
) -> Option<SharpSplit> {
    let faces = face_normals(positions, triangles, |v| v as usize);
    find_split(positions.len(), triangles, &faces, None, angle_degrees)
}

/// [`sharp_split`] from the faces' area normals, with the corner table when the caller has one
/// (it must be of these triangles).
fn find_split(
    vertices: usize,
    triangles: &[[u32; 3]],
    faces: &[[f32; 3]],
    corners: Option<&CornerTable>,
    angle_degrees: f32,
) -> Option<SharpSplit> {
    if triangles.iter().flatten().any(|&v| v as usize >= vertices) {
        return None;
    }
    let built;
    // A table of other triangles (another vertex or corner count) is not used.
    let fits =
        |c: &&CornerTable| c.vertices() == vertices && c.corners.len() == 3 * triangles.len();
    let corners = match corners.filter(fits) {
        Some(corners) => corners,
        None => {
            built = CornerTable::new(vertices, triangles);
            &built
        }
    };
    let cos_limit = angle_degrees.to_radians().cos();
    let units: Vec<[f32; 3]> = if faces.len() >= PARALLEL_TRIANGLES {
        faces.par_iter().map(|&n| normalized(n)).collect()
    } else {
        faces.iter().map(|&n| normalized(n)).collect()
    };
    // The sharp edges' faces first (one test per edge, no walk): most meshes have none.
    let sharp = |&[f, g]: &[u32; 2]| is_sharp(units[f as usize], units[g as usize], cos_limit);
    let sharp_pairs: Vec<[u32; 2]> = if corners.pairs.len() >= PARALLEL_TRIANGLES {
        corners.pairs.par_iter().copied().filter(sharp).collect()
    } else {
        corners.pairs.iter().copied().filter(sharp).collect()
    };
    if sharp_pairs.is_empty() {
        return None;
    }
    // Only the ends of sharp edges can split.
    let mut candidates: Vec<u32> = sharp_pairs
        .iter()
        .flat_map(|&[f, g]| {
            let (tf, tg) = (triangles[f as usize], triangles[g as usize]);
            tf.into_iter().filter(move |v| tg.contains(v))
        })
        .collect();
    candidates.sort_unstable();
    candidates.dedup();
    let find =
        |scratch: &mut Scratch, &v: &u32| scratch.groups(v, corners, triangles, &units, cos_limit);
    let found: Vec<SplitVertex> = if candidates.len() >= PARALLEL_TRIANGLES / 8 {
        candidates
            .par_iter()
            .with_min_len(1024)
            .map_init(Scratch::default, find)
            .flatten()
            .collect()
    } else {
        let mut scratch = Scratch::default();
        candidates
            .iter()
            .filter_map(|v| find(&mut scratch, v))
            .collect()
    };
    if found.is_empty() {
        return None;
    }
    let mut vertex_of: Vec<u32> = (0..vertices as u32).collect();
    let mut split_triangles = triangles.to_vec();
    let mut split = vec![false; vertices];
    for found in found {
        split[found.vertex as usize] = true;
        // Group 0 (the first corner's) keeps the vertex; the others get new shading vertices.
        let first_new = vertex_of.len() as u32;
        vertex_of.extend((1..found.groups).map(|_| found.vertex));
        for &(corner, group) in &found.corners {
            let shading = match group {
                0 => found.vertex,
                g => first_new + g - 1,
            };
            split_triangles[corner as usize / 3][corner as usize % 3] = shading;
        }
    }
    Some(SharpSplit {
        vertex_of,
        triangles: split_triangles,
        split,
    })
}

/// A split vertex: how many smoothing groups it has and each of its corners' group.
struct SplitVertex {
    vertex: u32,
    groups: u32,
    corners: Vec<(u32, u32)>,
}

/// One thread's working lists for [`Scratch::groups`].
#[derive(Default)]
struct Scratch {
    /// (other end of an edge, index of the corner whose face has that edge).
    ends: Vec<(u32, u32)>,
    /// Pairs of corners whose faces share an edge that is not sharp.
    joined: Vec<(u32, u32)>,
    roots: Vec<u32>,
    group: Vec<u32>,
}

impl Scratch {
    /// The smoothing groups of vertex `v` (its corners in `table`), when it has two or
    /// more: its faces joined across each edge (v, u) whose faces do not turn by more than the
    /// angle whose cosine is `cos_limit` (every pair of faces on an edge with more than two).
    fn groups(
        &mut self,
        v: u32,
        table: &CornerTable,
        triangles: &[[u32; 3]],
        units: &[[f32; 3]],
        cos_limit: f32,
    ) -> Option<SplitVertex> {
        let around = table.around(v as usize);
        table.ends(v, triangles, &mut self.ends);
        self.joined.clear();
        let mut any_sharp = false;
        let face = |i: u32| around[i as usize] / 3;
        for run in self.ends.chunk_by(|a, b| a.0 == b.0) {
            for (a, &(_, i)) in run.iter().enumerate() {
                for &(_, j) in &run[a + 1..] {
                    let (fi, fj) = (face(i), face(j));
                    if fi == fj {
                        continue;
                    }
                    match is_sharp(units[fi as usize], units[fj as usize], cos_limit) {
                        true => any_sharp = true,
                        false => self.joined.push((i, j)),
                    }
                }
            }
        }
        if !any_sharp {
            return None;
        }
        self.roots.clear();
        self.roots.extend(0..around.len() as u32);
        for &(i, j) in &self.joined {
            let (a, b) = (root(&self.roots, i), root(&self.roots, j));
            self.roots[a.max(b) as usize] = a.min(b);
        }
        // Groups numbered in the order of their first corners.
        self.group.clear();
        self.group.resize(around.len(), u32::MAX);
        let mut groups = 0;
        for i in 0..around.len() as u32 {
            let r = root(&self.roots, i) as usize;
            if self.group[r] == u32::MAX {
                self.group[r] = groups;
                groups += 1;
            }
            self.group[i as usize] = self.group[r];
        }
        if groups < 2 {
            return None;
        }
        Some(SplitVertex {
            vertex: v,
            groups,
            corners: around
                .iter()
                .copied()
                .zip(self.group.iter().copied())
                .collect(),
        })
    }
}

/// Whether two faces with unit normals `a` and `b` (zero: no normal) meet at a sharp edge: both
/// have a normal and they turn by more than the angle whose cosine is `cos_limit`.
fn is_sharp(a: [f32; 3], b: [f32; 3], cos_limit: f32) -> bool {
    a != [0.0; 3] && b != [0.0; 3] && a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < cos_limit
}

/// The angles (radians) at the three corners of a triangle with area normal `n` (not zero).
fn corner_angles(corners: [[f32; 3]; 3], n: [f32; 3]) -> [f32; 3] {
    let twice_area = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    [0, 1, 2].map(|k| {
        let (a, b, c) = (corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]);
        let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let ac = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let dot = ab[0] * ac[0] + ab[1] * ac[1] + ab[2] * ac[2];
        // |ab × ac| is twice the area at every corner; atan2 is exact for thin triangles.
        let angle = twice_area.atan2(dot);
        if angle.is_finite() {
            angle
        } else {
            0.0
        }
    })
}

/// The triangle's unnormalised normal (twice its area long), or zero when a corner is out of
/// range or not finite.
fn face_normal(positions: &[[f32; 3]], t: &[u32; 3]) -> [f32; 3] {
    let corner = |v: u32| positions.get(v as usize).copied();
    let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2])) else {
        return [0.0; 3];
    };
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ac = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        ab[1] * ac[2] - ab[2] * ac[1],
        ab[2] * ac[0] - ab[0] * ac[2],
        ab[0] * ac[1] - ab[1] * ac[0],
    ];
    if n.iter().all(|c| c.is_finite()) {
        n
    } else {
        [0.0; 3]
    }
}

/// `n` at unit length, or zero when it has no direction (zero, tiny or not finite).
fn normalized(n: [f32; 3]) -> [f32; 3] {
    // In f64: a sum of tiny areas can underflow when squared in f32.
    let [x, y, z] = n.map(f64::from);
    let length = (x * x + y * y + z * z).sqrt();
    if length > 0.0 && length.is_finite() {
        [
            (x / length) as f32,
            (y / length) as f32,
            (z / length) as f32,
        ]
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f32; 3], b: [f32; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    /// The unit cube, outward-wound, two triangles per side.
    fn cube() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let positions = (0..8)
            .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
            .collect();
        let quads = [
            [0, 2, 3, 1], // z = 0, facing -z
            [4, 5, 7, 6], // z = 1, facing +z
            [0, 1, 5, 4], // y = 0, facing -y
            [2, 6, 7, 3], // y = 1, facing +y
            [0, 4, 6, 2], // x = 0, facing -x
            [1, 3, 7, 5], // x = 1, facing +x
        ];
        let triangles = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        (positions, triangles)
    }

    #[test]
    fn a_cube_corner_points_along_the_diagonal() {
        let (positions, triangles) = cube();
        let normals = vertex_normals(&positions, &triangles);
        let s = 1.0 / 3f32.sqrt();
        // Each corner has equal area of its three sides around it (each side's two triangles
        // split the side's area; a corner is in one or both of them).
        assert!(close(normals[7], [s, s, s]), "{:?}", normals[7]);
        assert!(close(normals[0], [-s, -s, -s]), "{:?}", normals[0]);
        for n in &normals {
            let length = n.iter().map(|c| c * c).sum::<f32>().sqrt();
            assert!((length - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn a_flat_plane_has_the_planes_normal_everywhere() {
        let n = 6u32;
        let positions: Vec<[f32; 3]> = (0..=n)
            .flat_map(|y| (0..=n).map(move |x| [x as f32 * 0.3, y as f32 * 0.7, 2.0]))
            .collect();
        let index = |x: u32, y: u32| y * (n + 1) + x;
        let triangles: Vec<[u32; 3]> = (0..n)
            .flat_map(|y| {
                (0..n).flat_map(move |x| {
                    [
                        [index(x, y), index(x + 1, y), index(x + 1, y + 1)],
                        [index(x, y), index(x + 1, y + 1), index(x, y + 1)],
                    ]
                })
            })
            .collect();
        for normal in vertex_normals(&positions, &triangles) {
            assert!(close(normal, [0.0, 0.0, 1.0]), "{normal:?}");
        }
    }

    #[test]
    fn degenerate_and_broken_triangles_give_no_nan() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0], // on the line through 0 and 1: triangle 0-1-3 has no area
            [f32::NAN, 0.0, 0.0],
            [5.0, 5.0, 5.0],      // used by no triangle
            [f32::MAX, 0.0, 0.0], // with the next: a cross product that overflows
            [0.0, f32::MAX, 0.0],
        ];
        let triangles = vec![
            [0, 1, 2],
            [0, 1, 3],
            [1, 1, 1],
            [0, 4, 2],
            [0, 1, 99],
            [0, 6, 7],
        ];
        let normals = vertex_normals(&positions, &triangles);
        assert_eq!(normals.len(), positions.len());
        assert!(normals.iter().flatten().all(|c| c.is_finite()));
        // Only the good triangle counts: its corners face +z, the rest have no direction.
        for v in [0, 1, 2] {
            assert!(close(normals[v], [0.0, 0.0, 1.0]), "{v}: {:?}", normals[v]);
        }
        for v in [3, 4, 5, 6, 7] {
            assert_eq!(normals[v], [0.0; 3], "{v}");
        }
    }

    #[test]
    fn a_big_mesh_gives_the_same_normals_in_parallel() {
        // A bumpy grid past the parallel threshold, against the serial sum done by hand.
        let n = 200u32;
        let positions: Vec<[f32; 3]> = (0..=n)
            .flat_map(|y| {
                (0..=n).map(move |x| {
                    let (fx, fy) = (x as f32 * 0.1, y as f32 * 0.1);
                    [fx, fy, (fx * 1.3).sin() * (fy * 0.7).cos()]
                })
            })
            .collect();
        let index = |x: u32, y: u32| y * (n + 1) + x;
        let triangles: Vec<[u32; 3]> = (0..n)
            .flat_map(|y| {
                (0..n).flat_map(move |x| {
                    [
                        [index(x, y), index(x + 1, y), index(x + 1, y + 1)],
                        [index(x, y), index(x + 1, y + 1), index(x, y + 1)],
                    ]
                })
            })
            .collect();
        assert!(triangles.len() >= PARALLEL_TRIANGLES);
        let normals = vertex_normals(&positions, &triangles);
        let mut sums = vec![[0.0f32; 3]; positions.len()];
        for t in &triangles {
            let f = face_normal(&positions, t);
            for &v in t {
                for k in 0..3 {
                    sums[v as usize][k] += f[k];
                }
            }
        }
        for (n, s) in normals.iter().zip(sums) {
            assert!(close(*n, normalized(s)));
        }
        // Bumpy: the normals vary, unlike a plane's.
        assert!(normals.iter().any(|n| n[2] < 0.9));
    }

    /// Each corner's normal in `split`'s shading for `positions`, per triangle.
    fn corner_normals(split: &SharpSplit, positions: &[[f32; 3]]) -> Vec<[[f32; 3]; 3]> {
        let normals = split.normals(positions);
        split
            .triangles()
            .iter()
            .map(|t| t.map(|s| normals[s as usize]))
            .collect()
    }

    fn unit_face(positions: &[[f32; 3]], t: &[u32; 3]) -> [f32; 3] {
        normalized(face_normal(positions, t))
    }

    #[test]
    fn a_cube_shades_each_side_with_its_own_normal() {
        let (positions, triangles) = cube();
        let split = sharp_split(&positions, &triangles, SHARP_EDGE_ANGLE).expect("split");
        // Every corner is on three sides: three shading vertices each.
        assert_eq!(split.split_vertex_count(), 8);
        assert_eq!(split.vertex_of().len(), 24);
        for (t, corners) in triangles.iter().zip(corner_normals(&split, &positions)) {
            for n in corners {
                assert!(close(n, unit_face(&positions, t)), "{t:?}: {n:?}");
            }
        }
        // The shading vertices stand on the corners of their own triangles.
        for (t, s) in triangles.iter().zip(split.triangles()) {
            assert_eq!(s.map(|s| split.vertex_of()[s as usize]), *t);
        }
    }

    /// A cylinder as CAD exporters write it (rim vertices only, caps fanned from slivers): the
    /// caps are flat to their rims, the side is round up to them, and the side's normal at a
    /// rim vertex points straight out from the axis although the vertex has two side triangles
    /// on one side and one on the other (area weights would turn it by about 1.9°).
    #[test]
    fn a_cad_cylinder_keeps_its_rims_and_its_round_side() {
        let mesh = fairmesh::mesh::shapes::cad_cylinder(32, 1.0, 2.0);
        let split = sharp_split(&mesh.positions, &mesh.triangles, SHARP_EDGE_ANGLE).unwrap();
        assert_eq!(split.split_vertex_count(), 64);
        let normals = corner_normals(&split, &mesh.positions);
        let (mut caps, mut sides) = (0, 0);
        for (t, corners) in mesh.triangles.iter().zip(normals) {
            let face = unit_face(&mesh.positions, t);
            for (&v, n) in t.iter().zip(corners) {
                if face[2].abs() > 0.99 {
                    caps += 1;
                    assert_eq!(n, [0.0, 0.0, face[2].signum()]);
                } else {
                    sides += 1;
                    let [x, y, _] = mesh.positions[v as usize];
                    let out = normalized([x, y, 0.0]);
                    assert!(
                        n[2] == 0.0 && close(n, out),
                        "vertex {v}: {n:?}, out {out:?}"
                    );
                }
            }
        }
        assert_eq!((caps, sides), (3 * 60, 3 * 64));
    }

    #[test]
    fn a_smooth_sphere_is_not_split() {
        let mesh = fairmesh::mesh::shapes::icosphere(3);
        assert!(sharp_split(&mesh.positions, &mesh.triangles, SHARP_EDGE_ANGLE).is_none());
    }

    /// A sphere and a cube in one mesh: the cube splits, and every sphere vertex keeps exactly
    /// the area-weighted normal it has alone.
    #[test]
    fn vertices_that_do_not_split_keep_the_area_weighted_normals() {
        let ball = fairmesh::mesh::shapes::icosphere(2);
        let (cube_positions, cube_triangles) = cube();
        let offset = ball.positions.len() as u32;
        let mut positions = ball.positions.clone();
        positions.extend(cube_positions.iter().map(|p| [p[0] + 3.0, p[1], p[2]]));
        let mut triangles = ball.triangles.clone();
        triangles.extend(cube_triangles.iter().map(|t| t.map(|v| v + offset)));
        let split = sharp_split(&positions, &triangles, SHARP_EDGE_ANGLE).unwrap();
        assert_eq!(split.split_vertex_count(), 8);
        let normals = split.normals(&positions);
        let alone = vertex_normals(&ball.positions, &ball.triangles);
        assert_eq!(normals[..alone.len()], alone[..]);
    }

    /// Noise along the normals, as a scan shows it: at 0.15 mean edge lengths no vertex
    /// splits, at 0.3 (the editor's default noise) under one in a hundred (14 of 2562). A
    /// finely sampled box splits along its edges and nowhere else.
    #[test]
    fn a_noisy_sphere_stays_smooth_and_a_box_keeps_its_edges() {
        use fairmesh::noise::{add_noise, NoiseOptions};
        for (sigma, most) in [(0.15, 0), (0.3, 25)] {
            let mut ball = fairmesh::mesh::shapes::icosphere(4);
            add_noise(&mut ball, &NoiseOptions::default().with_sigma(sigma));
            let split = sharp_split(&ball.positions, &ball.triangles, SHARP_EDGE_ANGLE);
            let count = split.map_or(0, |s| s.split_vertex_count());
            assert!(count <= most, "noise {sigma}: {count} of 2562 split");
        }
        let block = fairmesh::mesh::shapes::cuboid([1.0, 1.0, 1.0], 0.05);
        let split = sharp_split(&block.positions, &block.triangles, SHARP_EDGE_ANGLE).unwrap();
        // On two of the box's sides (each coordinate 0 or 1 on its sides).
        let on_edge = |v: u32| {
            let p = block.positions[v as usize];
            let on_sides = p
                .iter()
                .filter(|&&c| c.abs() < 1e-5 || (c - 1.0).abs() < 1e-5);
            on_sides.count() >= 2
        };
        let split_vertices = &split.vertex_of()[block.positions.len()..];
        assert!(split_vertices.iter().all(|&v| on_edge(v)));
        // The box's 12 edges have 19 vertices each between its 8 corners.
        assert_eq!(split.split_vertex_count(), 8 + 12 * 19);
    }

    /// A sheet folded along its middle column: folded at 90° the fold's vertices shade each side
    /// flat; moved to a gentle fold (or flat) nothing splits, and the normals are
    /// [`vertex_normals`], bit for bit, with or without a kept corner table.
    #[test]
    fn a_fold_splits_while_it_is_sharp() {
        let n = 4u32;
        let index = |x: u32, y: u32| y * (n + 1) + x;
        let at = |fold_degrees: f32| -> Vec<[f32; 3]> {
            let (sin, cos) = fold_degrees.to_radians().sin_cos();
            (0..=n)
                .flat_map(|y| {
                    (0..=n).map(move |x| {
                        // x beyond the middle column turns up about it.
                        let d = x as f32 - (n / 2) as f32;
                        match d > 0.0 {
                            true => [d * cos, y as f32, d * sin],
                            false => [d, y as f32, 0.0],
                        }
                    })
                })
                .collect()
        };
        let triangles = fairmesh::mesh::shapes::grid(n as usize).triangles;
        let table = CornerTable::new(((n + 1) * (n + 1)) as usize, &triangles);
        let folded = at(90.0);
        let (split, normals) = shading_normals(&folded, &triangles, Some(&table), 90.0 - 1.0);
        let split = split.expect("split at 90°");
        assert_eq!(
            Some(&split),
            sharp_split(&folded, &triangles, 89.0).as_ref()
        );
        assert_eq!(normals, split.normals(&folded));
        assert_eq!(split.split_vertex_count(), (n + 1) as usize);
        let fold_vertex = index(n / 2, n / 2);
        let mut sides: Vec<[f32; 3]> = (0..split.vertex_of().len())
            .filter(|&s| split.vertex_of()[s] == fold_vertex)
            .map(|s| normals[s])
            .collect();
        sides.sort_by(|a, b| a[2].total_cmp(&b[2]));
        assert_eq!(sides.len(), 2);
        assert!(close(sides[0], [-1.0, 0.0, 0.0]) || close(sides[0], [1.0, 0.0, 0.0]));
        assert!(close(sides[1], [0.0, 0.0, 1.0]), "{sides:?}");
        // Just under the angle: smooth.
        assert!(sharp_split(&folded, &triangles, 91.0).is_none());
        for fold in [0.0, 30.0] {
            let moved = at(fold);
            for table in [Some(&table), None] {
                let (split, normals) = shading_normals(&moved, &triangles, table, 89.0);
                assert!(split.is_none(), "{fold}°");
                assert_eq!(normals, vertex_normals(&moved, &triangles));
            }
        }
    }

    #[test]
    fn a_split_mesh_with_broken_triangles_gives_no_nan() {
        let (mut positions, mut triangles) = cube();
        positions.extend([
            [f32::NAN, 0.0, 0.0],
            [f32::MAX, 0.0, 0.0],
            [0.0, f32::MAX, 0.0],
        ]);
        triangles.extend([[0, 8, 1], [0, 9, 10], [1, 1, 1], [0, 1, 0]]);
        let split = sharp_split(&positions, &triangles, SHARP_EDGE_ANGLE).unwrap();
        let normals = split.normals(&positions);
        assert!(normals.iter().flatten().all(|c| c.is_finite()));
        assert!(normals[8..11].iter().all(|&n| n == [0.0; 3]));
        // Positions that are all one point: no normal anywhere, still no NaN.
        let normals = split.normals(&vec![[1.0; 3]; positions.len()]);
        assert!(normals.iter().all(|&n| n == [0.0; 3]));
        // A vertex out of range: not split (the mesh shades as before).
        triangles.push([0, 1, 99]);
        assert!(sharp_split(&positions, &triangles, SHARP_EDGE_ANGLE).is_none());
    }

    #[test]
    fn a_big_split_mesh_gives_the_same_split_in_parallel() {
        // Cubes side by side past the parallel threshold: each splits as one cube does.
        let (positions, triangles) = cube();
        let copies = PARALLEL_TRIANGLES / triangles.len() + 1;
        let all_positions: Vec<[f32; 3]> = (0..copies)
            .flat_map(|i| {
                positions
                    .iter()
                    .map(move |p| [p[0] + 2.0 * i as f32, p[1], p[2]])
            })
            .collect();
        let all_triangles: Vec<[u32; 3]> = (0..copies as u32)
            .flat_map(|i| triangles.iter().map(move |t| t.map(|v| v + 8 * i)))
            .collect();
        assert!(all_triangles.len() >= PARALLEL_TRIANGLES);
        let split = sharp_split(&all_positions, &all_triangles, SHARP_EDGE_ANGLE).unwrap();
        assert_eq!(split.vertex_of().len(), 24 * copies);
        let normals = split.normals(&all_positions);
        for (t, s) in all_triangles.iter().zip(split.triangles()) {
            for &s in s {
                assert!(close(normals[s as usize], unit_face(&all_positions, t)));
            }
        }
    }
}
