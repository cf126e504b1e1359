//! Connectivity of a [`TriMesh`]: one-ring neighbours and vertex-to-face incidence (CSR), ordered
//! boundary loops, connected components, manifold checks, Euler characteristic and genus.
//!
//! Built in O(V + F) plus a small sort per vertex, in parallel over vertices: vertex-to-face lists
//! come from a counting sort of the corners; each vertex then sorts the other corners of its faces,
//! tagged with the direction of the edge in that face, which gives at once its neighbours, which
//! of its edges lie on the boundary (used by one face), which are non-manifold (more than two
//! faces) and which are inconsistently oriented (two faces traversing the edge the same way).
//! The same pass compares the triangles whose smallest corner the vertex is, which finds the
//! triangles that repeat an earlier one's corners (loading drops them) without a pass of its own.
//!
//! Boundary loops follow the faces' orientation: a boundary half-edge `v -> u` is one that a face
//! traverses from `v` to `u` and no face traverses back.

use super::TriMesh;
use rayon::prelude::*;

/// A connected component of the mesh (vertices joined by triangles).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ComponentInfo {
    pub vertices: usize,
    pub faces: usize,
    pub edges: usize,
    pub boundary_loops: usize,
    /// V - E + F.
    pub euler_characteristic: i64,
    /// `(2 - chi - b) / 2`, when the component is a manifold (orientable or not, the formula is the
    /// orientable one; see `Topology::inconsistent_edges`).
    pub genus: Option<i64>,
}

impl ComponentInfo {
    pub fn is_closed(&self) -> bool {
        self.boundary_loops == 0
    }
}

/// Connectivity derived from a mesh's triangles. Neighbour and face lists are sorted ascending.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    neighbor_offsets: Vec<u32>,
    neighbors: Vec<u32>,
    face_offsets: Vec<u32>,
    vertex_faces: Vec<u32>,
    is_boundary: Vec<bool>,
    /// Ordered boundary loops (vertex indices), following the faces' orientation.
    pub boundary_loops: Vec<Vec<u32>>,
    /// Edges (lower index first) used by more than two triangles.
    pub non_manifold_edges: Vec<[u32; 2]>,
    /// Vertices whose triangles do not form a single fan (or that lie on a non-manifold edge).
    pub non_manifold_vertices: Vec<u32>,
    /// Edges used by two triangles that traverse them in the same direction.
    pub inconsistent_edges: usize,
    /// Component index of every vertex (isolated vertices get their own component).
    pub component_of_vertex: Vec<u32>,
    pub components: Vec<ComponentInfo>,
    /// Triangles (ascending) whose three corners an earlier triangle has, in either orientation.
    pub repeated_triangles: Vec<u32>,
    edge_count: usize,
}

/// Per-vertex result of the parallel pass.
#[derive(Default, Clone, Copy)]
struct VertexScan {
    neighbor_count: u32,
    boundary_edges: u32,
    non_manifold_edge: bool,
    multiple_fans: bool,
    inconsistent_edges: u32,
    /// Among the triangles whose smallest corner this vertex is, two have the same corners (or
    /// there are too many to tell in the scan).
    repeats: bool,
}

