//! Painting where to fair: the brush's settings, which vertices a dab of the brush reaches, and
//! the compact form a file's mask is remembered in between runs.
//!
//! A dab reaches the vertices that project within the brush's radius (screen pixels) of the
//! cursor and lie on the surface the cursor sees: a ray from the eye through the cursor is
//! intersected with the displayed triangles, and a vertex counts only if it is no farther from
//! the eye than that hit plus the brush's radius at that depth (so the back of the mesh and parts
//! hidden behind the picked surface are not painted). Its weight falls from 1 to 0 over the outer
//! `softness` part of the radius, so the fairing fades out at the painted region's edge.

use glam::{Mat4, Vec3, Vec4Swizzles};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

use fairmesh::fairing::Mask;

/// The brush in use: whether the left button paints, the stroke being painted and the mask's
/// revision (its tint is uploaded again when it changes). `tasks/mask.rs` changes it.
#[derive(Debug, Default)]
pub(in crate::app) struct Painting {
    /// The left button paints the mask instead of orbiting.
    pub(in crate::app) paint_mode: bool,
    /// The mask's weights while a stroke is being painted.
    pub(in crate::app) stroke: Option<Vec<f32>>,
    /// Where the brush's last dab of the stroke was (screen points).
    pub(in crate::app) last_dab: Option<egui::Pos2>,
    /// Bumped with every change of the document's mask, so that its tint is uploaded again.
    pub(in crate::app) mask_revision: u64,
}

/// The brush and the remembered masks (part of the persisted settings).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PaintSettings {
    /// Brush radius in screen points.
    pub radius: f32,
    /// The outer part of the radius (0 to 1) over which the brush fades out.
    pub softness: f32,
    /// Tint the painted region in the view.
    pub show_mask: bool,
    /// The brush lowers the mask (protects) instead of raising it.
    pub erase: bool,
    /// The mask last painted on each file, most recent last (at most [`REMEMBERED_MASKS`]).
    pub masks: Vec<StoredMask>,
}

impl Default for PaintSettings {
    fn default() -> Self {
        Self {
            radius: 40.0,
            softness: 0.5,
            show_mask: true,
            erase: false,
            masks: Vec::new(),
        }
    }
}

/// Files whose masks are remembered.
pub const REMEMBERED_MASKS: usize = 16;
/// Runs of painted vertices one remembered mask may hold (a mask painted with a brush has a few
/// hundred; a scattered one that needs more is not remembered).
pub const MAX_STORED_RUNS: usize = 20_000;

/// A mask as the settings keep it: runs of consecutive vertices with the same weight (weights
/// in 255ths), unpainted vertices left out.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredMask {
    pub path: PathBuf,
    pub vertex_count: usize,
    /// (first vertex, count, weight × 255).
    pub runs: Vec<(u32, u32, u8)>,
}

impl StoredMask {
    /// `mask` of the file at `path` in stored form; `None` when it has too many runs.
    pub fn of(path: &Path, mask: &Mask) -> Option<StoredMask> {
        let mut runs: Vec<(u32, u32, u8)> = Vec::new();
        for (v, &w) in mask.weights().iter().enumerate() {
            if w <= 0.0 {
                continue;
            }
            // A painted vertex stays painted, however faintly.
            let level = ((w.min(1.0) * 255.0).round() as u8).max(1);
            match runs.last_mut() {
                Some((start, count, last)) if *last == level && *start + *count == v as u32 => {
                    *count += 1
                }
                _ => {
                    if runs.len() == MAX_STORED_RUNS {
                        return None;
                    }
                    runs.push((v as u32, 1, level));
                }
            }
        }
        Some(StoredMask {
            path: path.to_path_buf(),
            vertex_count: mask.len(),
            runs,
        })
    }

    /// The mask again, if it was made for a mesh of `vertex_count` vertices.
    pub fn mask(&self, vertex_count: usize) -> Option<Mask> {
        if self.vertex_count != vertex_count {
            return None;
        }
        let mut weights = vec![0.0f32; vertex_count];
        for &(start, count, level) in &self.runs {
            let range = start as usize..(start as usize).saturating_add(count as usize);
            weights.get_mut(range)?.fill(level as f32 / 255.0);
        }
        Mask::new(weights).ok()
    }
}

