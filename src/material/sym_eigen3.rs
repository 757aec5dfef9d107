//! Eigen-decomposition of a symmetric 3 x 3 matrix by the cyclic Jacobi method, for the
//! log strain's spectral form (one per integration point and evaluation).
//!
//! # Method
//!
//! Sweeps over the pairs `(0, 1), (0, 2), (1, 2)`; each plane rotation `J` zeroes `a_pq`
//! exactly (Golub & Van Loan, *Matrix Computations*, Alg. 8.5.2, with Rutishauser's update
//! of the diagonal, `a_pp -= t a_pq`, `a_qq += t a_pq`), `t = tan θ` the smaller root of
//! `t² + 2τt - 1 = 0`, `τ = (a_qq - a_pp) / (2 a_pq)`. Convergence is quadratic; the sweeps
//! stop when the largest off-diagonal entry is below `10⁻¹⁷` of the largest entry (its effect on the
//! eigenvalues is then below round-off), typically after 3-4 sweeps: ~30 flops and one
//! square root per rotation, against nalgebra's general Householder tridiagonalisation
//! plus implicit QR. Backward stable like that one: `A = V Λ Vᵀ` to `O(ε |A|)`, so that the
//! strain of a nearly rigid motion keeps its own relative precision when the decomposed
//! matrix is `C - I` (see `material::log_strain`). Eigenvalues in no particular order.

use crate::geometry::Mat3;

/// Sweeps before giving up on the threshold (never reached for finite input: quadratic
/// convergence takes 3-5).
const MAX_SWEEPS: usize = 30;

/// `2^27`: from this `|τ|` on, a rotation's `t`, `c` and `s` are `0.5 / τ`, 1 and `t` to
/// the last bit (`τ² >= 2^54`, so `1 + τ²` rounds to `τ²`; `t² <= 2^-56`, so `1 + t²`
/// rounds to 1).
const SMALL_ROTATION_TAU: f64 = 134_217_728.0;

/// Eigenvalues and orthonormal eigenvectors (columns) of the symmetric `a` (only its upper
/// triangle is read). Non-finite input gives non-finite output, as the caller checks.
pub fn sym_eigen3(a: &Mat3) -> ([f64; 3], Mat3) {
    let mut m = [
        [a[(0, 0)], a[(0, 1)], a[(0, 2)]],
        [a[(0, 1)], a[(1, 1)], a[(1, 2)]],
        [a[(0, 2)], a[(1, 2)], a[(2, 2)]],
    ];
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..MAX_SWEEPS {
        // Largest entries, not sums of squares (which underflow for tiny matrices).
        let off = m[0][1].abs().max(m[0][2].abs()).max(m[1][2].abs());
        let diag = m[0][0].abs().max(m[1][1].abs()).max(m[2][2].abs());
        if !(off > 1e-17 * diag.max(off)) {
            break;
        }
        // The pairs spelled out (not a loop over them): with constant indices the two
        // 3 x 3 arrays stay in registers. The same operations in the same order.
        rotate::<0, 1, 2>(&mut m, &mut v);
        rotate::<0, 2, 1>(&mut m, &mut v);
        rotate::<1, 2, 0>(&mut m, &mut v);
    }
    (
        [m[0][0], m[1][1], m[2][2]],
        Mat3::new(
            v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2], v[2][0], v[2][1], v[2][2],
        ),
    )
}

