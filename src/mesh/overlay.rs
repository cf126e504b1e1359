//! Loose triangles at non-manifold edges: the triangles a reconstruction left lying over a fan
//! (or hanging from an edge as a one-triangle fin), found so that smoothing can leave them out.
//!
//! A scan's surface reconstruction (the Stanford dragon's vrip, for one) leaves triangles such as
//! (14, 6, 7) over the fan 6-7-17-16-14 it duplicates: its edges 6-7 and 6-14 then have three
//! triangles each, 7-14 only this one. Every such edge marks its ends as boundary or non-manifold,
//! and a smoother that treats them so (a boundary curve through a vertex whose "loop" is one edge
//! long) holds them where the noise put them: on the noisy dragon, the 8 % of vertices next to
//! such triangles kept twice the error of the rest after any smoother of ours.
//!
//! The triangles are taken in patches: those joined across edges that have exactly two triangles
//! (manifold edges). A patch is *loose* when it is small (at most 16 triangles: an overlay is a
//! triangle or a short strip, a fin a triangle or two), meets the rest only at edges with more
//! than two triangles (at least one) or at its own boundary, and leaves each of those edges at
//! least two triangles. Removing it then takes nothing from the rest of the surface: its edges
//! with others stay manifold or better, its boundary edges go with it. Patches are taken
//! smallest first (then by their lowest triangle) and the counts updated as each goes, so where
//! two loose patches lie on the same edge the first goes and the second, now with a manifold
//! neighbour there, joins the surface; and where two overlays lie on a piece of surface of 16
//! triangles or fewer, the overlays go, not the piece.
//!
//! A corner that only loose triangles use (a fin's tip) has nothing left to smooth it and stays
//! where it is. Moving it with its base (by the mean of the base's moves) would take it farther
//! from the clean surface (the base's move takes out the base's noise, not the tip's;
//! `docs/measurements.md`).

use super::{Topology, TriMesh};
use std::collections::HashMap;

/// Faces in a loose patch, at most: a reconstruction's overlays are a triangle or a short strip;
/// a larger sheet meeting the surface at a non-manifold edge is surface of its own.
const MAX_PATCH: usize = 16;

/// The loose triangles of `triangles` (ascending indices; see the module docs); `topology` must
/// be built from them. Empty, at no cost, when the mesh has no non-manifold edge.
pub fn loose_triangles(triangles: &[[u32; 3]], topology: &Topology) -> Vec<u32> {
    if topology.non_manifold_edges.is_empty() {
        return Vec::new();
    }
    // Every loose patch has a non-manifold edge: the candidates are those edges' triangles.
    let mut candidates: Vec<u32> = Vec::new();
    for &[a, b] in &topology.non_manifold_edges {
        candidates.extend(
            topology
                .faces_of(a)
                .iter()
                .copied()
                .filter(|&f| triangles[f as usize].contains(&b)),
        );
    }
    candidates.sort_unstable();
    candidates.dedup();

    let mut counts = Counts {
        triangles,
        topology,
        edge: HashMap::new(),
        removed: vec![false; triangles.len()],
    };
    // Smallest patches first: where overlays lie on a small piece of surface (16 triangles or
    // fewer), that piece reads as a patch too, and the overlays must go before it is looked at
    // (their going leaves its edges manifold). Ties by the lowest triangle.
    let mut patch: Vec<u32> = Vec::new();
    let mut order: Vec<(usize, u32)> = Vec::new();
    for &f in &candidates {
        if counts.loose_patch(f, &mut patch) {
            order.push((patch.len(), f));
        }
    }
    order.sort_unstable();
    let mut loose = Vec::new();
    for (_, f) in order {
        if !counts.removed[f as usize] && counts.loose_patch(f, &mut patch) {
            counts.remove(&patch);
            loose.extend_from_slice(&patch);
        }
    }
    loose.sort_unstable();
    loose
}

