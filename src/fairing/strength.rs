//! How strongly to fair: an estimate of a mesh's noise, and the rule that picks the number of
//! constrained-fairing rounds from it ([`super::Strength::Auto`], the default).
//!
//! Not in the paper, which leaves the number of iterations to the user. Measured here: the
//! iterations within a round hardly matter (a round settles after 5 to 10), the rounds do, and
//! the best count differs from mesh to mesh (2, 5 and 40-60 rounds on three scans), while a clean
//! mesh should not be touched at all. So the default measures the noise before fairing (at or
//! below [`CLEAN_NOISE`] it does nothing; nor when the mesh reads that clean once the vertices on
//! its sharp edges are left out, `estimate_noise_away_from_edges`) and after every round, and stops once a round lowers the
//! estimate by less than 10 % ([`MIN_NOISE_FALL`]; in the measurements this ends after 5 to 11
//! rounds), once the estimate is below [`NOISE_LEFT`] of the input's, once a round moved the
//! vertices by less than [`MIN_MOVE_PER_NOISE`] times the estimate it left (coarse scans), or
//! after [`MAX_AUTO_ROUNDS`].
//!
//! The estimate, per vertex v with a closed fan: h_v = n_v · (m_v − x_v), the normal component of
//! the umbrella vector (m_v the mean of v's neighbours, n_v the area-weighted normal). On a clean
//! surface h_v is the curvature times the squared edge length and changes slowly from vertex to
//! vertex; noise makes it jump. So the estimate takes r_v = h_v − mean of h over v's neighbours
//! (curvature cancels to first order), and the noise level is the robust spread
//! 1.4826·median|r_v| (the median ignores creases and spikes as long as they are a minority),
//! divided by [`NOISE_GAIN`] (what r_v's spread is for Gaussian noise of standard deviation 1
//! along the normals on a valence-6 mesh, measured) and by the mean edge length. The result reads
//! as "noise of this standard deviation, in mean edge lengths".

use super::constrained::FanRings;
use super::creases::{fan_feature_edges, vertex_feature_edges, FeatureEdge};
use crate::mesh::{Topology, TriMesh};
use glam::Vec3A;
use rayon::prelude::*;

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
    estimate(mesh, topology, None, None).0
}

/// [`estimate_noise`] for a caller that has the fan-ordered one-rings (constrained fairing builds
/// them anyway): see [`scan_fans`].
pub(crate) fn estimate_noise_with_fans(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
) -> Option<f64> {
    estimate(mesh, topology, Some(fans), None).0
}

