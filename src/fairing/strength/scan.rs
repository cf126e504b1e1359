//! The fused scan over the fan-ordered one-rings behind the noise estimate and crease detection:
//! in one gather, every vertex's h_v (the normal part of its umbrella vector) and the mean edge
//! length, and the feature edges of the faces' own normals ([`crate::fairing::feature_edges`]);
//! then the robust spread of h's residuals. A hot kernel (its gather stays one function so each
//! vertex's ring is read once for all three).

use crate::fairing::feature_edges::{
    fan_feature_edges, fan_feature_neighbors, vertex_feature_edges, FeatureEdge,
};
use crate::mesh::{area_normal, FanRings, Topology, TriMesh};
use glam::Vec3A;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The spread of r_v (see the module docs) for unit Gaussian noise along the normals: measured
/// on flat and gently curved valence-6 meshes, and on `bunny00` with σ = 0.3 (the estimate then
/// reads 0.3).
pub const NOISE_GAIN: f64 = 1.5;

/// What [`scan_fans`] finds.
pub(crate) struct FanScan {
    /// [`estimate_noise`].
    pub noise: Option<f64>,
    /// The feature edges of the faces' own normals at the crease angle asked for, as
    /// [`super::creases::detect_creases`] finds them with no normal filtering.
    pub edges: Vec<FeatureEdge>,
}

/// The noise estimate and, at once, the feature edges at `crease_angle` (degrees) of the faces'
/// own normals (what crease detection needs when the estimate says the mesh is clean; a caller
/// whose mesh turns out noisy filters the normals and finds them again), in one gather over the
/// fan-ordered one-rings: a vertex with a closed fan takes its normal from the ring it reads for
/// the umbrella, Σ (x_k − x) × (x_(k+1) − x) (the sum of its faces' area normals), and its faces'
/// normals from consecutive offsets, so it reads no face at all. The other vertices (on a
/// boundary, or whose faces are no single oriented fan) read their faces.
///
/// Without `estimate` only the feature edges are found (`noise` is `None`): a caller that has
/// read the mesh clean once and only smooths it further (constrained fairing's later rounds)
/// saves the estimate's share, about a fifth of the gather and its median.
pub(crate) fn scan_fans(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    crease_angle: f64,
    estimate: bool,
) -> FanScan {
    let (heights, edges) = gather(
        mesh,
        topology,
        Some(fans),
        Some(crease_angle),
        None,
        estimate,
    );
    FanScan {
        noise: heights.and_then(|h| h.spread(topology, LeftOut::Nothing)),
        edges,
    }
}

/// Vertices per block of the estimate's gather (each block's edge-length sum and feature edges
/// are kept apart and joined in order, so nothing depends on the thread count).
pub(super) const VERTEX_BLOCK: usize = 4096;

/// The sine of the angle between two faces' normals below which their edge counts as flat, its
/// four corners as untouched by noise ([`Marks::exact`]): 0.06°. Noise of 0.04 mean edge lengths
/// along the normals (the least [`super::CLEAN_NOISE`] reads as noise) tilts two fair triangles
/// apart by about 3°, fifty times more, so on a noisy mesh only a few edges in a hundred come
/// out flat by chance; rounding positions to f32 tilts them by about 1e-7 over 1e-4 of an
/// edge's length relative to the coordinates, so a flat CAD face stays flat.
pub(super) const FLAT_SINE: f32 = 1e-3;

/// Per-vertex marks the gather sets for [`super::NoiseReading`].
pub(super) struct Marks {
    /// An end of a sharp edge (an edge where the faces' own normals turn by more than the crease
    /// angle).
    pub on_edge: Vec<AtomicBool>,
    /// A corner of a flat edge: one whose two faces lie in one plane, to [`FLAT_SINE`]. Noise
    /// moves each vertex on its own, so four vertices that still lie in one plane were not moved
    /// across it: a CAD part's flat faces and the quads of its curved ones (each two triangles in
    /// one plane) mark every one of their vertices, a noisy surface almost none.
    pub exact: Vec<AtomicBool>,
}

