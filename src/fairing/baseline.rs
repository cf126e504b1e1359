//! Baselines the constrained method is compared against (not from the paper's method; see the
//! "Baselines" section of the repository's `docs/paper.md`):
//! - Laplacian (umbrella) smoothing: x ← x + λ·(m − x), m the mean of the neighbours, λ = 0.5.
//! - Taubin λ|μ smoothing: a λ = 0.5 step, then a μ = −0.53 step, per iteration (MeshLab's and
//!   Open3D's defaults).
//! - HC Laplacian (Vollmer, Mencl and Müller 1999): p = m(q); b = p − (α·o + (1 − α)·q);
//!   q ← p − (β·b + (1 − β)·mean of the neighbours' b). `o` are the positions at the start of the
//!   run; with the default α = 0 it does not matter, which is MeshLab's variant (it pushes back
//!   towards the start-of-step positions); β = 0.5 as in MeshLab.
//!
//! All use uniform weights. With [`BoundaryMode::Curve`] a boundary vertex uses the curve
//! Laplacian (the mean of its two loop neighbours, as in section 3.3); with
//! [`BoundaryMode::Fixed`] it stays. Every step is a parallel gather over vertices that reads the
//! previous iterate only, so the result is bit-identical for any thread count.

use super::boundary::BoundaryCurves;
use super::{BoundaryMode, FairReport};
use crate::mesh::{Topology, TriMesh};
use rayon::prelude::*;

/// Options of [`fair_laplacian`].
#[derive(Clone, Debug)]
pub struct LaplacianOptions {
    pub iterations: usize,
    /// Step size, in (0, 1].
    pub lambda: f64,
    pub boundary: BoundaryMode,
}

impl Default for LaplacianOptions {
    fn default() -> Self {
        Self {
            iterations: 10,
            lambda: 0.5,
            boundary: BoundaryMode::Curve,
        }
    }
}

/// Options of [`fair_taubin`].
#[derive(Clone, Debug)]
pub struct TaubinOptions {
    pub iterations: usize,
    /// The shrinking step, positive.
    pub lambda: f64,
    /// The inflating step, negative, with |μ| slightly above λ.
    pub mu: f64,
    pub boundary: BoundaryMode,
}

impl Default for TaubinOptions {
    fn default() -> Self {
        Self {
            iterations: 10,
            lambda: 0.5,
            mu: -0.53,
            boundary: BoundaryMode::Curve,
        }
    }
}

/// Options of [`fair_hc`].
#[derive(Clone, Debug)]
pub struct HcOptions {
    pub iterations: usize,
    /// Pull towards the run's input positions (0: towards the start of each step, as MeshLab).
    pub alpha: f64,
    /// Weight of a vertex's own correction against its neighbours' mean correction.
    pub beta: f64,
    pub boundary: BoundaryMode,
}

impl Default for HcOptions {
    fn default() -> Self {
        Self {
            iterations: 10,
            alpha: 0.0,
            beta: 0.5,
            boundary: BoundaryMode::Curve,
        }
    }
}

/// Who each vertex averages over: mesh neighbours, loop neighbours (boundary, curve mode), or
/// nobody (boundary in fixed mode, unreferenced vertices): such a vertex does not move.
#[derive(Clone, Debug)]
pub struct UmbrellaStencil {
    offsets: Vec<u32>,
    neighbors: Vec<u32>,
}

impl UmbrellaStencil {
    pub fn new(topology: &Topology, boundary: BoundaryMode) -> Self {
        let vertex_count = topology.vertex_count();
        let mut loop_neighbors: Vec<Vec<u32>> = Vec::new();
        let mut loop_slot = vec![u32::MAX; vertex_count];
        if boundary == BoundaryMode::Curve {
            let curves = BoundaryCurves::new(&topology.boundary_loops, vertex_count);
            for (v, before, after) in curves.loop_neighbors() {
                if loop_slot[v as usize] == u32::MAX {
                    loop_slot[v as usize] = loop_neighbors.len() as u32;
                    loop_neighbors.push(Vec::new());
                }
                loop_neighbors[loop_slot[v as usize] as usize].extend([before, after]);
            }
        }
        let mut offsets = Vec::with_capacity(vertex_count + 1);
        offsets.push(0u32);
        let mut neighbors = Vec::with_capacity(topology.neighbor_csr().1.len());
        for v in 0..vertex_count as u32 {
            if !topology.is_boundary_vertex(v) {
                neighbors.extend_from_slice(topology.neighbors(v));
            } else if loop_slot[v as usize] != u32::MAX {
                neighbors.extend_from_slice(&loop_neighbors[loop_slot[v as usize] as usize]);
            }
            offsets.push(neighbors.len() as u32);
        }
        UmbrellaStencil { offsets, neighbors }
    }

