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
use rayon::prelude::*;
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

/// [`weld`], also giving the map from each input vertex to the vertex it became (`None` when no
/// vertex merged).
///
/// In parallel without changing the result: the positions are dealt into as many shards as there
/// are threads by their hash, each shard finds (with its own hash map) every vertex whose
/// position an earlier vertex of the shard has, and one pass in input order then numbers the
/// first occurrences. A position's first occurrence is the same whichever shard finds it, so the
/// map is the same for any thread count.
pub(crate) fn weld_with_map(mesh: &mut TriMesh) -> (WeldReport, Option<Vec<u32>>) {
    let positions = &mesh.positions;
    let n = positions.len();
    let shards = rayon::current_num_threads().clamp(1, 64) as u64;
    let shard_of = |hash: u64| ((((hash >> 24) & 0xffff_ffff) * shards) >> 32) as usize;
    // Each shard lists (later vertex, its first occurrence) pairs.
    let repeats: Vec<Vec<[u32; 2]>> = (0..shards as usize)
        .into_par_iter()
        .map(|shard| {
            let mut first: HashMap<KeyedPosition, u32, BuildHasherDefault<PositionHasher>> =
                // A shard's even share, and room for the deal to be uneven.
                HashMap::with_capacity_and_hasher(
                    n / shards as usize + n / 16 + 1,
                    Default::default(),
                );
            let mut repeats = Vec::new();
            for (v, p) in positions.iter().enumerate() {
                let key = KeyedPosition::new(p);
                if shard_of(key.hash) != shard {
                    continue;
                }
                match first.entry(key) {
                    std::collections::hash_map::Entry::Occupied(earlier) => {
                        repeats.push([v as u32, *earlier.get()])
                    }
                    std::collections::hash_map::Entry::Vacant(slot) => {
                        slot.insert(v as u32);
                    }
                }
            }
            repeats
        })
        .collect();
    let merged: usize = repeats.iter().map(Vec::len).sum();
    if merged == 0 {
        return (WeldReport { merged_vertices: 0 }, None);
    }
    // remap[v]: u32::MAX for a first occurrence, else the earlier vertex; then, in input order,
    // the welded index (an earlier vertex is numbered before any later copy reads it).
    let mut remap = vec![u32::MAX; n];
    for list in &repeats {
        for &[later, earlier] in list {
            remap[later as usize] = earlier;
        }
    }
    drop(repeats);
    let mut kept = Vec::with_capacity(n - merged);
    for v in 0..n {
        remap[v] = match remap[v] {
            u32::MAX => {
                kept.push(positions[v]);
                kept.len() as u32 - 1
            }
            earlier => remap[earlier as usize],
        };
    }
    mesh.triangles
        .par_iter_mut()
        .with_min_len(65_536)
        .for_each(|t| *t = t.map(|v| remap[v as usize]));
    mesh.positions = kept;
    (
        WeldReport {
            merged_vertices: merged,
        },
        Some(remap),
    )
}

/// A position's key (its bits, -0.0 as 0.0) with its hash worked out once: the shard and the
/// map both use it.
#[derive(Clone, Copy)]
struct KeyedPosition {
    bits: [u32; 3],
    hash: u64,
}

impl KeyedPosition {
    fn new(p: &[f32; 3]) -> KeyedPosition {
        let bits = position_key(p);
        // A multiply-xorshift mix of the three words (every output bit depends on every input bit).
        let mut h = (bits[0] as u64 | (bits[1] as u64) << 32).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ bits[2] as u64;
        h = (h ^ h >> 29).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        KeyedPosition {
            bits,
            hash: h ^ h >> 32,
        }
    }
}

impl PartialEq for KeyedPosition {
    fn eq(&self, other: &Self) -> bool {
        self.bits == other.bits
    }
}

impl Eq for KeyedPosition {}

impl std::hash::Hash for KeyedPosition {
    fn hash<H: Hasher>(&self, state: &mut H) {
        state.write_u64(self.hash);
    }
}

/// Remove triangles that repeat a vertex or an earlier triangle, and vertices that no triangle
/// uses.
pub fn clean(mesh: &mut TriMesh) -> CleanReport {
    clean_with_map(mesh).0
}

/// [`clean`], also giving the map from each input vertex to the vertex it became (`u32::MAX` for
/// a removed vertex); `None` when no vertex was removed.
pub(crate) fn clean_with_map(mesh: &mut TriMesh) -> (CleanReport, Option<Vec<u32>>) {
    clean_with_map_and(mesh, true)
}

