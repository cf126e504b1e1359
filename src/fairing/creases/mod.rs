//! Sharp creases: which edges are feature edges, which vertices lie on them, and the chains they
//! form, so that fairing can treat a crease like the paper treats a boundary (section 3.3).
//!
//! Not in the paper, which fairs every interior vertex alike and so rounds every sharp edge of a
//! CAD part. The reading here: a crease is a boundary between two surface patches. Each patch is
//! faired with the crease as its boundary (a triangle with one crease corner is solved with that
//! corner held, its other two keeping their midpoint; one with two is not solved, as a triangle
//! touching the boundary is not: [`super::constrained`]), each chain of crease edges is faired
//! as a curve with the paper's edge-centre constraints of section 3.3 (open chains between two
//! fixed ends, closed loops like boundary loops), and the corners stay where they are.
//!
//! Detection:
//! - A feature edge is an edge with exactly two faces whose normals differ by more than
//!   [`CreaseOptions::angle_degrees`]. On a noisy mesh the faces' own normals scatter by tens of
//!   degrees, so they are first filtered ([`CreaseOptions::normal_filtering`] passes, chosen from
//!   the noise estimate when fairing picks its own strength): a guided bilateral filter, read from
//!   Zhang et al., "Guided Mesh Normal Filtering" (2015). Each pass gives every face a guidance
//!   normal, the mean normal of the most consistent patch (the faces sharing a vertex with some
//!   face) among the patches that contain it, so a face beside a crease is guided by a patch on
//!   its own side; then each face averages the normals of the faces sharing a vertex with it,
//!   weighted by area and by exp(−|g_f − g_g|² / 2σ²) of the guidance normals
//!   (σ = [`CreaseOptions::normal_sigma`]). Noise averages out within each side, while across a
//!   crease the weights vanish. A plain bilateral filter (weights from the noisy normals
//!   themselves) would find many crease edges where there are none: the noise makes them.
//! - Feature edges that form small groups (fewer than [`CreaseOptions::min_edges`] edges joined at
//!   their ends) are dropped, and so are groups that zigzag (more than one corner per two edges):
//!   noise and single spikes of a scan make those, while a crease runs straight between a few
//!   corners. For this test a corner is where the edges themselves turn by more than
//!   [`CreaseOptions::zigzag_turn_degrees`] ([`ZIGZAG_TURN`], 55°, lower than the classes'
//!   70°): the bends of a coarse scan that the filter sharpens into feature edges wander, and
//!   fairing them as creases costs the scan more than it keeps. The hierarchy keeps them
//!   ([`HIERARCHY_ZIGZAG_TURN`], 70°): there they hold a coarse level's shape
//!   (`docs/measurements.md`, "Wandering groups are no creases").
//! - Edges the input file marks as sharp ([`CreaseOptions::file_edges`]: split normals, material
//!   boundaries, from [`crate::io::Source::hard_edges`]) are feature edges whatever
//!   their angle, and are never dropped as a small or zigzagging group: the file's author said so.
//! - A crease vertex has exactly two feature edges whose crease directions (the cross product of
//!   each edge's two filtered face normals: on a noisy crease the vertices zigzag, the faces on
//!   either side do not) turn by less than [`CreaseOptions::corner_turn_degrees`]; any other vertex
//!   with feature edges is a corner (the end of a crease, three or more creases meeting, a sharp
//!   turn, or a crease meeting the boundary) and is held fixed.
//!
//! Speed: detection runs before every round of constrained fairing, so it must cost little next to
//! a round. Constrained fairing and the hierarchy detect through `detect_creases_with_estimate`,
//! whose one gather over the fan-ordered one-rings gives the noise estimate and the feature edges
//! of the faces' own normals at once, so a clean mesh reads no face and never runs the filter. The
//! filter (noisy meshes) works in f32 on a face-around-face list built once for all passes. Every
//! vertex and face is computed by the same operations whatever the thread count.
//!
//! # Files
//! - `normal_filter`: the guided normal filter ([`filtered_face_normals`]).
//! - `feature_graph`: the feature edges' groups, the vertices' classes and the chains.
//! - `super::feature_edges` (beside this module, shared with the noise estimate's scan): which
//!   edges are feature edges.

