//! The noise estimate (see the parent module's docs): the robust spread of the change of h_v,
//! the normal part of the umbrella vector, from vertex to vertex; and the reading with the
//! vertices on sharp edges left out, which tells a coarse CAD part from a noisy scan.

use super::scan::{gather, Heights, VERTEX_BLOCK};
use crate::mesh::{FanRings, Topology, TriMesh};
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;

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
/// [`NoiseReading::away_from_edges`]. The flags are set as the edges are found, so no edge is
/// listed (a noisy mesh has many).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::grid;
    use crate::noise::{add_noise, NoiseMode, NoiseOptions};

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
