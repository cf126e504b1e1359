//! Measures of one mesh (volume, area, bounding box, mean edge length) and comparisons between
//! two meshes.
//!
//! Surface distance is the measure that matters for shape: smoothing and vertex splits move
//! vertices along the surface without changing it, so per-vertex distances overstate the change.
//! It is sampled both ways: from each mesh, area-weighted samples (each triangle's centroid and
//! the three points halfway between the centroid and a corner, each carrying a quarter of the
//! triangle's area) plus every vertex (for the maximum), projected onto the other mesh's surface
//! through a bounding volume hierarchy. The mean surface distance is the mean of the two one-way
//! area-weighted means; the Hausdorff estimate is the larger of the two one-way maxima.
//! Sums are taken in a fixed order so results do not depend on the thread count.

use crate::mesh::TriMesh;
use glam::DVec3;
use rayon::prelude::*;

/// Signed volume enclosed by the triangles (divergence theorem, about the bounding box centre to
/// limit cancellation); meaningful for closed, consistently oriented meshes.
pub fn signed_volume(mesh: &TriMesh) -> f64 {
    let centre = bounding_box(mesh)
        .map(|(lo, hi)| (lo + hi) * 0.5)
        .unwrap_or_default();
    signed_volume_about(mesh, centre)
}

/// Signed volume of the cones from `apex` to every triangle. For a closed mesh it does not depend
/// on `apex`; for an open mesh it does, so comparisons of open meshes use one apex for both.
pub fn signed_volume_about(mesh: &TriMesh, apex: DVec3) -> f64 {
    let mut six_volume = 0.0;
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle_points(t).map(|p| p - apex);
        six_volume += a.dot(b.cross(c));
    }
    six_volume / 6.0
}

/// Total surface area.
pub fn area(mesh: &TriMesh) -> f64 {
    (0..mesh.triangles.len())
        .map(|t| mesh.face_normal(t).length() * 0.5)
        .sum()
}

/// Axis-aligned bounding box (min, max) of the positions; `None` for an empty mesh.
pub fn bounding_box(mesh: &TriMesh) -> Option<(DVec3, DVec3)> {
    let mut iter = mesh
        .positions
        .iter()
        .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
    let first = iter.next()?;
    Some(iter.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

/// Mean length of the triangles' edges (an interior edge counts once per triangle, so on a closed
/// mesh this is exactly the mean over distinct edges). 0 for a mesh without triangles.
pub fn mean_edge_length(mesh: &TriMesh) -> f64 {
    if mesh.triangles.is_empty() {
        return 0.0;
    }
    let mut sum = 0.0;
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle_points(t);
        sum += (b - a).length() + (c - b).length() + (a - c).length();
    }
    sum / (3 * mesh.triangles.len()) as f64
}

/// One-way surface distance from the samples of one mesh to another mesh's surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct SurfaceDistance {
    /// Area-weighted mean distance.
    pub mean: f64,
    /// Largest distance over all samples and vertices.
    pub max: f64,
}

/// Comparisons that need the same connectivity (same triangles, vertex for vertex).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct VertexComparison {
    /// Root mean square vertex displacement.
    pub rms: f64,
    /// Largest vertex displacement.
    pub max_distance: f64,
    /// Mean angle between corresponding face normals, in degrees (degenerate faces skipped).
    pub normal_error_deg: f64,
    /// Mean distance between corresponding triangle barycenters.
    pub barycenter_drift: f64,
}

/// An edge counts in [`sharpened_edges`] when the angle between its two triangles' normals
/// exceeds the reference's by more than this, in degrees.
pub const SHARPENED_DEGREES: f64 = 30.0;

/// OTHER measured against REFERENCE.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Comparison {
    pub mean_surface_distance: f64,
    pub hausdorff: f64,
    /// (V_other - V_reference) / |V_reference| in percent, both about the reference's bounding
    /// box centre; `None` when the reference encloses no volume.
    pub volume_change_percent: Option<f64>,
    pub reference_to_other: SurfaceDistance,
    pub other_to_reference: SurfaceDistance,
    /// Present when both meshes have the same triangles.
    pub same_connectivity: Option<VertexComparison>,
}

