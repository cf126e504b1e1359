//! The local operator of section 3.2: eq (7) solved in closed form for one triangle, in the
//! precomputed form P = G·Q + h·C ([`LocalOperator`]), and what it gives each corner of a
//! triangle as weights of the corners' umbrella means, positions and anchors
//! ([`corner_weights`]); a triangle with one crease corner is solved with that corner held
//! ([`held_corner_weights`], not in the paper; see the parent module's docs). Which triangles
//! are solved, and how, is [`triangle_solve`].

use crate::mesh::Topology;

/// A 3×3 matrix, rows first.
pub type Matrix3 = [[f64; 3]; 3];

/// Eq (7) in precomputed form for one local matrix A: P = G·Q + h·C, where P and Q hold one row
/// per triangle corner and C = BP⁰ is the sum of the corners' anchors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalOperator {
    pub g: Matrix3,
    pub h: [f64; 3],
}

impl LocalOperator {
    /// The operator for an invertible local matrix `a` and B = [1 1 1]; `None` when `a` is
    /// singular or BA⁻¹ vanishes.
    pub fn from_matrix(a: &Matrix3) -> Option<Self> {
        let inverse = invert3(a)?;
        // w = (BA⁻¹)ᵀ: the column sums of A⁻¹.
        let w: [f64; 3] = std::array::from_fn(|c| inverse[0][c] + inverse[1][c] + inverse[2][c]);
        let norm_squared = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        if !(norm_squared > 0.0 && norm_squared.is_finite()) {
            return None;
        }
        // A⁻¹A⁻ᵀBᵀ = A⁻¹w.
        let h: [f64; 3] = std::array::from_fn(|r| {
            (inverse[r][0] * w[0] + inverse[r][1] * w[1] + inverse[r][2] * w[2]) / norm_squared
        });
        let g = std::array::from_fn(|r| std::array::from_fn(|c| inverse[r][c] - h[r] * w[c]));
        Some(LocalOperator { g, h })
    }

    /// The operator for the paper's uniform weights and the corners' valences.
    pub fn umbrella(valences: [usize; 3]) -> Option<Self> {
        if valences.iter().any(|&n| n < 3) {
            return None;
        }
        Self::from_matrix(&umbrella_local_matrix(valences))
    }

    /// P = G·Q + h·C; `q` and the result have one row per corner, one column per coordinate.
    pub fn solve(&self, q: &Matrix3, c: [f64; 3]) -> Matrix3 {
        std::array::from_fn(|r| {
            std::array::from_fn(|k| {
                self.g[r][0] * q[0][k]
                    + self.g[r][1] * q[1][k]
                    + self.g[r][2] * q[2][k]
                    + self.h[r] * c[k]
            })
        })
    }
}

/// A of section 3.2 for uniform weights: 1 on the diagonal, −1/n_r off it in row r.
pub fn umbrella_local_matrix(valences: [usize; 3]) -> Matrix3 {
    std::array::from_fn(|r| {
        std::array::from_fn(|c| {
            if r == c {
                1.0
            } else {
                -1.0 / valences[r] as f64
            }
        })
    })
}

/// Inverse by the adjugate; `None` when (nearly) singular.
pub fn invert3(a: &Matrix3) -> Option<Matrix3> {
    let cofactor = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]
    };
    let det = a[0][0] * cofactor(0, 0) + a[0][1] * cofactor(0, 1) + a[0][2] * cofactor(0, 2);
    let scale = a.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    // Singular unless |det| is greater than the threshold; a NaN determinant (or scale)
    // compares as neither, so it counts as singular too.
    let threshold = 1e-12 * scale * scale * scale;
    if det.abs().partial_cmp(&threshold) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    Some(std::array::from_fn(|r| {
        std::array::from_fn(|c| cofactor(c, r) / det)
    }))
}

/// How a triangle gets its local solution ([`triangle_solve`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum LocalSolve {
    /// Every corner free: the paper's solution ([`corner_weights`]).
    AllFree,
    /// The corner at this index (0, 1 or 2) held where it is, the other two solved
    /// ([`held_corner_weights`]).
    CornerHeld(usize),
}