    #[inline]
    fn of(&self, v: usize) -> &[u32] {
        &self.neighbors[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// The mean of `values` over v's stencil, or `None` for a vertex that does not move.
    #[inline]
    fn mean(&self, values: &[[f32; 3]], v: usize) -> Option<[f32; 3]> {
        let stencil = self.of(v);
        if stencil.is_empty() {
            return None;
        }
        let mut sum = [0.0f32; 3];
        for &u in stencil {
            let p = values[u as usize];
            for k in 0..3 {
                sum[k] += p[k];
            }
        }
        let inv = 1.0 / stencil.len() as f32;
        Some(sum.map(|s| s * inv))
    }

    /// `next = x + factor·(m(x) − x)` over all vertices; returns the largest move.
    pub fn relax(&self, x: &[[f32; 3]], next: &mut [[f32; 3]], factor: f32) -> f64 {
        let max_squared = next
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(chunk, out)| {
                let mut max_squared = 0.0f32;
                for (i, new_position) in out.iter_mut().enumerate() {
                    let v = chunk * CHUNK + i;
                    let p = x[v];
                    *new_position = match self.mean(x, v) {
                        None => p,
                        Some(m) => {
                            let step: [f32; 3] = std::array::from_fn(|k| factor * (m[k] - p[k]));
                            max_squared = max_squared.max(length_squared(step));
                            std::array::from_fn(|k| p[k] + step[k])
                        }
                    };
                }
                max_squared
            })
            .reduce(|| 0.0, f32::max);
        (max_squared as f64).sqrt()
    }
}

const CHUNK: usize = 2048;

#[inline]
fn length_squared(a: [f32; 3]) -> f32 {
    a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
}

/// Laplacian smoothing in place.
pub fn fair_laplacian(
    mesh: &mut TriMesh,
    topology: &Topology,
    options: &LaplacianOptions,
) -> FairReport {
    let stencil = UmbrellaStencil::new(topology, options.boundary);
    let mut next = mesh.positions.clone();
    let mut report = FairReport::default();
    for _ in 0..options.iterations {
        report.max_move = stencil.relax(&mesh.positions, &mut next, options.lambda as f32);
        report.iterations_run += 1;
        std::mem::swap(&mut mesh.positions, &mut next);
    }
    report
}

/// Taubin λ|μ smoothing in place; `max_move` is the net move of the last iteration's two steps.
pub fn fair_taubin(mesh: &mut TriMesh, topology: &Topology, options: &TaubinOptions) -> FairReport {
    let stencil = UmbrellaStencil::new(topology, options.boundary);
    let mut half = mesh.positions.clone();
    let mut next = mesh.positions.clone();
    let mut report = FairReport::default();
    for _ in 0..options.iterations {
        stencil.relax(&mesh.positions, &mut half, options.lambda as f32);
        stencil.relax(&half, &mut next, options.mu as f32);
        report.max_move = largest_move(&mesh.positions, &next);
        report.iterations_run += 1;
        std::mem::swap(&mut mesh.positions, &mut next);
    }
    report
}

/// HC Laplacian smoothing in place.
pub fn fair_hc(mesh: &mut TriMesh, topology: &Topology, options: &HcOptions) -> FairReport {
    let stencil = UmbrellaStencil::new(topology, options.boundary);
    let original = mesh.positions.clone();
    let vertex_count = original.len();
    let mut smoothed = vec![[0.0f32; 3]; vertex_count];
    let mut corrections = vec![[0.0f32; 3]; vertex_count];
    let mut next = vec![[0.0f32; 3]; vertex_count];
    let (alpha, beta) = (options.alpha as f32, options.beta as f32);
    let mut report = FairReport::default();
    for _ in 0..options.iterations {
        let q = &mesh.positions;
        // p = m(q); b = p − (α·o + (1 − α)·q); fixed vertices get b = 0.
        smoothed
            .par_chunks_mut(CHUNK)
            .zip(corrections.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(chunk, (p_out, b_out))| {
                for (i, (p, b)) in p_out.iter_mut().zip(b_out.iter_mut()).enumerate() {
                    let v = chunk * CHUNK + i;
                    match stencil.mean(q, v) {
                        None => {
                            *p = q[v];
                            *b = [0.0; 3];
                        }
                        Some(m) => {
                            *p = m;
                            *b = std::array::from_fn(|k| {
                                m[k] - (alpha * original[v][k] + (1.0 - alpha) * q[v][k])
                            });
                        }
                    }
                }
            });
        // q ← p − (β·b + (1 − β)·mean of the neighbours' b).
        let (smoothed, corrections) = (&smoothed, &corrections);
        next.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(chunk, out)| {
                for (i, new_position) in out.iter_mut().enumerate() {
                    let v = chunk * CHUNK + i;
                    *new_position = match stencil.mean(corrections, v) {
                        None => q[v],
                        Some(mean_b) => std::array::from_fn(|k| {
                            smoothed[v][k] - (beta * corrections[v][k] + (1.0 - beta) * mean_b[k])
                        }),
                    };
                }
            });
        report.max_move = largest_move(&mesh.positions, &next);
        report.iterations_run += 1;
        std::mem::swap(&mut mesh.positions, &mut next);
    }
    report
}