/// [`loose_triangles`] until none is left (removing a patch can leave another loose): the loose
/// triangles' indices in `mesh` (ascending), `mesh` without them and its topology; `None` when
/// it has none. Same vertices: nothing is renumbered.
pub fn without_loose_triangles(
    mesh: &TriMesh,
    topology: &Topology,
) -> Option<(Vec<u32>, TriMesh, Topology)> {
    let first = loose_triangles(&mesh.triangles, topology);
    if first.is_empty() {
        return None;
    }
    // Which of `mesh`'s triangles each of `kept`'s is.
    let mut index: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
    let mut all = Vec::new();
    let mut kept = mesh.clone();
    let mut loose = first;
    loop {
        all.extend(loose.iter().map(|&f| index[f as usize]));
        super::remove_triangles(&mut kept, &loose);
        let mut next = loose.iter().copied().peekable();
        let mut at = 0u32;
        index.retain(|_| {
            let gone = next.next_if_eq(&at).is_some();
            at += 1;
            !gone
        });
        let kept_topology = Topology::build(&kept);
        loose = loose_triangles(&kept.triangles, &kept_topology);
        if loose.is_empty() {
            all.sort_unstable();
            return Some((all, kept, kept_topology));
        }
    }
}

fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

fn edges(t: [u32; 3]) -> [(u32, u32); 3] {
    [key(t[0], t[1]), key(t[1], t[2]), key(t[2], t[0])]
}

/// Triangles per edge, as the loose patches found so far leave them (counted on
/// first use, then kept up to date).
struct Counts<'a> {
    triangles: &'a [[u32; 3]],
    topology: &'a Topology,
    edge: HashMap<(u32, u32), u32>,
    /// Per triangle: removed so far.
    removed: Vec<bool>,
}

