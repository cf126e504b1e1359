//! [`Measures`]: how far one mesh is from a reference mesh (volume change, surface distances,
//! per-vertex comparisons and the heat map's distances), computed on the measuring worker.

use std::sync::Arc;

use fairmesh::TriMesh;

/// How far one mesh is from a reference mesh (computed on the worker with every result).
#[derive(Clone, Debug)]
pub struct Measures {
    /// Enclosed volume change in percent (`None` when the reference encloses no volume).
    pub volume_change_percent: Option<f64>,
    /// Mean (area-weighted, both ways) and maximum (Hausdorff) surface distance, model units.
    pub mean_distance: f64,
    pub max_distance: f64,
    /// Per-vertex comparisons, present when both meshes share their triangles.
    pub vertex_rms: Option<f64>,
    pub barycenter_drift: Option<f64>,
    /// Distance of every vertex from the reference surface (the heat map), model units.
    pub vertex_distances: Arc<Vec<f32>>,
}

impl Measures {
    /// `other` measured against `reference`.
    pub fn of(reference: &TriMesh, other: &TriMesh) -> Self {
        Self::of_unless(reference, other, &|| false).expect("never stopped")
    }

    /// [`Self::of`], giving up (`None`) soon after `stop` says so.
    pub fn of_unless(
        reference: &TriMesh,
        other: &TriMesh,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Option<Self> {
        let reference_index = fairmesh::metrics::ClosestPointIndex::new(reference);
        let other_index = fairmesh::metrics::ClosestPointIndex::new(other);
        let (forth, vertex_distances) =
            reference_index.distance_and_vertex_distances_unless(other, stop)?;
        let (back, _) = other_index.distance_and_vertex_distances_unless(reference, stop)?;
        let vertices = fairmesh::metrics::compare_vertices(reference, other);
        let vertex_distances = vertex_distances.into_iter().map(|d| d as f32).collect();
        Some(Self {
            volume_change_percent: fairmesh::metrics::volume_change_percent(reference, other),
            mean_distance: 0.5 * (forth.mean + back.mean),
            max_distance: forth.max.max(back.max),
            vertex_rms: vertices.map(|v| v.rms),
            barycenter_drift: vertices.map(|v| v.barycenter_drift),
            vertex_distances: Arc::new(vertex_distances),
        })
    }
}