impl Marks {
    /// No vertex marked, for `n` vertices.
    pub fn new(n: usize) -> Self {
        let none = || {
            (0..n)
                .into_par_iter()
                .with_min_len(VERTEX_BLOCK)
                .map(|_| AtomicBool::new(false))
                .collect()
        };
        Marks {
            on_edge: none(),
            exact: none(),
        }
    }

    /// Marks the corners of the flat edges (v, u) with u > v of v's closed fan: `faces[k]` is the
    /// area normal of the face (v, ring[k − 1], ring[k]), so faces k and k + 1 share the edge
    /// (v, ring[k]), and their corners are v and ring[k − 1], ring[k], ring[k + 1].
    fn mark_flat_edges(&self, v: u32, ring: &[u32], faces: &[Vec3A]) {
        let n = ring.len();
        for (k, &u) in ring.iter().enumerate() {
            let (a, b) = (faces[k], faces[(k + 1) % n]);
            let scale = a.length_squared() * b.length_squared();
            if u > v
                && a.dot(b) > 0.0
                && scale > 0.0
                && scale.is_finite()
                && a.cross(b).length_squared() <= FLAT_SINE * FLAT_SINE * scale
            {
                for w in [v, ring[(k + n - 1) % n], u, ring[(k + 1) % n]] {
                    self.exact[w as usize].store(true, Ordering::Relaxed);
                }
            }
        }
    }
}

/// Every vertex's h_v and the mean edge length, from one gather (see the module docs).
pub(super) struct Heights {
    /// h_v, NaN where it is not defined.
    heights: Vec<f32>,
    /// The mean edge length (positive and finite).
    edge: f64,
}

/// The gather behind the estimates: [`Heights`] (`None` when the mean edge length is not
/// positive and finite; the mean edge length is summed in the same gather, as
/// [`crate::metrics::mean_edge_length`] defines it) and, with a crease angle, the feature edges,
/// or, with `marks` too, no list but both ends of every feature edge marked in `marks.on_edge`
/// and the four corners of every flat edge in `marks.exact` ([`Marks`]). Without `want_heights`
/// no heights are taken (`None`).
pub(super) fn gather(
    mesh: &TriMesh,
    topology: &Topology,
    fans: Option<&FanRings>,
    crease_angle: Option<f64>,
    marks: Option<&Marks>,
    want_heights: bool,
) -> (Option<Heights>, Vec<FeatureEdge>) {
    let n = mesh.positions.len();
    let point = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
    let ring_offsets = topology.neighbor_csr().0;
    let threshold = crease_angle.map(|angle| angle.to_radians().cos() as f32);
    let mut heights = vec![0.0f32; n];
    // Per vertex: h_v (NaN where it is not defined: an open fan, fewer than three neighbours, no
    // normal); its share of the edge lengths (half of each of its faces' two edges at v, so that
    // the shares add up to the faces' edge lengths); its feature edges.
    let blocks: Vec<(f64, Vec<FeatureEdge>)> = heights
        .par_chunks_mut(VERTEX_BLOCK)
        .enumerate()
        .map(|(b, out)| {
            let mut edge_sum = 0.0f64;
            let mut edges = Vec::new();
            let mut d = [Vec3A::ZERO; 64];
            // faces[k]: the area normal of face (v, x_(k−1), x_k).
            let mut faces = [Vec3A::ZERO; 64];
            for (i, h) in out.iter_mut().enumerate() {
                let v = (b * VERTEX_BLOCK + i) as u32;
                let valence = topology.valence(v);
                let x = point(v);
                let mut offset = Vec3A::ZERO;
                let mut normal = Vec3A::ZERO;
                let mut lengths = 0.0f32;
                match fans.filter(|fans| fans.closed_fan[v as usize]) {
                    Some(fans) => {
                        let ring = &fans.ring[ring_offsets[v as usize] as usize
                            ..ring_offsets[v as usize + 1] as usize];
                        for (slot, &u) in d.iter_mut().zip(ring) {
                            *slot = point(u) - x;
                        }
                        let d = &d[..valence];
                        let mut previous = d[valence - 1];
                        for (&dk, face) in d.iter().zip(&mut faces) {
                            offset += dk;
                            *face = previous.cross(dk);
                            normal += *face;
                            if want_heights {
                                lengths += dk.length();
                            }
                            previous = dk;
                        }
                        match (threshold, marks) {
                            (Some(threshold), Some(marks)) => {
                                let faces = &faces[..valence];
                                for (u, _) in fan_feature_neighbors(v, ring, faces, threshold) {
                                    marks.on_edge[v as usize].store(true, Ordering::Relaxed);
                                    marks.on_edge[u as usize].store(true, Ordering::Relaxed);
                                }
                                marks.mark_flat_edges(v, ring, faces);
                            }
                            (Some(threshold), None) => {
                                fan_feature_edges(v, ring, &faces[..valence], threshold, &mut edges)
                            }
                            (None, _) => {}
                        }
                    }
                    None => {
                        for &u in topology.neighbors(v) {
                            offset += point(u) - x;
                        }
                        for &f in topology.faces_of(v) {
                            normal += area_normal(mesh, f);
                            for c in mesh.triangles[f as usize] {
                                if c != v && want_heights {
                                    lengths += 0.5 * (point(c) - x).length();
                                }
                            }
                        }
                        if let Some(threshold) = threshold {
                            let normal = |f: u32| area_normal(mesh, f);
                            let first = edges.len();
                            vertex_feature_edges(mesh, topology, v, normal, threshold, &mut edges);
                            if let Some(marks) = marks {
                                for ([a, b], _) in edges.drain(first..) {
                                    marks.on_edge[a as usize].store(true, Ordering::Relaxed);
                                    marks.on_edge[b as usize].store(true, Ordering::Relaxed);
                                }
                            }
                        }
                    }
                }
                edge_sum += lengths as f64;
                *h = match normal.try_normalize().filter(|_| want_heights) {
                    Some(normal) if !topology.is_boundary_vertex(v) && valence >= 3 => {
                        normal.dot(offset) / valence as f32
                    }
                    _ => f32::NAN,
                };
            }
            (edge_sum, edges)
        })
        .collect();
    let edge = blocks.iter().map(|(sum, _)| sum).sum::<f64>() / (3 * mesh.triangles.len()) as f64;
    let edges: Vec<FeatureEdge> = blocks.into_iter().flat_map(|(_, e)| e).collect();
    let heights = (edge > 0.0 && edge.is_finite()).then_some(Heights { heights, edge });
    (heights, edges)
}