impl Counts<'_> {
    fn edge(&mut self, e: (u32, u32)) -> u32 {
        let (topology, triangles, removed) = (self.topology, self.triangles, &self.removed);
        *self.edge.entry(e).or_insert_with(|| {
            topology
                .faces_of(e.0)
                .iter()
                .filter(|&&g| triangles[g as usize].contains(&e.1) && !removed[g as usize])
                .count() as u32
        })
    }

    /// Gathers into `patch` the triangles joined to `f` across edges with exactly two triangles
    /// and says whether they make a loose patch: at most [`MAX_PATCH`] triangles, at least one
    /// edge with more than two, every such edge left with two or more without the patch.
    fn loose_patch(&mut self, f: u32, patch: &mut Vec<u32>) -> bool {
        patch.clear();
        patch.push(f);
        let mut next = 0;
        let mut rim: Vec<(u32, u32)> = Vec::new();
        while next < patch.len() {
            let g = patch[next];
            next += 1;
            for e in edges(self.triangles[g as usize]) {
                match self.edge(e) {
                    2 => {
                        // The other triangle on e (not removed, so counted in the two; none
                        // only where a triangle repeats a corner, which is no patch to take).
                        let Some(other) = self.topology.faces_of(e.0).iter().copied().find(|&h| {
                            h != g
                                && self.triangles[h as usize].contains(&e.1)
                                && !self.removed[h as usize]
                        }) else {
                            return false;
                        };
                        if !patch.contains(&other) {
                            if patch.len() == MAX_PATCH {
                                return false;
                            }
                            patch.push(other);
                        }
                    }
                    1 => {}
                    _ => rim.push(e),
                }
            }
        }
        if rim.is_empty() {
            return false;
        }
        // Each non-manifold rim edge keeps two triangles or more.
        rim.sort_unstable();
        let mut i = 0;
        while i < rim.len() {
            let run = rim[i..].iter().take_while(|&&e| e == rim[i]).count();
            if self.edge(rim[i]) < run as u32 + 2 {
                return false;
            }
            i += run;
        }
        true
    }

    fn remove(&mut self, patch: &[u32]) {
        for &g in patch {
            let t = self.triangles[g as usize];
            // (Every edge of the patch was counted while it was gathered.)
            for e in edges(t) {
                if let Some(count) = self.edge.get_mut(&e) {
                    *count = count.saturating_sub(1);
                }
            }
            self.removed[g as usize] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::bipyramid_with;
    use super::*;

    fn loose(extra: &[[u32; 3]]) -> Vec<u32> {
        let mesh = bipyramid_with(extra);
        loose_triangles(&mesh.triangles, &Topology::build(&mesh))
    }

    #[test]
    fn a_triangle_lying_over_a_fan_is_loose_and_its_removal_leaves_a_closed_manifold() {
        // (0, 1, 3) lies over apex 0's triangles (0, 1, 2) and (0, 2, 3): edges 0-1 and 0-3
        // get a third triangle, 1-3 is its own.
        let mesh = bipyramid_with(&[[0, 1, 3]]);
        let topology = Topology::build(&mesh);
        assert_eq!(topology.non_manifold_edges.len(), 2);
        assert_eq!(loose_triangles(&mesh.triangles, &topology), vec![12]);
        let mut without = mesh.clone();
        without.triangles.remove(12);
        let topology = Topology::build(&without);
        assert!(topology.is_manifold() && topology.is_closed());
        // A manifold has none, and costs nothing.
        assert!(loose(&[]).is_empty());
    }

    #[test]
    fn a_strip_joined_across_its_own_edge_goes_as_one_patch() {
        // (0, 1, 3) and (1, 4, 3) share the edge 1-3 and nothing else does: each has the other
        // as a manifold neighbour, and together they meet the rest only at edges with three
        // triangles (0-1, 0-3, 3-4) and at their own edge 1-4.
        assert_eq!(loose(&[[0, 1, 3], [1, 4, 3]]), vec![12, 13]);
    }

    #[test]
    fn without_loose_triangles_names_them_in_the_mesh_and_leaves_none() {
        // An overlay on each apex's fan and a fin: all go, the rest is the bipyramid again.
        let extra = [[0, 1, 3], [8, 5, 3], [2, 1, 7]];
        let mut mesh = bipyramid_with(&extra);
        mesh.positions.extend([[2.0, 2.0, 2.0], [2.0, 3.0, 2.0]]);
        mesh.triangles.push([7, 9, 10]);
        let topology = Topology::build(&mesh);
        let (loose, kept, kept_topology) = without_loose_triangles(&mesh, &topology).unwrap();
        assert_eq!(loose, vec![12, 13, 14]);
        let expected: Vec<[u32; 3]> = mesh
            .triangles
            .iter()
            .enumerate()
            .filter(|(f, _)| !loose.contains(&(*f as u32)))
            .map(|(_, t)| *t)
            .collect();
        assert_eq!(kept.triangles, expected);
        assert_eq!(kept.positions, mesh.positions);
        assert!(loose_triangles(&kept.triangles, &kept_topology).is_empty());
        assert!(without_loose_triangles(&kept, &kept_topology).is_none());
    }

    #[test]
    fn triangles_that_repeat_a_corner_or_another_triangle_are_taken_without_a_panic() {
        // The loader drops both kinds; a library caller may not have.
        let degenerate = loose(&[[0, 1, 3], [0, 1, 1]]);
        assert!(degenerate.contains(&12), "{degenerate:?}");
        // Two copies of one overlay: each has the other as its manifold neighbour across all
        // three edges, and together they are one loose patch. (The bipyramid, 12 triangles
        // meeting them at edges with four, reads as a patch too: the smaller goes first.)
        assert_eq!(loose(&[[0, 1, 3], [0, 1, 3]]), vec![12, 13]);
    }

    #[test]
    fn a_fin_hanging_from_an_edge_is_loose() {
        let mesh = bipyramid_with(&[[0, 1, 7]]);
        let topology = Topology::build(&mesh);
        assert_eq!(topology.non_manifold_edges, vec![[0, 1]]);
        assert_eq!(loose_triangles(&mesh.triangles, &topology), vec![12]);
    }

    #[test]
    fn a_sheet_of_more_than_a_patch_meeting_the_surface_stays() {
        // A T-junction: a sheet (a fan of MAX_PATCH + 1 triangles around a new vertex c, whose
        // rim starts 0, 1) meets the bipyramid along the edge 0-1.
        let mut mesh = bipyramid_with(&[]);
        let c = mesh.positions.len() as u32;
        mesh.positions.push([0.5, 0.0, 2.0]);
        let mut rim = vec![0, 1];
        for k in 0..MAX_PATCH as u32 {
            rim.push(c + 1 + k);
            mesh.positions.push([k as f32, 2.0, 2.0]);
        }
        for pair in rim.windows(2) {
            mesh.triangles.push([c, pair[0], pair[1]]);
        }
        let topology = Topology::build(&mesh);
        assert_eq!(topology.non_manifold_edges, vec![[0, 1]]);
        assert!(loose_triangles(&mesh.triangles, &topology).is_empty());
        // One triangle fewer and it is a flap that comes off.
        mesh.triangles.pop();
        let topology = Topology::build(&mesh);
        assert_eq!(loose_triangles(&mesh.triangles, &topology).len(), MAX_PATCH);
        // Two triangles over the same edge (0-1 with four): the first goes, and the second,
        // with its edge 0-1 then at three, goes too, leaving the surface's two.
        assert_eq!(loose(&[[0, 1, 3], [1, 0, 4]]), vec![12, 13]);
    }
}