impl PaintSettings {
    /// The mask remembered for `path` on a mesh of `vertex_count` vertices.
    pub fn mask_for(&self, path: &Path, vertex_count: usize) -> Option<Mask> {
        self.masks
            .iter()
            .rev()
            .find(|stored| stored.path == path)?
            .mask(vertex_count)
    }

    /// Remembers `mask` (or forgets it, `None`) for `path`; false when it was too detailed to
    /// keep.
    pub fn remember(&mut self, path: &Path, mask: Option<&Mask>) -> bool {
        self.masks.retain(|stored| stored.path != path);
        let Some(mask) = mask else {
            return true;
        };
        let Some(stored) = StoredMask::of(path, mask) else {
            return false;
        };
        self.masks.push(stored);
        let excess = self.masks.len().saturating_sub(REMEMBERED_MASKS);
        self.masks.drain(..excess);
        true
    }

    /// The brush's weight at `fraction` of its radius from the cursor (1 inside, fading to 0 at
    /// the rim over the soft part).
    pub fn weight_at(&self, fraction: f32) -> f32 {
        let softness = self.softness.clamp(0.0, 1.0);
        if fraction >= 1.0 {
            return 0.0;
        }
        if softness <= 0.0 || fraction <= 1.0 - softness {
            return 1.0;
        }
        let t = (1.0 - fraction) / softness;
        t * t * (3.0 - 2.0 * t)
    }
}

/// Where the brush is: the cursor and the view it is in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushView {
    /// Projection times view of the image the cursor is over.
    pub view_proj: Mat4,
    pub eye: Vec3,
    /// The image's rectangle on screen (points).
    pub rect: egui::Rect,
    pub cursor: egui::Pos2,
    /// Brush radius in points.
    pub radius: f32,
}

impl BrushView {
    /// Normalized device coordinates of a screen point.
    fn ndc(&self, point: egui::Pos2) -> (f32, f32) {
        let x = (point.x - self.rect.left()) / self.rect.width().max(1.0) * 2.0 - 1.0;
        let y = 1.0 - (point.y - self.rect.top()) / self.rect.height().max(1.0) * 2.0;
        (x, y)
    }

    /// The ray from the eye through the cursor (unit direction).
    fn ray(&self) -> Option<(Vec3, Vec3)> {
        let inverse = self.view_proj.inverse();
        let (x, y) = self.ndc(self.cursor);
        let unproject = |z: f32| {
            let p = inverse * glam::Vec4::new(x, y, z, 1.0);
            (p.w.abs() > f32::EPSILON).then(|| p.xyz() / p.w)
        };
        let (near, far) = (unproject(0.0)?, unproject(1.0)?);
        let direction = (far - near).try_normalize()?;
        Some((self.eye, direction))
    }

    /// Screen position (points) and clip w of a world point.
    fn project(&self, p: Vec3) -> Option<(egui::Pos2, f32)> {
        let clip = self.view_proj * p.extend(1.0);
        if clip.w <= f32::EPSILON {
            return None;
        }
        let (x, y) = (clip.x / clip.w, clip.y / clip.w);
        let screen = egui::pos2(
            self.rect.left() + (x + 1.0) * 0.5 * self.rect.width(),
            self.rect.top() + (1.0 - y) * 0.5 * self.rect.height(),
        );
        Some((screen, clip.w))
    }
}