/// Compare `other` against `reference`.
///
/// ```
/// use fairmesh::metrics::compare;
///
/// let reference = fairmesh::bundled::load_bunny(&Default::default())?.mesh;
/// let mut shifted = reference.clone();
/// for p in &mut shifted.positions {
///     p[1] += 0.001; // move the whole mesh up
/// }
/// let comparison = compare(&reference, &shifted);
/// let vertices = comparison.same_connectivity.expect("same triangles");
/// assert!((vertices.rms - 0.001).abs() < 1e-5);
/// assert!(comparison.mean_surface_distance <= 0.001 + 1e-5);
/// assert!(comparison.volume_change_percent.unwrap().abs() < 1e-3);
/// # Ok::<(), fairmesh::io::IoError>(())
/// ```
pub fn compare(reference: &TriMesh, other: &TriMesh) -> Comparison {
    let reference_index = ClosestPointIndex::new(reference);
    let other_index = ClosestPointIndex::new(other);
    let other_to_reference = reference_index.distance_from(other);
    let reference_to_other = other_index.distance_from(reference);
    Comparison {
        mean_surface_distance: 0.5 * (other_to_reference.mean + reference_to_other.mean),
        hausdorff: other_to_reference.max.max(reference_to_other.max),
        volume_change_percent: volume_change_percent(reference, other),
        reference_to_other,
        other_to_reference,
        same_connectivity: compare_vertices(reference, other),
    }
}

/// Volume change of `other` against `reference` in percent (see [`Comparison`]).
pub fn volume_change_percent(reference: &TriMesh, other: &TriMesh) -> Option<f64> {
    let apex = bounding_box(reference)
        .map(|(lo, hi)| (lo + hi) * 0.5)
        .unwrap_or_default();
    let before = signed_volume_about(reference, apex);
    let after = signed_volume_about(other, apex);
    (before.abs() > 0.0 && before.is_finite()).then(|| (after - before) / before.abs() * 100.0)
}

/// How far `positions` (new positions of `base`'s vertices, as a fairing returns them) moved
/// `base`: the relative change of the enclosed volume (a fraction, not percent; each volume
/// taken with [`signed_volume`]; NaN when `base` encloses none) and the root mean square vertex
/// displacement. Both are NaN when the vertex counts differ or there are no vertices. The
/// editor shows these with every result, before [`compare`]'s slower surface distances arrive.
pub fn change_of_positions(base: &TriMesh, positions: &[[f32; 3]]) -> (f64, f64) {
    if positions.len() != base.positions.len() || positions.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let before = signed_volume(base);
    let after_mesh = TriMesh {
        positions: positions.to_vec(),
        triangles: base.triangles.clone(),
    };
    let after = signed_volume(&after_mesh);
    let volume_change = if before.abs() > 0.0 {
        (after - before) / before.abs()
    } else {
        f64::NAN
    };
    let sum_squared: f64 = positions
        .iter()
        .zip(&base.positions)
        .map(|(p, q)| {
            (0..3)
                .map(|k| (p[k] as f64 - q[k] as f64).powi(2))
                .sum::<f64>()
        })
        .sum();
    (volume_change, (sum_squared / positions.len() as f64).sqrt())
}

/// How far the vertices slid along the surface: the root mean square, over the vertices, of the
/// part of each vertex's move from `before` (its position there) that is perpendicular to its
/// normal in `after` (area-weighted), in model units. What a file's texture coordinates, which
/// stay with their vertices, see of a smoothing: a slide moves the texture over the surface,
/// while a move along the normal does not. NaN when the vertex counts differ or there are no
/// vertices.
pub fn tangential_slide(before: &[[f32; 3]], after: &TriMesh) -> f64 {
    if before.len() != after.positions.len() || before.is_empty() {
        return f64::NAN;
    }
    let point = |p: &[f32; 3]| DVec3::from(p.map(f64::from));
    let sum_squared: f64 = before
        .iter()
        .zip(&after.positions)
        .zip(after.vertex_normals())
        .map(|((b, a), n)| {
            let moved = point(a) - point(b);
            (moved - n * moved.dot(n)).length_squared()
        })
        .sum();
    (sum_squared / before.len() as f64).sqrt()
}