/// How triangle `t` gets a local solution: [`LocalSolve::AllFree`] with every corner free (none
/// held: `held` flags the boundary, crease and pinned vertices), [`LocalSolve::CornerHeld`] with
/// one corner held where it is (see the module docs: the one held corner, held by a crease, not
/// by the boundary, which the paper leaves unsolved, nor pinned), `None` for no solution (two or
/// three corners held, or the one held by the boundary or pinned). Only a triangle whose corners
/// are distinct and of valence three or more (so that A is invertible) is solved.
pub(super) fn triangle_solve(
    t: &[u32; 3],
    held: &[bool],
    topology: &Topology,
    pinned: &[bool],
) -> Option<LocalSolve> {
    let distinct = t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    if !distinct || t.iter().any(|&c| topology.valence(c) < 3) {
        return None;
    }
    let mut held_at = (0..3).filter(|&k| held[t[k] as usize]);
    match (held_at.next(), held_at.next()) {
        (None, _) => Some(LocalSolve::AllFree),
        (Some(h), None) => {
            let c = t[h];
            let by_crease = !topology.is_boundary_vertex(c)
                && !pinned.get(c as usize).copied().unwrap_or(false);
            by_crease.then_some(LocalSolve::CornerHeld(h))
        }
        _ => None,
    }
}