/// The vertices a dab of the brush reaches and how far from the cursor each is (0 at the
/// cursor, 1 at the rim); empty when the cursor is not over the mesh.
pub fn brush_hits(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    view: &BrushView,
) -> Vec<(u32, f32)> {
    let Some((origin, direction)) = view.ray() else {
        return Vec::new();
    };
    let Some((hit, hit_triangle)) = nearest_hit(positions, triangles, origin, direction) else {
        return Vec::new();
    };
    let hit_point = origin + direction * hit;
    // Half the brush's radius in world units at the picked depth: how far behind the picked
    // surface a vertex under the brush may lie and still count as on it.
    let Some((centre, _)) = view.project(hit_point) else {
        return Vec::new();
    };
    let right = direction.cross(Vec3::Y).normalize_or(Vec3::X);
    let world_per_point = view
        .project(hit_point + right)
        .map_or(0.0, |(p, _)| 1.0 / (p - centre).length().max(1e-6));
    let depth_slack = 0.5 * view.radius * world_per_point;
    let radius = view.radius.max(0.5);
    let candidates: Vec<(u32, f32)> = positions
        .par_iter()
        .enumerate()
        .filter_map(|(v, &p)| {
            let p = Vec3::from_array(p);
            let (screen, _) = view.project(p)?;
            let fraction = (screen - view.cursor).length() / radius;
            let depth = (p - origin).dot(direction);
            (fraction < 1.0 && depth <= hit + depth_slack).then_some((v as u32, fraction))
        })
        .collect();
    // Facing the eye as the picked triangle does (whichever way the mesh is wound): the far side
    // of a thin part under the brush faces away.
    let facing = |normal: Vec3, at: Vec3| normal.dot(origin - at);
    let picked_side = facing(
        triangle_normal(positions, &triangles[hit_triangle]),
        hit_point,
    )
    .signum();
    let normals = vertex_normals(positions, triangles, &candidates);
    candidates
        .into_iter()
        .zip(normals)
        .filter(|&((v, _), normal)| {
            facing(normal, Vec3::from_array(positions[v as usize])) * picked_side >= 0.0
        })
        .map(|(candidate, _)| candidate)
        .collect()
}

/// Area-weighted normal (not normalized) of one triangle.
fn triangle_normal(positions: &[[f32; 3]], t: &[u32; 3]) -> Vec3 {
    let corner = |v: u32| Vec3::from_array(positions[v as usize]);
    (corner(t[1]) - corner(t[0])).cross(corner(t[2]) - corner(t[0]))
}

/// Area-weighted vertex normals of the `candidates` only, in their order. One per vertex, never
/// split at a sharp edge as smooth shading's are (`render::normals`): a vertex has one mask
/// weight, so a vertex on a rim faces the eye or not by the mean of the sides that meet there.
fn vertex_normals(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    candidates: &[(u32, f32)],
) -> Vec<Vec3> {
    // Vertex -> its place among the candidates: a dense table, as every triangle is looked up.
    let mut slot = vec![u32::MAX; positions.len()];
    for (i, &(v, _)) in candidates.iter().enumerate() {
        slot[v as usize] = i as u32;
    }
    let mut normals = vec![Vec3::ZERO; candidates.len()];
    for t in triangles {
        let slots = t.map(|v| slot.get(v as usize).copied().unwrap_or(u32::MAX));
        if slots.iter().all(|&s| s == u32::MAX) {
            continue;
        }
        let normal = triangle_normal(positions, t);
        for s in slots.into_iter().filter(|&s| s != u32::MAX) {
            normals[s as usize] += normal;
        }
    }
    normals
}

