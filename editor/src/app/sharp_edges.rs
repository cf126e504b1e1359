//! The sharp edges the hierarchy keeps, drawn as lines over the mesh while the "Keep sharp edges"
//! controls are hovered or were just changed, so the user sees what the angle picks.
//!
//! The lines are painted with egui over the 3D view, without a depth test: an edge is drawn
//! when at least one of its two faces faces the camera, which hides the edges on the far side of
//! the mesh (a concave part can still show an edge that a nearer part covers).

use glam::Vec3;

use fairmesh::TriMesh;

/// At most this many edges are drawn in a frame (every n-th beyond it): egui tessellates each
/// line on the CPU.
const MAX_DRAWN: usize = 40_000;

/// The kept sharp edges of a mesh and, for each, its two faces (to tell whether one faces the
/// camera).
#[derive(Debug, Default)]
pub struct SharpEdgeLines {
    edges: Vec<[u32; 2]>,
    /// The faces on either side of each edge, in the mesh's orientation (`[u32::MAX; 3]` when an
    /// edge has fewer than two).
    faces: Vec<[[u32; 3]; 2]>,
}

impl SharpEdgeLines {
    /// Finds the two faces of each of `edges` (vertex ids of `mesh`, lower first) with one pass
    /// over the triangles; edges with other ids are dropped.
    pub fn new(mesh: &TriMesh, mut edges: Vec<[u32; 2]>) -> Self {
        let n = mesh.positions.len() as u32;
        edges.retain(|&[a, b]| a < b && b < n);
        edges.sort_unstable();
        edges.dedup();
        let mut faces = vec![[[u32::MAX; 3]; 2]; edges.len()];
        if !edges.is_empty() {
            for triangle in &mesh.triangles {
                for k in 0..3 {
                    let (a, b) = (triangle[k], triangle[(k + 1) % 3]);
                    if let Ok(i) = edges.binary_search(&[a.min(b), a.max(b)]) {
                        let slot = &mut faces[i];
                        let free = if slot[0][0] == u32::MAX { 0 } else { 1 };
                        slot[free] = *triangle;
                    }
                }
            }
        }
        Self { edges, faces }
    }

    pub fn len(&self) -> usize {
        self.edges.len()
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Screen segments of the edges a camera at `eye` sees on `positions` (the mesh's vertex
    /// order), projected with `view_proj` into `rect`.
    pub fn segments(
        &self,
        positions: &[[f32; 3]],
        view_proj: glam::Mat4,
        eye: Vec3,
        rect: egui::Rect,
    ) -> Vec<[egui::Pos2; 2]> {
        let at = |v: u32| positions.get(v as usize).map(|&p| Vec3::from(p));
        let facing = |face: &[u32; 3]| -> bool {
            let (Some(a), Some(b), Some(c)) = (at(face[0]), at(face[1]), at(face[2])) else {
                return false;
            };
            (b - a).cross(c - a).dot(eye - a) > 0.0
        };
        let project = |p: Vec3| -> Option<egui::Pos2> {
            let clip = view_proj * p.extend(1.0);
            (clip.w > f32::EPSILON).then(|| {
                egui::pos2(
                    rect.left() + (clip.x / clip.w + 1.0) * 0.5 * rect.width(),
                    rect.top() + (1.0 - clip.y / clip.w) * 0.5 * rect.height(),
                )
            })
        };
        let stride = self.edges.len().div_ceil(MAX_DRAWN).max(1);
        self.edges
            .iter()
            .zip(&self.faces)
            .step_by(stride)
            .filter(|(_, faces)| faces.iter().any(facing))
            .filter_map(|(&[a, b], _)| Some([project(at(a)?)?, project(at(b)?)?]))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A folded sheet: two triangles meeting at the edge 1-2 (the fold), seen from +z.
    fn fold() -> TriMesh {
        TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.5],
            ],
            vec![[0, 1, 2], [2, 1, 3]],
        )
    }

    fn view() -> (glam::Mat4, egui::Rect) {
        (
            glam::Mat4::IDENTITY,
            egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(100.0, 100.0)),
        )
    }

    #[test]
    fn an_edge_is_drawn_where_it_projects_when_a_face_looks_at_the_camera() {
        let mesh = fold();
        let lines = SharpEdgeLines::new(&mesh, vec![[1, 2], [0, 9]]);
        assert_eq!(lines.len(), 1, "an edge with an unknown vertex is dropped");
        let (view_proj, rect) = view();
        let front = lines.segments(&mesh.positions, view_proj, Vec3::new(0.3, 0.3, 5.0), rect);
        // x = 1 is the right edge of the view, y = 1 its top.
        assert_eq!(
            front,
            vec![[egui::pos2(100.0, 50.0), egui::pos2(50.0, 0.0)]]
        );
        let behind = lines.segments(&mesh.positions, view_proj, Vec3::new(0.3, 0.3, -5.0), rect);
        assert!(behind.is_empty(), "both faces look away: {behind:?}");
    }
}
