//! How strongly to fair: an estimate of a mesh's noise, and the rule that picks the number of
//! constrained-fairing rounds from it ([`super::Strength::Auto`], the default).
//!
//! Not in the paper, which leaves the number of iterations to the user. Measured here: the
//! iterations within a round hardly matter (a round settles after 5 to 10), the rounds do, and
//! the best count differs from mesh to mesh (2, 5 and 40-60 rounds on three scans), while a clean
//! mesh should not be touched at all. So the default measures the noise before fairing (at or
//! below [`CLEAN_NOISE`] it does nothing) and after every round, and stops once a round lowers the
//! estimate by less than 10 % ([`MIN_NOISE_FALL`]; in the measurements this ends after 5 to 11
//! rounds), once the estimate is below [`NOISE_LEFT`] of the input's, or after
//! [`MAX_AUTO_ROUNDS`].
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

use crate::mesh::{Topology, TriMesh};
use glam::DVec3;
use rayon::prelude::*;

/// The spread of r_v (see the module docs) for unit Gaussian noise along the normals: measured
/// on flat and gently curved valence-6 meshes, and on `bunny00` with σ = 0.3 (the estimate then
/// reads 0.3).
pub const NOISE_GAIN: f64 = 1.5;

/// The noise level of `mesh`, in mean edge lengths (see the module docs); `None` when fewer than
/// 16 vertices have a closed fan.
pub fn estimate_noise(mesh: &TriMesh, topology: &Topology) -> Option<f64> {
    let n = mesh.positions.len();
    let edge = crate::metrics::mean_edge_length(mesh);
    if !(edge > 0.0 && edge.is_finite()) {
        return None;
    }
    // h_v with its validity (closed fan, finite normal).
    let heights: Vec<Option<f64>> = (0..n as u32)
        .into_par_iter()
        .map(|v| {
            let ring = topology.neighbors(v);
            if topology.is_boundary_vertex(v) || ring.len() < 3 {
                return None;
            }
            let x = mesh.point(v);
            let mean = ring.iter().map(|&u| mesh.point(u)).sum::<DVec3>() / ring.len() as f64;
            let normal = topology
                .faces_of(v)
                .iter()
                .map(|&f| mesh.face_normal(f as usize))
                .sum::<DVec3>()
                .try_normalize()?;
            Some(normal.dot(mean - x))
        })
        .collect();
    let mut residuals: Vec<f64> = (0..n as u32)
        .into_par_iter()
        .filter_map(|v| {
            let own = heights[v as usize]?;
            let ring = topology.neighbors(v);
            let mut sum = 0.0;
            for &u in ring {
                sum += heights[u as usize]?;
            }
            Some((own - sum / ring.len() as f64).abs())
        })
        .collect();
    if residuals.len() < 16 {
        return None;
    }
    let middle = residuals.len() / 2;
    let (_, median, _) = residuals.select_nth_unstable_by(middle, f64::total_cmp);
    Some(1.4826 * *median / NOISE_GAIN / edge)
}

/// At or below this estimate a mesh counts as clean and automatic fairing leaves it alone (mean
/// edge lengths; clean scans and CAD parts measure 0.000 to 0.035, see `docs/measurements.md`).
pub const CLEAN_NOISE: f64 = 0.04;

/// Automatic fairing stops once the estimate has fallen to this fraction of where it started.
pub const NOISE_LEFT: f64 = 0.02;

/// Automatic fairing also stops once a round lowers the estimate by less than 10%.
pub const MIN_NOISE_FALL: f64 = 0.9;

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