impl Topology {
    /// The connectivity of `mesh` (see the module docs for how it is computed). A kernel: its
    /// passes share one scratch space, so they stay in one function.
    pub fn build(mesh: &TriMesh) -> Topology {
        let vertex_count = mesh.positions.len();
        let triangles = &mesh.triangles;

        // Vertex -> faces by counting sort; face ids come out ascending per vertex.
        let mut face_offsets = vec![0u32; vertex_count + 1];
        for t in triangles {
            for &v in t {
                face_offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..vertex_count {
            face_offsets[v + 1] += face_offsets[v];
        }
        let mut cursor = face_offsets.clone();
        let mut vertex_faces = vec![0u32; face_offsets[vertex_count] as usize];
        for (f, t) in triangles.iter().enumerate() {
            for &v in t {
                let slot = &mut cursor[v as usize];
                vertex_faces[*slot as usize] = f as u32;
                *slot += 1;
            }
        }
        drop(cursor);

        // Each vertex: its faces' other corners tagged with direction (bit 0: the face goes from
        // this vertex to the neighbour). At most two entries per face, so the scratch space is
        // laid out with offsets 2 * face_offsets.
        let mut scratch = vec![0u32; 2 * vertex_faces.len()];
        let mut slices: Vec<&mut [u32]> = Vec::with_capacity(vertex_count);
        {
            let mut rest: &mut [u32] = &mut scratch;
            for v in 0..vertex_count {
                let len = 2 * (face_offsets[v + 1] - face_offsets[v]) as usize;
                let (head, tail) = rest.split_at_mut(len);
                slices.push(head);
                rest = tail;
            }
        }
        let scans: Vec<VertexScan> = slices
            .into_par_iter()
            .enumerate()
            .map(|(v, slot)| {
                let faces = &vertex_faces[face_offsets[v] as usize..face_offsets[v + 1] as usize];
                scan_vertex(v as u32, faces, triangles, slot)
            })
            .collect();

        // Compact the neighbour lists (entries are sorted; neighbours are entries >> 1,
        // deduplicated in place by scan_vertex into the slot's prefix) within the scratch space
        // itself: a vertex has at most two neighbours per face, so every list moves down or stays,
        // and no second array of all the neighbours is held beside the scratch space (the peak of a
        // load).
        let mut neighbor_offsets = vec![0u32; vertex_count + 1];
        for v in 0..vertex_count {
            neighbor_offsets[v + 1] = neighbor_offsets[v] + scans[v].neighbor_count;
        }
        let mut neighbors = scratch;
        for v in 0..vertex_count {
            let start = 2 * face_offsets[v] as usize;
            let count = scans[v].neighbor_count as usize;
            neighbors.copy_within(start..start + count, neighbor_offsets[v] as usize);
        }
        neighbors.truncate(neighbor_offsets[vertex_count] as usize);
        neighbors.shrink_to_fit();

        let is_boundary: Vec<bool> = scans.iter().map(|s| s.boundary_edges > 0).collect();
        let mut non_manifold_edges = Vec::new();
        let mut non_manifold_vertices = Vec::new();
        let mut inconsistent = 0usize;
        for (v, s) in scans.iter().enumerate() {
            if s.non_manifold_edge || s.multiple_fans {
                non_manifold_vertices.push(v as u32);
            }
            inconsistent += s.inconsistent_edges as usize;
        }
        // Each non-manifold edge was seen from both ends; list it once, from its lower end.
        for &v in &non_manifold_vertices {
            if !scans[v as usize].non_manifold_edge {
                continue;
            }
            let nbrs = &neighbors
                [neighbor_offsets[v as usize] as usize..neighbor_offsets[v as usize + 1] as usize];
            for &u in nbrs {
                if u > v
                    && edge_face_count(
                        v,
                        u,
                        &vertex_faces[face_offsets[v as usize] as usize
                            ..face_offsets[v as usize + 1] as usize],
                        triangles,
                    ) > 2
                {
                    non_manifold_edges.push([v, u]);
                }
            }
        }

        let mut topology = Topology {
            edge_count: neighbors.len() / 2,
            neighbor_offsets,
            neighbors,
            face_offsets,
            vertex_faces,
            is_boundary,
            boundary_loops: Vec::new(),
            non_manifold_edges,
            non_manifold_vertices,
            inconsistent_edges: inconsistent / 2,
            component_of_vertex: Vec::new(),
            components: Vec::new(),
            repeated_triangles: Vec::new(),
        };
        // The vertices the scan flagged list their triangles again, exactly (rare: none on a
        // clean mesh).
        let mut lowest = Vec::new();
        for (v, s) in scans.iter().enumerate() {
            if s.repeats {
                lowest.clear();
                lowest.extend(topology.faces_of(v as u32).iter().filter(|&&f| {
                    let t = triangles[f as usize];
                    t[0].min(t[1]).min(t[2]) == v as u32
                }));
                super::repeats_among(triangles, &lowest, &mut topology.repeated_triangles);
            }
        }
        topology.repeated_triangles.sort_unstable();
        topology.boundary_loops = topology.trace_boundary_loops(triangles);
        topology.find_components(triangles);
        topology
    }

    pub fn vertex_count(&self) -> usize {
        self.is_boundary.len()
    }

    /// Number of distinct undirected edges.
    pub fn edge_count(&self) -> usize {
        self.edge_count
    }

    /// The distinct one-ring neighbours of `v`, ascending.
    #[inline]
    pub fn neighbors(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.neighbors[self.neighbor_offsets[v] as usize..self.neighbor_offsets[v + 1] as usize]
    }

    /// Number of distinct one-ring neighbours of `v`.
    #[inline]
    pub fn valence(&self, v: u32) -> usize {
        let v = v as usize;
        (self.neighbor_offsets[v + 1] - self.neighbor_offsets[v]) as usize
    }

    /// The triangles incident to `v`, ascending.
    #[inline]
    pub fn faces_of(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.vertex_faces[self.face_offsets[v] as usize..self.face_offsets[v + 1] as usize]
    }

    /// CSR arrays of the one-ring: `neighbors()[offsets[v]..offsets[v + 1]]`.
    pub fn neighbor_csr(&self) -> (&[u32], &[u32]) {
        (&self.neighbor_offsets, &self.neighbors)
    }

    /// CSR arrays of the vertex-to-face incidence.
    pub fn face_csr(&self) -> (&[u32], &[u32]) {
        (&self.face_offsets, &self.vertex_faces)
    }

    #[inline]
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.is_boundary[v as usize]
    }

    pub fn boundary_flags(&self) -> &[bool] {
        &self.is_boundary
    }

    /// No boundary edges anywhere.
    pub fn is_closed(&self) -> bool {
        self.boundary_loops.is_empty()
    }

    /// Every edge has one or two faces and every vertex a single fan of faces.
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges.is_empty() && self.non_manifold_vertices.is_empty()
    }

