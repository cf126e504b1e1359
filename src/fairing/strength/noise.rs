//! The noise estimate (see the parent module's docs): the robust spread of the change of h_v,
//! the normal part of the umbrella vector, from vertex to vertex; and the reading with the
//! vertices on sharp edges left out, which tells a coarse CAD part from a noisy scan.

use super::scan::{gather, Heights, LeftOut, Marks, VERTEX_BLOCK};
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
    heights.and_then(|h| h.spread(topology, LeftOut::Nothing))
}

/// [`estimate_noise`] for a caller that has the fan-ordered one-rings (constrained fairing builds
/// them anyway), with, from the same gather, which vertices lie on a sharp edge (an edge where
/// the faces' own normals turn by more than `crease_angle` degrees), for
/// [`NoiseReading::away_from_edges`], and which are corners of a flat edge, for
/// [`NoiseReading::clean_off_flat_edges`]. The flags are set as the edges are found, so no edge is
/// listed (a noisy mesh has many).
pub(crate) fn read_noise(
    mesh: &TriMesh,
    topology: &Topology,
    fans: &FanRings,
    crease_angle: f64,
) -> NoiseReading {
    let marks = Marks::new(mesh.positions.len());
    let (heights, _) = gather(
        mesh,
        topology,
        Some(fans),
        Some(crease_angle),
        Some(&marks),
        true,
    );
    let flags = |marks: Vec<AtomicBool>| {
        marks
            .into_par_iter()
            .with_min_len(VERTEX_BLOCK)
            .map(AtomicBool::into_inner)
            .collect()
    };
    NoiseReading {
        heights,
        on_edge: flags(marks.on_edge),
        exact: flags(marks.exact),
    }
}

/// What [`read_noise`] gathered.
pub(crate) struct NoiseReading {
    heights: Option<Heights>,
    /// Whether each vertex is an end of a sharp edge.
    on_edge: Vec<bool>,
    /// Whether each vertex is a corner of a flat edge (two faces in one plane, so no noise moved
    /// it across that plane).
    exact: Vec<bool>,
}

impl NoiseReading {
    /// [`estimate_noise`].
    pub fn noise(&self, topology: &Topology) -> Option<f64> {
        self.heights.as_ref()?.spread(topology, LeftOut::Nothing)
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
            .filter_map(|beside| {
                let on_edge = &self.on_edge;
                heights.spread(topology, LeftOut::Edges { on_edge, beside })
            })
            .reduce(f64::min)
    }

    /// Whether the mesh reads clean once the vertices that no noise moved are left out: the
    /// corners of its flat edges (two faces in one plane; see `Marks::exact` in the scan). Noise
    /// moves every vertex on its own, so a flat edge survives it only by chance (a few edges in
    /// a hundred at the least noise that counts); a CAD part, on the other hand, is made of
    /// them: its flat faces, and its curved faces written as quads of two triangles in one
    /// plane. Such a part reads noisy where every vertex lies on a rim and its h_v changes with
    /// the size of the cap's slivers (`docs/measurements.md`, "The clean set"), and away from
    /// its edges nothing is left to read. Read on the other vertices (the flat edges' corners
    /// still enter their neighbours' means), the estimate sees only what noise could have
    /// moved: clean when fewer than 16 of them are left, or when they read at most
    /// `clean_noise`; a noisy patch on a clean part still reads noisy.
    pub fn clean_off_flat_edges(&self, topology: &Topology, clean_noise: f64) -> bool {
        let Some(heights) = self.heights.as_ref() else {
            return false;
        };
        heights
            .spread(topology, LeftOut::Exact(&self.exact))
            .is_none_or(|noise| noise <= clean_noise)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fairing::strength::CLEAN_NOISE;
    use crate::mesh::fixtures::grid;
    use crate::mesh::shapes::cad_cylinder;
    use crate::noise::{add_noise, NoiseMode, NoiseOptions};

    fn reading(mesh: &TriMesh) -> (Topology, NoiseReading) {
        let topology = Topology::build(mesh);
        let fans = FanRings::new(&mesh.triangles, &topology);
        let reading = read_noise(mesh, &topology, &fans, 60.0);
        (topology, reading)
    }

    fn share(flags: &[bool]) -> f64 {
        flags.iter().filter(|&&f| f).count() as f64 / flags.len() as f64
    }

    #[test]
    fn noise_leaves_almost_no_flat_edge_and_a_cad_part_is_made_of_them() {
        // A CAD cylinder (every vertex on a rim, caps of slivers) reads noisy by its plain
        // estimate, yet all its vertices are corners of flat edges (the caps, and each side quad
        // two triangles in one plane), so off them nothing is left to read: clean.
        let part = cad_cylinder(16, 0.5, 1.5);
        let (topology, clean) = reading(&part);
        assert!(clean.noise(&topology).unwrap() > CLEAN_NOISE);
        assert_eq!(share(&clean.exact), 1.0);
        assert!(clean.clean_off_flat_edges(&topology, CLEAN_NOISE));
        // The least noise that counts moves every vertex off its faces' planes: almost no flat
        // edge is left, and the reading on the rest is the plain one.
        for (mesh, name) in [(part, "cad cylinder"), (grid(60), "plane")] {
            for (sigma, seed) in [(0.05, 1), (0.3, 2)] {
                let mut noisy = mesh.clone();
                let options = NoiseOptions::default().with_sigma(sigma).with_seed(seed);
                add_noise(&mut noisy, &options.with_mode(NoiseMode::Normal));
                let (topology, reading) = reading(&noisy);
                let exact = share(&reading.exact);
                assert!(exact < 0.1, "{name} sigma {sigma}: {exact} exact");
                let noise = reading.noise(&topology).unwrap();
                assert_eq!(
                    reading.clean_off_flat_edges(&topology, CLEAN_NOISE),
                    noise <= CLEAN_NOISE,
                    "{name} sigma {sigma}: noise {noise}"
                );
            }
        }
    }

    #[test]
    fn a_noisy_patch_on_a_flat_part_still_reads_noisy_off_its_flat_edges() {
        // Noise on a quarter of a plane: the clean three quarters are flat edges' corners and
        // are not read; the patch is, and reads its noise.
        let clean = grid(60);
        let mut patch = clean.clone();
        add_noise(&mut patch, &NoiseOptions::default().with_sigma(0.3));
        let mut mesh = clean.clone();
        for (v, p) in mesh.positions.iter_mut().enumerate() {
            let (x, y) = (v % 61, v / 61);
            if x < 30 && y < 30 {
                *p = patch.positions[v];
            }
        }
        let (topology, reading) = reading(&mesh);
        assert!((0.6..0.8).contains(&share(&reading.exact)));
        assert!(!reading.clean_off_flat_edges(&topology, CLEAN_NOISE));
        let (topology, reading) = self::reading(&clean);
        assert!(reading.clean_off_flat_edges(&topology, CLEAN_NOISE));
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