fn largest_move(before: &[[f32; 3]], after: &[[f32; 3]]) -> f64 {
    let max_squared = before
        .par_iter()
        .zip(after.par_iter())
        .map(|(a, b)| length_squared(std::array::from_fn(|k| b[k] - a[k])))
        .reduce(|| 0.0, f32::max);
    (max_squared as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 5×5 grid of the unit square, two triangles per cell; vertex (i, j) is 5j + i.
    fn grid() -> TriMesh {
        let mut positions = Vec::new();
        for j in 0..5 {
            for i in 0..5 {
                positions.push([i as f32, j as f32, 0.0]);
            }
        }
        let mut triangles = Vec::new();
        for j in 0..4u32 {
            for i in 0..4u32 {
                let v = 5 * j + i;
                triangles.push([v, v + 1, v + 6]);
                triangles.push([v, v + 6, v + 5]);
            }
        }
        TriMesh::new(positions, triangles)
    }

    #[test]
    fn a_laplacian_step_moves_a_bump_by_lambda_times_its_height_and_reports_that_move() {
        // The grid's centre lifted by 1 above its six flat neighbours: one step of λ = 0.5 moves
        // it down by 0.5 (its neighbours' mean is straight below it), each of its
        // neighbours up by 0.5 / 6 (one of their six neighbours is the bump), the rest not at
        // all; the largest move reported is the centre's.
        let mut mesh = grid();
        mesh.positions[12][2] = 1.0;
        let topology = Topology::build(&mesh);
        let options = LaplacianOptions {
            iterations: 1,
            lambda: 0.5,
            boundary: BoundaryMode::Fixed,
        };
        let report = fair_laplacian(&mut mesh, &topology, &options);
        assert!((report.max_move - 0.5).abs() < 1e-6, "{}", report.max_move);
        assert!((mesh.positions[12][2] - 0.5).abs() < 1e-6);
        // Its neighbours along the grid's diagonals (v ± 6) and edges (v ± 1, v ± 5).
        for v in [6, 7, 11, 13, 17, 18] {
            assert!((mesh.positions[v][2] - 0.5 / 6.0).abs() < 1e-6, "{v}");
        }
        assert_eq!((mesh.positions[8][2], mesh.positions[16][2]), (0.0, 0.0));
    }

    #[test]
    fn fixed_boundary_stays_and_bump_flattens() {
        let mut mesh = grid();
        mesh.positions[12][2] = 1.0;
        let topology = Topology::build(&mesh);
        let before = mesh.positions.clone();
        fair_laplacian(
            &mut mesh,
            &topology,
            &LaplacianOptions {
                iterations: 20,
                boundary: BoundaryMode::Fixed,
                ..Default::default()
            },
        );
        for v in 0..25u32 {
            if topology.is_boundary_vertex(v) {
                assert_eq!(mesh.positions[v as usize], before[v as usize]);
            }
        }
        assert!(mesh.positions[12][2] < 0.1);
    }

    #[test]
    fn hc_and_taubin_even_out_a_jittered_plane_and_keep_it_flat() {
        // The interior vertices pushed off their grid points within the plane: both smoothers
        // move them back towards the regular grid (doing nothing would not) and out of the plane
        // not at all (every mean of points at z = 0 is at z = 0).
        let regular = grid();
        let mut jittered = regular.clone();
        let topology = Topology::build(&regular);
        for v in 0..25u32 {
            if !topology.is_boundary_vertex(v) {
                let sign = if v % 2 == 0 { 1.0 } else { -1.0 };
                jittered.positions[v as usize][0] += 0.3 * sign;
                jittered.positions[v as usize][1] -= 0.2 * sign;
            }
        }
        let off_grid = |m: &TriMesh| -> f64 {
            (0..25u32)
                .filter(|&v| !topology.is_boundary_vertex(v))
                .map(|v| m.point(v).distance(regular.point(v)))
                .sum()
        };
        let mut hc = jittered.clone();
        fair_hc(&mut hc, &topology, &HcOptions::default());
        let mut taubin = jittered.clone();
        fair_taubin(&mut taubin, &topology, &TaubinOptions::default());
        for (name, mesh) in [("HC", &hc), ("Taubin", &taubin)] {
            assert!(mesh.positions.iter().all(|p| p[2] == 0.0), "{name}");
            assert!(
                off_grid(mesh) < 0.5 * off_grid(&jittered),
                "{name}: {} from the grid, jittered {}",
                off_grid(mesh),
                off_grid(&jittered)
            );
        }
    }

    /// A level-3 icosphere (642 vertices) with Gaussian noise along the normals of 0.3 mean edge
    /// lengths.
    fn noisy_sphere() -> TriMesh {
        let mut mesh = crate::mesh::shapes::icosphere(3);
        crate::noise::add_noise(
            &mut mesh,
            &crate::noise::NoiseOptions::default()
                .with_sigma(0.3)
                .with_seed(1)
                .with_mode(crate::noise::NoiseMode::Normal),
        );
        mesh
    }

    /// Mean distance of the vertices from the unit sphere the noise was added to.
    fn radius_error(mesh: &TriMesh) -> f64 {
        (0..mesh.vertex_count() as u32)
            .map(|v| (mesh.point(v).length() - 1.0).abs())
            .sum::<f64>()
            / mesh.vertex_count() as f64
    }

    /// Relative volume change of `after` against `before`, and its radius error over `before`'s.
    fn volume_and_noise(before: &TriMesh, after: &TriMesh) -> (f64, f64) {
        let volume = crate::metrics::signed_volume;
        (
            (volume(after) - volume(before)) / volume(before),
            radius_error(after) / radius_error(before),
        )
    }

    /// (volume change, radius error left) of the noisy sphere after `fair`.
    fn on_the_noisy_sphere(fair: &dyn Fn(&mut TriMesh, &Topology)) -> (f64, f64) {
        let noisy = noisy_sphere();
        let topology = Topology::build(&noisy);
        let mut mesh = noisy.clone();
        fair(&mut mesh, &topology);
        volume_and_noise(&noisy, &mesh)
    }

    // (volume change, radius error left) on the noisy sphere, measured: Laplacian (-15.7 %, 149 %:
    // the sphere shrinks inside its noise), Taubin (+0.91 %, 40 %), HC (-0.21 %, 30 %). Taubin
    // without its μ step is the Laplacian; HC without its correction step is the umbrella mean
    // alone, a Laplacian of λ = 1.

    #[test]
    fn the_laplacian_shrinks_a_noisy_sphere() {
        let laplacian = on_the_noisy_sphere(&|m, t| {
            fair_laplacian(m, t, &LaplacianOptions::default());
        });
        assert!(laplacian.0 < -0.1, "{laplacian:?}");
    }

    #[test]
    fn taubin_smooths_a_noisy_sphere_and_keeps_its_volume() {
        let taubin = on_the_noisy_sphere(&|m, t| {
            fair_taubin(m, t, &TaubinOptions::default());
        });
        assert!(taubin.0.abs() < 0.015 && taubin.1 < 0.5, "{taubin:?}");
    }

    #[test]
    fn hc_smooths_a_noisy_sphere_and_keeps_its_volume() {
        let hc = on_the_noisy_sphere(&|m, t| {
            fair_hc(m, t, &HcOptions::default());
        });
        assert!(hc.0.abs() < 0.004 && hc.1 < 0.4, "{hc:?}");
    }
}