    /// Manifold and consistently oriented.
    pub fn is_oriented_manifold(&self) -> bool {
        self.is_manifold() && self.inconsistent_edges == 0
    }

    /// V - E + F over the whole mesh.
    pub fn euler_characteristic(&self) -> i64 {
        self.components.iter().map(|c| c.euler_characteristic).sum()
    }

    fn trace_boundary_loops(&self, triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
        // Boundary half-edges v -> u, grouped by v (v ascending).
        let mut half_edges: Vec<(u32, u32)> = Vec::new();
        for v in 0..self.vertex_count() as u32 {
            if !self.is_boundary[v as usize] {
                continue;
            }
            for &f in self.faces_of(v) {
                let u = next_in_face(triangles[f as usize], v);
                if edge_face_count(v, u, self.faces_of(v), triangles) == 1 {
                    half_edges.push((v, u));
                }
            }
        }
        half_edges.sort_unstable();
        let mut used = vec![false; half_edges.len()];
        let first_out = |v: u32, used: &[bool]| -> Option<usize> {
            let start = half_edges.partition_point(|&(a, _)| a < v);
            (start..half_edges.len())
                .take_while(|&i| half_edges[i].0 == v)
                .find(|&i| !used[i])
        };
        let mut loops = Vec::new();
        for start in 0..half_edges.len() {
            if used[start] {
                continue;
            }
            let origin = half_edges[start].0;
            let mut current = start;
            let mut boundary_loop = Vec::new();
            loop {
                used[current] = true;
                let (v, u) = half_edges[current];
                boundary_loop.push(v);
                if u == origin {
                    break;
                }
                match first_out(u, &used) {
                    Some(next) => current = next,
                    None => break, // open chain: only on inconsistently oriented input
                }
            }
            loops.push(boundary_loop);
        }
        loops
    }

