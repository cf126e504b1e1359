//! Sharp creases: which edges are feature edges, which vertices lie on them, and the chains they
//! form, so that fairing can treat a crease like the paper treats a boundary (section 3.3).
//!
//! Not in the paper, which fairs every interior vertex alike and so rounds every sharp edge of a
//! CAD part. The reading here: a crease is a boundary between two surface patches. Each patch is
//! faired with the crease as its boundary (a triangle touching a crease vertex is not solved, as a
//! triangle touching the boundary is not), each chain of crease edges is faired as a curve with
//! the paper's edge-centre constraints of section 3.3 (open chains between two fixed ends, closed
//! loops like boundary loops), and the corners stay where they are.
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
//!   themselves) was tried first: on a cube with noise of 0.3 edge lengths it found six times
//!   too many crease edges, and thousands on the noisy bunny, which has none.
//! - Feature edges that form small groups (fewer than [`CreaseOptions::min_edges`] edges joined at
//!   their ends) are dropped, and so are groups that zigzag (more than one corner per two edges):
//!   noise and single spikes of a scan make those, while a crease runs straight between a few
//!   corners (for this test a corner is where the edges themselves turn sharply).
//! - A crease vertex has exactly two feature edges whose crease directions (the cross product of
//!   each edge's two filtered face normals: on a noisy crease the vertices zigzag, the faces on
//!   either side do not) turn by less than [`CreaseOptions::corner_turn_degrees`]; any other vertex with feature edges is a corner (the
//!   end of a crease, three or more creases meeting, a sharp turn, or a crease meeting the
//!   boundary) and is held fixed.

use crate::mesh::{Topology, TriMesh};
use glam::DVec3;
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
}

with_setters!(CreaseOptions {
    with_angle_degrees => angle_degrees: f64,
    with_normal_filtering => normal_filtering: usize,
    with_normal_sigma => normal_sigma: f64,
    with_min_edges => min_edges: usize,
    with_corner_turn_degrees => corner_turn_degrees: f64,
});

