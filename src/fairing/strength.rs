//! How strongly to fair: an estimate of a mesh's noise, and the rule that picks the number of
//! constrained-fairing rounds from it ([`super::Strength::Auto`], the default).
//!
//! Not in the paper, which leaves the number of iterations to the user. Measured here: the
//! iterations within a round hardly matter (a round settles after 5 to 10), the rounds do, and
//! the best count differs from mesh to mesh (2-4 rounds on coarsely sampled scans, 20-40 on
//! finely sampled ones and on CAD parts), while a clean mesh should not be touched at all. So the
//! default measures the noise before fairing (at or below [`CLEAN_NOISE`] it does nothing; nor
//! when the mesh reads that clean once the vertices on its sharp edges are left out,
//! `NoiseReading::away_from_edges`), and a noisy mesh is faired round by round while Stein's
//! unbiased risk estimate of the result goes down (`RoundRisk`).
//!
//! # The noise estimate
//! Per vertex v with a closed fan: h_v = n_v · (m_v − x_v), the normal component of
//! the umbrella vector (m_v the mean of v's neighbours, n_v the area-weighted normal). On a clean
//! surface h_v is the curvature times the squared edge length and changes slowly from vertex to
//! vertex; noise makes it jump. So the estimate takes r_v = h_v − mean of h over v's neighbours
//! (curvature cancels to first order), and the noise level is the robust spread
//! 1.4826·median|r_v| (the median ignores creases and spikes as long as they are a minority),
//! divided by [`NOISE_GAIN`] (what r_v's spread is for Gaussian noise of standard deviation 1
//! along the normals on a valence-6 mesh, measured) and by the mean edge length. The result reads
//! as "noise of this standard deviation, in mean edge lengths".
//!
//! # When to stop: Stein's unbiased risk estimate
//! Neither the estimate's fall from round to round nor how far a round moves the vertices tells
//! a finely sampled mesh, where more rounds keep removing noise, from a coarse one, where they
//! wear its detail away (`docs/measurements.md`). What does is the expected error of the result
//! itself, which Stein's lemma gives without the clean surface (Stein 1981; the Monte-Carlo
//! divergence of Ramani, Blu and Unser, "Monte-Carlo SURE", IEEE TIP 2008). Model the input as
//! y_v = x_v + σ g_v n_v (noise of standard deviation σ along the normals) and the rounds' result
//! as f(y). Then, per vertex, with n_v the result's normal,
//!
//!   E Σ (n_v · (f_v − x_v))² = E [ Σ (n_v · (f_v − y_v))² − N σ² + 2 σ² Σ n_vᵀ ∂f_v/∂y_v n_v ],
//!
//! and the last sum (the smoother's divergence along the normals) is estimated by fairing, next to
//! the input, a copy of it moved by ε b_v along the input's normals (b_v a fixed draw of ±1,
//! [`sign_draw`]; the normals averaged over the one-rings [`RISK_DRAW_AVERAGING`] times, so that
//! they stand for the clean surface's): Σ b_v n_v · (f_v(y + ε b n) − f_v(y)) / ε. That is
//! Hutchinson's estimate of a trace, bᵀ J b for E[bᵀ J b] = tr J; with b_v = ±1 (Rademacher)
//! its variance is 2 Σ_{u≠v} J_uv², the least of any draw of independent b_v, where a Gaussian
//! draw adds 2 Σ J_vv² from b_v² ≠ 1 (measured on the noisy elephant, eight draws: the first
//! round's divergence spreads 0.39-0.42 with ±1 against 0.39-0.43 from a Gaussian draw;
//! `docs/measurements.md`, "The stop: small falls add up, a draw of ±1"). The copy goes through
//! the same operator, round for round, so every round costs its iterations twice. σ itself is
//! read from the input by second differences ([`second_difference_variance`]): with L the umbrella
//! operator (the mean of the neighbours), r_v = n_v · ((I − L)² y)_v is, on a smooth surface,
//! the change of the curvature term across two rings (small) plus the noise filtered by a row of
//! (I − L)², whose squared norm g_v is known; so σ² = Σ r_v² / Σ g_v over the vertices whose two
//! rings hold no crease and no boundary vertex (there the surface is not smooth). It replaced a
//! reading from the first round's residual, E Σ (n · (f − y))² = bias + σ² (N − 2 div +
//! Σ |n · ∂f n|²) taken with the bias as zero, which read 0-9 % high (the shape the round removes
//! counts as noise) and so stopped the coarse scans a round late (`docs/measurements.md`, "σ by
//! second differences"). A round is kept when it lowers the risk below the last kept round's by
//! at least [`RISK_MIN_FALL`] of what the second round lowered it by (so small falls add up until
//! they count, and a round that is lower by less than that is not worth its extra smoothing);
//! the rounds stop [`RISK_PATIENCE`] rounds after the last kept one (the risk is not always
//! convex in the rounds: a CAD part's creases found again after a few rounds lower it again), or
//! after [`MAX_AUTO_ROUNDS`], and the mesh goes back to the last kept round.

