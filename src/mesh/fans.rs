//! Fan-ordered one-rings ([`FanRings`]): every vertex's neighbours in the order its faces turn
//! around it, where they form one closed, consistently oriented fan. The constrained-fairing
//! operator, the noise estimate, the crease detection, the tangential relaxation and multires'
//! vertex normals read them; a closed fan gives a vertex's normal and its faces' normals from
//! consecutive ring entries, without reading a face. Also the cutting of a CSR array into blocks
//! of vertices for parallel passes that write every vertex's slice
//! ([`split_into_vertex_blocks`]).

use super::Topology;
use rayon::prelude::*;

/// Every vertex's one-ring, in fan order where possible, sharing the topology's one-ring CSR
/// offsets (a closed fan has as many entries as the vertex has neighbours).
pub(crate) struct FanRings {
    /// For a vertex with a closed, consistently oriented fan, its neighbours in fan order (faces
    /// (v, ring[k], ring[k+1])); otherwise the topology's sorted neighbours.
    pub ring: Vec<u32>,
    pub closed_fan: Vec<bool>,
}

impl FanRings {
    pub fn new(triangles: &[[u32; 3]], topology: &Topology) -> Self {
        let (offsets, neighbors) = topology.neighbor_csr();
        let is_boundary = topology.boundary_flags();
        let mut ring = vec![0u32; neighbors.len()];
        let mut closed = vec![false; offsets.len().saturating_sub(1)];
        split_into_vertex_blocks(&mut ring, offsets)
            .into_par_iter()
            .zip(closed.par_chunks_mut(VERTEX_BLOCK))
            .for_each(|((first, block), closed_block)| {
                let base = offsets[first] as usize;
                for (i, closed_v) in closed_block.iter_mut().enumerate() {
                    let v = first + i;
                    let ring_v =
                        &mut block[offsets[v] as usize - base..offsets[v + 1] as usize - base];
                    let v = v as u32;
                    *closed_v =
                        !is_boundary[v as usize] && closed_fan(v, topology, triangles, ring_v);
                    if !*closed_v {
                        ring_v.copy_from_slice(topology.neighbors(v));
                    }
                }
            });
        FanRings {
            ring,
            closed_fan: closed,
        }
    }
}

/// Writes v's neighbours in fan order (faces (v, fan[k], fan[k+1])) into `fan` when v has a closed,
/// consistently oriented fan with as many faces as neighbours; returns whether it does.
fn closed_fan(v: u32, topology: &Topology, triangles: &[[u32; 3]], fan: &mut [u32]) -> bool {
    let faces = topology.faces_of(v);
    if faces.len() < 3 || faces.len() != topology.valence(v) || faces.len() > 64 {
        return false;
    }
    // Each face as the directed edge opposite v: (next after v, next after that).
    let mut edge_buffer = [(0u32, 0u32); 64];
    let edges = &mut edge_buffer[..faces.len()];
    for (edge, &f) in edges.iter_mut().zip(faces) {
        let t = triangles[f as usize];
        let Some(r) = t.iter().position(|&c| c == v) else {
            return false;
        };
        *edge = (t[(r + 1) % 3], t[(r + 2) % 3]);
    }
    let mut used = [false; 64];
    let (first, mut current) = edges[0];
    used[0] = true;
    fan[0] = first;
    let mut len = 1;
    while current != first {
        if len == fan.len() {
            return false;
        }
        fan[len] = current;
        len += 1;
        let Some(next) = (0..edges.len()).find(|&e| !used[e] && edges[e].0 == current) else {
            return false;
        };
        used[next] = true;
        current = edges[next].1;
    }
    len == faces.len() && used[..edges.len()].iter().all(|&u| u)
}

/// Vertices per block of [`split_into_vertex_blocks`] (and of the constrained-fairing operator's
/// gather, whose blocks must be these).
pub(crate) const VERTEX_BLOCK: usize = 4096;

/// `data`, a CSR array with `offsets`, cut at every [`VERTEX_BLOCK`]-th vertex: (the block's first
/// vertex, its entries `offsets[first]..offsets[first + VERTEX_BLOCK]`), for parallel passes that
/// write every vertex's slice without a slice per vertex made on one thread before the pass.
pub(crate) fn split_into_vertex_blocks<'a, T>(
    data: &'a mut [T],
    offsets: &[u32],
) -> Vec<(usize, &'a mut [T])> {
    let vertices = offsets.len().saturating_sub(1);
    let mut blocks = Vec::with_capacity(vertices.div_ceil(VERTEX_BLOCK));
    let mut rest = data;
    for first in (0..vertices).step_by(VERTEX_BLOCK) {
        let last = (first + VERTEX_BLOCK).min(vertices);
        let (head, tail) =
            std::mem::take(&mut rest).split_at_mut((offsets[last] - offsets[first]) as usize);
        blocks.push((first, head));
        rest = tail;
    }
    blocks
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::irregular_sphere;

    #[test]
    fn fan_order_follows_the_faces() {
        let mesh = irregular_sphere();
        let topology = Topology::build(&mesh);
        for v in 0..mesh.positions.len() as u32 {
            let mut fan = vec![0u32; topology.valence(v)];
            assert!(
                closed_fan(v, &topology, &mesh.triangles, &mut fan),
                "closed manifold"
            );
            for k in 0..fan.len() {
                let (a, b) = (fan[k], fan[(k + 1) % fan.len()]);
                assert!(mesh.triangles.iter().any(
                    |t| (0..3).any(|r| t[r] == v && t[(r + 1) % 3] == a && t[(r + 2) % 3] == b)
                ));
            }
        }
    }
}