/// [`estimate_noise_with_fans`] with the vertices on sharp edges left out (edges where the faces'
/// own normals turn by more than `crease_angle` degrees; such a vertex is neither counted nor
/// taken into its neighbours' means), the less of two readings: with the vertices beside those
/// edges counted, and without them (where a curved surface meets a sharp feature its curvature
/// does not cancel in the neighbours' mean); `None` when both leave fewer than a quarter of the
/// vertices. On a coarse CAD part most vertices lie on or beside its edges, and those make the
/// median read noise where there is none.
pub(crate) fn estimate_noise_away_from_edges(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    crease_angle: f64,
) -> Option<f64> {
    let (heights, edges) = gather(mesh, topology, Some(fans), Some(crease_angle));
    let heights = heights?;
    let mut on_edge = vec![false; mesh.positions.len()];
    for ([a, b], _) in &edges {
        on_edge[*a as usize] = true;
        on_edge[*b as usize] = true;
    }
    [false, true]
        .into_iter()
        .filter_map(|beside| heights.spread(topology, Some((&on_edge, beside))))
        .reduce(f64::min)
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
pub(crate) fn scan_fans(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    crease_angle: f64,
) -> FanScan {
    let (noise, edges) = estimate(mesh, topology, Some(fans), Some(crease_angle));
    FanScan { noise, edges }
}

/// Vertices per block of the estimate's gather (each block's edge-length sum and feature edges
/// are kept apart and joined in order, so nothing depends on the thread count).
const VERTEX_BLOCK: usize = 4096;

/// The estimate (with the mean edge length summed in the same gather, as
/// [`crate::metrics::mean_edge_length`] defines it) and, with a crease angle, the feature edges.
fn estimate(
    mesh: &TriMesh,
    topology: &Topology,
    fans: Option<&FanRings>,
    crease_angle: Option<f64>,
) -> (Option<f64>, Vec<FeatureEdge>) {
    let (heights, edges) = gather(mesh, topology, fans, crease_angle);
    (heights.and_then(|h| h.spread(topology, None)), edges)
}

/// Every vertex's h_v and the mean edge length, from one gather (see the module docs).
struct Heights {
    /// h_v, NaN where it is not defined.
    heights: Vec<f32>,
    /// The mean edge length (positive and finite).
    edge: f64,
}

/// The gather behind [`estimate`]: [`Heights`] (`None` when the mean edge length is not
/// positive and finite) and, with a crease angle, the feature edges.
fn gather(
    mesh: &TriMesh,
    topology: &Topology,
    fans: Option<&FanRings>,
    crease_angle: Option<f64>,
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
                        for &dk in d {
                            offset += dk;
                            normal += previous.cross(dk);
                            lengths += dk.length();
                            previous = dk;
                        }
                        if let Some(threshold) = threshold {
                            fan_feature_edges(v, ring, d, threshold, &mut edges);
                        }
                    }
                    None => {
                        for &u in topology.neighbors(v) {
                            offset += point(u) - x;
                        }
                        for &f in topology.faces_of(v) {
                            normal += area_normal(mesh, f);
                            for c in mesh.triangles[f as usize] {
                                if c != v {
                                    lengths += 0.5 * (point(c) - x).length();
                                }
                            }
                        }
                        if let Some(threshold) = threshold {
                            let unit = |f: u32| {
                                area_normal(mesh, f).try_normalize().unwrap_or(Vec3A::ZERO)
                            };
                            vertex_feature_edges(mesh, topology, v, unit, threshold, &mut edges);
                        }
                    }
                }
                edge_sum += lengths as f64;
                *h = match normal.try_normalize() {
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
        let mut residuals: Vec<f32> = (0..heights.len() as u32)
            .into_par_iter()
            .with_min_len(VERTEX_BLOCK)
            .filter_map(|v| {
                if skip(v) || beside(v) {
                    return None;
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
                    return None;
                }
                // NaN (a vertex or a neighbour without h) fails the comparison.
                let residual = (own - sum / count as f32).abs();
                (residual >= 0.0).then_some(residual)
            })
            .collect();
        // Only a reading away from the edges needs the count (the per-round estimate skips it).
        if residuals.len() < 16
            || away.is_some()
                && 4 * residuals.len() < heights.par_iter().filter(|h| h.is_finite()).count()
        {
            return None;
        }
        let middle = residuals.len() / 2;
        let (_, median, _) = residuals.select_nth_unstable_by(middle, f32::total_cmp);
        Some(1.4826 * *median as f64 / NOISE_GAIN / self.edge)
    }
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

/// Automatic fairing stops once the estimate has fallen to this fraction of where it started.
pub const NOISE_LEFT: f64 = 0.02;

/// Automatic fairing also stops once a round lowers the estimate by less than 10%.
pub const MIN_NOISE_FALL: f64 = 0.9;

/// Automatic fairing also stops after a round (not the first) that moved the vertices by less
/// (root mean square, in mean edge lengths) than this many times the noise estimate it left:
/// while noise goes, a round moves the vertices about three times the estimate; on a coarsely
/// sampled mesh the rounds soon move less than that while they wear its detail away (the
/// elephant of `tests/data`: best after 3-4 rounds, the estimate rule ran 7).
pub const MIN_MOVE_PER_NOISE: f64 = 2.0;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::noise::{add_noise, NoiseMode, NoiseOptions};

    /// A flat grid of `n`×`n` squares of side 1, each cut into two triangles (valence 6 inside).
    fn grid(n: usize) -> TriMesh {
        let mut positions = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                positions.push([x as f32, y as f32, 0.0]);
            }
        }
        let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
        let mut triangles = Vec::new();
        for y in 0..n {
            for x in 0..n {
                triangles.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
                triangles.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
            }
        }
        TriMesh::new(positions, triangles)
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
