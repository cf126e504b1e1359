//! How strongly to fair: an estimate of a mesh's noise, and the rule that picks the number of
//! constrained-fairing rounds from it ([`super::Strength::Auto`], the default).
//!
//! Not in the paper, which leaves the number of iterations to the user. Measured here: the
//! iterations within a round hardly matter (a round settles after 5 to 10), the rounds do, and
//! the best count differs from mesh to mesh (2-4 rounds on coarsely sampled scans, 20-40 on
//! finely sampled ones and on CAD parts), while a clean mesh should not be touched at all. So the
//! default measures the noise before fairing (at or below [`CLEAN_NOISE`] it does nothing; nor
//! when the mesh reads that clean once the vertices on its sharp edges are left out,
//! `NoiseReading::away_from_edges`, or once the corners of its flat edges are, which noise would
//! have moved out of their faces' common plane, `NoiseReading::clean_off_flat_edges`), and a
//! noisy mesh is faired round by round while Stein's unbiased risk estimate of the result goes
//! down (`RoundRisk`).
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
//! `risk::sign_draw`; the normals averaged over the one-rings [`RISK_DRAW_AVERAGING`] times, so
//! that they stand for the clean surface's): Σ b_v n_v · (f_v(y + ε b n) − f_v(y)) / ε. That is
//! Hutchinson's estimate of a trace, bᵀ J b for E[bᵀ J b] = tr J; with b_v = ±1 (Rademacher) its
//! variance is 2 Σ_{u≠v} J_uv², the least of any draw of independent b_v, where a Gaussian draw
//! adds 2 Σ J_vv² from b_v² ≠ 1 (`docs/measurements.md`, "The stop: small falls add up, a draw of
//! ±1"). The copy goes through the same operator, round for round, so every round costs its
//! iterations twice. σ itself is read from the input by second differences
//! (`risk::second_difference_variance`): with L the umbrella operator (the mean of the neighbours),
//! r_v = n_v · ((I − L)² y)_v is, on a smooth surface, the change of the curvature term across two
//! rings (small) plus the noise filtered by a row of (I − L)², whose squared norm g_v is known; so
//! σ² = Σ r_v² / Σ g_v over the vertices whose two rings hold no crease and no boundary vertex
//! (there the surface is not smooth). A reading from the first round's residual, E Σ (n · (f − y))²
//! = bias + σ² (N − 2 div + Σ |n · ∂f n|²) taken with the bias as zero, would read high (the shape
//! the round removes counts as noise) and stop the coarse scans a round late
//! (`docs/measurements.md`, "σ by second differences"). A round is kept when it lowers the risk
//! below the last kept round's by at least [`RISK_MIN_FALL`] of what the second round lowered it by
//! (so small falls add up until they count, and a round that is lower by less than that is not
//! worth its extra smoothing); the rounds stop [`RISK_PATIENCE`] rounds after the last kept one
//! (the risk is not always convex in the rounds: a CAD part's creases found again after a few
//! rounds lower it again), or after [`MAX_AUTO_ROUNDS`], and the mesh goes back to the last kept
//! round.
//!
//! # Files
//! - `scan`: the fused gather over the fan-ordered one-rings: h_v, the mean edge length and the
//!   faces' own feature edges at once (`scan_fans`, which crease detection uses too).
//! - `noise`: the noise estimate from it ([`estimate_noise`]), and the readings that tell a CAD
//!   part from a noisy mesh.
//! - `risk`: Stein's unbiased risk estimate that stops the automatic rounds.

mod noise;
mod risk;
mod scan;

pub use noise::estimate_noise;
pub(crate) use noise::{read_noise, NoiseReading};
pub(crate) use risk::RoundRisk;
pub use risk::{RISK_DRAW_AVERAGING, RISK_MIN_FALL, RISK_PATIENCE, RISK_STEP};
pub(crate) use scan::scan_fans;
pub use scan::NOISE_GAIN;

/// At or below this estimate a mesh counts as clean and automatic fairing leaves it alone (mean
/// edge lengths; clean scans and CAD parts measure 0.000 to 0.035, see `docs/measurements.md`).
pub const CLEAN_NOISE: f64 = 0.04;

/// At most this many rounds in automatic mode, a doubled round ([`DOUBLED_FROM_ROUND`]) counting
/// as [`DOUBLED_STEP`].
pub const MAX_AUTO_ROUNDS: usize = 60;

/// Automatic strength: from this round on (counted from 0), every round moves the vertices
/// [`DOUBLED_STEP`] times as far as its iterations took them (the round's move extrapolated),
/// so the rounds that crawl on a finely sampled mesh cover the same ground in about half as
/// many. A round multiplies each shape mode of the surface by about 1 − λ (λ in [0, 1]: the
/// noise's modes near 1, the shape's near 0); a doubled round by 1 − 2λ, which is (1 − λ)² to
/// first order for the slow modes and stays within [−1, 1] for every mode, so nothing grows; by
/// this round the fast modes are gone (the rounds before it are plain, and the coarsely sampled
/// scans, which stop after 2 to 6 rounds, never reach it). Only vertices off the creases and the
/// boundary are extrapolated: curves and corners keep their rounds' own moves. The risk's copy
/// takes the same steps, so the rule that stops the rounds reads the map that made the mesh
/// (`docs/measurements.md`, "Doubled rounds").
pub const DOUBLED_FROM_ROUND: usize = 14;

/// The step of a doubled round ([`DOUBLED_FROM_ROUND`]).
pub const DOUBLED_STEP: f32 = 2.0;

/// Normal-filter passes crease detection gets for a mesh with this noise estimate: none
/// for a clean mesh, more the noisier it is.
pub fn normal_filtering_for(noise: f64) -> usize {
    if noise <= CLEAN_NOISE {
        0
    } else {
        ((noise / 0.05).ceil() as usize).clamp(1, 10)
    }
}