    fn find_components(&mut self, triangles: &[[u32; 3]]) {
        let n = self.vertex_count();
        let mut parent: Vec<u32> = (0..n as u32).collect();
        fn root(parent: &mut [u32], mut v: u32) -> u32 {
            while parent[v as usize] != v {
                let grand = parent[parent[v as usize] as usize];
                parent[v as usize] = grand;
                v = grand;
            }
            v
        }
        for t in triangles {
            let a = root(&mut parent, t[0]);
            for &w in &t[1..] {
                let b = root(&mut parent, w);
                let a = root(&mut parent, a);
                if a != b {
                    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                    parent[hi as usize] = lo;
                }
            }
        }
        // Number components in order of their lowest vertex.
        let mut index_of_root = vec![u32::MAX; n];
        let mut component_of_vertex = vec![0u32; n];
        let mut components: Vec<ComponentInfo> = Vec::new();
        for v in 0..n as u32 {
            let r = root(&mut parent, v);
            if index_of_root[r as usize] == u32::MAX {
                index_of_root[r as usize] = components.len() as u32;
                components.push(ComponentInfo {
                    vertices: 0,
                    faces: 0,
                    edges: 0,
                    boundary_loops: 0,
                    euler_characteristic: 0,
                    genus: None,
                });
            }
            let c = index_of_root[r as usize];
            component_of_vertex[v as usize] = c;
            let info = &mut components[c as usize];
            info.vertices += 1;
            info.edges += self.neighbors(v).iter().filter(|&&u| u > v).count();
        }
        for t in triangles {
            components[component_of_vertex[t[0] as usize] as usize].faces += 1;
        }
        for l in &self.boundary_loops {
            components[component_of_vertex[l[0] as usize] as usize].boundary_loops += 1;
        }
        let mut manifold_component = vec![true; components.len()];
        for &v in &self.non_manifold_vertices {
            manifold_component[component_of_vertex[v as usize] as usize] = false;
        }
        for (c, info) in components.iter_mut().enumerate() {
            info.euler_characteristic =
                info.vertices as i64 - info.edges as i64 + info.faces as i64;
            let twice_genus = 2 - info.euler_characteristic - info.boundary_loops as i64;
            if manifold_component[c] && info.faces > 0 && twice_genus >= 0 && twice_genus % 2 == 0 {
                info.genus = Some(twice_genus / 2);
            }
        }
        self.component_of_vertex = component_of_vertex;
        self.components = components;
    }
}

/// The edges exactly two of `triangles` share, each as `[lower corner, higher corner, first
/// triangle, second triangle]` (triangles in ascending order), in ascending order of their
/// corners: one sort of every triangle's three edges.
pub fn two_face_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 4]> {
    let mut edges: Vec<(u32, u32, u32)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| {
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                (a.min(b), a.max(b), t as u32)
            })
        })
        .collect();
    edges.par_sort_unstable();
    edges
        .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
        .filter(|shared| shared.len() == 2)
        .map(|shared| [shared[0].0, shared[0].1, shared[0].2, shared[1].2])
        .collect()
}

#[inline]
fn next_in_face(t: [u32; 3], v: u32) -> u32 {
    if t[0] == v {
        t[1]
    } else if t[1] == v {
        t[2]
    } else {
        t[0]
    }
}

#[inline]
fn prev_in_face(t: [u32; 3], v: u32) -> u32 {
    if t[0] == v {
        t[2]
    } else if t[1] == v {
        t[0]
    } else {
        t[1]
    }
}

/// Number of `v`'s faces (given as `faces`) that contain `u`.
fn edge_face_count(v: u32, u: u32, faces: &[u32], triangles: &[[u32; 3]]) -> usize {
    let _ = v;
    faces
        .iter()
        .filter(|&&f| triangles[f as usize].contains(&u))
        .count()
}