/// One Jacobi rotation in the plane `(P, Q)` (`R` the third index) zeroing `m[P][Q]`, and
/// its accumulation into the eigenvectors `v` (module docs).
#[inline(always)]
fn rotate<const P: usize, const Q: usize, const R: usize>(
    m: &mut [[f64; 3]; 3],
    v: &mut [[f64; 3]; 3],
) {
    let apq = m[P][Q];
    if apq == 0.0 {
        return;
    }
    let tau = (m[Q][Q] - m[P][P]) / (2.0 * apq);
    let (t, c, s) = if tau.abs() >= SMALL_ROTATION_TAU {
        // The late rotations of every decomposition: `a_pq` below 2^-28 of its pair's
        // gap. There `1 + τ²` rounds to `τ²`, whose square root is `|τ|` exactly, so the
        // general formula's `t` is `sign / (2|τ|) = 0.5 / τ`, and `1 + t²` rounds to 1,
        // so `c = 1`, `s = t`: the same bits without two square roots and two divisions,
        // which are the latency of the whole decomposition. Also where `τ²` overflows.
        let t = 0.5 / tau;
        (t, 1.0, t)
    } else {
        // sqrt(1 + τ²) rather than libm's hypot (several times slower).
        let t = tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt());
        let c = 1.0 / (1.0 + t * t).sqrt();
        (t, c, t * c)
    };
    m[P][P] -= t * apq;
    m[Q][Q] += t * apq;
    m[P][Q] = 0.0;
    m[Q][P] = 0.0;
    let (arp, arq) = (m[R][P], m[R][Q]);
    m[R][P] = c * arp - s * arq;
    m[P][R] = m[R][P];
    m[R][Q] = s * arp + c * arq;
    m[Q][R] = m[R][Q];
    for row in v.iter_mut() {
        let (vp, vq) = (row[P], row[Q]);
        row[P] = c * vp - s * vq;
        row[Q] = s * vp + c * vq;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SymmetricEigen;

    /// Random symmetric matrices (also graded, nearly diagonal, with double and triple
    /// eigenvalues, and tiny ones like `C - I` of a small strain): `V Λ Vᵀ = A` and
    /// `VᵀV = I` to 1e-15 of `|A|`, and the sorted eigenvalues equal nalgebra's to 1e-14 of
    /// `|A|` (both backward stable).
    #[test]
    fn decomposes_like_the_general_method() {
        let mut seed = 99u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut cases: Vec<Mat3> = Vec::new();
        for k in 0..400 {
            let scale = 10f64.powi(-(k % 9));
            let r = Mat3::from_fn(|_, _| rnd()) * scale;
            cases.push(r + r.transpose());
        }
        // A rotated diag(d, d, e), diag(d, d, d), a diagonal one and zero.
        let q = SymmetricEigen::new(cases[0]).eigenvectors;
        cases.push(q * Mat3::from_diagonal(&[2e-6, 2e-6, -1e-6].into()) * q.transpose());
        cases.push(q * Mat3::from_diagonal(&[3e-4, 3e-4, 3e-4].into()) * q.transpose());
        cases.push(Mat3::from_diagonal(&[1.0, -2.0, 0.5].into()));
        cases.push(Mat3::new(0.0, 1e-300, 0.0, 1e-300, 0.0, 0.0, 0.0, 0.0, 0.0));
        cases.push(Mat3::zeros());
        for a in cases {
            let (lam, v) = sym_eigen3(&a);
            let size = a.norm().max(f64::MIN_POSITIVE);
            let back = v * Mat3::from_diagonal(&lam.into()) * v.transpose();
            assert!((back - a).norm() <= 1e-15 * size * 4.0, "{a}");
            assert!((v.transpose() * v - Mat3::identity()).norm() <= 4e-15);
            let mut mine = lam;
            mine.sort_by(f64::total_cmp);
            let reference = SymmetricEigen::new(a).eigenvalues;
            let mut theirs = [reference[0], reference[1], reference[2]];
            theirs.sort_by(f64::total_cmp);
            for i in 0..3 {
                assert!((mine[i] - theirs[i]).abs() <= 1e-14 * size, "{a}");
            }
        }
    }

    /// The sweeps as a loop over the pairs, the form before the rotations were spelled out
    /// per pair (`rotate`): the oracle of the test below.
    fn looped(a: &Mat3) -> ([f64; 3], Mat3) {
        let mut m = [
            [a[(0, 0)], a[(0, 1)], a[(0, 2)]],
            [a[(0, 1)], a[(1, 1)], a[(1, 2)]],
            [a[(0, 2)], a[(1, 2)], a[(2, 2)]],
        ];
        let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for _ in 0..MAX_SWEEPS {
            let off = m[0][1].abs().max(m[0][2].abs()).max(m[1][2].abs());
            let diag = m[0][0].abs().max(m[1][1].abs()).max(m[2][2].abs());
            if !(off > 1e-17 * diag.max(off)) {
                break;
            }
            for (p, q) in [(0, 1), (0, 2), (1, 2)] {
                let apq = m[p][q];
                if apq == 0.0 {
                    continue;
                }
                let tau = (m[q][q] - m[p][p]) / (2.0 * apq);
                let t = if tau.abs() > 1e150 {
                    0.5 / tau
                } else {
                    tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt())
                };
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = t * c;
                m[p][p] -= t * apq;
                m[q][q] += t * apq;
                m[p][q] = 0.0;
                m[q][p] = 0.0;
                let r = 3 - p - q;
                let (arp, arq) = (m[r][p], m[r][q]);
                m[r][p] = c * arp - s * arq;
                m[p][r] = m[r][p];
                m[r][q] = s * arp + c * arq;
                m[q][r] = m[r][q];
                for row in &mut v {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
        ([m[0][0], m[1][1], m[2][2]], Mat3::from_fn(|i, j| v[i][j]))
    }

    /// The rotations spelled out per pair give the looped sweeps' eigenvalues and
    /// eigenvectors bit for bit: random (graded down to 1e-8), nearly repeated spectra
    /// (spreads 1e-9..1e-15 of the scale, rotated), exactly repeated and diagonal ones.
    #[test]
    fn spelled_out_rotations_equal_the_loop_bit_for_bit() {
        let mut seed = 5u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut cases: Vec<Mat3> = Vec::new();
        for k in 0..300 {
            let r = Mat3::from_fn(|_, _| rnd()) * 10f64.powi(-(k % 9));
            cases.push(r + r.transpose());
        }
        for k in 0..200 {
            let q = SymmetricEigen::new(cases[k] * 1e3).eigenvectors;
            let spread = 10f64.powi(-9 - (k % 7) as i32);
            let d = [1e-3, 1e-3 * (1.0 + spread * rnd()), -5e-4 + 1e-3 * rnd()];
            let d = if k % 2 == 0 {
                d
            } else {
                [d[0], d[1], d[0] * (1.0 - spread)]
            };
            cases.push(q * Mat3::from_diagonal(&d.into()) * q.transpose());
        }
        cases.push(Mat3::from_diagonal(&[1.0, -2.0, 0.5].into()));
        cases.push(Mat3::identity() * 3e-4);
        cases.push(Mat3::zeros());
        let bits = |lam: [f64; 3], v: Mat3| {
            (
                lam.map(f64::to_bits),
                v.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            )
        };
        for a in cases {
            let (l1, v1) = sym_eigen3(&a);
            let (l2, v2) = looped(&a);
            assert_eq!(bits(l1, v1), bits(l2, v2), "{a}");
        }
    }

    /// The shortcut for small rotations gives the general formula's `t`, `c` and `s` bit
    /// for bit, at and beyond its threshold and for either sign (the general formula
    /// evaluated here as the module did before the shortcut, with its
    /// branch for `τ²` overflowing).
    #[test]
    fn small_rotation_shortcut_is_the_general_formula_bit_for_bit() {
        let general = |tau: f64| {
            let t = if tau.abs() > 1e150 {
                0.5 / tau
            } else {
                tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt())
            };
            let c = 1.0 / (1.0 + t * t).sqrt();
            [t, c, t * c].map(f64::to_bits)
        };
        let mut seed = 17u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut taus = vec![
            SMALL_ROTATION_TAU,
            SMALL_ROTATION_TAU.next_up(),
            1e20,
            1e150,
        ];
        for _ in 0..200_000 {
            // Mantissas in [1, 2), exponents 27..=300.
            taus.push((1.0 + rnd()) * 2f64.powi(27 + (rnd() * 274.0) as i32));
        }
        for tau in taus {
            for tau in [tau, -tau] {
                assert!(tau.abs() >= SMALL_ROTATION_TAU);
                let t = 0.5 / tau;
                assert_eq!([t, 1.0, t].map(f64::to_bits), general(tau), "tau = {tau:e}");
            }
        }
    }
}