mod feature_graph;
mod normal_filter;

pub use feature_graph::MIN_FAIRED_LOOP;
pub use normal_filter::filtered_face_normals;
pub(crate) use normal_filter::FaceRingCache;

use super::feature_edges::{vertex_feature_edges, FeatureEdge};
use super::strength::{normal_filtering_for, scan_fans};
use crate::mesh::{FanRings, Topology, TriMesh};
use feature_graph::{classify, keep_groups, Turn};
use glam::{Vec3A, Vec4};
use normal_filter::{filter_face_normals, xyz};
use rayon::prelude::*;
use std::collections::HashMap;

/// Angle scale of the normal filter (length of the difference of unit normals; 0.5 is about 29
/// degrees).
pub const NORMAL_SIGMA: f64 = 0.5;

/// Options of [`detect_creases`].
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct CreaseOptions {
    /// An edge is a feature edge when its two faces' (filtered) normals differ by more than this.
    pub angle_degrees: f64,
    /// Passes of the guided normal filter before the angles are taken (0: the faces' own
    /// normals).
    pub normal_filtering: usize,
    /// Angle scale of the normal filter: the length of the difference of two unit normals at
    /// which a neighbour's weight falls to e^(−1/2) (0.5 is about 29 degrees).
    pub normal_sigma: f64,
    /// Groups of joined feature edges with fewer edges than this are not creases.
    pub min_edges: usize,
    /// A vertex whose two feature edges turn by more than this is a corner.
    pub corner_turn_degrees: f64,
    /// For dropping groups that zigzag: a vertex whose two feature edges' positions turn by more
    /// than this counts as a corner, and a group with more than one such corner per two edges is
    /// no crease. `None` (the default): the angle of the use, [`ZIGZAG_TURN`] for fairing and
    /// [`detect_creases`], [`HIERARCHY_ZIGZAG_TURN`] for the hierarchy.
    pub zigzag_turn_degrees: Option<f64>,
    /// Edges the input file marks as sharp (its normals split there, or two of its materials
    /// meet: [`crate::io::Source::hard_edges`]), each `[a, b]` with `a < b`: feature edges
    /// whatever their angle, never dropped as a small or zigzagging group. Empty: none.
    pub file_edges: std::sync::Arc<[[u32; 2]]>,
}

with_setters!(CreaseOptions {
    with_angle_degrees => angle_degrees: f64,
    with_normal_filtering => normal_filtering: usize,
    with_normal_sigma => normal_sigma: f64,
    with_min_edges => min_edges: usize,
    with_corner_turn_degrees => corner_turn_degrees: f64,
    with_zigzag_turn_degrees => zigzag_turn_degrees: Option<f64>,
});

impl Default for CreaseOptions {
    fn default() -> Self {
        Self {
            angle_degrees: DEFAULT_CREASE_ANGLE,
            normal_filtering: 0,
            normal_sigma: NORMAL_SIGMA,
            min_edges: 8,
            corner_turn_degrees: 70.0,
            zigzag_turn_degrees: None,
            file_edges: std::sync::Arc::from([]),
        }
    }
}

/// [`CreaseOptions::zigzag_turn_degrees`] for fairing (where it is `None`): holding the wandering
/// bends a coarse scan's filtered normals show costs its fairing more than it keeps.
pub const ZIGZAG_TURN: f64 = 55.0;

/// [`CreaseOptions::zigzag_turn_degrees`] for the hierarchy (where it is `None`): there the same
/// bends keep a coarse level's shape (multires from level 9 of the noisy
/// elephant ends 0.35 edge lengths from the clean surface with them, 0.44 without them).
pub const HIERARCHY_ZIGZAG_TURN: f64 = 70.0;