use super::constrained::FanRings;
use super::creases::{fan_feature_edges, fan_feature_neighbors, vertex_feature_edges, FeatureEdge};
use crate::mesh::{Topology, TriMesh};
use glam::Vec3A;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// The spread of r_v (see the module docs) for unit Gaussian noise along the normals: measured
/// on flat and gently curved valence-6 meshes, and on `bunny00` with σ = 0.3 (the estimate then
/// reads 0.3).
pub const NOISE_GAIN: f64 = 1.5;

/// The noise level of `mesh`, in mean edge lengths (see the module docs); `None` when fewer than
/// 16 vertices have a closed fan.
///
/// In f32 (positions are f32, the differences x_u − x_v of neighbours are exact, and h_v, the
/// normal part of their mean, carries a relative rounding error near 1e-7, far below the
/// 0.001-edge-length resolution the estimate is read at), in two parallel gathers over the
/// vertices; each vertex is computed by the same operations whatever the thread count, and the
/// median does not depend on the order, so neither does the result.
pub fn estimate_noise(mesh: &TriMesh, topology: &Topology) -> Option<f64> {
    let (heights, _) = gather(mesh, topology, None, None, None, true);
    heights.and_then(|h| h.spread(topology, None))
}

/// [`estimate_noise`] for a caller that has the fan-ordered one-rings (constrained fairing builds
/// them anyway), with, from the same gather, which vertices lie on a sharp edge (an edge where
/// the faces' own normals turn by more than `crease_angle` degrees), for
/// [`NoiseReading::away_from_edges`]. On the noisy 1.2M-face bunny (500k such edges) the reading
/// away from the edges took a gather of its own that listed every edge with its direction: 68 ms,
/// now a few (the flags are set as the edges are found).
pub(crate) fn read_noise(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    crease_angle: f64,
) -> NoiseReading {
    let flags: Vec<AtomicBool> = (0..mesh.positions.len())
        .into_par_iter()
        .with_min_len(VERTEX_BLOCK)
        .map(|_| AtomicBool::new(false))
        .collect();
    let (heights, _) = gather(
        mesh,
        topology,
        Some(fans),
        Some(crease_angle),
        Some(&flags),
        true,
    );
    let on_edge = flags
        .into_par_iter()
        .with_min_len(VERTEX_BLOCK)
        .map(AtomicBool::into_inner)
        .collect();
    NoiseReading { heights, on_edge }
}

/// What [`read_noise`] gathered.
pub(crate) struct NoiseReading {
    heights: Option<Heights>,
    /// Whether each vertex is an end of a sharp edge.
    on_edge: Vec<bool>,
}

impl NoiseReading {
    /// [`estimate_noise`].
    pub fn noise(&self, topology: &Topology) -> Option<f64> {
        self.heights.as_ref()?.spread(topology, None)
    }

    /// The estimate with the vertices on sharp edges left out (such a vertex is neither counted
    /// nor taken into its neighbours' means), the less of two readings: with the vertices beside
    /// those edges counted, and without them (where a curved surface meets a sharp feature its
    /// curvature does not cancel in the neighbours' mean); `None` when both leave fewer than a
    /// quarter of the vertices. On a coarse CAD part most vertices lie on or beside its edges,
    /// and those make the median read noise where there is none.
    pub fn away_from_edges(&self, topology: &Topology) -> Option<f64> {
        let heights = self.heights.as_ref()?;
        [false, true]
            .into_iter()
            .filter_map(|beside| heights.spread(topology, Some((&self.on_edge, beside))))
            .reduce(f64::min)
    }
}

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
        noise: heights.and_then(|h| h.spread(topology, None)),
        edges,
    }
}

/// Vertices per block of the estimate's gather (each block's edge-length sum and feature edges
/// are kept apart and joined in order, so nothing depends on the thread count).
const VERTEX_BLOCK: usize = 4096;

/// Every vertex's h_v and the mean edge length, from one gather (see the module docs).
struct Heights {
    /// h_v, NaN where it is not defined.
    heights: Vec<f32>,
    /// The mean edge length (positive and finite).
    edge: f64,
}