/// Per-vertex comparisons, when `other` has the same triangles as `reference`.
pub fn compare_vertices(reference: &TriMesh, other: &TriMesh) -> Option<VertexComparison> {
    if !same_connectivity(reference, other) {
        return None;
    }
    let n = reference.positions.len().max(1) as f64;
    let mut sum_sq = 0.0;
    let mut max_distance: f64 = 0.0;
    for v in 0..reference.positions.len() as u32 {
        let d = reference.point(v).distance(other.point(v));
        sum_sq += d * d;
        max_distance = max_distance.max(d);
    }
    let mut angle_sum = 0.0;
    let mut angle_count = 0usize;
    let mut drift_sum = 0.0;
    for t in 0..reference.triangles.len() {
        let (a, b) = (reference.face_normal(t), other.face_normal(t));
        if a.length_squared() > 0.0 && b.length_squared() > 0.0 {
            angle_sum += a.angle_between(b).to_degrees();
            angle_count += 1;
        }
        let centre = |m: &TriMesh| m.triangle_points(t).iter().sum::<DVec3>() / 3.0;
        drift_sum += centre(reference).distance(centre(other));
    }
    let faces = reference.triangles.len().max(1) as f64;
    Some(VertexComparison {
        rms: (sum_sq / n).sqrt(),
        max_distance,
        normal_error_deg: if angle_count > 0 {
            angle_sum / angle_count as f64
        } else {
            0.0
        },
        barycenter_drift: drift_sum / faces,
    })
}

/// Whether `other` has the same triangles over as many vertices as `reference`.
fn same_connectivity(reference: &TriMesh, other: &TriMesh) -> bool {
    reference.triangles == other.triangles && reference.positions.len() == other.positions.len()
}

/// How many edges of `other` bend by more than [`SHARPENED_DEGREES`] beyond the same edge of
/// `reference` (the angle between the normals of the two triangles that share it): the folds and
/// ridges a smoothing added, or the noise it left. Against the clean mesh, a good smoothing of a
/// noisy copy leaves next to none. Over the edges exactly two triangles share, not counting those
/// beside a degenerate triangle; `None` unless the two meshes have the same triangles.
pub fn sharpened_edges(reference: &TriMesh, other: &TriMesh) -> Option<usize> {
    if !same_connectivity(reference, other) {
        return None;
    }
    // (lower corner, higher corner, triangle) for every edge of every triangle, sorted so that
    // an edge's triangles sit side by side.
    let mut edges: Vec<(u32, u32, u32)> = reference
        .triangles
        .iter()
        .enumerate()
        .flat_map(|(t, tri)| {
            (0..3).map(move |k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                (a.min(b), a.max(b), t as u32)
            })
        })
        .collect();
    edges.sort_unstable();
    let bend = |mesh: &TriMesh, s: u32, t: u32| {
        let (a, b) = (mesh.face_normal(s as usize), mesh.face_normal(t as usize));
        (a.length_squared() > 0.0 && b.length_squared() > 0.0)
            .then(|| a.angle_between(b).to_degrees())
    };
    let sharpened = edges
        .chunk_by(|x, y| (x.0, x.1) == (y.0, y.1))
        .filter(|shared| shared.len() == 2)
        .filter(|shared| {
            let (s, t) = (shared[0].2, shared[1].2);
            matches!(
                (bend(reference, s, t), bend(other, s, t)),
                (Some(before), Some(after)) if after - before > SHARPENED_DEGREES
            )
        })
        .count();
    Some(sharpened)
}

/// Closest-point queries against a mesh's surface: a bounding volume hierarchy over its triangles
/// (median split of centroids along the longest axis, up to four triangles a leaf).
pub struct ClosestPointIndex<'a> {
    mesh: &'a TriMesh,
    nodes: Vec<BvhNode>,
    order: Vec<u32>,
}

#[derive(Clone, Copy)]
struct BvhNode {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first index into `order`; inner node: index of the left child (right is next to it).
    first: u32,
    /// Number of triangles in a leaf; 0 for an inner node.
    count: u32,
}

const LEAF_SIZE: usize = 4;

