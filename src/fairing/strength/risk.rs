//! When to stop the automatic rounds: Stein's unbiased risk estimate of the rounds' result (see
//! the parent module's docs), read from a copy of the input moved along its (averaged) normals
//! and faired beside it, with σ read by second differences away from the creases.

use super::scan::VERTEX_BLOCK;
use crate::mesh::{unit_vertex_normals, Topology, TriMesh};
use glam::Vec3A;
use rayon::prelude::*;

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
/// Measured on the 32-row peer table over three noise seeds (`docs/measurements.md`, "The stop:
/// small falls add up, a draw of ±1"): letting the falls add up comes closer to the clean
/// surfaces than keeping the least and counting only a round's own fall.
pub const RISK_MIN_FALL: f64 = 0.005;

/// How far the risk's copy of the input is moved along the normals, in mean edge lengths (small
/// against the noise, large against f32 rounding; 0.02 and 0.1 stop every tuning mesh alike).
pub const RISK_STEP: f64 = 0.05;

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
    /// input's copy having gone through the same rounds to `copy`; `normals` are `mesh`'s unit
    /// vertex normals when the caller has them (the volume correction's), else they are computed.
    pub(crate) fn read(
        &self,
        mesh: &TriMesh,
        topology: &Topology,
        copy: &[[f32; 3]],
        normals: Option<&[Vec3A]>,
    ) -> f64 {
        let computed;
        let normals = match normals {
            Some(normals) => normals,
            None => {
                computed = unit_vertex_normals(mesh, topology);
                &computed
            }
        };
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
/// row's listing is most of the cost).
///
/// Measured on the 16 meshes of the peer table with noise of 0.15, 0.3 and 0.5 edge lengths along
/// the normals and per coordinate (`docs/measurements.md`): the reading over the truth has a mean
/// |log| of 0.043, 0.031 and 0.037, against 0.059, 0.037 and 0.043 for the first round's
/// residual, and 0.068, 0.034 and 0.037 with the creases' and the boundary's rings read too (a
/// CAD part's edges read as noise: the cube 13 % high at 0.15). In parallel; every vertex is
/// computed alike and the blocks' sums are joined in order, so the result does not depend on the
/// thread count. A kernel: the residual and the gain of a vertex are summed in the same pass
/// over its two rings, so the function stays whole.
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
/// See [`GAIN_STRIDE`]: the gains are averaged over at least this many vertices. Against
/// reading every gain, 2048 takes 1.9 % of noisy bunny00's instructions off its run and leaves
/// 71 of the 72 default rows of the meshes it reaches as they were, the other one round shorter
/// and closer (`docs/measurements.md`, "σ by second differences").
const GAIN_STRIDE_FROM: usize = 2048;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::grid;
    use crate::noise::{add_noise, NoiseOptions};

    /// A standard normal draw for vertex `v`, the same on every run (Box-Muller from two uniforms
    /// of a SplitMix64 hash of `v`).
    fn gaussian_draw(v: u64) -> f32 {
        let h = mix(v ^ 0x5EED_F00D_CAFE_0001);
        let u1 = ((h >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
        let u2 = ((mix(h) >> 11) as f64) / (1u64 << 53) as f64;
        ((-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
    }

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
            risk.read(&result, &topology, &moved.positions, None)
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
}