/// Which vertices a noise reading ([`Heights::spread`]) leaves out.
#[derive(Clone, Copy)]
pub(super) enum LeftOut<'a> {
    /// None: every vertex with a defined h is read.
    Nothing,
    /// The vertices on a sharp edge (`on_edge`), neither counted nor taken into their
    /// neighbours' means (on a flat face beside a crease h is 0 but for the crease's own
    /// vertices); with `beside` the vertices beside one are not counted either. The reading is
    /// `None` when fewer than a quarter of the vertices with a defined h are left.
    Edges { on_edge: &'a [bool], beside: bool },
    /// The vertices marked `exact` are not counted, but stay in their neighbours' means (their h
    /// is the clean surface's).
    Exact(&'a [bool]),
}

impl Heights {
    /// The noise level: the robust spread of r_v (see the module docs) over the vertices that
    /// `left_out` does not leave out, `None` with fewer than 16 of them to read.
    pub(super) fn spread(&self, topology: &Topology, left_out: LeftOut) -> Option<f64> {
        let heights = &self.heights;
        let skip = |v: u32| match left_out {
            LeftOut::Edges { on_edge, .. } => on_edge[v as usize],
            _ => false,
        };
        let uncounted = |v: u32| match left_out {
            LeftOut::Nothing => false,
            LeftOut::Edges { on_edge, beside } => {
                on_edge[v as usize]
                    || beside && topology.neighbors(v).iter().any(|&u| on_edge[u as usize])
            }
            LeftOut::Exact(exact) => exact[v as usize],
        };
        // Every vertex's |r_v|, a positive NaN where it is not read (left out, no neighbour
        // counted, or no h at it or a neighbour). (A filtered parallel collect of the read ones
        // cost more than the residuals themselves; `total_cmp` orders positive NaNs after every
        // number, so the median of the read ones is the element at half their count.)
        let residuals: Vec<f32> = (0..heights.len() as u32)
            .into_par_iter()
            .with_min_len(VERTEX_BLOCK)
            .map(|v| {
                if uncounted(v) {
                    return f32::NAN;
                }
                let own = heights[v as usize];
                let mut sum = 0.0;
                let mut count = 0usize;
                for &u in topology.neighbors(v) {
                    if !skip(u) {
                        sum += heights[u as usize];
                        count += 1;
                    }
                }
                if count == 0 {
                    return f32::NAN;
                }
                // (abs clears the sign of a NaN too.)
                (own - sum / count as f32).abs()
            })
            .collect();
        let read = residuals
            .par_iter()
            .with_min_len(VERTEX_BLOCK)
            .filter(|r| !r.is_nan())
            .count();
        // Only a reading away from the edges needs the count (the per-round estimate skips it).
        let edges = matches!(left_out, LeftOut::Edges { .. });
        if read < 16 || edges && 4 * read < heights.par_iter().filter(|h| h.is_finite()).count() {
            return None;
        }
        let median = select_non_negative(&residuals, read / 2)?;
        Some(1.4826 * median as f64 / NOISE_GAIN / self.edge)
    }
}

/// The value of rank `rank` (from 0) of `values`, all of them positive or zero or positive NaNs, in
/// `f32::total_cmp`'s order (`None` when there are no more than `rank` values). For such values
/// that order is the order of their bits as unsigned integers, so the rank is found by counting the
/// values' top 12 bits (sign, exponent and 3 bits of the mantissa) in parallel, then selecting
/// among the few values that share the top bits of the one sought. The same value as
/// `select_nth_unstable_by` with `total_cmp`, in about a quarter of its time on 600k residuals (2
/// threads).
fn select_non_negative(values: &[f32], rank: usize) -> Option<f32> {
    const SHIFT: u32 = 20;
    const BINS: usize = 1 << (32 - SHIFT);
    let histogram = values
        .par_chunks(4 * VERTEX_BLOCK)
        .fold(
            || vec![0usize; BINS],
            |mut histogram, chunk| {
                for v in chunk {
                    histogram[(v.to_bits() >> SHIFT) as usize] += 1;
                }
                histogram
            },
        )
        .reduce_with(|mut a, b| {
            for (a, b) in a.iter_mut().zip(b) {
                *a += b;
            }
            a
        })
        .unwrap_or_default();
    // The bin holding the rank, and the rank within it.
    let mut below = 0;
    let bin = histogram.iter().position(|&count| {
        below += count;
        below > rank
    })?;
    below -= histogram[bin];
    let mut candidates: Vec<f32> = values
        .par_iter()
        .with_min_len(VERTEX_BLOCK)
        .copied()
        .filter(|v| (v.to_bits() >> SHIFT) as usize == bin)
        .collect();
    Some(
        *candidates
            .select_nth_unstable_by(rank - below, f32::total_cmp)
            .1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_selected_rank_is_the_sorted_values_at_that_rank() {
        // Zeros, ties, NaNs, values over many exponents and many within one bin of the top
        // bits: every rank against a plain sort (and one past the end).
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        let mut values = Vec::new();
        for i in 0..20_000 {
            values.push(match i % 7 {
                0 => 0.0,
                1 => f32::NAN,
                2 => 1.0 + (next() % 64) as f32 * 1e-6,
                3 => 0.25,
                _ => f32::from_bits(next() % 0x7f00_0000),
            });
        }
        let mut sorted = values.clone();
        sorted.sort_by(f32::total_cmp);
        for rank in (0..values.len())
            .step_by(97)
            .chain([0, 9_999, values.len() - 1])
        {
            let selected = select_non_negative(&values, rank).unwrap();
            assert_eq!(selected.to_bits(), sorted[rank].to_bits(), "rank {rank}");
        }
        assert_eq!(select_non_negative(&values, values.len()), None);
        assert_eq!(select_non_negative(&[], 0), None);
    }
}
