//! Welding and clean-up after loading.
//!
//! Files split vertices at normal and UV seams; unwelded, a scan falls apart into separate pieces
//! and no smoother works. [`weld`] merges vertices whose positions are bit-identical (with -0.0
//! treated as 0.0), keeping each vertex's first occurrence, so the welded order is the input order
//! with repeats removed. [`clean`] drops triangles that repeat a vertex, triangles that repeat an
//! earlier triangle (the same three corners, in either orientation: a scan's reconstruction can
//! leave such pockets, and fairing pulled them to a point), and vertices that no triangle uses,
//! again keeping the remaining vertices and triangles in input order.

use super::TriMesh;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A multiply-rotate hasher for position keys: SipHash's DoS resistance buys nothing here and
/// costs a third of the weld time on large meshes.
#[derive(Default)]
pub(crate) struct PositionHasher(u64);

impl Hasher for PositionHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    fn write_u32(&mut self, value: u32) {
        self.write_u64(value as u64);
    }
    fn write_u64(&mut self, value: u64) {
        self.0 = (self.0.rotate_left(5) ^ value).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, value: usize) {
        self.write_u64(value as u64);
    }
}

/// What [`weld`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WeldReport {
    /// Vertices merged into an earlier vertex with the same position.
    pub merged_vertices: usize,
}

/// What [`clean`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CleanReport {
    /// Triangles that used one vertex twice or three times.
    pub removed_degenerate_faces: usize,
    /// Triangles with the same three corners as an earlier one (either orientation).
    pub removed_repeated_faces: usize,
    /// Vertices that no triangle referenced.
    pub removed_unreferenced_vertices: usize,
}

fn position_key(p: &[f32; 3]) -> [u32; 3] {
    // +0.0 and -0.0 are the same point; NaN never reaches here (loaders reject it).
    p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

/// Merge vertices with bit-identical positions. Returns the report; `mesh` is rewritten in place.
/// Triangle indices must be in range (loaders check that first).
pub fn weld(mesh: &mut TriMesh) -> WeldReport {
    weld_with_map(mesh).0
}

/// [`weld`], also giving the map from each input vertex to the vertex it became.
pub(crate) fn weld_with_map(mesh: &mut TriMesh) -> (WeldReport, Vec<u32>) {
    let n = mesh.positions.len();
    let mut first_index: HashMap<[u32; 3], u32, BuildHasherDefault<PositionHasher>> =
        HashMap::with_capacity_and_hasher(n, Default::default());
    let mut remap = Vec::with_capacity(n);
    let mut kept = Vec::with_capacity(n);
    for p in &mesh.positions {
        let next = kept.len() as u32;
        let index = *first_index.entry(position_key(p)).or_insert(next);
        if index == next {
            kept.push(*p);
        }
        remap.push(index);
    }
    let merged = n - kept.len();
    if merged > 0 {
        for t in &mut mesh.triangles {
            *t = t.map(|v| remap[v as usize]);
        }
        mesh.positions = kept;
    }
    (
        WeldReport {
            merged_vertices: merged,
        },
        remap,
    )
}

/// Remove triangles that repeat a vertex or an earlier triangle, and vertices that no triangle
/// uses.
pub fn clean(mesh: &mut TriMesh) -> CleanReport {
    clean_with_map(mesh).0
}

/// [`clean`], also giving the map from each input vertex to the vertex it became (`u32::MAX` for
/// a removed vertex); `None` when no vertex was removed.
pub(crate) fn clean_with_map(mesh: &mut TriMesh) -> (CleanReport, Option<Vec<u32>>) {
    let before_faces = mesh.triangles.len();
    mesh.triangles
        .retain(|&[a, b, c]| a != b && b != c && a != c);
    let removed_degenerate_faces = before_faces - mesh.triangles.len();
    let mut seen: std::collections::HashSet<[u32; 3], BuildHasherDefault<PositionHasher>> =
        std::collections::HashSet::with_capacity_and_hasher(
            mesh.triangles.len(),
            Default::default(),
        );
    let distinct = mesh.triangles.len();
    mesh.triangles.retain(|t| {
        let mut corners = *t;
        corners.sort_unstable();
        seen.insert(corners)
    });
    let removed_repeated_faces = distinct - mesh.triangles.len();

    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let unused = used.iter().filter(|u| !**u).count();
    let mut map = None;
    if unused > 0 {
        let mut remap = vec![u32::MAX; mesh.positions.len()];
        let mut next = 0u32;
        let mut kept = Vec::with_capacity(mesh.positions.len() - unused);
        for (v, p) in mesh.positions.iter().enumerate() {
            if used[v] {
                remap[v] = next;
                next += 1;
                kept.push(*p);
            }
        }
        for t in &mut mesh.triangles {
            *t = t.map(|v| remap[v as usize]);
        }
        mesh.positions = kept;
        map = Some(remap);
    }
    (
        CleanReport {
            removed_degenerate_faces,
            removed_repeated_faces,
            removed_unreferenced_vertices: unused,
        },
        map,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weld_merges_seam_copies_in_first_occurrence_order() {
        // Two triangles sharing an edge, stored with the shared corners duplicated.
        let mut mesh = TriMesh::new(
            vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [0., 1., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [-0.0, 1., 0.],
            ],
            vec![[0, 1, 2], [3, 4, 5]],
        );
        let report = weld(&mut mesh);
        assert_eq!(report.merged_vertices, 2);
        assert_eq!(
            mesh.positions,
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]
        );
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
    }

    #[test]
    fn clean_drops_degenerate_faces_and_unused_vertices() {
        let mut mesh = TriMesh::new(
            vec![[0., 0., 0.], [9., 9., 9.], [1., 0., 0.], [0., 1., 0.]],
            vec![[0, 2, 3], [0, 0, 2], [2, 3, 3]],
        );
        let report = clean(&mut mesh);
        assert_eq!(report.removed_degenerate_faces, 2);
        assert_eq!(report.removed_unreferenced_vertices, 1);
        assert_eq!(
            mesh.positions,
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]]
        );
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn clean_drops_triangles_that_repeat_an_earlier_one_in_either_orientation() {
        // A tetrahedron whose face 1-2-3 comes three times: once more rotated, once reversed.
        let mut mesh = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            vec![
                [0, 2, 1],
                [1, 2, 3],
                [2, 3, 1],
                [0, 1, 3],
                [3, 2, 1],
                [0, 3, 2],
            ],
        );
        let report = clean(&mut mesh);
        assert_eq!(report.removed_repeated_faces, 2);
        assert_eq!(report.removed_degenerate_faces, 0);
        assert_eq!(
            mesh.triangles,
            vec![[0, 2, 1], [1, 2, 3], [0, 1, 3], [0, 3, 2]],
            "the first of each kept, in input order"
        );
    }
}
