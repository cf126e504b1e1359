//! Closest points on a mesh's surface: a bounding volume hierarchy over its triangles, and the
//! one-way surface distance sampled from another mesh (see the parent module for how the samples
//! are taken and summed).

use super::SurfaceDistance;
use crate::mesh::TriMesh;
use glam::DVec3;
use rayon::prelude::*;

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

    fn octahedron(scale: f32) -> TriMesh {
        crate::mesh::fixtures::octahedron(scale)
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