/// [`clean_with_map`] but for the repeated triangles, which a caller that builds the topology
/// next finds from it ([`Topology::repeated_triangles`]) for less. Repeated triangles leave no
/// vertex unused, so leaving them for later changes no other result.
pub(crate) fn clean_with_map_but_repeats(mesh: &mut TriMesh) -> (CleanReport, Option<Vec<u32>>) {
    clean_with_map_and(mesh, false)
}

fn clean_with_map_and(mesh: &mut TriMesh, repeats: bool) -> (CleanReport, Option<Vec<u32>>) {
    let before_faces = mesh.triangles.len();
    mesh.triangles
        .retain(|&[a, b, c]| a != b && b != c && a != c);
    let removed_degenerate_faces = before_faces - mesh.triangles.len();
    let distinct = mesh.triangles.len();
    if repeats {
        let repeats = repeated_triangles(&mesh.triangles, mesh.positions.len());
        remove_triangles(mesh, &repeats);
    }
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

/// The triangles (ascending indices) whose three corners an earlier triangle already has, in any
/// order. The triangles are listed by their smallest corner (a counting sort: no hashing, and
/// the lists are short), and only triangles in the same list are compared.
fn repeated_triangles(triangles: &[[u32; 3]], vertices: usize) -> Vec<u32> {
    // Indices past `vertices` are not this function's to refuse: list them all the same.
    let vertices = triangles
        .iter()
        .flatten()
        .max()
        .map_or(0, |&v| v as usize + 1)
        .max(vertices);
    let mut starts = vec![0u32; vertices + 1];
    for t in triangles {
        let low = t[0].min(t[1]).min(t[2]) as usize;
        starts[low + 1] += 1;
    }
    for v in 0..vertices {
        starts[v + 1] += starts[v];
    }
    let mut next = starts.clone();
    let mut listed = vec![0u32; triangles.len()];
    for (f, t) in triangles.iter().enumerate() {
        let low = t[0].min(t[1]).min(t[2]) as usize;
        listed[next[low] as usize] = f as u32;
        next[low] += 1;
    }
    // The lists are independent: checked in parallel, in chunks of vertices, joined in order.
    let chunks: Vec<Vec<u32>> = (0..vertices)
        .into_par_iter()
        .with_min_len(16_384)
        .fold(Vec::new, |mut repeats, v| {
            let list = &listed[starts[v] as usize..starts[v + 1] as usize];
            repeats_among(triangles, list, &mut repeats);
            repeats
        })
        .collect();
    let mut repeats: Vec<u32> = chunks.concat();
    repeats.sort_unstable();
    repeats
}

/// Remove the triangles at `indices` (ascending), keeping the others in order.
pub(crate) fn remove_triangles(mesh: &mut TriMesh, indices: &[u32]) {
    if indices.is_empty() {
        return;
    }
    let mut next = indices.iter().copied().peekable();
    let mut index = 0u32;
    mesh.triangles.retain(|_| {
        let repeat = next.next_if_eq(&index).is_some();
        index += 1;
        !repeat
    });
}

/// Of `faces` (ascending, all with the same smallest corner), append to `repeats` those whose
/// corners an earlier one of them has, in any order.
pub(crate) fn repeats_among(triangles: &[[u32; 3]], faces: &[u32], repeats: &mut Vec<u32>) {
    let sorted = |t: [u32; 3]| {
        let mut t = t;
        t.sort_unstable();
        t
    };
    if faces.len() <= 16 {
        // In triangle order: a later one with an earlier one's corners repeats it.
        for (i, &f) in faces.iter().enumerate() {
            let corners = sorted(triangles[f as usize]);
            if faces[..i]
                .iter()
                .any(|&g| sorted(triangles[g as usize]) == corners)
            {
                repeats.push(f);
            }
        }
    } else {
        // A busy vertex (a fan's hub): sort by corners, then triangle.
        let mut keyed: Vec<([u32; 3], u32)> = faces
            .iter()
            .map(|&f| (sorted(triangles[f as usize]), f))
            .collect();
        keyed.sort_unstable();
        for pair in keyed.windows(2) {
            if pair[0].0 == pair[1].0 {
                repeats.push(pair[1].1);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Topology;

    /// A tetrahedron whose face 1-2-3 comes three times: once more rotated (2), once reversed (4).
    const TETRAHEDRON_WITH_REPEATS: [[u32; 3]; 6] = [
        [0, 2, 1],
        [1, 2, 3],
        [2, 3, 1],
        [0, 1, 3],
        [3, 2, 1],
        [0, 3, 2],
    ];

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
    fn weld_gives_the_first_occurrence_map_for_any_thread_count() {
        // A 12 x 12 grid stored as separate triangles (every corner copied), shuffled so first
        // occurrences are spread over the file, with -0.0 and 0.0 both present.
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        let corner = |i: u32, j: u32| [i as f32 - 6.0, j as f32 * 0.5, 0.0f32];
        for k in 0..144u32 {
            let (i, j) = ((k * 37) % 144 / 12, (k * 37) % 144 % 12);
            for [a, b] in [[(i, j), (i + 1, j)], [(i + 1, j + 1), (i, j + 1)]] {
                let first = positions.len() as u32;
                positions.push(corner(a.0, a.1));
                positions.push(corner(b.0, b.1));
                positions.push(if k % 2 == 0 {
                    [-0.0, 1.0, 0.0]
                } else {
                    [0.0, 1.0, 0.0]
                });
                triangles.push([first, first + 1, first + 2]);
            }
        }
        // The map by definition: each vertex to the count of distinct positions before its first
        // occurrence.
        let key = |p: &[f32; 3]| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        let mut firsts: Vec<[u32; 3]> = Vec::new();
        let expected: Vec<u32> = positions
            .iter()
            .map(|p| match firsts.iter().position(|f| *f == key(p)) {
                Some(i) => i as u32,
                None => {
                    firsts.push(key(p));
                    firsts.len() as u32 - 1
                }
            })
            .collect();
        for threads in [1, 2, 3, 7] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut mesh = TriMesh::new(positions.clone(), triangles.clone());
            let (report, map) = pool.install(|| weld_with_map(&mut mesh));
            assert_eq!(report.merged_vertices, positions.len() - firsts.len());
            assert_eq!(map.as_deref(), Some(&expected[..]), "{threads} threads");
            assert_eq!(mesh.positions.len(), firsts.len());
            for (t, original) in mesh.triangles.iter().zip(&triangles) {
                for (&w, &v) in t.iter().zip(original) {
                    assert_eq!(
                        key(&mesh.positions[w as usize]),
                        key(&positions[v as usize])
                    );
                }
            }
        }
        // Nothing to merge: no map.
        let mut welded = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]],
            vec![[0, 1, 2]],
        );
        assert_eq!(weld_with_map(&mut welded).1, None);
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
        let mut mesh = TriMesh::new(
            vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            TETRAHEDRON_WITH_REPEATS.to_vec(),
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

    #[test]
    fn repeats_around_a_busy_hub_are_found_and_the_first_kept() {
        // A fan of 40 triangles around hub 0 (more than a short list holds), with triangle 5
        // repeated reversed at the end and triangle 30 repeated rotated in the middle.
        let mut positions = vec![[0.0f32, 0.0, 1.0]];
        let mut triangles = Vec::new();
        for i in 0..40u32 {
            let angle = i as f32 * std::f32::consts::TAU / 40.0;
            positions.push([angle.cos(), angle.sin(), 0.0]);
            triangles.push([0, 1 + i, 1 + (i + 1) % 40]);
        }
        let five = triangles[5];
        let thirty = triangles[30];
        triangles.insert(20, [thirty[1], thirty[2], thirty[0]]);
        triangles.push([five[0], five[2], five[1]]);
        let mut expected = triangles.clone();
        expected.remove(41);
        expected.remove(31);
        assert_eq!(
            repeated_triangles(&triangles, positions.len()),
            vec![31, 41]
        );
        // The same from the topology, as loading finds them; and a tetrahedron's short lists.
        let fan = TriMesh::new(positions.clone(), triangles.clone());
        assert_eq!(Topology::build(&fan).repeated_triangles, vec![31, 41]);
        let tetrahedron = TETRAHEDRON_WITH_REPEATS;
        let corners = vec![[0.0f32; 3]; 4];
        let with_repeats = TriMesh::new(corners, tetrahedron.to_vec());
        assert_eq!(
            Topology::build(&with_repeats).repeated_triangles,
            vec![2, 4]
        );
        let mut mesh = TriMesh::new(positions, triangles);
        let report = clean(&mut mesh);
        assert_eq!(report.removed_repeated_faces, 2);
        assert_eq!(
            mesh.triangles, expected,
            "the first of each kept, in input order"
        );
    }
}