/// Fills `slot` with v's neighbours (deduplicated, ascending, in its prefix) and classifies v's
/// edges and fans.
fn scan_vertex(v: u32, faces: &[u32], triangles: &[[u32; 3]], slot: &mut [u32]) -> VertexScan {
    let mut scan = VertexScan::default();
    let mut len = 0;
    // The other two corners (ascending) of the triangles whose smallest corner is v: two equal
    // pairs are two triangles with the same corners.
    let mut lowest = [[0u32; 2]; 16];
    let mut lowest_count = 0;
    for &f in faces {
        let t = triangles[f as usize];
        let (next, prev) = (next_in_face(t, v), prev_in_face(t, v));
        slot[len] = next << 1 | 1; // edge v -> next
        slot[len + 1] = prev << 1; // edge prev -> v
        len += 2;
        if v < next && v < prev {
            let pair = [next.min(prev), next.max(prev)];
            if lowest_count == lowest.len() {
                scan.repeats = true;
            } else {
                scan.repeats |= lowest[..lowest_count].contains(&pair);
                lowest[lowest_count] = pair;
                lowest_count += 1;
            }
        }
    }
    slot[..len].sort_unstable();

    let mut write = 0usize;
    let mut i = 0usize;
    while i < len {
        // Neighbours are written back into the prefix: `write` never passes the group being read.
        let u = slot[i] >> 1;
        let mut outgoing = 0u32;
        let mut incoming = 0u32;
        while i < len && slot[i] >> 1 == u {
            if slot[i] & 1 == 1 {
                outgoing += 1;
            } else {
                incoming += 1;
            }
            i += 1;
        }
        match outgoing + incoming {
            1 => scan.boundary_edges += 1,
            2 if outgoing != 1 => scan.inconsistent_edges += 1,
            2 => {}
            _ => scan.non_manifold_edge = true,
        }
        slot[write] = u;
        write += 1;
    }
    scan.neighbor_count = write as u32;

    if !faces.is_empty() && !scan.non_manifold_edge {
        scan.multiple_fans = if scan.inconsistent_edges == 0 && faces.len() <= 64 {
            !single_fan_by_walk(v, faces, triangles)
        } else {
            !single_fan_by_union(v, faces, triangles, &slot[..write])
        };
    }
    scan
}

/// With consistent orientation each face (v, a, b) is a link edge a -> b, and every link vertex has
/// at most one edge in and one out; the faces form one fan exactly when walking the link from a
/// fan's start (a link vertex no edge enters, or any face of a closed fan) visits every face.
fn single_fan_by_walk(v: u32, faces: &[u32], triangles: &[[u32; 3]]) -> bool {
    let mut links = [(0u32, 0u32); 64];
    let links = &mut links[..faces.len()];
    for (link, &f) in links.iter_mut().zip(faces) {
        let t = triangles[f as usize];
        *link = (next_in_face(t, v), prev_in_face(t, v));
    }
    let start = links
        .iter()
        .position(|&(a, _)| !links.iter().any(|&(_, b)| b == a))
        .unwrap_or(0);
    let mut visited = 1;
    let mut current = links[start].1;
    while let Some(next) = links.iter().position(|&(a, _)| a == current) {
        if next == start || visited == links.len() {
            break;
        }
        visited += 1;
        current = links[next].1;
    }
    visited == links.len()
}

/// The orientation-agnostic fan check: union the two other corners of each face over v's local
/// neighbour indices; a single fan is a single connected link.
fn single_fan_by_union(v: u32, faces: &[u32], triangles: &[[u32; 3]], neighbors: &[u32]) -> bool {
    let mut parent: Vec<u32> = (0..neighbors.len() as u32).collect();
    let local = |x: u32| neighbors.binary_search(&x).unwrap_or(0);
    let mut components = neighbors.len();
    for &f in faces {
        let t = triangles[f as usize];
        if union(
            &mut parent,
            local(next_in_face(t, v)),
            local(prev_in_face(t, v)),
        ) {
            components -= 1;
        }
    }
    components == 1
}

