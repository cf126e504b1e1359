//! Measures of one mesh (volume, area, bounding box, mean edge length) and comparisons between
//! two meshes. PROVISIONAL: comparisons are to come.

use crate::mesh::TriMesh;

/// Signed volume enclosed by the triangles (divergence theorem, about the bounding box centre to
/// limit cancellation); meaningful for closed, consistently oriented meshes.
pub fn signed_volume(mesh: &TriMesh) -> f64 {
    let centre = bounding_box(mesh)
        .map(|(lo, hi)| (lo + hi) * 0.5)
        .unwrap_or_default();
    let mut six_volume = 0.0;
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle_points(t).map(|p| p - centre);
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
pub fn bounding_box(mesh: &TriMesh) -> Option<(glam::DVec3, glam::DVec3)> {
    let mut iter = mesh
        .positions
        .iter()
        .map(|p| glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
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