impl<'a> ClosestPointIndex<'a> {
    pub fn new(mesh: &'a TriMesh) -> Self {
        let faces = mesh.triangles.len();
        let mut order: Vec<u32> = (0..faces as u32).collect();
        let centroids: Vec<DVec3> = (0..faces)
            .map(|t| mesh.triangle_points(t).iter().sum::<DVec3>() / 3.0)
            .collect();
        let mut nodes = Vec::with_capacity(2 * faces / LEAF_SIZE + 1);
        if faces > 0 {
            nodes.push(BvhNode {
                lo: DVec3::ZERO,
                hi: DVec3::ZERO,
                first: 0,
                count: faces as u32,
            });
            // Split nodes breadth-first with an explicit work list (no recursion depth limits).
            let mut pending = vec![0usize];
            while let Some(node_index) = pending.pop() {
                let BvhNode { first, count, .. } = nodes[node_index];
                let range = first as usize..(first + count) as usize;
                let (mut lo, mut hi) =
                    (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
                let (mut clo, mut chi) = (lo, hi);
                for &t in &order[range.clone()] {
                    for p in mesh.triangle_points(t as usize) {
                        lo = lo.min(p);
                        hi = hi.max(p);
                    }
                    clo = clo.min(centroids[t as usize]);
                    chi = chi.max(centroids[t as usize]);
                }
                nodes[node_index].lo = lo;
                nodes[node_index].hi = hi;
                if range.len() <= LEAF_SIZE {
                    continue;
                }
                let extent = chi - clo;
                let axis = if extent.x >= extent.y && extent.x >= extent.z {
                    0
                } else if extent.y >= extent.z {
                    1
                } else {
                    2
                };
                let mid = range.len() / 2;
                order[range.clone()].select_nth_unstable_by(mid, |&a, &b| {
                    centroids[a as usize][axis]
                        .total_cmp(&centroids[b as usize][axis])
                        .then(a.cmp(&b))
                });
                let left = nodes.len();
                nodes.push(BvhNode {
                    lo,
                    hi,
                    first,
                    count: mid as u32,
                });
                nodes.push(BvhNode {
                    lo,
                    hi,
                    first: first + mid as u32,
                    count: count - mid as u32,
                });
                nodes[node_index].first = left as u32;
                nodes[node_index].count = 0;
                pending.push(left);
                pending.push(left + 1);
            }
        }
        Self { mesh, nodes, order }
    }

    /// Distance from `p` to the closest point of the surface (infinite for a mesh without faces).
    pub fn distance(&self, p: DVec3) -> f64 {
        self.closest(p).map_or(f64::INFINITY, |(d2, _)| d2.sqrt())
    }

    /// Squared distance to, and index of, a closest triangle (the distance is exact; where
    /// several triangles are equally close, which one is named depends on the search).
    pub fn closest(&self, p: DVec3) -> Option<(f64, u32)> {
        self.closest_near(p, None)
    }

    /// Like [`Self::closest`], starting from the distance to triangle `hint` (when it is one of
    /// this mesh's): a triangle near `p` gives a tight bound that prunes most of the tree. The
    /// distance is the same whatever the hint.
    pub fn closest_near(&self, p: DVec3, hint: Option<u32>) -> Option<(f64, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = (f64::INFINITY, u32::MAX);
        if let Some(t) = hint.filter(|&t| (t as usize) < self.mesh.triangles.len()) {
            let [a, b, c] = self.mesh.triangle_points(t as usize);
            best = (
                (closest_point_on_triangle(p, a, b, c) - p).length_squared(),
                t,
            );
        }
        let mut stack: Vec<(f64, u32)> = Vec::with_capacity(64);
        stack.push((box_distance_sq(&self.nodes[0], p), 0));
        while let Some((bound, index)) = stack.pop() {
            if bound >= best.0 {
                continue;
            }
            let node = self.nodes[index as usize];
            if node.count > 0 {
                for &t in &self.order[node.first as usize..(node.first + node.count) as usize] {
                    let [a, b, c] = self.mesh.triangle_points(t as usize);
                    let d2 = (closest_point_on_triangle(p, a, b, c) - p).length_squared();
                    if d2 < best.0 || (d2 == best.0 && t < best.1) {
                        best = (d2, t);
                    }
                }
            } else {
                let (l, r) = (node.first, node.first + 1);
                let (dl, dr) = (
                    box_distance_sq(&self.nodes[l as usize], p),
                    box_distance_sq(&self.nodes[r as usize], p),
                );
                // Visit the nearer child first: push it last.
                if dl <= dr {
                    stack.push((dr, r));
                    stack.push((dl, l));
                } else {
                    stack.push((dl, l));
                    stack.push((dr, r));
                }
            }
        }
        Some(best)
    }

    /// One-way distance from `from`'s surface samples and vertices to this surface.
    ///
    /// When `from` has this mesh's triangle count (a smoothed or noisy copy: the case the editor
    /// and `compare` meet), each query starts from the triangle of the same index, which is
    /// nearby, and prunes most of the tree: 3-4 times fewer node visits. Any hint gives the same
    /// distances, so other meshes are measured exactly too, just more slowly.
    pub fn distance_from(&self, from: &TriMesh) -> SurfaceDistance {
        self.distance_and_vertex_distances_from(from).0
    }

    /// [`Self::distance_from`] and [`Self::vertex_distances`] in one go (the first needs the
    /// second: its maximum includes the vertices).
    pub fn distance_and_vertex_distances_from(
        &self,
        from: &TriMesh,
    ) -> (SurfaceDistance, Vec<f64>) {
        self.distance_and_vertex_distances_unless(from, &|| false)
            .expect("never stopped")
    }

    /// [`Self::distance_and_vertex_distances_from`], giving up (`None`) once `stop` says so:
    /// it is asked before every triangle's and vertex's queries, so a caller whose result went
    /// stale (the editor, when the user moves on) gets its threads back within microseconds.
    pub fn distance_and_vertex_distances_unless(
        &self,
        from: &TriMesh,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Option<(SurfaceDistance, Vec<f64>)> {
        let hinted = from.triangles.len() == self.mesh.triangles.len();
        let per_face: Vec<(f64, f64, f64)> = (0..from.triangles.len())
            .into_par_iter()
            .map(|t| {
                if stop() {
                    return (0.0, 0.0, 0.0);
                }
                let [a, b, c] = from.triangle_points(t);
                let area = (b - a).cross(c - a).length() * 0.5;
                let centroid = (a + b + c) / 3.0;
                let samples = [
                    centroid,
                    (centroid + a) * 0.5,
                    (centroid + b) * 0.5,
                    (centroid + c) * 0.5,
                ];
                let hint = hinted.then_some(t as u32);
                let mut weighted = 0.0;
                let mut max: f64 = 0.0;
                for s in samples {
                    let d = self.distance_near(s, hint);
                    weighted += d * area * 0.25;
                    max = max.max(d);
                }
                (weighted, area, max)
            })
            .collect();
        let vertex_distances: Vec<f64> = (0..from.positions.len() as u32)
            .into_par_iter()
            .map(|v| {
                if stop() {
                    return f64::NAN;
                }
                self.distance(from.point(v))
            })
            .collect();
        if stop() {
            return None;
        }
        let vertex_max = vertex_distances.iter().copied().fold(0.0, f64::max);
        let (mut weighted, mut total_area, mut max) = (0.0, 0.0, vertex_max);
        for (w, a, m) in per_face {
            weighted += w;
            total_area += a;
            max = max.max(m);
        }
        let distance = SurfaceDistance {
            mean: if total_area > 0.0 {
                weighted / total_area
            } else {
                0.0
            },
            max,
        };
        Some((distance, vertex_distances))
    }

    /// Distance from every vertex of `from` to this surface (for heat maps).
    pub fn vertex_distances(&self, from: &TriMesh) -> Vec<f64> {
        (0..from.positions.len() as u32)
            .into_par_iter()
            .map(|v| self.distance(from.point(v)))
            .collect()
    }

    fn distance_near(&self, p: DVec3, hint: Option<u32>) -> f64 {
        self.closest_near(p, hint)
            .map_or(f64::INFINITY, |(d2, _)| d2.sqrt())
    }
}

fn box_distance_sq(node: &BvhNode, p: DVec3) -> f64 {
    let d = (node.lo - p).max(DVec3::ZERO).max(p - node.hi);
    d.length_squared()
}

/// Closest point to `p` on triangle (a, b, c), by the Voronoi regions of its corners and edges.
/// Degenerate triangles (two corners at one point, or all three on a line) give a point of the
/// triangle too, never NaN.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    // The parameter along an edge; an edge of length zero has its one point at 0.
    let ratio = |x: f64, y: f64| if y == 0.0 { 0.0 } else { x / y };
    let ab = b - a;
    let ac = c - a;
    let scale = ab.length_squared().max(ac.length_squared());
    if ab.cross(ac).length_squared() <= 1e-24 * scale * scale {
        // No area: the closest point of its three edges.
        let on_segment = |x: DVec3, y: DVec3| {
            let e = y - x;
            x + e * ratio((p - x).dot(e), e.length_squared()).clamp(0.0, 1.0)
        };
        return [on_segment(a, b), on_segment(b, c), on_segment(c, a)]
            .into_iter()
            .min_by(|x, y| {
                (*x - p)
                    .length_squared()
                    .total_cmp(&(*y - p).length_squared())
            })
            .unwrap_or(a);
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * ratio(d1, d1 - d3);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * ratio(d2, d2 - d6);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ratio(d4 - d3, (d4 - d3) + (d5 - d6));
    }
    let denom = va + vb + vc;
    let v = vb / denom;
    let w = vc / denom;
    a + ab * v + ac * w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangential_slide_is_the_move_along_the_surface_only() {
        // A flat grid (normals +z): every vertex moved 0.3 up and 0.1 along x, one in four also
        // 0.2 along y.
        let mut grid = TriMesh::default();
        for j in 0..4u32 {
            for i in 0..4u32 {
                grid.positions.push([i as f32, j as f32, 0.0]);
            }
        }
        for j in 0..3u32 {
            for i in 0..3u32 {
                let v = j * 4 + i;
                grid.triangles.push([v, v + 1, v + 5]);
                grid.triangles.push([v, v + 5, v + 4]);
            }
        }
        let mut moved = grid.clone();
        for (v, p) in moved.positions.iter_mut().enumerate() {
            p[0] += 0.1;
            p[2] += 0.3;
            if v % 4 == 0 {
                p[1] += 0.2;
            }
        }
        let expected = ((12.0 * 0.01 + 4.0 * 0.05) / 16.0f64).sqrt();
        let slide = tangential_slide(&grid.positions, &moved);
        assert!(
            (slide - expected).abs() < 1e-6,
            "{slide} against {expected}"
        );
        // Straight up: no slide at all.
        let mut lifted = grid.clone();
        for p in &mut lifted.positions {
            p[2] += 0.5;
        }
        assert!(tangential_slide(&grid.positions, &lifted) < 1e-12);
        assert!(tangential_slide(&grid.positions[1..], &lifted).is_nan());
    }

    #[test]
    fn sharpened_edges_are_the_bends_grown_past_the_reference() {
        // A 4×4 grid folded up along the column x = 1 by `degrees`: exactly its three edges on
        // that column bend, by `degrees`; every other edge stays flat.
        let folded = |degrees: f64| {
            let rise = degrees.to_radians().tan();
            let mut grid = TriMesh::default();
            for j in 0..4u32 {
                for i in 0..4u32 {
                    let z = (i as f64 - 1.0).max(0.0) * rise;
                    grid.positions.push([i as f32, j as f32, z as f32]);
                }
            }
            for j in 0..3u32 {
                for i in 0..3u32 {
                    let v = j * 4 + i;
                    grid.triangles.push([v, v + 1, v + 5]);
                    grid.triangles.push([v, v + 5, v + 4]);
                }
            }
            grid
        };
        let sharpened = |reference: &TriMesh, other: &TriMesh| {
            sharpened_edges(reference, other).expect("same triangles")
        };
        let flat = folded(0.0);
        assert_eq!(sharpened(&flat, &flat), 0);
        assert_eq!(sharpened(&flat, &folded(20.0)), 0);
        assert_eq!(sharpened(&flat, &folded(50.0)), 3);
        // Measured against the reference's own bend: 50° → 70° grows by 20° only.
        assert_eq!(sharpened(&folded(50.0), &folded(70.0)), 0);
        assert_eq!(sharpened(&folded(50.0), &flat), 0);
        let mut other_triangles = flat.clone();
        other_triangles.triangles.swap(0, 1);
        assert_eq!(sharpened_edges(&flat, &other_triangles), None);
    }

    #[test]
    fn change_of_identical_or_translated_positions_keeps_the_volume() {
        let mesh = TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        );
        let (dv, rms) = change_of_positions(&mesh, &mesh.positions);
        assert_eq!(dv, 0.0);
        assert_eq!(rms, 0.0);
        let moved: Vec<_> = mesh
            .positions
            .iter()
            .map(|p| [p[0] + 0.5, p[1], p[2]])
            .collect();
        let (dv, rms) = change_of_positions(&mesh, &moved);
        assert!(dv.abs() < 1e-12, "translation keeps the volume");
        assert!((rms - 0.5).abs() < 1e-12);
        let (dv, rms) = change_of_positions(&mesh, &moved[..3]);
        assert!(dv.is_nan() && rms.is_nan(), "other vertex count");
    }