/// The gather behind the estimates: [`Heights`] (`None` when the mean edge length is not
/// positive and finite; the mean edge length is summed in the same gather, as
/// [`crate::metrics::mean_edge_length`] defines it) and, with a crease angle, the feature edges,
/// or, with `on_edge` too, no list but both ends of every feature edge marked there. Without
/// `want_heights` no heights are taken (`None`).
fn gather(
    mesh: &TriMesh,
    topology: &Topology,
    fans: Option<&FanRings>,
    crease_angle: Option<f64>,
    on_edge: Option<&[AtomicBool]>,
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
                        match (threshold, on_edge) {
                            (Some(threshold), Some(on_edge)) => {
                                let faces = &faces[..valence];
                                for (u, _) in fan_feature_neighbors(v, ring, faces, threshold) {
                                    on_edge[v as usize].store(true, Ordering::Relaxed);
                                    on_edge[u as usize].store(true, Ordering::Relaxed);
                                }
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
                            if let Some(on_edge) = on_edge {
                                for ([a, b], _) in edges.drain(first..) {
                                    on_edge[a as usize].store(true, Ordering::Relaxed);
                                    on_edge[b as usize].store(true, Ordering::Relaxed);
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

impl Heights {
    /// The noise level: the robust spread of r_v (see the module docs), `None` with fewer than
    /// 16 vertices to read. With `away = Some((on_edge, beside))` the vertices on a feature edge
    /// are left out (neither counted nor taken into their neighbours' means: on a flat face
    /// beside a crease h is 0 but for the crease's own vertices), with `beside` the vertices
    /// beside one are not counted either, and `None` comes back when fewer than a quarter of the
    /// vertices with a defined h are left.
    fn spread(&self, topology: &Topology, away: Option<(&[bool], bool)>) -> Option<f64> {
        let heights = &self.heights;
        let skip = |v: u32| away.is_some_and(|(on_edge, _)| on_edge[v as usize]);
        let beside = |v: u32| {
            away.is_some_and(|(on_edge, beside)| {
                beside && topology.neighbors(v).iter().any(|&u| on_edge[u as usize])
            })
        };
        // Every vertex's |r_v|, a positive NaN where it is not read (left out, no neighbour
        // counted, or no h at it or a neighbour). (A filtered parallel collect of the read ones
        // cost more than the residuals themselves; `total_cmp` orders positive NaNs after every
        // number, so the median of the read ones is the element at half their count.)
        let residuals: Vec<f32> = (0..heights.len() as u32)
            .into_par_iter()
            .with_min_len(VERTEX_BLOCK)
            .map(|v| {
                if skip(v) || beside(v) {
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
        if read < 16
            || away.is_some() && 4 * read < heights.par_iter().filter(|h| h.is_finite()).count()
        {
            return None;
        }
        let median = select_non_negative(&residuals, read / 2)?;
        Some(1.4826 * median as f64 / NOISE_GAIN / self.edge)
    }
}

/// The value of rank `rank` (from 0) of `values`, all of them positive or zero or positive NaNs,
/// in `f32::total_cmp`'s order (`None` when there are no more than `rank` values). For such values that order is the order
/// of their bits as unsigned integers, so the rank is found by counting the values' top 12 bits
/// (sign, exponent and 3 bits of the mantissa) in parallel, then selecting among the few values
/// that share the top bits of the one sought. The same value as `select_nth_unstable_by` with
/// `total_cmp`, in about a quarter of its time on 600k residuals (2 threads).
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

/// The area normal of face `f`, (x_b − x_a) × (x_c − x_a) (twice its area long), in f32.
#[inline]
pub(crate) fn area_normal(mesh: &TriMesh, f: u32) -> Vec3A {
    let [a, b, c] =
        mesh.triangles[f as usize].map(|v| Vec3A::from_array(mesh.positions[v as usize]));
    (b - a).cross(c - a)
}

/// Every face's area normal ([`area_normal`]), in parallel.
pub(crate) fn face_normals(mesh: &TriMesh) -> Vec<Vec3A> {
    (0..mesh.triangles.len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|f| area_normal(mesh, f))
        .collect()
}

/// At or below this estimate a mesh counts as clean and automatic fairing leaves it alone (mean
/// edge lengths; clean scans and CAD parts measure 0.000 to 0.035, see `docs/measurements.md`).
pub const CLEAN_NOISE: f64 = 0.04;

/// How many times the directions of the risk's draw are averaged over each vertex's one-ring
/// (the vertex and its neighbours, unit normals, equal weights) before the copy is moved along
/// them. The noise lies along the clean surface's normals; the input's own normals are tilted
/// from those by the noise itself (16° on average on the noisy cylinder, mean cos² 0.90), and a
/// divergence read along them comes out short by about that cos², less so as the rounds smooth
/// the mesh, so the risk falls too slowly and the rounds stopped early on the CAD parts. Averaged
/// a few times, the draw's directions lie within a few degrees of the clean normals on finely
/// sampled meshes (the cylinder's cos² 0.98 after five averagings) while a coarse scan's bends
/// blur (the elephant's cos² stays 0.90 after five). Measured on the 32-row peer table of
/// `docs/measurements.md` (with σ then read from the first round): one or two averagings leave
/// the gear stopping early (its faces 18.9° / 18.0° off against 16.0° with three), four stop the
/// cow and the dragon late.
pub const RISK_DRAW_AVERAGING: usize = 3;

/// The rounds stop once this many rounds in a row have not been kept ([`RISK_MIN_FALL`]): near
/// its least the risk is flat, and on a CAD part it may rise for a round before the creases
/// found again lower it further.
pub const RISK_PATIENCE: usize = 2;

/// A round is kept (and the rounds go on) when it lowers the risk below the last kept round's
/// by at least this fraction of what the second round lowered it by. The falls of the rounds
/// after a kept one add up until they pass it, so a finely sampled mesh or a CAD part whose risk
/// falls slowly but steadily runs on, while near the least, where the risk is flat, a round that
/// reads lower by less is not kept: its extra smoothing is within the estimate's own scatter
/// (the elephant with isotropic noise reads rounds 4 and 5 within 0.04 % of each other; round
/// 4 is the closer).
///
/// Measured on the 32-row peer table over three noise seeds, against the rule it replaced (the
/// least always kept; only a round's own fall of this fraction counting towards
/// [`RISK_PATIENCE`]): closer on every seed's geometric mean, the noisy 1.2M-face bunny 43 → 59
/// rounds and 0.0433 → 0.0402 edge lengths for about a fifth more time (`docs/measurements.md`,
/// "The stop: small falls add up, a draw of ±1").
pub const RISK_MIN_FALL: f64 = 0.005;

/// How far the risk's copy of the input is moved along the normals, in mean edge lengths (small
/// against the noise, large against f32 rounding; 0.02 and 0.1 stop every tuning mesh alike).
pub const RISK_STEP: f64 = 0.05;

/// At most this many rounds in automatic mode.
pub const MAX_AUTO_ROUNDS: usize = 60;

/// Normal-filter passes crease detection gets for a mesh with this noise estimate: none
/// for a clean mesh, more the noisier it is.
pub fn normal_filtering_for(noise: f64) -> usize {
    if noise <= CLEAN_NOISE {
        0
    } else {
        ((noise / 0.05).ceil() as usize).clamp(1, 10)
    }
}

/// Stein's unbiased risk estimate of the rounds' result (see the module docs): made from the
/// input before the first round, it holds the input, the Gaussian draw b_v and its directions
/// (the input's unit normals, averaged), and gives the perturbed copy to fair beside it.
pub(crate) struct RoundRisk {
    input: Vec<[f32; 3]>,
    /// The input's unit normals (area-weighted) averaged [`RISK_DRAW_AVERAGING`] times over the
    /// one-rings, the directions of the draw.
    directions: Vec<Vec3A>,
    draw: Vec<f32>,
    /// The copy's step, absolute.
    step: f64,
    /// σ² (absolute): [`second_difference_variance`], or the noise estimate's where that
    /// reading cannot be made.
    variance: f64,
}

/// What one reading of [`RoundRisk`] sums over the vertices.
#[derive(Clone, Copy, Default)]
struct RiskSums {
    /// Σ (n_v · (f_v − y_v))², n_v the result's unit normal.
    residual: f64,
    /// Σ b_v n⁰_v · (f̃_v − f_v) / ε: the divergence along the normals.
    divergence: f64,
    /// Vertices summed (those with a normal).
    count: usize,
}

impl RoundRisk {
    /// The risk of fairing `mesh` (the input, before any round; `edge` its mean edge length,
    /// `noise` its noise estimate in edge lengths; `held` flags the vertices on creases or the
    /// boundary, whose two rings σ is not read over, empty for none) and the copy to fair beside
    /// it.
    pub(crate) fn new(
        mesh: &TriMesh,
        topology: &Topology,
        edge: f64,
        noise: f64,
        held: &[bool],
    ) -> (RoundRisk, Vec<[f32; 3]>) {
        let step = RISK_STEP * edge;
        let mut directions = unit_vertex_normals(mesh, topology);
        for _ in 0..RISK_DRAW_AVERAGING {
            directions = averaged_over_rings(topology, &directions);
        }
        let draw: Vec<f32> = (0..mesh.positions.len() as u32)
            .into_par_iter()
            .with_min_len(VERTEX_BLOCK)
            .map(|v| sign_draw(v.into()))
            .collect();
        let copy = mesh
            .positions
            .par_iter()
            .zip(&directions)
            .zip(&draw)
            .with_min_len(VERTEX_BLOCK)
            .map(|((p, n), &b)| (Vec3A::from_array(*p) + *n * (b * step as f32)).to_array())
            .collect();
        let fallback = noise * edge;
        let variance = second_difference_variance(mesh, topology, &directions, held)
            .filter(|variance| *variance > 0.0 && variance.is_finite())
            .unwrap_or(fallback * fallback);
        let risk = RoundRisk {
            input: mesh.positions.clone(),
            directions,
            draw,
            step,
            variance,
        };
        (risk, copy)
    }

    /// The estimated risk (per vertex, squared length) of `mesh` as the rounds' result, the
    /// input's copy having gone through the same rounds to `copy`.
    pub(crate) fn read(&self, mesh: &TriMesh, topology: &Topology, copy: &[[f32; 3]]) -> f64 {
        let normals = unit_vertex_normals(mesh, topology);
        let step = self.step;
        let sums = mesh
            .positions
            .par_chunks(VERTEX_BLOCK)
            .enumerate()
            .map(|(b, block)| {
                let start = b * VERTEX_BLOCK;
                let mut sums = RiskSums::default();
                for (i, p) in block.iter().enumerate() {
                    let v = start + i;
                    let (n, n0) = (normals[v], self.directions[v]);
                    if n == Vec3A::ZERO || n0 == Vec3A::ZERO {
                        continue;
                    }
                    let f = Vec3A::from_array(*p);
                    let moved = n.dot(f - Vec3A::from_array(self.input[v])) as f64;
                    let response = n0.dot(Vec3A::from_array(copy[v]) - f) as f64 / step;
                    sums.add(moved, self.draw[v] as f64 * response);
                }
                sums
            })
            .collect::<Vec<RiskSums>>()
            .into_iter()
            .fold(RiskSums::default(), RiskSums::sum);
        (sums.residual + 2.0 * self.variance * sums.divergence) / sums.count.max(1) as f64
    }
}

impl RiskSums {
    /// Adds one vertex: its residual along the normal and b_v times its response.
    fn add(&mut self, moved: f64, divergence: f64) {
        self.residual += moved * moved;
        self.divergence += divergence;
        self.count += 1;
    }

    fn sum(self, other: RiskSums) -> RiskSums {
        RiskSums {
            residual: self.residual + other.residual,
            divergence: self.divergence + other.divergence,
            count: self.count + other.count,
        }
    }
}

/// Every vertex's `directions` averaged with its neighbours' (equal weights), as a unit vector
/// (zero where the sum is), in parallel.
fn averaged_over_rings(topology: &Topology, directions: &[Vec3A]) -> Vec<Vec3A> {
    (0..directions.len() as u32)
        .into_par_iter()
        .with_min_len(VERTEX_BLOCK)
        .map(|v| {
            topology
                .neighbors(v)
                .iter()
                .fold(directions[v as usize], |sum, &u| {
                    sum + directions[u as usize]
                })
                .normalize_or_zero()
        })
        .collect()
}

/// σ² of noise along the normals of `mesh`, read by second differences (see the module docs):
/// Σ r_v² / Σ g_v with r_v = n_v · ((I − L)² y)_v (`directions`: unit normals of the clean
/// surface as well as the input tells them) and g_v the squared norm of row v of (I − L)², the
/// variance r_v would have for unit noise; over the vertices with no `held` vertex within two
/// rings (over all where fewer than a tenth are such; `held` empty: none). `None` where no vertex
/// can be read. On big meshes g_v is averaged over every [`GAIN_STRIDE`]-th vertex read (its
/// row's listing is most of the cost: 150 ms of the 1.2M-face mesh on two threads, taken for
/// every vertex).
///
/// Measured on the 16 meshes of the peer table with noise of 0.15, 0.3 and 0.5 edge lengths along
/// the normals and per coordinate (`docs/measurements.md`): the reading over the truth has a mean
/// |log| of 0.043, 0.031 and 0.037, against 0.059, 0.037 and 0.043 for the first round's
/// residual, and 0.068, 0.034 and 0.037 with the creases' and the boundary's rings read too (a
/// CAD part's edges read as noise: the cube 13 % high at 0.15). In parallel; every vertex is
/// computed alike and the blocks' sums are joined in order, so the result does not depend on the
/// thread count.
fn second_difference_variance(
    mesh: &TriMesh,
    topology: &Topology,
    directions: &[Vec3A],
    held: &[bool],
) -> Option<f64> {
    let n = mesh.positions.len();
    let position = |v: u32| Vec3A::from_array(mesh.positions[v as usize]);
    // (I − L) y: every vertex less the mean of its neighbours.
    let first: Vec<Vec3A> = (0..n as u32)
        .into_par_iter()
        .with_min_len(VERTEX_BLOCK)
        .map(|v| {
            let ring = topology.neighbors(v);
            if ring.is_empty() {
                return Vec3A::ZERO;
            }
            position(v) - ring.iter().map(|&u| position(u)).sum::<Vec3A>() / ring.len() as f32
        })
        .collect();
    // The held vertices grown by a ring.
    let grown = |flags: &[bool]| -> Vec<bool> {
        (0..n as u32)
            .into_par_iter()
            .with_min_len(VERTEX_BLOCK)
            .map(|v| flags[v as usize] || topology.neighbors(v).iter().any(|&u| flags[u as usize]))
            .collect()
    };
    let excluded = if held.len() == n {
        grown(&grown(held))
    } else {
        vec![false; n]
    };
    let readable = |v: u32| topology.valence(v) > 0 && directions[v as usize] != Vec3A::ZERO;
    let away = (0..n as u32)
        .into_par_iter()
        .with_min_len(VERTEX_BLOCK)
        .filter(|&v| readable(v) && !excluded[v as usize])
        .count();
    let everywhere = 10 * away < n;
    let stride = if away > GAIN_STRIDE * GAIN_STRIDE_FROM {
        GAIN_STRIDE
    } else {
        1
    } as u32;
    let (residual, read, gain, gained) = (0..n.div_ceil(VERTEX_BLOCK))
        .into_par_iter()
        .map(|b| {
            let (mut residual, mut read, mut gain, mut gained) = (0.0f64, 0usize, 0.0f64, 0usize);
            let mut row: Vec<(u32, f64)> = Vec::new();
            for v in (b * VERTEX_BLOCK..n.min((b + 1) * VERTEX_BLOCK)).map(|v| v as u32) {
                if !readable(v) || (excluded[v as usize] && !everywhere) {
                    continue;
                }
                let ring = topology.neighbors(v);
                let mean =
                    ring.iter().map(|&u| first[u as usize]).sum::<Vec3A>() / ring.len() as f32;
                let r = directions[v as usize].dot(first[v as usize] - mean) as f64;
                residual += r * r;
                read += 1;
                if v % stride != 0 {
                    continue;
                }
                gained += 1;
                // Row v of (I − L)² = e_v − 2·L_v + Σ_u L_vu·L_u: its entries listed, sorted by
                // vertex, and each vertex's summed before it is squared.
                row.clear();
                row.push((v, 1.0));
                let own = 1.0 / ring.len() as f64;
                for &u in ring {
                    row.push((u, -2.0 * own));
                    let theirs = topology.neighbors(u);
                    let weight = own / theirs.len() as f64;
                    row.extend(theirs.iter().map(|&w| (w, weight)));
                }
                row.sort_unstable_by_key(|&(w, _)| w);
                let mut at = 0;
                while at < row.len() {
                    let (w, mut entry) = row[at];
                    at += 1;
                    while at < row.len() && row[at].0 == w {
                        entry += row[at].1;
                        at += 1;
                    }
                    gain += entry * entry;
                }
            }
            (residual, read, gain, gained)
        })
        .collect::<Vec<(f64, usize, f64, usize)>>()
        .into_iter()
        .fold((0.0, 0, 0.0, 0), |(a, b, c, d), (e, f, g, h)| {
            (a + e, b + f, c + g, d + h)
        });
    (gain > 0.0).then(|| (residual / read as f64) / (gain / gained as f64))
}

/// [`second_difference_variance`] takes the gains of every this-many-th vertex on meshes with
/// more than this times [`GAIN_STRIDE_FROM`] vertices read.
const GAIN_STRIDE: usize = 8;
/// See [`GAIN_STRIDE`]: the gains are averaged over at least this many vertices.
const GAIN_STRIDE_FROM: usize = 16384;

/// SplitMix64's finaliser: a well-mixed 64-bit hash of `z`.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The risk's draw for vertex `v`: +1 or −1, each with probability one half, the same on every
/// run and for any thread count (the lowest bit of a SplitMix64 hash of `v`).
fn sign_draw(v: u64) -> f32 {
    if mix(v ^ 0x5EED_F00D_CAFE_0001) & 1 == 0 {
        1.0
    } else {
        -1.0
    }
}

/// Every vertex's unit normal, the sum of its faces' area normals (zero where that is zero), in
/// parallel.
fn unit_vertex_normals(mesh: &TriMesh, topology: &Topology) -> Vec<Vec3A> {
    let faces = face_normals(mesh);
    (0..mesh.positions.len() as u32)
        .into_par_iter()
        .with_min_len(VERTEX_BLOCK)
        .map(|v| {
            topology
                .faces_of(v)
                .iter()
                .map(|&f| faces[f as usize])
                .sum::<Vec3A>()
                .normalize_or_zero()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::{add_noise, NoiseMode, NoiseOptions};

    /// A standard normal draw for vertex `v`, the same on every run (Box-Muller from two uniforms
    /// of a SplitMix64 hash of `v`).
    fn gaussian_draw(v: u64) -> f32 {
        let h = mix(v ^ 0x5EED_F00D_CAFE_0001);
        let u1 = ((h >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        let u2 = ((mix(h) >> 11) as f64) / (1u64 << 53) as f64;
        ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
    }

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

    use crate::mesh::fixtures::grid;

    #[test]
    fn the_risk_ranks_smoothers_of_a_noisy_plane_by_their_true_error() {
        // A plane with noise of sigma 0.3 along its normal, and three "smoothers" of it whose
        // error is known, p -> x + a·(p − x) with x the clean vertex: a = 0 the clean plane itself
        // (error 0), a = 1/2 the halfway blend (error sigma²/4 per vertex), a = 1 the input left
        // as it is (error sigma²). Per vertex the risk reads the residual (1 − a)²·sigma² plus
        // twice the divergence a times the variance read from the input: with the variance
        // exact, that is each error plus sigma². A wrong sign or scale of the divergence would
        // rank the input first or the blend last.
        let clean = grid(80);
        let topology = Topology::build(&clean);
        let sigma = 0.3f32;
        let input = noisy_plane(&clean, sigma);
        let edge = crate::metrics::mean_edge_length(&input);
        let (risk, copy) = RoundRisk::new(&input, &topology, edge, 0.0, &[]);
        // Each smoother applied to the input and to the risk's copy: p -> x + a·(p − x), x the
        // clean vertex (so that its derivative is a times the identity).
        let smooth = |mesh: &TriMesh, a: f32| {
            let mut out = mesh.clone();
            for (p, x) in out.positions.iter_mut().zip(&clean.positions) {
                for k in 0..3 {
                    p[k] = x[k] + a * (p[k] - x[k]);
                }
            }
            out
        };
        let copy_mesh = TriMesh::new(copy, input.triangles.clone());
        let read = |a: f32| {
            let (result, moved) = (smooth(&input, a), smooth(&copy_mesh, a));
            risk.read(&result, &topology, &moved.positions)
        };
        // Sigma as read from the input by second differences: the noise itself.
        let (oracle, half, none) = (read(0.0), read(0.5), read(1.0));
        let variance = risk.variance;
        let truth = (sigma * sigma) as f64;
        assert!(
            (variance / truth - 1.0).abs() < 0.1,
            "sigma² read {variance}, truth {truth}"
        );
        let expected = [0.0, 0.5, 1.0].map(|a| (1.0 - a) * (1.0 - a) * truth + 2.0 * a * variance);
        for (read, expected) in [oracle, half, none].iter().zip(expected) {
            // The divergence is estimated from one draw: a few percent of it.
            assert!(
                (read - expected).abs() < 0.1 * expected,
                "risks {oracle} {half} {none}, expected {expected:?}"
            );
        }
        assert!(oracle < half && half < none);
    }

    /// A plane of `grid(n)` with noise of `sigma` along its normal (the same draw every time).
    fn noisy_plane(clean: &TriMesh, sigma: f32) -> TriMesh {
        let mut input = clean.clone();
        for (v, p) in input.positions.iter_mut().enumerate() {
            p[2] += sigma * gaussian_draw(1_000_003 + v as u64);
        }
        input
    }

    #[test]
    fn the_draw_lies_along_the_clean_normals_not_the_noisy_ones() {
        // On a plane with noise of sigma 0.3 (a quarter of its mean edge) the input's own normals
        // tilt by ~14° (mean cos² 0.94); the draw's directions, averaged over the one-rings, must
        // lie much closer to the plane's normal (unaveraged they would be the input's).
        let clean = grid(60);
        let topology = Topology::build(&clean);
        let input = noisy_plane(&clean, 0.3);
        let edge = crate::metrics::mean_edge_length(&input);
        let (risk, _) = RoundRisk::new(&input, &topology, edge, 0.0, &[]);
        let mean_cos2 = |normals: &[Vec3A]| {
            normals.iter().map(|n| (n.z * n.z) as f64).sum::<f64>() / normals.len() as f64
        };
        let own = mean_cos2(&unit_vertex_normals(&input, &topology));
        let draw = mean_cos2(&risk.directions);
        assert!(own < 0.95, "the noisy normals' cos² {own}");
        assert!(
            1.0 - draw < 0.25 * (1.0 - own),
            "the draw's cos² {draw} (the input's {own})"
        );
    }

    /// The noise `noisy` holds over `clean`: the root mean square of the vertices' moves (the
    /// drawn σ for noise along the normals, whatever the draw's own spread came to).
    fn drawn_sigma(noisy: &TriMesh, clean: &TriMesh) -> f64 {
        let squares: f64 = noisy
            .positions
            .iter()
            .zip(&clean.positions)
            .map(|(p, q)| (Vec3A::from_array(*p) - Vec3A::from_array(*q)).length_squared() as f64)
            .sum();
        (squares / clean.positions.len() as f64).sqrt()
    }

    /// σ (absolute) as [`RoundRisk`] reads it from `input`, away from `held`.
    fn sigma_read(input: &TriMesh, topology: &Topology, held: &[bool]) -> f64 {
        let edge = crate::metrics::mean_edge_length(input);
        let (risk, _) = RoundRisk::new(input, topology, edge, 0.0, held);
        risk.variance.sqrt()
    }

    #[test]
    fn sigma_by_second_differences_reads_a_coarse_bumpy_surface_clean_and_its_noise_right() {
        // A grid bent into bumps eight edges wide, 0.8 high: its curvature changes within a few
        // rings, so one ring of differences (the umbrella's normal part) reads it as noise of
        // 0.12 edge lengths; two rings of differences read 0.05. With noise of 0.3 edge lengths
        // along the normals on top, σ must read within 4 % of the noise drawn (one ring would
        // read 7 % high).
        let n = 60;
        let mut clean = grid(n);
        for p in &mut clean.positions {
            let wave = |c: f32| (std::f32::consts::TAU * c / 8.0).sin();
            p[2] = 0.8 * wave(p[0]) * wave(p[1]);
        }
        let topology = Topology::build(&clean);
        let edge = crate::metrics::mean_edge_length(&clean);
        let boundary = topology.boundary_flags();
        let clean_reading = sigma_read(&clean, &topology, boundary) / edge;
        assert!(
            clean_reading < 0.06,
            "the clean surface reads {clean_reading} edge lengths"
        );
        let mut noisy = clean.clone();
        add_noise(&mut noisy, &NoiseOptions::default().with_sigma(0.3));
        let drawn = drawn_sigma(&noisy, &clean);
        let reading = sigma_read(&noisy, &topology, boundary);
        assert!(
            (reading / drawn - 1.0).abs() < 0.04,
            "sigma read {reading}, drawn {drawn}"
        );
    }

    #[test]
    fn sigma_is_read_away_from_the_creases() {
        // A cube with noise of 0.15 edge lengths along the normals: its edges, where the
        // surface is not smooth, read as noise unless their two rings are left out.
        use crate::fairing::creases::{detect_creases, CreaseOptions};
        let clean = crate::mesh::shapes::cuboid([1.0, 1.0, 1.0], 0.05);
        let topology = Topology::build(&clean);
        let creases = detect_creases(&clean, &topology, &CreaseOptions::default());
        let held: Vec<bool> = (0..clean.positions.len() as u32)
            .map(|v| creases.is_feature(v))
            .collect();
        assert!(held.iter().any(|&h| h));
        let mut noisy = clean.clone();
        add_noise(&mut noisy, &NoiseOptions::default().with_sigma(0.15));
        let drawn = drawn_sigma(&noisy, &clean);
        let away = sigma_read(&noisy, &topology, &held);
        let everywhere = sigma_read(&noisy, &topology, &[]);
        assert!(
            (away / drawn - 1.0).abs() < 0.04,
            "away from the creases {away}, drawn {drawn}"
        );
        assert!(
            everywhere / drawn > 1.08,
            "over every vertex {everywhere}, drawn {drawn}"
        );
    }

    #[test]
    fn a_clean_plane_has_no_noise_and_a_noisy_one_reads_its_sigma() {
        let clean = grid(60);
        let topology = Topology::build(&clean);
        assert_eq!(estimate_noise(&clean, &topology), Some(0.0));
        for mode in [NoiseMode::Normal, NoiseMode::Isotropic] {
            let mut noisy = clean.clone();
            add_noise(
                &mut noisy,
                &NoiseOptions::default().with_sigma(0.3).with_mode(mode),
            );
            let estimate = estimate_noise(&noisy, &topology).unwrap();
            assert!(
                (estimate - 0.3).abs() < 0.1,
                "{mode:?}: estimate {estimate} for sigma 0.3"
            );
        }
    }
}
