//! Seeded Gaussian noise for trying the method on controlled damage.
//!
//! Sigma is given as a fraction of the mesh's mean edge length, so one setting means the same on
//! any mesh. Three modes:
//! - `Direction`: each vertex moves along a uniformly random unit direction by a N(0, sigma)
//!   distance (the paper's "random direction" noise).
//! - `Isotropic`: each coordinate gets independent N(0, sigma) noise.
//! - `Normal`: each vertex moves along its area-weighted normal by a N(0, sigma) distance.
//!
//! The generator is PCG (rand_pcg::Pcg64Mcg) seeded with `seed`, drawn in vertex order, so a seed
//! gives the same mesh on every machine and thread count.

use crate::mesh::TriMesh;
use crate::metrics;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal, StandardNormal};

/// Exhaustive on purpose: the editor, the CLI and the Python package each name every choice, so a
/// new one is a breaking change that they all take up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NoiseMode {
    /// Random unit direction, Gaussian distance.
    Direction,
    /// Independent Gaussian per coordinate.
    Isotropic,
    /// Along the vertex normal, Gaussian distance.
    #[default]
    Normal,
}

/// Options of [`add_noise`]; build them with `NoiseOptions::default()` and the `with_*` setters.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct NoiseOptions {
    /// Standard deviation as a fraction of the mean edge length.
    pub sigma: f64,
    /// Seed of the generator: the same seed gives the same noise.
    pub seed: u64,
    /// Which way vertices move.
    pub mode: NoiseMode,
}

with_setters!(NoiseOptions {
    with_sigma => sigma: f64,
    with_seed => seed: u64,
    with_mode => mode: NoiseMode,
});

impl Default for NoiseOptions {
    fn default() -> Self {
        Self {
            sigma: 0.3,
            seed: 1,
            mode: NoiseMode::Normal,
        }
    }
}

/// Adds noise in place; returns the absolute sigma used (model units).
///
/// ```
/// use fairmesh::noise::{add_noise, NoiseMode, NoiseOptions};
///
/// let clean = fairmesh::bundled::load_bunny(&Default::default())?.mesh;
/// let mut noisy = clean.clone();
/// let options = NoiseOptions::default()
///     .with_sigma(0.2)
///     .with_seed(7)
///     .with_mode(NoiseMode::Normal);
/// let sigma = add_noise(&mut noisy, &options);
/// assert!(sigma > 0.0);
/// // Seeded: the same seed gives the same mesh.
/// let mut again = clean.clone();
/// add_noise(&mut again, &options);
/// assert_eq!(noisy.positions, again.positions);
/// # Ok::<(), fairmesh::io::IoError>(())
/// ```
pub fn add_noise(mesh: &mut TriMesh, options: &NoiseOptions) -> f64 {
    let sigma = options.sigma.max(0.0) * metrics::mean_edge_length(mesh);
    if sigma == 0.0 || !sigma.is_finite() {
        return 0.0;
    }
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(options.seed);
    let gauss = Normal::new(0.0, sigma).expect("sigma is finite and positive");
    let normals = match options.mode {
        NoiseMode::Normal => mesh.vertex_normals(),
        _ => Vec::new(),
    };
    for (v, p) in mesh.positions.iter_mut().enumerate() {
        let offset = match options.mode {
            NoiseMode::Isotropic => glam::DVec3::new(
                gauss.sample(&mut rng),
                gauss.sample(&mut rng),
                gauss.sample(&mut rng),
            ),
            NoiseMode::Direction => random_unit(&mut rng) * gauss.sample(&mut rng),
            NoiseMode::Normal => normals[v] * gauss.sample(&mut rng),
        };
        for c in 0..3 {
            p[c] = (p[c] as f64 + offset[c]) as f32;
        }
    }
    sigma
}

fn random_unit(rng: &mut impl Rng) -> glam::DVec3 {
    loop {
        let d = glam::DVec3::new(
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
            StandardNormal.sample(rng),
        );
        let len = d.length();
        if len > 1e-12 {
            return d / len;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize) -> TriMesh {
        let mut mesh = TriMesh::default();
        for y in 0..=n {
            for x in 0..=n {
                mesh.positions.push([x as f32, y as f32, 0.0]);
            }
        }
        let id = |x: usize, y: usize| (y * (n + 1) + x) as u32;
        for y in 0..n {
            for x in 0..n {
                mesh.triangles
                    .push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
                mesh.triangles
                    .push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
            }
        }
        mesh
    }

    #[test]
    fn same_seed_same_noise_other_seed_other_noise() {
        let options = NoiseOptions {
            sigma: 0.2,
            seed: 7,
            mode: NoiseMode::Direction,
        };
        let (mut a, mut b, mut c) = (grid(8), grid(8), grid(8));
        add_noise(&mut a, &options);
        add_noise(&mut b, &options);
        add_noise(
            &mut c,
            &NoiseOptions {
                seed: 8,
                ..options.clone()
            },
        );
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn normal_noise_on_a_plane_moves_only_along_the_normal_with_the_asked_sigma() {
        let clean = grid(60);
        let mut noisy = clean.clone();
        let sigma = add_noise(
            &mut noisy,
            &NoiseOptions {
                sigma: 0.3,
                seed: 3,
                mode: NoiseMode::Normal,
            },
        );
        let mean_edge = metrics::mean_edge_length(&clean);
        assert!((sigma - 0.3 * mean_edge).abs() < 1e-12);
        let mut sum_sq = 0.0;
        for (p, q) in clean.positions.iter().zip(&noisy.positions) {
            assert_eq!((p[0], p[1]), (q[0], q[1]));
            sum_sq += (q[2] as f64).powi(2);
        }
        let measured = (sum_sq / clean.positions.len() as f64).sqrt();
        assert!(
            (measured / sigma - 1.0).abs() < 0.1,
            "measured sigma {measured}, asked {sigma}"
        );
    }

    #[test]
    fn isotropic_noise_spreads_over_all_axes() {
        let clean = grid(40);
        let mut noisy = clean.clone();
        let sigma = add_noise(
            &mut noisy,
            &NoiseOptions {
                sigma: 0.5,
                seed: 1,
                mode: NoiseMode::Isotropic,
            },
        );
        for axis in 0..3 {
            let var: f64 = clean
                .positions
                .iter()
                .zip(&noisy.positions)
                .map(|(p, q)| ((q[axis] - p[axis]) as f64).powi(2))
                .sum::<f64>()
                / clean.positions.len() as f64;
            assert!(
                (var.sqrt() / sigma - 1.0).abs() < 0.15,
                "axis {axis}: {} vs {sigma}",
                var.sqrt()
            );
        }
    }
}