fn union(parent: &mut [u32], a: usize, b: usize) -> bool {
    let find = |parent: &mut [u32], mut x: usize| {
        while parent[x] as usize != x {
            x = parent[x] as usize;
        }
        x
    };
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra == rb {
        return false;
    }
    parent[ra.max(rb)] = ra.min(rb) as u32;
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn octahedron() -> TriMesh {
        crate::mesh::fixtures::octahedron(1.0)
    }

    #[test]
    fn two_face_edges_are_the_edges_exactly_two_triangles_share() {
        // Two squares side by side, each cut into [0, 1, 4], [0, 4, 3] and [1, 2, 5], [1, 5, 4]:
        // 9 edges, of which the two diagonals and the middle edge have two faces.
        let grid = crate::mesh::fixtures::grid(2);
        let one_row: Vec<[u32; 3]> = grid.triangles[..4].to_vec();
        let edges = two_face_edges(&one_row);
        assert_eq!(edges, vec![[0, 4, 0, 1], [1, 4, 0, 3], [1, 5, 2, 3]]);
        // Three triangles on one edge: that edge is no two-face edge.
        let fin = crate::mesh::fixtures::three_triangles_on_one_edge();
        assert!(two_face_edges(&fin.triangles).is_empty());
    }

    #[test]
    fn octahedron_is_a_closed_oriented_sphere() {
        let topo = Topology::build(&octahedron());
        assert!(topo.is_closed());
        assert!(topo.is_oriented_manifold());
        assert_eq!(topo.edge_count(), 12);
        assert_eq!(topo.euler_characteristic(), 2);
        assert_eq!(topo.components.len(), 1);
        assert_eq!(topo.components[0].genus, Some(0));
        assert_eq!(topo.neighbors(4), &[0, 1, 2, 3]);
        assert_eq!(topo.valence(0), 4);
        assert_eq!(topo.faces_of(4), &[0, 1, 2, 3]);
    }

    #[test]
    fn open_fan_has_one_ordered_boundary_loop() {
        // Drop the bottom four faces of the octahedron: a square pyramid without base.
        let mut mesh = octahedron();
        mesh.triangles.truncate(4);
        mesh.positions.truncate(5);
        let topo = Topology::build(&mesh);
        assert_eq!(topo.boundary_loops.len(), 1);
        let l = &topo.boundary_loops[0];
        assert_eq!(l.len(), 4);
        // Face (0,2,4) goes 0 -> 2, so the boundary loop goes 0 -> 2 -> 1 -> 3.
        let start = l.iter().position(|&v| v == 0).unwrap();
        let rotated: Vec<u32> = (0..4).map(|i| l[(start + i) % 4]).collect();
        assert_eq!(rotated, vec![0, 2, 1, 3]);
        assert!(topo.is_boundary_vertex(0) && !topo.is_boundary_vertex(4));
        assert_eq!(topo.components[0].genus, Some(0));
        assert_eq!(topo.components[0].boundary_loops, 1);
    }

    #[test]
    fn finds_non_manifold_edge_and_vertex() {
        // Three triangles on one edge (0,1).
        let mesh = crate::mesh::fixtures::three_triangles_on_one_edge();
        let topo = Topology::build(&mesh);
        assert_eq!(topo.non_manifold_edges, vec![[0, 1]]);
        assert!(!topo.is_manifold());

        // Two fans touching at one vertex (a bow tie).
        let bow_tie = TriMesh::new(
            vec![
                [0., 0., 0.],
                [1., 1., 0.],
                [1., -1., 0.],
                [-1., 1., 0.],
                [-1., -1., 0.],
            ],
            vec![[0, 2, 1], [0, 3, 4]],
        );
        let topo = Topology::build(&bow_tie);
        assert!(topo.non_manifold_edges.is_empty());
        assert_eq!(topo.non_manifold_vertices, vec![0]);
    }

    #[test]
    fn counts_components_and_flipped_faces() {
        let mut mesh = octahedron();
        let shifted: Vec<[f32; 3]> = mesh
            .positions
            .iter()
            .map(|p| [p[0] + 5.0, p[1], p[2]])
            .collect();
        let tris: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| t.map(|v| v + 6)).collect();
        mesh.positions.extend(shifted);
        mesh.triangles.extend(tris);
        mesh.triangles[0] = [0, 4, 2]; // flip one face of the first octahedron
        let topo = Topology::build(&mesh);
        assert_eq!(topo.components.len(), 2);
        assert_eq!(topo.inconsistent_edges, 3);
        assert_eq!(topo.euler_characteristic(), 4);
    }
}