impl Default for CreaseOptions {
    fn default() -> Self {
        Self {
            angle_degrees: DEFAULT_CREASE_ANGLE,
            normal_filtering: 0,
            normal_sigma: NORMAL_SIGMA,
            min_edges: 8,
            corner_turn_degrees: 70.0,
        }
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

/// Unit face normals, filtered `passes` times (see the module docs): each pass takes, for every
/// face, a guidance normal (the mean normal of the most consistent patch that contains it), then
/// averages the normals of the faces around it weighted by area and by how close their guidance
/// normals are to its own.
pub fn filtered_face_normals(
    mesh: &TriMesh,
    topology: &Topology,
    passes: usize,
    sigma: f64,
) -> Vec<DVec3> {
    let face_count = mesh.triangles.len();
    let (mut normals, areas): (Vec<DVec3>, Vec<f64>) = (0..face_count)
        .into_par_iter()
        .map(|f| {
            let n = mesh.face_normal(f);
            let length = n.length();
            if length > 0.0 && length.is_finite() {
                (n / length, length)
            } else {
                (DVec3::ZERO, 0.0)
            }
        })
        .unzip();
    // The faces sharing a vertex with f (f included; a face sharing an edge appears twice).
    let around = |f: usize| {
        mesh.triangles[f]
            .iter()
            .flat_map(|&c| topology.faces_of(c).iter().map(|&g| g as usize))
    };
    let inverse = 1.0 / (2.0 * sigma * sigma);
    for _ in 0..passes {
        let current = &normals;
        // Each patch (the faces around a face): its area-weighted mean normal and how much its
        // normals disagree (the largest difference from the mean).
        let patches: Vec<(DVec3, f64)> = (0..face_count)
            .into_par_iter()
            .map(|f| {
                let mean = around(f)
                    .map(|g| current[g] * areas[g])
                    .sum::<DVec3>()
                    .try_normalize()
                    .unwrap_or(current[f]);
                let spread = around(f)
                    .map(|g| (current[g] - mean).length_squared())
                    .fold(0.0, f64::max);
                (mean, spread)
            })
            .collect();
        // Guidance: the mean of the most consistent patch among those containing f.
        let guidance: Vec<DVec3> = (0..face_count)
            .into_par_iter()
            .map(|f| {
                around(f)
                    .map(|g| patches[g])
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map_or(current[f], |(mean, _)| mean)
            })
            .collect();
        normals = (0..face_count)
            .into_par_iter()
            .map(|f| {
                let own = guidance[f];
                let mut sum = DVec3::ZERO;
                for g in around(f) {
                    let d = (guidance[g] - own).length_squared();
                    sum += current[g] * (areas[g] * (-d * inverse).exp());
                }
                sum.try_normalize().unwrap_or(current[f])
            })
            .collect();
    }
    normals
}

/// Finds the creases of `mesh` (`topology` built from it).
pub fn detect_creases(mesh: &TriMesh, topology: &Topology, options: &CreaseOptions) -> Creases {
    let vertex_count = mesh.positions.len();
    let normals = filtered_face_normals(
        mesh,
        topology,
        options.normal_filtering,
        options.normal_sigma,
    );
    let threshold = options.angle_degrees.to_radians().cos();
    // Feature edges, found from their lower end: the faces both ends share.
    // Each feature edge with the direction its two faces' normals give it (n_a × n_b, along the
    // crease however noisy the vertex positions are).
    let found: Vec<([u32; 2], DVec3)> = (0..vertex_count as u32)
        .into_par_iter()
        .with_min_len(1024)
        .flat_map_iter(|v| {
            // The faces of an edge v-u are among v's own: no other vertex's list is searched.
            let faces_v = topology.faces_of(v);
            let normals = &normals;
            faces_v.iter().enumerate().flat_map(move |(i, &f)| {
                mesh.triangles[f as usize]
                    .into_iter()
                    .filter(move |&u| u > v)
                    .filter_map(move |u| {
                        // Each edge once: from the first of its faces in v's list.
                        let has_u = |g: &u32| mesh.triangles[*g as usize].contains(&u);
                        if faces_v[..i].iter().any(has_u) {
                            return None;
                        }
                        let mut others = faces_v[i + 1..].iter().filter(|g| has_u(g));
                        let (Some(&g), None) = (others.next(), others.next()) else {
                            return None;
                        };
                        let (na, nb) = (normals[f as usize], normals[g as usize]);
                        (na != DVec3::ZERO && nb != DVec3::ZERO && na.dot(nb) < threshold)
                            .then(|| ([v, u], na.cross(nb).normalize_or_zero()))
                    })
            })
        })
        .collect();
    let edges: Vec<[u32; 2]> = found.iter().map(|&(e, _)| e).collect();
    let directions: HashMap<[u32; 2], DVec3> = found.into_iter().collect();
    // Small groups are noise or spikes; so are groups that zigzag (more corners than one per two
    // edges: a true crease, even a noisy one, runs straight between few corners).
    let max_turn = options.corner_turn_degrees.to_radians().cos();
    let min_edges = options.min_edges;
    let edges = keep_groups(edges, vertex_count, None, |edges, _| edges >= min_edges);
    // The zigzag test turns by the edges' positions: noise that lines up into a fake crease
    // zigzags there, while the faces' crease directions may still agree.
    let class = classify(topology, &edges, Turn::Positions(mesh), max_turn);
    let edges = keep_groups(edges, vertex_count, Some(&class), |edges, corners| {
        2 * corners <= edges
    });
    let class = classify(topology, &edges, Turn::Directions(&directions), max_turn);
    Creases::from_classified(edges, class)
}

impl Creases {
    /// The creases given by their feature edges (each once, lower index first) and every
    /// vertex's class: the chains are walked from the corners along the feature edges, then the
    /// closed loops of crease vertices that remain. A vertex classed `Crease` must have exactly
    /// two feature edges (one with another number is taken as a corner).
    pub fn from_classified(edges: Vec<[u32; 2]>, mut class: Vec<FeatureClass>) -> Creases {
        let vertex_count = class.len();
        let (offsets, adjacent) = feature_neighbors(&edges, vertex_count);
        let feature_neighbors =
            |v: u32| &adjacent[offsets[v as usize] as usize..offsets[v as usize + 1] as usize];
        for (v, c) in class.iter_mut().enumerate() {
            let count = feature_neighbors(v as u32).len();
            *c = match (*c, count) {
                (_, 0) => FeatureClass::Smooth,
                (FeatureClass::Crease, 2) => FeatureClass::Crease,
                _ => FeatureClass::Corner,
            };
        }
        let mut used = vec![false; adjacent.len()];
        let slot = |from: u32, to: u32| -> usize {
            let start = offsets[from as usize] as usize;
            start
                + feature_neighbors(from)
                    .iter()
                    .position(|&u| u == to)
                    .expect("a feature edge is listed at both ends")
        };
        let walk = |start: u32, first: u32, used: &mut Vec<bool>| -> Option<Chain> {
            if used[slot(start, first)] {
                return None;
            }
            let mut vertices = vec![start];
            let (mut previous, mut current) = (start, first);
            loop {
                used[slot(previous, current)] = true;
                used[slot(current, previous)] = true;
                if current == start {
                    return Some(Chain {
                        vertices,
                        closed: true,
                    });
                }
                vertices.push(current);
                if class[current as usize] != FeatureClass::Crease {
                    return Some(Chain {
                        vertices,
                        closed: false,
                    });
                }
                let next = feature_neighbors(current)
                    .iter()
                    .copied()
                    .find(|&u| u != previous)
                    .expect("a crease vertex has two feature edges");
                (previous, current) = (current, next);
            }
        };
        let mut chains = Vec::new();
        for v in 0..vertex_count as u32 {
            if class[v as usize] == FeatureClass::Corner {
                for &u in feature_neighbors(v) {
                    chains.extend(walk(v, u, &mut used));
                }
            }
        }
        for v in 0..vertex_count as u32 {
            if class[v as usize] == FeatureClass::Crease {
                let first = feature_neighbors(v)[0];
                chains.extend(walk(v, first, &mut used));
            }
        }
        // A closed crease of a few vertices is no curve the section 3.3 constraints can fair (in
        // multires from coarse levels its vertices were seen to run together, leaving faces with
        // no area): it is held in place, as corners are, and its edges become chains between them.
        if chains
            .iter()
            .any(|c| c.closed && c.vertices.len() < MIN_FAIRED_LOOP)
        {
            for chain in chains
                .iter()
                .filter(|c| c.closed && c.vertices.len() < MIN_FAIRED_LOOP)
            {
                for &v in &chain.vertices {
                    class[v as usize] = FeatureClass::Corner;
                }
            }
            return Creases::from_classified(edges, class);
        }
        Creases {
            class,
            edges,
            chains,
        }
    }
}

/// Closed creases with fewer vertices than this are held in place.
pub const MIN_FAIRED_LOOP: usize = 8;

/// The feature neighbours of every vertex: CSR offsets and entries.
fn feature_neighbors(edges: &[[u32; 2]], vertex_count: usize) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; vertex_count + 1];
    for e in edges {
        offsets[e[0] as usize + 1] += 1;
        offsets[e[1] as usize + 1] += 1;
    }
    for v in 0..vertex_count {
        offsets[v + 1] += offsets[v];
    }
    let mut fill = offsets.clone();
    let mut adjacent = vec![0u32; 2 * edges.len()];
    for &[a, b] in edges {
        adjacent[fill[a as usize] as usize] = b;
        fill[a as usize] += 1;
        adjacent[fill[b as usize] as usize] = a;
        fill[b as usize] += 1;
    }
    (offsets, adjacent)
}

