//! The feature graph: the feature edges joined at their vertices, the groups they form (small
//! and zigzagging ones dropped, [`keep_groups`]), every vertex classed smooth, crease or corner by
//! how its feature edges turn ([`classify`]), and the chains walked from the corners
//! ([`Creases::from_classified`]).

use super::{Chain, Creases, FeatureClass};
use crate::mesh::{Topology, TriMesh};
use glam::Vec3A;
use std::collections::HashMap;

impl Creases {
    /// The creases given by their feature edges (each once, lower index first) and every
    /// vertex's class: the chains are walked from the corners along the feature edges, then the
    /// closed loops of crease vertices that remain. A vertex classed `Crease` must have exactly
    /// two feature edges (one with another number is taken as a corner).
    pub fn from_classified(edges: Vec<[u32; 2]>, mut class: Vec<FeatureClass>) -> Creases {
        let graph = FeatureGraph::new(&edges, class.len());
        settle_classes(&graph, &mut class);
        let chains = walk_chains(&graph, &class);
        // A closed crease of a few vertices is no curve the section 3.3 constraints can fair (its
        // vertices run together, leaving faces with no area, in multires from coarse levels): it
        // is held in place, as corners are, and its edges become chains between them.
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

/// The classes `graph` allows: a vertex with no feature edge is smooth; one classed `Crease`
/// with two stays a crease vertex; any other with feature edges is a corner.
fn settle_classes(graph: &FeatureGraph, class: &mut [FeatureClass]) {
    for (v, c) in class.iter_mut().enumerate() {
        if *c != FeatureClass::Smooth && graph.index(v as u32).is_none() {
            *c = FeatureClass::Smooth;
        }
    }
    for (i, &v) in graph.vertices.list.iter().enumerate() {
        let c = &mut class[v as usize];
        *c = match (*c, graph.neighbors_at(i).len()) {
            (FeatureClass::Crease, 2) => FeatureClass::Crease,
            _ => FeatureClass::Corner,
        };
    }
}

/// The chains of `graph`'s feature edges: walked from every corner along each of its feature
/// edges to the next corner (open), then around the loops of crease vertices that remain
/// (closed); every edge in one chain.
fn walk_chains(graph: &FeatureGraph, class: &[FeatureClass]) -> Vec<Chain> {
    let mut used = vec![false; graph.adjacent.len()];
    let slot = |from: u32, to: u32| -> usize {
        let i = graph.index(from).expect("a feature edge's end is listed");
        graph.offsets[i] as usize
            + graph
                .neighbors_at(i)
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
            let next = graph
                .neighbors(current)
                .iter()
                .copied()
                .find(|&u| u != previous)
                .expect("a crease vertex has two feature edges");
            (previous, current) = (current, next);
        }
    };
    let mut chains = Vec::new();
    for (i, &v) in graph.vertices.list.iter().enumerate() {
        if class[v as usize] == FeatureClass::Corner {
            for &u in graph.neighbors_at(i) {
                chains.extend(walk(v, u, &mut used));
            }
        }
    }
    for (i, &v) in graph.vertices.list.iter().enumerate() {
        if class[v as usize] == FeatureClass::Crease {
            let first = graph.neighbors_at(i)[0];
            chains.extend(walk(v, first, &mut used));
        }
    }
    chains
}

/// Closed creases with fewer vertices than this are held in place.
pub const MIN_FAIRED_LOOP: usize = 8;

/// The vertices on feature edges, each with a place of its own (0, 1, …), so that what is kept
/// per vertex need not be of the mesh's size (a detection on a mesh of 600k vertices with a
/// hundred feature edges touches a few hundred entries).
struct FeatureVertices {
    /// The vertices with a feature edge, ascending: `list[place]`.
    list: Vec<u32>,
    /// With many edges, every vertex's place (`u32::MAX`: none).
    table: Option<Vec<u32>>,
}

impl FeatureVertices {
    /// The ends of `edges`, between vertices numbered below `vertex_count`.
    fn new(edges: &[[u32; 2]], vertex_count: usize) -> FeatureVertices {
        // Few edges (a detection on a clean or faired mesh): the vertices sorted, found by
        // bisection. Many (the faces' own normals of a noisy scan make an edge of a quarter of
        // its edges): a table of the mesh's size finds them at once.
        if 32 * edges.len() < vertex_count {
            let mut list: Vec<u32> = edges.iter().flatten().copied().collect();
            list.sort_unstable();
            list.dedup();
            FeatureVertices { list, table: None }
        } else {
            let mut table = vec![u32::MAX; vertex_count];
            for &v in edges.iter().flatten() {
                table[v as usize] = 0;
            }
            let mut list = Vec::new();
            for (v, place) in table.iter_mut().enumerate() {
                if *place == 0 {
                    *place = list.len() as u32;
                    list.push(v as u32);
                }
            }
            FeatureVertices {
                list,
                table: Some(table),
            }
        }
    }

    /// The place of vertex `v`, if it has a feature edge.
    fn place(&self, v: u32) -> Option<usize> {
        match &self.table {
            Some(table) => table
                .get(v as usize)
                .filter(|&&place| place != u32::MAX)
                .map(|&place| place as usize),
            None => self.list.binary_search(&v).ok(),
        }
    }