/// [`corner_weights`] for a triangle solved with corner `held` held where it is (see the module
/// docs): per free corner r, the weights its solution gives each corner c's umbrella mean,
/// position and anchor (the held corner's rows are zero). Built as coefficient vectors over
/// (m_0, m_1, m_2, x_0, x_1, x_2, anchor_0, anchor_1, anchor_2).
pub(super) fn held_corner_weights(n: [usize; 3], held: usize) -> [[[f64; 3]; 3]; 3] {
    type Coefficients = [f64; 9];
    let unit = |i: usize| -> Coefficients { std::array::from_fn(|k| f64::from(u8::from(k == i))) };
    let plus = |a: Coefficients, b: Coefficients, scale: f64| -> Coefficients {
        std::array::from_fn(|k| a[k] + scale * b[k])
    };
    let a_matrix = umbrella_local_matrix(n);
    // q_r = m_r − Σ_{c ≠ r} x_c / n_r.
    let q: [Coefficients; 3] = std::array::from_fn(|r| {
        (0..3)
            .filter(|&c| c != r)
            .fold(unit(r), |q, c| plus(q, unit(3 + c), -1.0 / n[r] as f64))
    });
    let (a, b) = match held {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    // The free pair's anchors sum: P_a + P_b = K.
    let k = plus(unit(6 + a), unit(6 + b), 1.0);
    let d: [f64; 3] = std::array::from_fn(|r| a_matrix[r][a] - a_matrix[r][b]);
    let e: [Coefficients; 3] = std::array::from_fn(|r| {
        let e = plus([0.0; 9], k, a_matrix[r][b]);
        let e = plus(e, unit(3 + held), a_matrix[r][held]);
        plus(e, q[r], -1.0)
    });
    let d_squared: f64 = d.iter().map(|x| x * x).sum();
    let p_a = (0..3).fold([0.0; 9], |s, r| plus(s, e[r], -d[r] / d_squared));
    let p_b = plus(k, p_a, -1.0);
    let mut weights = [[[0.0; 3]; 3]; 3];
    for (r, p) in [(a, p_a), (b, p_b)] {
        weights[r] = std::array::from_fn(|c| [p[c], p[3 + c], p[6 + c]]);
    }
    weights
}

/// For the valence triple `n` of a triangle's corners: per corner r, the weights its local
/// solution gives each corner c's umbrella mean, position and anchor (G_rc,
/// G_rc/n_c − Σ_c' G_rc'/n_c', h_r; see "How it is computed").
pub(super) fn corner_weights(n: [usize; 3]) -> [[[f64; 3]; 3]; 3] {
    let op = LocalOperator::umbrella(n).expect("valences are at least 3");
    std::array::from_fn(|r| {
        let k_sum: f64 = (0..3).map(|c| op.g[r][c] / n[c] as f64).sum();
        std::array::from_fn(|c| [op.g[r][c], op.g[r][c] / n[c] as f64 - k_sum, op.h[r]])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::fixtures::Rng;

    /// Solves the dense system `m·x = rhs` by Gaussian elimination with partial pivoting.
    #[allow(clippy::needless_range_loop)] // rows and columns by index read like the textbook
    fn gauss_solve<const N: usize>(mut m: [[f64; N]; N], mut rhs: [f64; N]) -> [f64; N] {
        for col in 0..N {
            let pivot = (col..N)
                .max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))
                .unwrap();
            m.swap(col, pivot);
            rhs.swap(col, pivot);
            for row in col + 1..N {
                let factor = m[row][col] / m[col][col];
                for k in col..N {
                    m[row][k] -= factor * m[col][k];
                }
                rhs[row] -= factor * rhs[col];
            }
        }
        let mut x = [0.0; N];
        for row in (0..N).rev() {
            let tail: f64 = (row + 1..N).map(|k| m[row][k] * x[k]).sum();
            x[row] = (rhs[row] - tail) / m[row][row];
        }
        x
    }

    /// The KKT system of min ‖AP − Q‖² s.t. BP = C, one coordinate:
    /// [2AᵀA Bᵀ; B 0]·[P; λ] = [2AᵀQ; C].
    fn kkt_solve(a: &Matrix3, q: [f64; 3], c: f64) -> [f64; 3] {
        let mut m = [[0.0; 4]; 4];
        let mut rhs = [0.0; 4];
        for r in 0..3 {
            for s in 0..3 {
                m[r][s] = 2.0 * (0..3).map(|k| a[k][r] * a[k][s]).sum::<f64>();
            }
            m[r][3] = 1.0;
            m[3][r] = 1.0;
            rhs[r] = 2.0 * (0..3).map(|k| a[k][r] * q[k]).sum::<f64>();
        }
        rhs[3] = c;
        let x = gauss_solve(m, rhs);
        [x[0], x[1], x[2]]
    }

    #[test]
    fn eq7_matches_kkt_and_keeps_the_barycentre() {
        let mut rng = Rng(0x9e3779b97f4a7c15);
        for case in 0..2000 {
            // Uniform weights from random valences, and every fourth case general weights
            // (eq 7 holds for any invertible A).
            let a = if case % 4 == 3 {
                std::array::from_fn(|r| {
                    std::array::from_fn(|c| if r == c { 1.0 } else { -rng.range(0.0, 0.45) })
                })
            } else {
                let n = [0; 3].map(|_| 3 + (rng.next() * 12.0) as usize);
                umbrella_local_matrix(n)
            };
            let op = LocalOperator::from_matrix(&a).expect("diagonally dominant");
            let q: Matrix3 = std::array::from_fn(|_| std::array::from_fn(|_| rng.range(-5.0, 5.0)));
            let c: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let p = op.solve(&q, c);
            for k in 0..3 {
                let direct = kkt_solve(&a, [q[0][k], q[1][k], q[2][k]], c[k]);
                let scale = direct.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                for r in 0..3 {
                    let error = (p[r][k] - direct[r]).abs() / scale;
                    assert!(error < 1e-9, "case {case}: relative error {error}");
                }
                let barycentre_error = (p[0][k] + p[1][k] + p[2][k] - c[k]).abs();
                assert!(barycentre_error < 1e-12, "case {case}: {barycentre_error}");
            }
        }
    }

    #[test]
    fn a_triangle_solved_with_a_crease_corner_held_keeps_its_free_pairs_midpoint() {
        // The free corners a, b of a triangle whose corner h is held at x_h minimise ‖AP − Q‖²
        // with P_a + P_b = anchor_a + anchor_b; solved directly (Lagrange) against the weights.
        let mut rng = Rng(0x2545f4914f6cdd1d);
        for case in 0..600 {
            let n = [0; 3].map(|_| 3 + (rng.next() * 12.0) as usize);
            let held = case % 3;
            let weights = held_corner_weights(n, held);
            let a = umbrella_local_matrix(n);
            let (fa, fb) = match held {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            let m: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let x: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let anchor: [f64; 3] = std::array::from_fn(|_| rng.range(-5.0, 5.0));
            let q: [f64; 3] = std::array::from_fn(|r| {
                m[r] - (0..3).filter(|&c| c != r).map(|c| x[c]).sum::<f64>() / n[r] as f64
            });
            // Unknowns P_a, P_b, λ: 2·MᵀM·P + λ·1 = 2·Mᵀ(Q − A_h·x_h), P_a + P_b = K.
            let column = |c: usize| [a[0][c], a[1][c], a[2][c]];
            let (ma, mb, mh) = (column(fa), column(fb), column(held));
            let rest: [f64; 3] = std::array::from_fn(|k| q[k] - mh[k] * x[held]);
            let dot = |u: [f64; 3], v: [f64; 3]| (0..3).map(|k| u[k] * v[k]).sum::<f64>();
            let system = [
                [2.0 * dot(ma, ma), 2.0 * dot(ma, mb), 1.0],
                [2.0 * dot(mb, ma), 2.0 * dot(mb, mb), 1.0],
                [1.0, 1.0, 0.0],
            ];
            let rhs = [
                2.0 * dot(ma, rest),
                2.0 * dot(mb, rest),
                anchor[fa] + anchor[fb],
            ];
            let direct = gauss_solve(system, rhs);
            for (r, expected) in [(fa, direct[0]), (fb, direct[1])] {
                let solved: f64 = (0..3)
                    .map(|c| {
                        weights[r][c][0] * m[c]
                            + weights[r][c][1] * x[c]
                            + weights[r][c][2] * anchor[c]
                    })
                    .sum();
                let error = (solved - expected).abs() / expected.abs().max(1.0);
                assert!(
                    error < 1e-9,
                    "case {case}, corner {r}: {solved} against {expected}"
                );
            }
            // The held corner gets no solution from the triangle.
            assert_eq!(weights[held], [[0.0; 3]; 3]);
        }
    }

    #[test]
    fn eq7_literal_form_equals_precomputed_form() {
        // P = A⁻¹Q + A⁻¹A⁻ᵀBᵀ(C − BA⁻¹Q)/‖BA⁻¹‖², evaluated literally, one coordinate.
        let n = [5, 6, 7];
        let a = umbrella_local_matrix(n);
        let inv = invert3(&a).unwrap();
        let q = [0.3, -1.2, 2.5];
        let c = 0.7;
        let ainv_q: [f64; 3] = std::array::from_fn(|r| (0..3).map(|k| inv[r][k] * q[k]).sum());
        let b_ainv: [f64; 3] = std::array::from_fn(|k| (0..3).map(|r| inv[r][k]).sum());
        let norm2: f64 = b_ainv.iter().map(|x| x * x).sum();
        let ainv_ainvt_bt: [f64; 3] =
            std::array::from_fn(|r| (0..3).map(|k| inv[r][k] * b_ainv[k]).sum());
        let residual = c - ainv_q.iter().sum::<f64>();
        let literal: [f64; 3] =
            std::array::from_fn(|r| ainv_q[r] + ainv_ainvt_bt[r] * residual / norm2);
        let q3 = [[q[0], 0.0, 0.0], [q[1], 0.0, 0.0], [q[2], 0.0, 0.0]];
        let p = LocalOperator::umbrella(n)
            .unwrap()
            .solve(&q3, [c, 0.0, 0.0]);
        for r in 0..3 {
            assert!((p[r][0] - literal[r]).abs() < 1e-14);
        }
    }
}