/// How the turn at a vertex with two feature edges is measured.
enum Turn<'a> {
    /// Between the edges themselves (from the vertex positions).
    Positions(&'a TriMesh),
    /// Between the edges' crease directions (from their faces' filtered normals).
    Directions(&'a HashMap<[u32; 2], DVec3>),
}

/// Every vertex's class, from its feature edges.
fn classify(
    topology: &Topology,
    edges: &[[u32; 2]],
    turn: Turn,
    max_turn: f64,
) -> Vec<FeatureClass> {
    let vertex_count = topology.vertex_count();
    let (offsets, adjacent) = feature_neighbors(edges, vertex_count);
    (0..vertex_count)
        .map(
            |v| match &adjacent[offsets[v] as usize..offsets[v + 1] as usize] {
                [] => FeatureClass::Smooth,
                _ if topology.is_boundary_vertex(v as u32) => FeatureClass::Corner,
                &[a, b] => {
                    let straight = match &turn {
                        Turn::Positions(mesh) => {
                            let x = mesh.point(v as u32);
                            let incoming = (x - mesh.point(a)).normalize_or_zero();
                            let outgoing = (mesh.point(b) - x).normalize_or_zero();
                            incoming.dot(outgoing)
                        }
                        // The signs of crease directions are arbitrary.
                        Turn::Directions(directions) => {
                            let key = |u: u32| [u.min(v as u32), u.max(v as u32)];
                            directions[&key(a)].dot(directions[&key(b)]).abs()
                        }
                    };
                    if straight >= max_turn {
                        FeatureClass::Crease
                    } else {
                        FeatureClass::Corner
                    }
                }
                _ => FeatureClass::Corner,
            },
        )
        .collect()
}

/// The feature edges whose group (edges joined at shared vertices) `keep(edges, corners)` accepts;
/// corners are counted from `class` when given.
fn keep_groups(
    edges: Vec<[u32; 2]>,
    vertex_count: usize,
    class: Option<&[FeatureClass]>,
    keep: impl Fn(usize, usize) -> bool,
) -> Vec<[u32; 2]> {
    if edges.is_empty() {
        return edges;
    }
    let mut parent: Vec<u32> = (0..vertex_count as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    for &[a, b] in &edges {
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    let mut edge_count = vec![0usize; vertex_count];
    let mut corner_count = vec![0usize; vertex_count];
    let roots: Vec<u32> = edges.iter().map(|e| root(&mut parent, e[0])).collect();
    for &r in &roots {
        edge_count[r as usize] += 1;
    }
    if let Some(class) = class {
        for v in 0..vertex_count {
            if class[v] == FeatureClass::Corner {
                corner_count[root(&mut parent, v as u32) as usize] += 1;
            }
        }
    }
    edges
        .into_iter()
        .zip(roots)
        .filter(|&(_, r)| keep(edge_count[r as usize], corner_count[r as usize]))
        .map(|(e, _)| e)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes::{cuboid, cylinder};

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
}