    fn octahedron(scale: f32) -> TriMesh {
        crate::mesh::fixtures::octahedron(scale)
    }

    #[test]
    fn octahedron_volume_area_and_edges() {
        let mesh = octahedron(1.0);
        assert!((signed_volume(&mesh) - 4.0 / 3.0).abs() < 1e-12);
        assert!((area(&mesh) - 8.0 * 3f64.sqrt() / 2.0 * 2.0 / 2.0).abs() < 1e-12);
        assert!((mean_edge_length(&mesh) - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        assert!(
            (closest_point_on_triangle(DVec3::new(0.2, 0.2, 5.0), a, b, c)
                - DVec3::new(0.2, 0.2, 0.0))
            .length()
                < 1e-15
        );
        assert_eq!(
            closest_point_on_triangle(DVec3::new(-1.0, -1.0, 0.0), a, b, c),
            a
        );
        assert_eq!(
            closest_point_on_triangle(DVec3::new(2.0, -0.5, 0.0), a, b, c),
            b
        );
        assert_eq!(
            closest_point_on_triangle(DVec3::new(0.5, -1.0, 1.0), a, b, c),
            DVec3::new(0.5, 0.0, 0.0)
        );
        let on_hypotenuse = closest_point_on_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((on_hypotenuse - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-15);
    }

    #[test]
    fn degenerate_triangles_give_a_point_on_them_not_nan() {
        // Two corners at one point: the triangle is the segment a-c.
        let (a, c) = (DVec3::ZERO, DVec3::X);
        for p in [
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::new(-1.0, 0.0, 2.0),
            DVec3::Y,
        ] {
            for (x, y, z) in [(a, a, c), (a, c, a), (c, a, a)] {
                let q = closest_point_on_triangle(p, x, y, z);
                assert!(q.is_finite(), "{p} on ({x}, {y}, {z}) gave {q}");
                let expected = DVec3::new(p.x.clamp(0.0, 1.0), 0.0, 0.0);
                assert!((q - expected).length() < 1e-12, "{p}: {q} vs {expected}");
            }
        }
        // All three corners at one point.
        assert_eq!(closest_point_on_triangle(DVec3::Y, a, a, a), a);
    }

    #[test]
    fn scaled_copy_is_as_far_as_the_scaling_moves_it() {
        // Octahedron scaled by 1.1: every face plane moves out by 0.1/sqrt(3), the corners by 0.1.
        let (reference, other) = (octahedron(1.0), octahedron(1.1));
        let result = compare(&reference, &other);
        let plane_offset = 0.1 / 3f64.sqrt();
        assert!((result.other_to_reference.max - 0.1).abs() < 1e-6);
        assert!(
            result.mean_surface_distance > 0.9 * plane_offset && result.mean_surface_distance < 0.1
        );
        assert!((result.hausdorff - 0.1).abs() < 1e-6);
        assert!(
            (result.volume_change_percent.unwrap() - (1.1f64.powi(3) - 1.0) * 100.0).abs() < 1e-4
        );
        let v = result.same_connectivity.unwrap();
        assert!((v.rms - 0.1).abs() < 1e-6 && (v.max_distance - 0.1).abs() < 1e-6);
        assert!(v.normal_error_deg.abs() < 1e-4);
        assert!((v.barycenter_drift - plane_offset).abs() < 1e-6);
    }

    #[test]
    fn sliding_vertices_along_the_surface_changes_no_surface_distance() {
        // Same flat square, two triangulations with the shared vertex moved within the plane.
        let a = TriMesh::new(
            vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [0., 1., 0.],
                [0.5, 0.5, 0.],
            ],
            vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        );
        let mut b = a.clone();
        b.positions[4] = [0.3, 0.6, 0.0];
        let result = compare(&a, &b);
        assert!(result.mean_surface_distance < 1e-12 && result.hausdorff < 1e-12);
        // One of five vertices moved by sqrt(0.05): the vertex measures see it.
        let moved = 0.05f64.sqrt();
        let v = result.same_connectivity.unwrap();
        assert!(
            (v.max_distance - moved).abs() < 1e-7 && (v.rms - moved / 5f64.sqrt()).abs() < 1e-7
        );
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mesh = crate::mesh::subdivide_loop(&crate::mesh::subdivide_loop(&octahedron(1.0)));
        let index = ClosestPointIndex::new(&mesh);
        for i in 0..200 {
            let f = i as f64;
            let p = DVec3::new(
                (f * 0.37).sin() * 1.5,
                (f * 0.71).cos() * 1.2,
                (f * 0.13).sin(),
            );
            let brute = (0..mesh.face_count())
                .map(|t| {
                    let [a, b, c] = mesh.triangle_points(t);
                    (closest_point_on_triangle(p, a, b, c) - p).length()
                })
                .fold(f64::INFINITY, f64::min);
            assert!((index.distance(p) - brute).abs() < 1e-12, "query {i}");
            // Any starting triangle gives the same distance: a near one, a far one.
            for hint in [
                0,
                mesh.face_count() as u32 / 2,
                mesh.face_count() as u32 - 1,
            ] {
                let (d2, _) = index.closest_near(p, Some(hint)).unwrap();
                assert!((d2.sqrt() - brute).abs() < 1e-12, "query {i}, hint {hint}");
            }
        }
    }

    #[test]
    fn a_stopped_distance_gives_up_and_an_unstopped_one_matches() {
        let mesh = crate::mesh::subdivide_loop(&octahedron(1.0));
        let mut bumpy = mesh.clone();
        bumpy.positions[3][0] += 0.1;
        let index = ClosestPointIndex::new(&mesh);
        assert!(index
            .distance_and_vertex_distances_unless(&bumpy, &|| true)
            .is_none());
        // Stopping after some queries (the counter is shared by the worker threads).
        let asked = std::sync::atomic::AtomicUsize::new(0);
        let stop_later = || asked.fetch_add(1, std::sync::atomic::Ordering::Relaxed) > 20;
        assert!(index
            .distance_and_vertex_distances_unless(&bumpy, &stop_later)
            .is_none());
        let (never, vertices) = index
            .distance_and_vertex_distances_unless(&bumpy, &|| false)
            .unwrap();
        let plain = index.distance_from(&bumpy);
        assert_eq!((never.mean, never.max), (plain.mean, plain.max));
        assert!(never.max > 0.05);
        assert_eq!(vertices, index.vertex_distances(&bumpy));
    }

    #[test]
    fn hinted_surface_distance_is_the_brute_force_one_whatever_the_triangle_order() {
        // A bumpy copy with the same triangle count: `distance_from` starts each face's queries
        // from the same-index triangle. Reversing the copy's triangle order makes those hints
        // far away; the distances must not change, and must equal a brute-force search.
        let mesh = crate::mesh::subdivide_loop(&octahedron(1.0));
        let mut bumpy = mesh.clone();
        for (v, p) in bumpy.positions.iter_mut().enumerate() {
            let s = 1.0 + 0.05 * ((v as f32) * 1.7).sin();
            *p = [p[0] * s, p[1] * s, p[2] * s];
        }
        let mut reversed = bumpy.clone();
        reversed.triangles.reverse();
        let index = ClosestPointIndex::new(&mesh);
        let (near, vertex_near) = index.distance_and_vertex_distances_from(&bumpy);
        let (far, vertex_far) = index.distance_and_vertex_distances_from(&reversed);
        assert_eq!(near.max, far.max);
        assert!((near.mean - far.mean).abs() < 1e-12 * near.mean);
        assert_eq!(vertex_near, vertex_far);
        let brute = |p: DVec3| {
            (0..mesh.face_count())
                .map(|t| {
                    let [a, b, c] = mesh.triangle_points(t);
                    (closest_point_on_triangle(p, a, b, c) - p).length()
                })
                .fold(f64::INFINITY, f64::min)
        };
        let (mut weighted, mut total_area, mut max) = (0.0, 0.0, 0.0f64);
        for t in 0..bumpy.face_count() {
            let [a, b, c] = bumpy.triangle_points(t);
            let area = (b - a).cross(c - a).length() * 0.5;
            let centroid = (a + b + c) / 3.0;
            for s in [
                centroid,
                (centroid + a) * 0.5,
                (centroid + b) * 0.5,
                (centroid + c) * 0.5,
            ] {
                let d = brute(s);
                weighted += d * area * 0.25;
                max = max.max(d);
            }
            total_area += area;
        }
        for v in 0..bumpy.positions.len() as u32 {
            let d = brute(bumpy.point(v));
            assert!((vertex_near[v as usize] - d).abs() < 1e-12);
            max = max.max(d);
        }
        assert!(near.mean > 1e-3, "the copy is really bumpy: {}", near.mean);
        assert!((near.mean - weighted / total_area).abs() < 1e-12);
        assert!((near.max - max).abs() < 1e-12);
    }
}
