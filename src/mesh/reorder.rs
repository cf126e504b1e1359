//! Locality reordering: a vertex numbering in which every vertex's one-ring sits close to it in
//! memory, for the gather kernels (fairing) that read each neighbour's data once per pass.
//!
//! The order is breadth-first over the one-rings (Cuthill-McKee without the degree sort), one
//! component after the other, each started from its lowest-numbered vertex. Consecutive BFS
//! fronts are rings around the seed, so a vertex's neighbours lie in its own front or the two next
//! to it: on a mesh of V vertices the distance in memory between neighbours is a few fronts of
//! about √V vertices, a window that stays in the core's L2 cache even at millions of vertices,
//! where the input order of a scan or a subdivided mesh can put neighbours megabytes apart.
//! (On a 1.2M-face mesh this more than halves the time of a fairing iteration; the repository's
//! `docs/measurements.md` has the numbers.)

/// A breadth-first locality order of the graph given by the one-ring CSR arrays
/// (`offsets.len()` = vertex count + 1): `order[i]` is the vertex placed at position `i`. Every
/// vertex appears exactly once; isolated vertices keep their relative order.
pub fn breadth_first_order(offsets: &[u32], neighbors: &[u32]) -> Vec<u32> {
    let vertex_count = offsets.len().saturating_sub(1);
    let mut placed = vec![false; vertex_count];
    let mut order = Vec::with_capacity(vertex_count);
    for seed in 0..vertex_count {
        if placed[seed] {
            continue;
        }
        placed[seed] = true;
        order.push(seed as u32);
        let mut head = order.len() - 1;
        while head < order.len() {
            let v = order[head] as usize;
            head += 1;
            for &u in &neighbors[offsets[v] as usize..offsets[v + 1] as usize] {
                if !std::mem::replace(&mut placed[u as usize], true) {
                    order.push(u);
                }
            }
        }
    }
    order
}

/// The Morton code of point `p` in the cube of side `extent` from corner `lo` (the bounding box's
/// low corner and its longest side), quantized to 10 bits per axis: the bits of the three
/// coordinates interleaved, x lowest. Sorting by it puts points that are close in space mostly
/// close in the order (the hierarchy's first level, the guided normal filter's faces).
pub(crate) fn morton_code(p: glam::DVec3, lo: glam::DVec3, extent: f64) -> u64 {
    // Spreads 10 bits to every third bit.
    let spread = |x: u64| {
        let mut x = x & 0x3ff;
        x = (x | x << 16) & 0x030000ff;
        x = (x | x << 8) & 0x0300f00f;
        x = (x | x << 4) & 0x030c30c3;
        (x | x << 2) & 0x09249249
    };
    let q = |c: usize| ((p[c] - lo[c]) / extent * 1023.0).clamp(0.0, 1023.0) as u64;
    spread(q(0)) | spread(q(1)) << 1 | spread(q(2)) << 2
}

/// The inverse permutation of `order`: `position[order[i]] = i`.
pub fn inverse_permutation(order: &[u32]) -> Vec<u32> {
    let mut position = vec![0u32; order.len()];
    for (i, &v) in order.iter().enumerate() {
        position[v as usize] = i as u32;
    }
    position
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{fixtures, Topology, TriMesh};

    #[test]
    fn order_is_a_permutation_and_neighbours_are_close() {
        // A long strip of quads numbered row by row: vertex (i, j) of a 2 x n grid is numbered
        // j * n + i, so a vertex and its neighbour in the other row are n apart.
        let n = 200u32;
        let positions = (0..2 * n)
            .map(|k| [(k % n) as f32, (k / n) as f32, 0.0])
            .collect();
        let mut triangles = Vec::new();
        for i in 0..n - 1 {
            let (a, b, c, d) = (i, i + 1, n + i, n + i + 1);
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
        let mesh = TriMesh::new(positions, triangles);
        let topology = Topology::build(&mesh);
        let (offsets, neighbors) = topology.neighbor_csr();
        let order = breadth_first_order(offsets, neighbors);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..2 * n).collect::<Vec<_>>());
        let position = inverse_permutation(&order);
        let widest = (0..2 * n)
            .flat_map(|v| topology.neighbors(v).iter().map(move |&u| (v, u)))
            .map(|(v, u)| position[v as usize].abs_diff(position[u as usize]))
            .max()
            .unwrap();
        assert!(widest <= 4, "neighbours {widest} apart after reordering");
    }

    #[test]
    fn isolated_vertices_and_components_are_all_placed() {
        let mut mesh = fixtures::octahedron(1.0);
        // A second octahedron and an unreferenced vertex.
        let offset = mesh.positions.len() as u32;
        let second = fixtures::octahedron(2.0);
        mesh.positions.push([9.0, 9.0, 9.0]);
        mesh.positions.extend(second.positions.iter().copied());
        mesh.triangles
            .extend(second.triangles.iter().map(|t| t.map(|v| v + offset + 1)));
        let topology = Topology::build(&mesh);
        let (offsets, neighbors) = topology.neighbor_csr();
        let order = breadth_first_order(offsets, neighbors);
        let position = inverse_permutation(&order);
        assert_eq!(order.len(), mesh.positions.len());
        assert_eq!(order[position[offset as usize] as usize], offset);
        // The first component comes first, then the isolated vertex, then the second component.
        assert!(order[..6].iter().all(|&v| v < 6));
        assert_eq!(order[6], 6);
    }
}