    /// The places of both ends of an edge whose ends are listed.
    fn ends(&self, [a, b]: [u32; 2]) -> [usize; 2] {
        [a, b].map(|v| self.place(v).expect("an edge's ends are listed"))
    }
}

/// The vertices on feature edges and their feature neighbours.
struct FeatureGraph {
    vertices: FeatureVertices,
    /// `adjacent[offsets[i]..offsets[i + 1]]`: the feature neighbours of the vertex at place i,
    /// in the order of the edges.
    offsets: Vec<u32>,
    adjacent: Vec<u32>,
}

impl FeatureGraph {
    /// The graph of `edges` between vertices numbered below `vertex_count`.
    fn new(edges: &[[u32; 2]], vertex_count: usize) -> FeatureGraph {
        let vertices = FeatureVertices::new(edges, vertex_count);
        let mut offsets = vec![0u32; vertices.list.len() + 1];
        for &e in edges {
            for end in vertices.ends(e) {
                offsets[end + 1] += 1;
            }
        }
        for i in 0..vertices.list.len() {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut adjacent = vec![0; 2 * edges.len()];
        for &[a, b] in edges {
            let [ia, ib] = vertices.ends([a, b]);
            adjacent[fill[ia] as usize] = b;
            fill[ia] += 1;
            adjacent[fill[ib] as usize] = a;
            fill[ib] += 1;
        }
        FeatureGraph {
            vertices,
            offsets,
            adjacent,
        }
    }

    /// The place of vertex `v`, if it has a feature edge.
    fn index(&self, v: u32) -> Option<usize> {
        self.vertices.place(v)
    }

    /// The feature neighbours of the `i`-th listed vertex.
    fn neighbors_at(&self, i: usize) -> &[u32] {
        &self.adjacent[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// The feature neighbours of vertex `v` (none if it has no feature edge).
    fn neighbors(&self, v: u32) -> &[u32] {
        self.index(v).map_or(&[], |i| self.neighbors_at(i))
    }
}

/// How the turn at a vertex with two feature edges is measured.
pub(super) enum Turn<'a> {
    /// Between the edges themselves (from the vertex positions).
    Positions(&'a TriMesh),
    /// Between the edges' crease directions (from their faces' filtered normals).
    Directions(&'a HashMap<[u32; 2], Vec3A>),
}

/// Every vertex's class, from its feature edges.
pub(super) fn classify(
    topology: &Topology,
    edges: &[[u32; 2]],
    turn: Turn,
    max_turn: f64,
) -> Vec<FeatureClass> {
    let graph = FeatureGraph::new(edges, topology.vertex_count());
    let mut class = vec![FeatureClass::Smooth; topology.vertex_count()];
    for (i, &v) in graph.vertices.list.iter().enumerate() {
        class[v as usize] = match graph.neighbors_at(i) {
            _ if topology.is_boundary_vertex(v) => FeatureClass::Corner,
            &[a, b] => {
                let straight = match &turn {
                    Turn::Positions(mesh) => {
                        let x = mesh.point(v);
                        let incoming = (x - mesh.point(a)).normalize_or_zero();
                        let outgoing = (mesh.point(b) - x).normalize_or_zero();
                        incoming.dot(outgoing)
                    }
                    // The signs of crease directions are arbitrary.
                    Turn::Directions(directions) => {
                        let key = |u: u32| [u.min(v), u.max(v)];
                        directions[&key(a)].dot(directions[&key(b)]).abs() as f64
                    }
                };
                if straight >= max_turn {
                    FeatureClass::Crease
                } else {
                    FeatureClass::Corner
                }
            }
            _ => FeatureClass::Corner,
        };
    }
    class
}

/// The feature edges whose group (edges joined at shared vertices) `keep(edges, corners)` accepts;
/// corners are counted from `class` when given.
pub(super) fn keep_groups(
    edges: Vec<[u32; 2]>,
    vertex_count: usize,
    class: Option<&[FeatureClass]>,
    keep: impl Fn(usize, usize) -> bool,
) -> Vec<[u32; 2]> {
    if edges.is_empty() {
        return edges;
    }
    // Union-find over the feature vertices' places.
    let vertices = FeatureVertices::new(&edges, vertex_count);
    let mut parent: Vec<u32> = (0..vertices.list.len() as u32).collect();
    fn root(parent: &mut [u32], mut v: usize) -> usize {
        while parent[v] as usize != v {
            parent[v] = parent[parent[v] as usize];
            v = parent[v] as usize;
        }
        v
    }
    let mut roots = Vec::with_capacity(edges.len());
    for &e in &edges {
        let [a, b] = vertices.ends(e);
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb)] = ra.min(rb) as u32;
        }
        roots.push(a);
    }
    let mut edge_count = vec![0u32; vertices.list.len()];
    let mut corner_count = vec![0u32; vertices.list.len()];
    for r in &mut roots {
        *r = root(&mut parent, *r);
        edge_count[*r] += 1;
    }
    if let Some(class) = class {
        for (i, &v) in vertices.list.iter().enumerate() {
            if class[v as usize] == FeatureClass::Corner {
                corner_count[root(&mut parent, i)] += 1;
            }
        }
    }
    edges
        .into_iter()
        .zip(roots)
        .filter(|&(_, r)| keep(edge_count[r] as usize, corner_count[r] as usize))
        .map(|(e, _)| e)
        .collect()
}