impl CreaseOptions {
    /// `self` with [`file_edges`](Self::file_edges) set to `edges`.
    #[must_use]
    pub fn with_file_edges(mut self, edges: Vec<[u32; 2]>) -> Self {
        self.file_edges = edges.into();
        self
    }
}

/// The default crease angle (degrees): see `docs/measurements.md` for how it was chosen.
pub const DEFAULT_CREASE_ANGLE: f64 = 40.0;

/// What a vertex is with respect to the creases.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FeatureClass {
    /// On no feature edge.
    #[default]
    Smooth,
    /// Inside a chain of feature edges: faired along the chain.
    Crease,
    /// Where chains end, meet or turn sharply: kept in place.
    Corner,
}

/// A run of feature edges: `vertices[k]`–`vertices[k + 1]` are feature edges. An open chain starts
/// and ends at corners; a closed one has only crease vertices (the last joins the first).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chain {
    pub vertices: Vec<u32>,
    pub closed: bool,
}

/// The creases of a mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Creases {
    /// One class per vertex.
    pub class: Vec<FeatureClass>,
    /// The feature edges, lower index first.
    pub edges: Vec<[u32; 2]>,
    pub chains: Vec<Chain>,
}

impl Creases {
    /// Whether vertex `v` is on a crease (a crease vertex or a corner).
    pub fn is_feature(&self, v: u32) -> bool {
        self.class
            .get(v as usize)
            .is_some_and(|&c| c != FeatureClass::Smooth)
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// Number of vertices of each class: (crease, corner).
    pub fn counts(&self) -> (usize, usize) {
        let crease = self
            .class
            .iter()
            .filter(|&&c| c == FeatureClass::Crease)
            .count();
        let corner = self
            .class
            .iter()
            .filter(|&&c| c == FeatureClass::Corner)
            .count();
        (crease, corner)
    }
}

/// Finds the creases of `mesh` (`topology` built from it).
pub fn detect_creases(mesh: &TriMesh, topology: &Topology, options: &CreaseOptions) -> Creases {
    detect_creases_cached(mesh, topology, options, &mut FaceRingCache::default())
}

/// [`detect_creases`] keeping the faces around each face in `cache` for the next detection on
/// the same connectivity.
pub(crate) fn detect_creases_cached(
    mesh: &TriMesh,
    topology: &Topology,
    options: &CreaseOptions,
    cache: &mut FaceRingCache,
) -> Creases {
    let normals = filter_face_normals(
        mesh,
        topology,
        options.normal_filtering,
        options.normal_sigma,
        cache,
    );
    finish(
        mesh,
        topology,
        feature_edges(mesh, topology, &normals, options),
        options,
    )
}

/// The noise estimate and the creases, with the normals filtered at least as much as the
/// estimate asks for ([`super::strength::normal_filtering_for`]), for a caller that has the
/// fan-ordered one-rings (constrained fairing builds them anyway; the hierarchy builds them for
/// this). The estimate's gather finds the feature edges of the faces' own normals at once
/// ([`super::strength::scan_fans`]); when the estimate says the mesh is clean (no filtering),
/// those are the creases' edges, and the guided filter is skipped entirely. Without `estimate`
/// no estimate is made (`None`) and the normals are filtered as `options` say: for a caller that
/// has read the mesh clean and only smooths it further.
pub(crate) fn detect_creases_with_estimate(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    options: &CreaseOptions,
    cache: &mut FaceRingCache,
    estimate: bool,
) -> (Option<f64>, Creases) {
    let scan = scan_fans(mesh, topology, fans, options.angle_degrees, estimate);
    let mut options = options.clone();
    options.normal_filtering = options
        .normal_filtering
        .max(scan.noise.map_or(0, normal_filtering_for));
    let creases = if options.normal_filtering == 0 {
        finish(mesh, topology, scan.edges, &options)
    } else {
        detect_creases_cached(mesh, topology, &options, cache)
    };
    (scan.noise, creases)
}

/// Every feature edge `[v, u]` (v < u, ascending by v then u) with the direction its two faces'
/// normals give it (n_a × n_b, along the crease however noisy the vertex positions are); in
/// parallel over the vertices, each edge found from its lower end.
fn feature_edges(
    mesh: &TriMesh,
    topology: &Topology,
    normals: &[Vec4],
    options: &CreaseOptions,
) -> Vec<FeatureEdge> {
    let threshold = options.angle_degrees.to_radians().cos() as f32;
    (0..mesh.positions.len() as u32)
        .into_par_iter()
        .with_min_len(1024)
        .flat_map_iter(|v| {
            let mut edges = Vec::new();
            vertex_feature_edges(
                mesh,
                topology,
                v,
                |f| xyz(normals[f as usize]),
                threshold,
                &mut edges,
            );
            edges
        })
        .collect()
}
/// The creases from the feature edges: small and zigzagging groups dropped, vertices classified,
/// chains walked.
fn finish(
    mesh: &TriMesh,
    topology: &Topology,
    found: Vec<FeatureEdge>,
    options: &CreaseOptions,
) -> Creases {
    let vertex_count = mesh.positions.len();
    if found.is_empty() && options.file_edges.is_empty() {
        return Creases {
            class: vec![FeatureClass::Smooth; vertex_count],
            ..Creases::default()
        };
    }
    let edges: Vec<[u32; 2]> = found.iter().map(|&(e, _)| e).collect();
    let mut directions: HashMap<[u32; 2], Vec3A> = found.into_iter().collect();
    // Small groups are noise or spikes; so are groups that zigzag (more corners than one per two
    // edges: a true crease, even a noisy one, runs straight between few corners).
    let max_turn = options.corner_turn_degrees.to_radians().cos();
    let min_edges = options.min_edges;
    let edges = keep_groups(edges, vertex_count, None, |edges, _| edges >= min_edges);
    // The zigzag test turns by the edges' positions: noise that lines up into a fake crease
    // zigzags there, while the faces' crease directions may still agree.
    let zigzag_turn = options
        .zigzag_turn_degrees
        .unwrap_or(ZIGZAG_TURN)
        .to_radians()
        .cos();
    let class = classify(topology, &edges, Turn::Positions(mesh), zigzag_turn);
    let mut edges = keep_groups(edges, vertex_count, Some(&class), |edges, corners| {
        2 * corners <= edges
    });
    // The file's own sharp edges join whatever their angle and length; their crease direction is
    // the edge's own (a crease direction lies along its edge).
    if !options.file_edges.is_empty() {
        for &[a, b] in options.file_edges.iter() {
            if a < b && (b as usize) < vertex_count && topology.neighbors(a).contains(&b) {
                edges.push([a, b]);
                directions.entry([a, b]).or_insert_with(|| {
                    let point = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
                    (point(b) - point(a)).normalize_or_zero()
                });
            }
        }
        edges.sort_unstable();
        edges.dedup();
    }
    let class = classify(topology, &edges, Turn::Directions(&directions), max_turn);
    Creases::from_classified(edges, class)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::area_normal;
    use crate::mesh::shapes::{cuboid, cylinder};

    /// The feature edges against every edge's faces counted over the whole mesh: an edge with
    /// three faces (a non-manifold spine) is none however sharp, a folded edge with two is one.
    #[test]
    fn feature_edges_are_the_sharp_edges_with_exactly_two_faces() {
        // Vertices 0-1 the spine; pages to 2, 3, 4 (three faces on the spine); page 0-1-2 folds
        // sharply onto face 1-2-5 along 1-2.
        let mesh = TriMesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, 1.0, 0.0],
                [0.5, -1.0, 0.0],
                [0.5, 0.0, 1.0],
                [1.5, 1.0, 0.9],
            ],
            triangles: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 1, 5]],
        };
        let topology = Topology::build(&mesh);
        let normals: Vec<Vec4> = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(f, _)| area_normal(&mesh, f as u32).normalize().extend(1.0))
            .collect();
        let options = CreaseOptions::default().with_angle_degrees(30.0);
        let found: Vec<[u32; 2]> = feature_edges(&mesh, &topology, &normals, &options)
            .into_iter()
            .map(|(e, _)| e)
            .collect();
        // By brute force: each edge's faces, over all faces.
        let threshold = options.angle_degrees.to_radians().cos() as f32;
        let mut expected = Vec::new();
        for v in 0..6u32 {
            for &u in topology.neighbors(v).iter().filter(|&&u| u > v) {
                let faces: Vec<usize> = (0..mesh.triangles.len())
                    .filter(|&f| mesh.triangles[f].contains(&v) && mesh.triangles[f].contains(&u))
                    .collect();
                if let [a, b] = faces[..] {
                    if xyz(normals[a]).dot(xyz(normals[b])) < threshold {
                        expected.push([v, u]);
                    }
                }
            }
        }
        assert_eq!(found, expected);
        assert_eq!(found, vec![[1, 2]], "the fold, not the spine");
    }

    #[test]
    fn a_box_has_twelve_creases_between_eight_corners() {
        let mesh = cuboid([2.0, 1.0, 0.5], 0.1);
        let topology = Topology::build(&mesh);
        let creases = detect_creases(&mesh, &topology, &CreaseOptions::default());
        let (crease, corner) = creases.counts();
        assert_eq!(corner, 8);
        assert_eq!(creases.chains.len(), 12);
        assert!(creases.chains.iter().all(|c| !c.closed));
        // 4·(20 + 10 + 5) edges along the box's edges, their inner vertices crease vertices.
        assert_eq!(creases.edges.len(), 4 * 35);
        assert_eq!(crease, 4 * 35 - 12);
    }

    /// The path constrained fairing and the hierarchy take (the estimate's gather over the fans
    /// finds the feature edges of the faces' own normals, and the guided filter is skipped on a
    /// clean mesh) gives the creases the general path gives, and filters like it on a noisy one.
    #[test]
    fn the_fan_scan_finds_the_creases_the_general_path_finds() {
        use crate::fairing::strength::{estimate_noise, normal_filtering_for};
        use crate::noise::{add_noise, NoiseOptions};
        let mut noisy = cuboid([1.0, 1.0, 1.0], 0.05);
        add_noise(&mut noisy, &NoiseOptions::default().with_sigma(0.3));
        for mesh in [cuboid([2.0, 1.0, 0.5], 0.1), cylinder(1.0, 1.0, 0.1), noisy] {
            let topology = Topology::build(&mesh);
            let fans = FanRings::new(&mesh.triangles, &topology);
            let options = CreaseOptions::default();
            let (estimate, creases) = detect_creases_with_estimate(
                &mesh,
                &topology,
                &fans,
                &options,
                &mut FaceRingCache::default(),
                true,
            );
            let general_estimate = estimate_noise(&mesh, &topology).unwrap();
            let estimate = estimate.unwrap();
            assert!(
                (estimate - general_estimate).abs() < 1e-5,
                "{estimate} {general_estimate}"
            );
            let filtering = normal_filtering_for(estimate);
            let general = detect_creases(
                &mesh,
                &topology,
                &options.clone().with_normal_filtering(filtering),
            );
            assert!(!creases.is_empty());
            assert_eq!(creases, general, "filtering {filtering}");
            // And without filtering the scan's raw edges are the general path's.
            let raw = scan_fans(&mesh, &topology, &fans, options.angle_degrees, true).edges;
            // The same without the estimate.
            let alone = scan_fans(&mesh, &topology, &fans, options.angle_degrees, false);
            assert_eq!(alone.noise, None);
            assert_eq!(alone.edges, raw);
            let general: Vec<[u32; 2]> = {
                let unit =
                    filter_face_normals(&mesh, &topology, 0, 0.5, &mut FaceRingCache::default());
                feature_edges(&mesh, &topology, &unit, &options)
                    .into_iter()
                    .map(|(e, _)| e)
                    .collect()
            };
            assert_eq!(raw.into_iter().map(|(e, _)| e).collect::<Vec<_>>(), general);
        }
    }

    #[test]
    fn a_cylinder_has_two_closed_creases_and_no_corner() {
        let mesh = cylinder(1.0, 1.0, 0.1);
        let topology = Topology::build(&mesh);
        let creases = detect_creases(&mesh, &topology, &CreaseOptions::default());
        assert_eq!(creases.counts().1, 0);
        assert_eq!(creases.chains.len(), 2);
        assert!(creases
            .chains
            .iter()
            .all(|c| c.closed && c.vertices.len() == 63));
        // The side's own edges turn by 360/63 degrees: smooth.
        let sharper = CreaseOptions::default().with_angle_degrees(3.0);
        assert!(detect_creases(&mesh, &topology, &sharper).edges.len() > 2 * 63);
    }

    /// A group of feature edges that turns by 60° at every vertex (a bend of a coarse scan that
    /// the filter sharpened wanders so) is no crease, while a straight one beside it is; with
    /// the classes' 70° as the zigzag test's corner turn, the wandering group would be kept.
    #[test]
    fn a_group_that_turns_sixty_degrees_at_every_vertex_is_no_crease() {
        // A flat lattice of equilateral triangles: the grid fixture sheared (its diagonals from
        // (x, y) to (x + 1, y + 1) then have unit length too).
        let n = 16;
        let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
        let mut mesh = crate::mesh::fixtures::grid(n);
        for p in &mut mesh.positions {
            p[0] -= 0.5 * p[1];
            p[1] *= 3f32.sqrt() / 2.0;
        }
        let topology = Topology::build(&mesh);
        // Straight: along row 2, 12 edges. Wandering: up from (8, 4), alternately to (x, y + 1)
        // (at 120°) and (x + 1, y + 1) (at 60°), 12 edges, each turning 60° from the last.
        let straight: Vec<u32> = (2..=14).map(|x| at(x, 2)).collect();
        let mut wandering = vec![at(8, 4)];
        let (mut x, mut y) = (8, 4);
        for step in 0..12 {
            if step % 2 == 1 {
                x += 1;
            }
            y += 1;
            wandering.push(at(x, y));
        }
        let point = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
        let mut found: Vec<FeatureEdge> = [&straight, &wandering]
            .iter()
            .flat_map(|path| path.windows(2))
            .map(|w| {
                assert!(topology.neighbors(w[0]).contains(&w[1]));
                let direction = (point(w[1]) - point(w[0])).normalize();
                ([w[0].min(w[1]), w[0].max(w[1])], direction)
            })
            .collect();
        found.sort_unstable_by_key(|&(e, _)| e);
        let on = |creases: &Creases, path: &[u32]| {
            path.windows(2)
                .filter(|w| creases.edges.contains(&[w[0].min(w[1]), w[0].max(w[1])]))
                .count()
        };
        let options = CreaseOptions::default();
        let creases = finish(&mesh, &topology, found.clone(), &options);
        assert_eq!(on(&creases, &straight), 12);
        assert_eq!(on(&creases, &wandering), 0);
        let seventy = options.with_zigzag_turn_degrees(Some(70.0));
        let creases = finish(&mesh, &topology, found, &seventy);
        assert_eq!(on(&creases, &straight), 12);
        assert_eq!(on(&creases, &wandering), 12);
    }
}