/// Distance along the ray to the nearest triangle it crosses, and that triangle
/// (Möller-Trumbore, both sides). Triangles naming a vertex out of range are skipped.
fn nearest_hit(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    origin: Vec3,
    direction: Vec3,
) -> Option<(f32, usize)> {
    let corner = |v: u32| positions.get(v as usize).map(|&p| Vec3::from_array(p));
    triangles
        .par_iter()
        .enumerate()
        .filter_map(|(index, t)| {
            let (a, b, c) = (corner(t[0])?, corner(t[1])?, corner(t[2])?);
            let (e1, e2) = (b - a, c - a);
            let p = direction.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-12 {
                return None;
            }
            let inv = 1.0 / det;
            let s = origin - a;
            let u = s.dot(p) * inv;
            let q = s.cross(e1);
            let w = direction.dot(q) * inv;
            let t = e2.dot(q) * inv;
            (u >= 0.0 && w >= 0.0 && u + w <= 1.0 && t > 0.0).then_some((t, index))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::camera::OrbitCamera;

    /// Three parallel 3×3 grids of quads (16 vertices each) seen from +z: at z = 0 facing the
    /// eye, at z = -0.2 facing away (the back of a thin part), at z = -4 facing the eye (a
    /// surface far behind).
    fn sheets() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for z in [0.0f32, -0.2, -4.0] {
            let base = positions.len() as u32;
            for j in 0..4 {
                for i in 0..4 {
                    positions.push([i as f32 - 1.5, j as f32 - 1.5, z]);
                }
            }
            for j in 0..3u32 {
                for i in 0..3u32 {
                    let v = base + j * 4 + i;
                    if z == -0.2 {
                        triangles.push([v, v + 5, v + 1]);
                        triangles.push([v, v + 4, v + 5]);
                    } else {
                        triangles.push([v, v + 1, v + 5]);
                        triangles.push([v, v + 5, v + 4]);
                    }
                }
            }
        }
        (positions, triangles)
    }

    fn view_from_front(cursor: egui::Pos2, radius: f32) -> BrushView {
        let camera = OrbitCamera {
            distance: 6.0,
            pitch: 0.0,
            ..OrbitCamera::default()
        };
        let rect = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(400.0, 400.0));
        BrushView {
            view_proj: camera.view_proj(1.0),
            eye: camera.eye(),
            rect,
            cursor,
            radius,
        }
    }

    #[test]
    fn a_dab_reaches_the_front_sheet_near_the_cursor_only() {
        let (positions, triangles) = sheets();
        // The centre of the view looks at the middle of the sheets (between four vertices, 75
        // points from it; the next ones are 167 points away).
        let view = view_from_front(egui::pos2(200.0, 200.0), 90.0);
        let hits = brush_hits(&positions, &triangles, &view);
        let mut vertices: Vec<u32> = hits.iter().map(|&(v, _)| v).collect();
        vertices.sort();
        // The four middle vertices of the front sheet (indices 5, 6, 9, 10), none behind.
        assert_eq!(vertices, vec![5, 6, 9, 10]);
        // A bigger brush takes the whole front sheet and still nothing of those behind.
        let wide = view_from_front(egui::pos2(200.0, 200.0), 400.0);
        let hits = brush_hits(&positions, &triangles, &wide);
        assert_eq!(hits.len(), 16);
        assert!(hits.iter().all(|&(v, _)| v < 16));
        // Off the mesh: nothing.
        let off = view_from_front(egui::pos2(5.0, 5.0), 20.0);
        assert!(brush_hits(&positions, &triangles, &off).is_empty());
    }

    #[test]
    fn the_brush_fades_over_its_soft_part() {
        let brush = PaintSettings {
            softness: 0.5,
            ..PaintSettings::default()
        };
        assert_eq!(brush.weight_at(0.2), 1.0);
        assert_eq!(brush.weight_at(0.5), 1.0);
        assert!((brush.weight_at(0.75) - 0.5).abs() < 1e-6);
        assert_eq!(brush.weight_at(1.0), 0.0);
    }

    #[test]
    fn stored_masks_round_trip_and_stay_bounded() {
        let path = Path::new("/scans/bunny.obj");
        let mut weights = vec![0.0f32; 100];
        weights[10..20].fill(1.0);
        weights[20] = 0.5;
        weights[50..52].fill(1.0);
        let mask = Mask::new(weights.clone()).unwrap();
        let stored = StoredMask::of(path, &mask).unwrap();
        assert_eq!(stored.runs, vec![(10, 10, 255), (20, 1, 128), (50, 2, 255)]);
        let back = stored.mask(100).unwrap();
        assert_eq!(back.weights()[..20], weights[..20]);
        assert!((back.weights()[20] - 0.5).abs() < 0.01);
        assert!(stored.mask(99).is_none(), "another mesh");
        // Every other vertex painted: too many runs to remember.
        let scattered = Mask::from_vertices(
            2 * MAX_STORED_RUNS + 2,
            (0..).step_by(2).take(MAX_STORED_RUNS + 1),
        );
        assert!(StoredMask::of(path, &scattered).is_none());

        let mut settings = PaintSettings::default();
        assert!(settings.remember(path, Some(&mask)));
        assert_eq!(settings.mask_for(path, 100).unwrap().painted_count(), 13);
        for i in 0..REMEMBERED_MASKS {
            settings.remember(&PathBuf::from(format!("/m/{i}.obj")), Some(&mask));
        }
        assert_eq!(settings.masks.len(), REMEMBERED_MASKS);
        assert!(
            settings.mask_for(path, 100).is_none(),
            "the oldest is forgotten"
        );
        settings.remember(Path::new("/m/3.obj"), None);
        assert!(settings.mask_for(Path::new("/m/3.obj"), 100).is_none());
    }
}
