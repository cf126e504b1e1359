//! The guided normal filter crease detection runs on a noisy mesh (read from Zhang et al.,
//! "Guided Mesh Normal Filtering", 2015; the parent module's docs give the reading): every pass
//! gives each face a guidance normal, the mean normal of the most consistent patch around it,
//! then averages the normals of the faces sharing a vertex with it, weighted by area and by how
//! close their guidance normals are. A hot kernel: its passes stay whole so their loops read as
//! one.

use crate::mesh::{area_normal, Topology, TriMesh};
use glam::{Mat4, Vec3A, Vec4};
use rayon::prelude::*;

/// Unit face normals, filtered `passes` times (see the module docs): each pass takes, for every
/// face, a guidance normal (the mean normal of the most consistent patch that contains it), then
/// averages the normals of the faces around it weighted by area and by how close their guidance
/// normals are to its own.
pub fn filtered_face_normals(
    mesh: &TriMesh,
    topology: &Topology,
    passes: usize,
    sigma: f64,
) -> Vec<Vec3A> {
    filter_face_normals(mesh, topology, passes, sigma, &mut FaceRingCache::default())
        .into_par_iter()
        .with_min_len(4096)
        .map(xyz)
        .collect()
}

/// The faces around each face, built the first time the guided filter runs and kept for later
/// detections on the same connectivity (constrained fairing finds the creases again before every
/// round: the lists stay, only the normals change).
#[derive(Default)]
pub(crate) struct FaceRingCache {
    rings: Option<FaceRings>,
    /// Keep the mesh's own face order (no Morton order): the mesh is numbered for locality.
    mesh_order: bool,
}

impl FaceRingCache {
    /// A cache for a mesh already numbered for locality (constrained fairing's rounds run on
    /// a copy numbered breadth-first, faces by their lowest corner): the filter keeps its face
    /// order instead of sorting the faces in Morton order (the lists are built faster and the
    /// passes read closer faces; the normals are the same bit for bit).
    pub(crate) fn in_mesh_order() -> FaceRingCache {
        FaceRingCache {
            rings: None,
            mesh_order: true,
        }
    }
}

