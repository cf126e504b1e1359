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

mod closest_point;

pub use closest_point::{closest_point_on_triangle, ClosestPointIndex};

use crate::mesh::TriMesh;
use glam::DVec3;

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
    let bend = |mesh: &TriMesh, s: u32, t: u32| {
        let (a, b) = (mesh.face_normal(s as usize), mesh.face_normal(t as usize));
        (a.length_squared() > 0.0 && b.length_squared() > 0.0)
            .then(|| a.angle_between(b).to_degrees())
    };
    let sharpened = crate::mesh::two_face_edges(&reference.triangles)
        .into_iter()
        .filter(|&[_, _, s, t]| {
            matches!(
                (bend(reference, s, t), bend(other, s, t)),
                (Some(before), Some(after)) if after - before > SHARPENED_DEGREES
            )
        })
        .count();
    Some(sharpened)
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
    fn normal_error_is_the_mean_turn_of_the_face_normals_in_degrees() {
        // Two separate triangles in the z = 0 plane; in `other` each is hinged about its edge on
        // the x axis, the first by 30 degrees and the second by 60: the mean turn is 45 degrees.
        let tilted = |degrees: f32, x: f32| {
            let (s, c) = degrees.to_radians().sin_cos();
            [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, c, s]]
        };
        let triangles = vec![[0, 1, 2], [3, 4, 5]];
        let reference = TriMesh::new(
            [tilted(0.0, 0.0), tilted(0.0, 2.0)].concat(),
            triangles.clone(),
        );
        let other = TriMesh::new([tilted(30.0, 0.0), tilted(60.0, 2.0)].concat(), triangles);
        let v = compare_vertices(&reference, &other).unwrap();
        assert!(
            (v.normal_error_deg - 45.0).abs() < 1e-3,
            "{}",
            v.normal_error_deg
        );
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
}