/// [`filtered_face_normals`], each unit normal with its face's doubled area in w (the area of
/// the input's face), by face id.
///
/// How it is computed: in f32 (normals are directions; a pass averages a dozen of them), with the
/// faces around each face (those sharing a vertex with it, each with the number of vertices it
/// shares) listed once, before the passes, in blocks of faces ([`FaceRings`]). A pass is then three
/// parallel gathers over the faces: every patch's mean and spread (once per face), every face's
/// guidance (the least spread among the patches around it), the filtered normal. The first and the
/// last take the faces around four at a time (their x, y, z and area in four lanes, the weights'
/// exponentials by [`exp_of_negative`]). Each face is computed by the same operations whatever the
/// thread count. No pass (a clean mesh) builds nothing: the normals are the faces' own. Three
/// arrays of the faces' size are written (the normals, the patches and then the filtered normals
/// over them, the guidance): a detection's first touch of their pages is a measurable part of its
/// time on a big mesh.
pub(super) fn filter_face_normals(
    mesh: &TriMesh,
    topology: &Topology,
    passes: usize,
    sigma: f64,
    cache: &mut FaceRingCache,
) -> Vec<Vec4> {
    // Unit normal and area (twice the area: only ratios matter) of face f.
    let unit = |f: u32| {
        let n = area_normal(mesh, f);
        let length = n.length();
        if length > 0.0 && length.is_finite() {
            (n / length).extend(length)
        } else {
            Vec4::ZERO
        }
    };
    let face_count = mesh.triangles.len();
    if passes == 0 {
        return (0..face_count as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(unit)
            .collect();
    }
    let mesh_order = cache.mesh_order;
    let rings = cache
        .rings
        .get_or_insert_with(|| FaceRings::build(mesh, topology, mesh_order));
    // The passes' arrays are in the rings' order of the faces.
    let mut current: Vec<Vec4> = match &rings.order {
        Some(order) => order
            .par_iter()
            .with_min_len(4096)
            .map(|&f| unit(f))
            .collect(),
        None => (0..face_count as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(unit)
            .collect(),
    };
    let inverse = (1.0 / (2.0 * sigma * sigma)) as f32;
    // Three arrays: the patches are no longer read once the guidance is taken, so the filtered
    // normals are written over them.
    let mut patches = vec![Vec4::ZERO; face_count];
    let mut guidance = vec![Vec4::ZERO; face_count];
    for _ in 0..passes {
        // Each patch (the faces around a face, with their multiplicities): its area-weighted
        // mean normal and how much its normals disagree (the largest squared difference from
        // the mean), as (mean, spread).
        rings.for_each_face(&mut patches, |f, around, shared, patch| {
            let own = xyz(current[f]);
            let mut sum = [Vec4::ZERO; 3];
            for k in (0..around.len()).step_by(4) {
                let ([n], m) = four([&current], around, shared, k, f);
                let weight = n.w_axis * m;
                for (s, n) in sum.iter_mut().zip([n.x_axis, n.y_axis, n.z_axis]) {
                    *s += n * weight;
                }
            }
            let sum = Vec3A::new(
                sum[0].element_sum(),
                sum[1].element_sum(),
                sum[2].element_sum(),
            );
            let mean = sum.try_normalize().unwrap_or(own);
            let mut spread = Vec4::ZERO;
            for k in (0..around.len()).step_by(4) {
                let ([n], _) = four([&current], around, shared, k, f);
                let d = [(n.x_axis, mean.x), (n.y_axis, mean.y), (n.z_axis, mean.z)]
                    .map(|(n, m)| n - Vec4::splat(m));
                spread = spread.max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            }
            *patch = mean.extend(spread.max_element());
        });
        // Guidance: the mean of the most consistent patch among those containing f (the
        // first of the least spread, in the order of the list).
        rings.for_each_face(&mut guidance, |f, around, _, guide| {
            let mut best = xyz(current[f]).extend(f32::INFINITY);
            for &g in around {
                let patch = patches[g as usize];
                if patch.w < best.w {
                    best = patch;
                }
            }
            *guide = xyz(best).extend(0.0);
        });
        let next = &mut patches;
        rings.for_each_face(next, |f, around, shared, out| {
            let own = guidance[f];
            let mut sum = [Vec4::ZERO; 3];
            for k in (0..around.len()).step_by(4) {
                let ([g, n], m) = four([&guidance, &current], around, shared, k, f);
                let d = [(g.x_axis, own.x), (g.y_axis, own.y), (g.z_axis, own.z)]
                    .map(|(g, o)| g - Vec4::splat(o));
                let d = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                let weight = n.w_axis * m * exp_of_negative(d * inverse);
                for (s, n) in sum.iter_mut().zip([n.x_axis, n.y_axis, n.z_axis]) {
                    *s += n * weight;
                }
            }
            let sum = Vec3A::new(
                sum[0].element_sum(),
                sum[1].element_sum(),
                sum[2].element_sum(),
            );
            let area = current[f].w;
            *out = sum.try_normalize().unwrap_or(xyz(current[f])).extend(area);
        });
        std::mem::swap(&mut current, next);
    }
    match &rings.order {
        Some(order) => {
            let mut normals = vec![Vec4::ZERO; current.len()];
            for (&f, n) in order.iter().zip(&current) {
                normals[f as usize] = *n;
            }
            normals
        }
        None => current,
    }
}

/// For each array of `values`, its four values at `around[k..k + 4]` as the columns of a matrix,
/// transposed (so its x axis holds their x, and so on), and their shared-vertex counts; past the
/// end of the list, face `own` (always in its own list) with a count of 0.
#[inline(always)]
fn four<const N: usize>(
    values: [&[Vec4]; N],
    around: &[u32],
    shared: &[u8],
    k: usize,
    own: usize,
) -> ([Mat4; N], Vec4) {
    let (faces, counts) = match (around.get(k..k + 4), shared.get(k..k + 4)) {
        (Some(&[a, b, c, d]), Some(&[ma, mb, mc, md])) => (
            [a, b, c, d].map(|g| g as usize),
            [ma, mb, mc, md].map(f32::from),
        ),
        _ => {
            let at = |i: usize| match around.get(k + i) {
                Some(&g) => (g as usize, f32::from(shared[k + i])),
                None => (own, 0.0),
            };
            let [(a, ma), (b, mb), (c, mc), (d, md)] = [at(0), at(1), at(2), at(3)];
            ([a, b, c, d], [ma, mb, mc, md])
        }
    };
    let [a, b, c, d] = faces;
    (
        values
            .map(|values| Mat4::from_cols(values[a], values[b], values[c], values[d]).transpose()),
        Vec4::from_array(counts),
    )
}

/// e^(−x) for each x ≥ 0: (e^(−x/16))^16, e^(−y) by its Taylor series to degree 7, so all four
/// lanes at once in a few multiplications (x is clamped to 16, where e^(−x) is 1e-7: the weights
/// it gives are to other weights as 1e-7 is to 1, and a face's own weight is 1). Relative error
/// below 5e-6 for x ≤ 8 (unit normals and σ = 0.5 give x ≤ 8; 3.8e-6 at worst, near 8): the
/// polynomial's few ulps of f32 rounding and the series' 1e-7 at y = 1/2, each doubled by every
/// squaring; well under what the weights' sum of a dozen f32 terms carries anyway.
#[inline(always)]
fn exp_of_negative(x: Vec4) -> Vec4 {
    let y = -x.min(Vec4::splat(16.0)) * (1.0 / 16.0);
    let mut e = Vec4::splat(1.0 / 5040.0);
    for c in [
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        e = e * y + Vec4::splat(c);
    }
    for _ in 0..4 {
        e *= e;
    }
    e
}

/// The x, y, z of a normal stored with its face's area in w.
#[inline]
pub(super) fn xyz(v: Vec4) -> Vec3A {
    Vec3A::from_vec4(v)
}

/// Faces per block of [`FaceRings`].
const FACE_BLOCK: usize = 4096;

/// For every face, the faces sharing a vertex with it (itself included), in ascending order of
/// their ids, each once with the number of vertices it shares (3 for the face itself, 2 across an
/// edge, 1 across a vertex): the union, with multiplicities, of its corners' face lists, which is
/// what the guided filter averages over. Kept in blocks of [`FACE_BLOCK`] faces, built and read in
/// parallel.
///
/// The faces are numbered here in Morton order of their centroids (`order`), and the lists hold
/// these numbers, so that the faces around a face are near it in the passes' arrays whatever the
/// file's face order: the passes are gathers, bound by the memory's latency. A mesh already
/// numbered for locality keeps its own order (`order` is `None`;
/// [`FaceRingCache::in_mesh_order`]). The lists keep the
/// order of the faces' ids, so every face's sums and choices are made in the same order as with
/// the file's numbering, and the filtered normals are the same bit for bit. (1.2M-face bunny, 5
/// passes: 1.14-1.24 s in the subdivided file's order, 0.77-0.81 s in Morton order, 3.4-3.9 s
/// with its faces shuffled.)
struct FaceRings {
    /// `order[i]`: the id of the face numbered `i` (`None`: face `i`, the mesh's own order).
    order: Option<Vec<u32>>,
    blocks: Vec<FaceRingBlock>,
}

struct FaceRingBlock {
    /// `faces[offsets[i]..offsets[i + 1]]` are around the block's face `i`.
    offsets: Vec<u32>,
    faces: Vec<u32>,
    /// How many vertices each listed face shares with the block's face.
    shared: Vec<u8>,
}

impl FaceRings {
    /// The lists in Morton order of the faces, or in the mesh's own order with `mesh_order`.
    fn build(mesh: &TriMesh, topology: &Topology, mesh_order: bool) -> FaceRings {
        let face_count = mesh.triangles.len();
        let order = (!mesh_order).then(|| morton_face_order(mesh));
        let number = order.as_deref().map(crate::mesh::inverse_permutation);
        let blocks = (0..face_count.div_ceil(FACE_BLOCK))
            .into_par_iter()
            .map(|index| {
                let faces = index * FACE_BLOCK..face_count.min((index + 1) * FACE_BLOCK);
                let block = faces.map(|i| order.as_ref().map_or(i as u32, |order| order[i]));
                let mut ring = FaceRingBlock {
                    offsets: Vec::with_capacity(block.len() + 1),
                    faces: Vec::with_capacity(14 * block.len()),
                    shared: Vec::with_capacity(14 * block.len()),
                };
                ring.offsets.push(0);
                for f in block {
                    let [a, b, c] = mesh.triangles[f as usize];
                    let start = ring.faces.len();
                    merge_face_lists(
                        [
                            topology.faces_of(a),
                            topology.faces_of(b),
                            topology.faces_of(c),
                        ],
                        &mut ring.faces,
                        &mut ring.shared,
                    );
                    if let Some(number) = &number {
                        for g in &mut ring.faces[start..] {
                            *g = number[*g as usize];
                        }
                    }
                    ring.offsets.push(ring.faces.len() as u32);
                }
                ring
            })
            .collect();
        FaceRings { order, blocks }
    }

    /// Calls `visit(f, faces around f, their shared-vertex counts, &mut out[f])` for every face,
    /// in parallel over blocks.
    fn for_each_face<T: Send>(
        &self,
        out: &mut [T],
        visit: impl Fn(usize, &[u32], &[u8], &mut T) + Sync,
    ) {
        out.par_chunks_mut(FACE_BLOCK)
            .zip(&self.blocks)
            .enumerate()
            .for_each(|(b, (out, ring))| {
                for (i, slot) in out.iter_mut().enumerate() {
                    let (start, end) = (ring.offsets[i] as usize, ring.offsets[i + 1] as usize);
                    visit(
                        b * FACE_BLOCK + i,
                        &ring.faces[start..end],
                        &ring.shared[start..end],
                        slot,
                    );
                }
            });
    }
}

/// The faces' ids in Morton order of their centroids (quantized to 10 bits per axis in the
/// bounding box of the vertices; ties by id, so the order is the same on any thread count).
fn morton_face_order(mesh: &TriMesh) -> Vec<u32> {
    let (lo, hi) = crate::metrics::bounding_box(mesh).unwrap_or_default();
    let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let mut keys: Vec<u64> = mesh
        .triangles
        .par_iter()
        .with_min_len(4096)
        .enumerate()
        .map(|(f, t)| {
            let centre = t
                .iter()
                .map(|&v| glam::DVec3::from(mesh.positions[v as usize].map(f64::from)))
                .sum::<glam::DVec3>()
                / 3.0;
            crate::mesh::morton_code(centre, lo, extent) << 32 | f as u64
        })
        .collect();
    keys.par_sort_unstable();
    keys.into_iter().map(|k| k as u32).collect()
}

/// Appends the union of three ascending face lists, each face once with the number of lists
/// holding it.
fn merge_face_lists(lists: [&[u32]; 3], faces: &mut Vec<u32>, shared: &mut Vec<u8>) {
    let [mut a, mut b, mut c] = lists;
    loop {
        let head = |l: &[u32]| l.first().copied().unwrap_or(u32::MAX);
        let (x, y, z) = (head(a), head(b), head(c));
        let m = x.min(y).min(z);
        if m == u32::MAX {
            break;
        }
        faces.push(m);
        shared.push((x == m) as u8 + (y == m) as u8 + (z == m) as u8);
        a = &a[(x == m) as usize..];
        b = &b[(y == m) as usize..];
        c = &c[(z == m) as usize..];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes::cuboid;

    #[test]
    fn the_filters_exponential_is_within_its_stated_error() {
        // Relative error below 5e-6 where unit normals and σ = 0.5 put the weights (x ≤ 8),
        // and no weight larger than e^(−16) beyond 16 (a face's own weight is 1).
        for i in 0..=8000 {
            let x = i as f32 * 0.001;
            let lanes = exp_of_negative(Vec4::new(x, x * 0.5, x * 0.25, 0.0));
            for (k, scale) in [1.0f32, 0.5, 0.25].into_iter().enumerate() {
                let exact = (-(f64::from(x * scale))).exp();
                let error = (f64::from(lanes[k]) - exact).abs() / exact;
                assert!(error < 5e-6, "x = {x}: {} against {exact}", lanes[k]);
            }
            assert_eq!(lanes[3], 1.0);
        }
        for x in [16.0f32, 20.0, 1e3, f32::MAX] {
            let e = exp_of_negative(Vec4::splat(x))[0];
            assert!((0.0..=1.2e-7).contains(&e), "x = {x}: {e}");
        }
    }

    /// The filter in the mesh's own face order (a mesh numbered for locality) gives the normals
    /// of the Morton order bit for bit, for every face: each face's sums run over its
    /// neighbours in the order of their ids either way.
    #[test]
    fn the_filter_in_the_meshs_own_face_order_gives_the_same_normals() {
        use crate::noise::{add_noise, NoiseOptions};
        let mut mesh = cuboid([1.0, 1.0, 1.0], 0.05);
        add_noise(&mut mesh, &NoiseOptions::default().with_sigma(0.3));
        let topology = Topology::build(&mesh);
        let filter =
            |cache: &mut FaceRingCache| filter_face_normals(&mesh, &topology, 3, 0.5, cache);
        let (mut morton, mut own) = (FaceRingCache::default(), FaceRingCache::in_mesh_order());
        let expected = filter(&mut morton);
        assert!(morton.rings.as_ref().unwrap().order.is_some());
        assert!(own.rings.is_none());
        let got = filter(&mut own);
        assert!(own.rings.as_ref().unwrap().order.is_none());
        assert_eq!(got, expected);
        // The filter moved the normals (a pass that did nothing would pass the comparison).
        let raw = filter_face_normals(&mesh, &topology, 0, 0.5, &mut own);
        assert!(raw.iter().zip(&got).filter(|(a, b)| a != b).count() > raw.len() / 2);
    }
}
