//! The Lagrangian logarithmic strain `E = ½ ln C` and its first and second derivatives,
//! the kinematic core of the finite-strain formulation (Miehe, Apel & Lambrecht, CMAME
//! 191, 2002; Papadopoulos & Lu, CMAME 190, 2001).
//!
//! # Why this formulation
//!
//! The additive split `E = Ee + Ep` in the Lagrangian log space lets the small-strain
//! Hill48/hardening return mapping and its consistent tangent run unchanged on `E`
//! ([`lagrangian_update`]); everything is a reference-frame quantity, so the model is
//! exactly objective and the orthotropy axes follow the material; the elastic part is
//! Hencky hyperelasticity. The split equals the multiplicative `F = Fe Fp` for coaxial
//! (proportional) loading and is the usual choice in sheet forming, where elastic strains
//! are small. See `docs/finite-strain.md`.
//!
//! # Spectral form
//!
//! With the right Cauchy-Green tensor `C = Fᵀ F = Q Λ Qᵀ` (eigenvalues `λ_i > 0`,
//! eigenvectors the columns of `Q`), `E = f(C)` with the scalar function
//! `f(λ) = ½ ln λ` applied to the eigenvalues. Derivatives of such isotropic matrix
//! functions follow from the Daleckii-Krein formulas (Bhatia, *Matrix Analysis*, V.3):
//! writing `H̃ = Qᵀ H Q` for a direction `H` in the eigenbasis,
//!
//! ```text
//! (Df(C)[H])~_ij       = f[λ_i, λ_j] H̃_ij,
//! (D²f(C)[H, K])~_ij   = Σ_k f[λ_i, λ_k, λ_j] (H̃_ik K̃_kj + K̃_ik H̃_kj),
//! ```
//!
//! with the first and second divided differences `f[a, b] = (f(a) - f(b)) / (a - b)`,
//! `f[a, a] = f'(a)`, `f[a, b, c] = (f[a, b] - f[b, c]) / (a - c)`. They hold for any
//! orthonormal eigenbasis, so repeated eigenvalues (the undeformed state `C = I`,
//! uniaxial tension with two equal lateral stretches) are no special case as long as the
//! divided differences are evaluated stably:
//!
//! * `f[a, b] = ½ log1p(d)/d / b` with `d = (a - b)/b`, exact to round-off for every
//!   `d` (and `1/(2b)` at `d = 0`);
//! * `f[a, b, c]` (sorted `a <= b <= c`): the quotient `(f[b, c] - f[a, b]) / (c - a)`
//!   when `c - a > 10⁻⁴ c` (cancellation costs at most 4 digits), else the Taylor series
//!   about the mean `m`, `f''(m)/2 + f⁗(m)/24 · ½ Σ (λ_i - m)²` (the first-order term
//!   vanishes; the truncation is `O(10⁻¹²)` relative).
//!
//! # Round-off: the strain from `C - I`, not from `C`
//!
//! Elastic strains in sheet bending are `10⁻⁶..10⁻³` while `C ≈ I`: `ln λ_i` of
//! eigenvalues `λ_i = 1 + μ_i` stored to an absolute `ε_mach` carries an absolute error
//! `ε_mach` in the strain, `E ε_mach ≈ 5·10⁻¹¹` MPa of stress for steel, whatever the load.
//! On a thin cantilever under 0.01 N (strains `~3·10⁻⁶`) that floor was 5·10⁻⁹ N of force
//! residual, 6·10⁻⁹ of the reference force: Newton could not reach its 10⁻⁹ tolerance.
//! So the decomposition is of `A = C - I = H + Hᵀ + HᵀH` formed from the displacement
//! gradient `H = F - I` (whose rigid rotation part cancels to `O(ε_mach |H|)`, not
//! `O(ε_mach)`), and `E = Q diag(½ log1p μ_i) Qᵀ` is accurate relative to the strain
//! itself. The divided differences need no such care: they are `O(1)` functions of the
//! `λ_i` with `O(1)` derivatives, so an absolute `ε_mach` in `λ_i` is a relative one in
//! `𝒫` and `ℒ`.
//!
//! # What the element needs
//!
//! In Voigt notation with strain-like vectors in engineering shear, with the Green-Lagrange
//! strain `E_GL = ½ (C - I)` as the element's strain variable and the log-space stress
//! `T` (work conjugate to `E`, `ψ(E)`):
//!
//! ```text
//! 𝒫 = ∂E/∂E_GL (6x6),     S = 𝒫ᵀ T,     ∂S/∂E_GL = 𝒫ᵀ D 𝒫 + ℒ(T),
//! ℒ(T)_mn = T : ∂²E/∂E_GL,m ∂E_GL,n = 4 T : D²f(C)[e_m, e_n]
//! ```
//!
//! (`𝒫 = 2 ∂E/∂C`, `ℒ = T : 4 ∂²E/∂C∂C` of Miehe et al.), `D = ∂T/∂E` the small-strain
//! algorithmic tangent. Every entry is checked against finite differences in the tests.

use super::sym_eigen3::sym_eigen3;
use super::{
    strain_from_tensor, stress_from_tensor, stress_to_tensor, FiniteResponse, Kinematics, Material,
    PointState, Tangent, Voigt,
};
use crate::geometry::Mat3;
use crate::{Error, Result};

/// Relative eigenvalue spread below which the second divided difference switches from
/// the quotient to the Taylor series (see the module docs).
const TAYLOR_SPREAD: f64 = 1e-4;

/// `f(λ) = ½ ln λ` and its spectral derivatives at one `C`.
#[derive(Clone, Debug)]
pub struct LogStrain {
    /// Eigenvectors of `C` (columns).
    q: Mat3,
    /// Eigenvalues `μ_i = λ_i - 1` of `C - I`, to their own relative precision.
    mu: [f64; 3],
    /// First divided differences `f[λ_i, λ_j]`.
    f1: [[f64; 3]; 3],
    /// Second divided differences `f[λ_i, λ_k, λ_j]`, indexed `[i][k][j]`.
    f2: [[[f64; 3]; 3]; 3],
    /// Eigenbasis components `Qᵀ e_m Q` of the six Voigt unit strains `e_m` (tensor form,
    /// engineering shear halved): the basis of `E_GL` directions.
    basis: [Mat3; 6],
}

impl LogStrain {
    /// Spectral decomposition of the symmetric `c`. Errors (a diverging iterate, not user
    /// input): a non-finite entry or an eigenvalue `<= 0` (an inverted element).
    pub fn new(c: &Mat3) -> Result<Self> {
        Self::from_stretch_excess(&(c - Mat3::identity()))
    }

    /// The same from `a = C - I` (symmetric), which carries a small strain to its own
    /// relative precision (see the module docs); [`from_displacement_gradient`]
    /// (Self::from_displacement_gradient) forms it without round-off from `I`.
    pub fn from_stretch_excess(a: &Mat3) -> Result<Self> {
        if !a.iter().all(|v| v.is_finite()) {
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                format!(
                    "non-finite right Cauchy-Green tensor {:?}",
                    (a + Mat3::identity()).as_slice()
                ),
            ));
        }
        let sym = (a + a.transpose()) * 0.5;
        let (mu, q) = sym_eigen3(&sym);
        let lambda = mu.map(|m| 1.0 + m);
        if mu.iter().any(|&m| m.is_nan() || m <= -1.0) {
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                format!(
                    "right Cauchy-Green tensor with eigenvalues {lambda:?} (inverted material)"
                ),
            ));
        }
        let (f1, f2) = divided_differences(&lambda);
        let basis = eigenbasis_units(&q);
        Ok(LogStrain {
            q,
            mu,
            f1,
            f2,
            basis,
        })
    }

    /// `C - I = H + Hᵀ + HᵀH` of the displacement gradient `h = F - I`: the rotation part
    /// of `h` cancels to `O(ε_mach |h|)` instead of the `O(ε_mach)` of `FᵀF - I`.
    pub fn from_displacement_gradient(h: &Mat3) -> Result<Self> {
        Self::from_stretch_excess(&(h + h.transpose() + h.transpose() * h))
    }

    /// `E = ½ ln C = Q diag(½ log1p μ_i) Qᵀ` (Voigt, engineering shear).
    pub fn strain(&self) -> Voigt {
        let d = Mat3::from_diagonal(&self.mu.map(|m| 0.5 * m.ln_1p()).into());
        strain_from_tensor(&(self.q * d * self.q.transpose()))
    }

    /// `𝒫 = ∂E/∂E_GL` (Voigt, engineering shear on both sides): column `n` is the
    /// directional derivative of `E` along `dC = 2 e_n`.
    pub fn projection(&self) -> Tangent {
        let mut p = Tangent::zeros();
        for n in 0..6 {
            let h = &self.basis[n];
            let de = Mat3::from_fn(|i, j| 2.0 * self.f1[i][j] * h[(i, j)]);
            p.set_column(n, &strain_from_tensor(&(self.q * de * self.q.transpose())));
        }
        p
    }

    /// `ℒ(T)_mn = T : ∂²E/∂E_GL,m ∂E_GL,n` for the log-space stress `t` (Voigt, tensor
    /// shear); symmetric.
    pub fn curvature(&self, t: &Voigt) -> Tangent {
        let tt = self.q.transpose() * stress_to_tensor(t) * self.q;
        // Σ_ikj f[λ_i, λ_k, λ_j] T̃_ij (H_ik K_kj + K_ik H_kj) = Σ_ik H_ik U_ik + Σ_kj H_kj V_kj
        // with U_ik = Σ_j Γ_ikj K_kj, V_kj = Σ_i Γ_ikj K_ik, Γ_ikj = f[λ_i, λ_k, λ_j] T̃_ij:
        // 2 x 27 products per direction K and 18 per pair instead of 108 per pair.
        let gamma: [[[f64; 3]; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|k| std::array::from_fn(|j| self.f2[i][k][j] * tt[(i, j)]))
        });
        // Filled in place (an array of returned pairs was copied whole: a tenth of the
        // samples of this function).
        let mut u = [[[0.0; 3]; 3]; 6];
        let mut v = [[[0.0; 3]; 3]; 6];
        for n in 0..6 {
            let k = &self.basis[n];
            for i in 0..3 {
                for kk in 0..3 {
                    u[n][i][kk] = (0..3).map(|j| gamma[i][kk][j] * k[(kk, j)]).sum();
                }
            }
            for kk in 0..3 {
                for j in 0..3 {
                    v[n][kk][j] = (0..3).map(|i| gamma[i][kk][j] * k[(i, kk)]).sum();
                }
            }
        }
        let mut l = Tangent::zeros();
        for m in 0..6 {
            let h = &self.basis[m];
            for n in m..6 {
                let (u, v) = (&u[n], &v[n]);
                let mut sum = 0.0;
                for a in 0..3 {
                    for b in 0..3 {
                        sum += h[(a, b)] * (u[a][b] + v[a][b]);
                    }
                }
                // dC = 2 e: the factor 4 of the two directions.
                l[(m, n)] = 4.0 * sum;
                l[(n, m)] = 4.0 * sum;
            }
        }
        l
    }
}

/// `Qᵀ e_m Q` of the six Voigt unit strains `e_m` (tensor form, engineering shear halved)
/// in closed form: `Q_ia Q_ib` for a normal unit `(i, i)`, `½ Q_ja Q_ib + ½ Q_ia Q_jb` for
/// a shear unit `(i, j)`, `i < j`. These are the products and sums, in the same order, that
/// the two 3 x 3 matrix products `Qᵀ (e_m Q)` form once their zero terms are dropped
/// (adding an exact zero changes nothing), so the same values bit for bit: 54 instead of
/// 324 multiplications.
fn eigenbasis_units(q: &Mat3) -> [Mat3; 6] {
    let normal = |i: usize| Mat3::from_fn(|a, b| q[(i, a)] * q[(i, b)]);
    let shear = |lo: usize, hi: usize| {
        Mat3::from_fn(|a, b| 0.5 * q[(hi, a)] * q[(lo, b)] + 0.5 * q[(lo, a)] * q[(hi, b)])
    };
    [
        normal(0),
        normal(1),
        normal(2),
        shear(0, 1),
        shear(1, 2),
        shear(0, 2),
    ]
}

/// The Lagrangian log-strain update of a small-strain `material` at the deformation
/// gradient `F = I + h`, given by its displacement gradient `h` (so that small strains keep
/// their relative precision, see the module docs; the default of
/// [`Material::update_finite_displacement_gradient`]):
///
/// 1. `E = ½ ln(FᵀF)`; the small-strain model, called with `E` as its strain and the
///    committed log-space stress `T_n` as its stress, returns `T` and `D = ∂T/∂E`
///    (additive split `E = Ee + Ep` in the reference frame, return mapping unchanged);
/// 2. `S = 𝒫ᵀ T`, `∂S/∂E_GL = 𝒫ᵀ D 𝒫 + ℒ(T)`;
/// 3. Cauchy `σ = F S Fᵀ / det F` into `trial.stress`, `T` into `trial.log_stress`.
///
/// Objective by construction: `E`, `T` and the history are reference-frame quantities,
/// unchanged by a superposed rotation `F -> R F`.
pub fn lagrangian_update<M: Material + ?Sized>(
    material: &M,
    h: &Mat3,
    committed: &PointState,
    trial: &mut PointState,
) -> Result<FiniteResponse> {
    let (f, j, ls, kin) = log_kinematics(h)?;
    let d = material.update(&kin, &log_space(committed), trial)?;
    let t = trial.stress;
    let p = ls.projection();
    let pk2 = p.transpose() * t;
    let tangent = p.transpose() * d * p + ls.curvature(&t);
    finish(trial, &f, j, &pk2);
    Ok(FiniteResponse { pk2, tangent })
}

/// The stress part of [`lagrangian_update`] (the same `trial` and `S`, bit for bit),
/// through [`Material::update_stress`]: no `ℒ(T)`, no `𝒫ᵀ D 𝒫`, no material tangent.
pub fn lagrangian_stress<M: Material + ?Sized>(
    material: &M,
    h: &Mat3,
    committed: &PointState,
    trial: &mut PointState,
) -> Result<Voigt> {
    let (f, j, ls, kin) = log_kinematics(h)?;
    material.update_stress(&kin, &log_space(committed), trial)?;
    let pk2 = ls.projection().transpose() * trial.stress;
    finish(trial, &f, j, &pk2);
    Ok(pk2)
}

/// `F = I + h`, `det F` (checked positive), the log strain and the kinematics it gives the
/// small-strain model.
fn log_kinematics(h: &Mat3) -> Result<(Mat3, f64, LogStrain, Kinematics)> {
    let f = Mat3::identity() + h;
    let j = f.determinant();
    if j <= 0.0 || !j.is_finite() {
        return Err(Error::no_convergence(
            crate::error::Failure::Local,
            format!("deformation gradient with determinant {j} (inverted material)"),
        ));
    }
    let ls = LogStrain::from_displacement_gradient(h)?;
    let kin = Kinematics {
        strain: ls.strain(),
        deformation_gradient: f,
    };
    Ok((f, j, ls, kin))
}

/// The committed state as the small-strain model sees it: the log-space stress.
fn log_space(committed: &PointState) -> PointState {
    PointState {
        stress: committed.log_stress,
        ..*committed
    }
}

/// `T` into `trial.log_stress`, Cauchy `σ = F S Fᵀ / J` into `trial.stress`.
fn finish(trial: &mut PointState, f: &Mat3, j: f64, pk2: &Voigt) {
    trial.log_stress = trial.stress;
    trial.stress = stress_from_tensor(&(f * stress_to_tensor(pk2) * f.transpose() / j));
}

/// The first divided differences `f[λ_i, λ_j]` (all nine ordered pairs) and the second
/// `f[λ_i, λ_k, λ_j]` (indexed `[i][k][j]`) of `f = ½ ln`. The second is symmetric and
/// `second` evaluates it on its sorted arguments `lo <= mid <= hi` from `f[mid, hi]` and
/// `f[lo, mid]`: so with the eigenvalues sorted once, the first differences of the sorted
/// pairs serve every one of the ten index multisets, and the nine ordered pairs need only
/// the three reversed ones more: 6 `log1p` instead of 26, the same values bit for bit.
fn divided_differences(lambda: &[f64; 3]) -> ([[f64; 3]; 3], [[[f64; 3]; 3]; 3]) {
    let mut order = [0, 1, 2];
    order.sort_by(|&x, &y| lambda[x].total_cmp(&lambda[y]));
    let mut rank = [0; 3];
    for (r, &i) in order.iter().enumerate() {
        rank[i] = r;
    }
    let s = order.map(|i| lambda[i]);
    // f[s_a, s_b] for a <= b (ascending arguments, as `second` forms them).
    let mut sorted_first = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in a..3 {
            sorted_first[a][b] = first(s[a], s[b]);
        }
    }
    let f1 = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            if rank[i] <= rank[j] {
                sorted_first[rank[i]][rank[j]]
            } else {
                first(lambda[i], lambda[j])
            }
        })
    });
    let mut f2 = [[[0.0; 3]; 3]; 3];
    for i in 0..3 {
        for k in i..3 {
            for j in k..3 {
                let mut r = [rank[i], rank[k], rank[j]];
                r.sort_unstable();
                let [lo, mid, hi] = r.map(|x| s[x]);
                let v = if hi - lo > TAYLOR_SPREAD * hi {
                    (sorted_first[r[1]][r[2]] - sorted_first[r[0]][r[1]]) / (hi - lo)
                } else {
                    second_taylor(lo, mid, hi)
                };
                for [a, b, c] in [
                    [i, k, j],
                    [i, j, k],
                    [k, i, j],
                    [k, j, i],
                    [j, i, k],
                    [j, k, i],
                ] {
                    f2[a][b][c] = v;
                }
            }
        }
    }
    (f1, f2)
}

/// `f[a, b]` for `f = ½ ln`, stable for `a ≈ b`.
fn first(a: f64, b: f64) -> f64 {
    let d = (a - b) / b;
    let ratio = if d == 0.0 { 1.0 } else { d.ln_1p() / d };
    0.5 * ratio / b
}

/// `f[a, b, c]` for `f = ½ ln` (symmetric in its arguments), stable for near-equal ones:
/// the definition that [`divided_differences`] evaluates with shared first differences.
#[cfg(test)]
fn second(a: f64, b: f64, c: f64) -> f64 {
    let mut v = [a, b, c];
    v.sort_by(|x, y| x.total_cmp(y));
    let [lo, mid, hi] = v;
    if hi - lo > TAYLOR_SPREAD * hi {
        (first(mid, hi) - first(lo, mid)) / (hi - lo)
    } else {
        second_taylor(lo, mid, hi)
    }
}

/// The Taylor series of `f[a, b, c]` about the mean (see the module docs).
fn second_taylor(a: f64, b: f64, c: f64) -> f64 {
    // f''/2 = -1/(4m²), f⁗/24 = -1/(8m⁴); h₂ = ½ Σ dᵢ² since Σ dᵢ = 0.
    let m = (a + b + c) / 3.0;
    let h2 = 0.5 * ((a - m).powi(2) + (b - m).powi(2) + (c - m).powi(2));
    -0.25 / (m * m) - 0.125 * h2 / m.powi(4)
}

#[cfg(test)]
mod tests {
    use super::super::strain_to_tensor;
    use super::*;
    use nalgebra::SymmetricEigen;

    fn c_of(f: &Mat3) -> Mat3 {
        f.transpose() * f
    }

    /// A set of deformations: general, two equal stretches (uniaxial), nearly equal
    /// (spread 1e-7, inside the Taylor branch), spread just above the switch, identity.
    fn cases() -> Vec<Mat3> {
        vec![
            Mat3::new(1.3, 0.2, -0.1, 0.05, 0.8, 0.15, -0.2, 0.1, 1.1),
            Mat3::from_diagonal(&[1.5, 0.8, 0.8].into()),
            Mat3::from_diagonal(&[1.0, 1.0 + 1e-7, 1.0 - 2e-8].into()),
            Mat3::from_diagonal(&[1.0, 1.0 + 2e-4, 1.0 - 1e-4].into()),
            Mat3::identity(),
        ]
    }

    /// The shared evaluation of the divided differences gives, bit for bit, the direct
    /// `first` and `second` of every index combination: distinct, two equal (in every
    /// position), three equal, nearly equal (the Taylor branch) and in every order.
    #[test]
    fn shared_divided_differences_equal_the_direct_ones_bit_for_bit() {
        let triples = [
            [1.3, 0.7, 1.1],
            [0.7, 1.3, 1.3],
            [1.3, 0.7, 1.3],
            [1.3, 1.3, 0.7],
            [1.0, 1.0, 1.0],
            [1.0 + 1e-9, 1.0 - 2e-9, 1.0],
            [2.0, 2.0 + 1e-6, 0.5],
            [0.5, 2.0, 2.0 + 1e-6],
        ];
        for lambda in triples {
            let (f1, f2) = divided_differences(&lambda);
            for i in 0..3 {
                for j in 0..3 {
                    assert_eq!(f1[i][j].to_bits(), first(lambda[i], lambda[j]).to_bits());
                    for k in 0..3 {
                        let direct = second(lambda[i], lambda[k], lambda[j]);
                        assert_eq!(f2[i][k][j].to_bits(), direct.to_bits(), "{lambda:?}");
                    }
                }
            }
        }
    }

    /// The closed-form eigenbasis components equal the two matrix products `Qᵀ e_m Q`
    /// they replace, bit for bit, for the eigenvectors of every test deformation.
    #[test]
    fn closed_form_basis_equals_the_matrix_products_bit_for_bit() {
        for f in cases() {
            let c = c_of(&f);
            let q = SymmetricEigen::new(c).eigenvectors;
            let units = eigenbasis_units(&q);
            for (m, unit) in units.iter().enumerate() {
                let mut e = Voigt::zeros();
                e[m] = 1.0;
                let product = q.transpose() * strain_to_tensor(&e) * q;
                for (x, y) in unit.iter().zip(product.iter()) {
                    // Equal, and zero only where both are (the sign of a zero may differ).
                    assert!(
                        x == y && (x.to_bits() == y.to_bits() || *x == 0.0),
                        "{m}: {x} {y}"
                    );
                }
            }
        }
    }

    #[test]
    fn divided_differences_match_their_definitions() {
        let f = |x: f64| 0.5 * x.ln();
        let (a, b, c) = (1.7, 0.9, 1.2);
        assert!((first(a, b) - (f(a) - f(b)) / (a - b)).abs() < 1e-15);
        assert!((first(a, a) - 0.5 / a).abs() < 1e-16);
        let exact = ((f(a) - f(b)) / (a - b) - (f(b) - f(c)) / (b - c)) / (a - c);
        assert!((second(a, b, c) - exact).abs() < 1e-14);
        // At the switch both branches agree: quotient round-off ~1e-16/1e-4, Taylor
        // truncation ~(1e-4)³.
        let m = 1.3;
        let (lo, mid, hi) = (m, m * (1.0 + 0.4e-4), m * (1.0 + 1.0e-4));
        let quotient = (first(mid, hi) - first(lo, mid)) / (hi - lo);
        let taylor = second_taylor(lo, mid, hi);
        assert!(
            (quotient - taylor).abs() < 1e-10 * taylor.abs(),
            "{quotient} {taylor}"
        );
        assert!((second(m, m, m) + 0.25 / (m * m)).abs() < 1e-15);
    }

    #[test]
    fn strain_is_half_log_of_c() {
        // Uniaxial stretch along a rotated axis: E has eigenvalue ln(1.5) along it.
        let f = Mat3::new(1.5, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let e = LogStrain::new(&c_of(&f)).unwrap().strain();
        assert!((e[0] - 1.5f64.ln()).abs() < 1e-15);
        assert!(e.rows(1, 5).amax() < 1e-15);
        // Rotation-free: F = R U gives the same E as U.
        let r = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1).into_inner();
        let u = cases()[0].transpose() * cases()[0];
        let a = LogStrain::new(&c_of(&u)).unwrap().strain();
        let b = LogStrain::new(&c_of(&(r * u))).unwrap().strain();
        assert!((a - b).amax() < 1e-14);
        assert!(LogStrain::new(&Mat3::from_diagonal(&[1.0, -1.0, 1.0].into())).is_err());
    }

    /// A strain of 1e-7 under a rotation of 1e-3 rad (the state of a stiff sheet bent by
    /// a small load): from the displacement gradient the strain keeps its relative
    /// precision, while `½ ln C` of the rounded `C = I + A` loses `ε_mach / 1e-7 ~ 1e-9`.
    /// Reference: the series `½ ln(I + A) = ½ (A - A²/2 + A³/3 - ...)`, exact to round-off
    /// for `|A| ~ 1e-6` after four terms.
    #[test]
    fn small_strain_under_rotation_keeps_its_relative_precision() {
        let w = Mat3::new(0.0, -1e-3, 0.4e-3, 1e-3, 0.0, -0.7e-3, -0.4e-3, 0.7e-3, 0.0);
        let eps = Mat3::new(
            1e-7, 0.3e-7, 0.0, 0.3e-7, -0.5e-7, 0.2e-7, 0.0, 0.2e-7, 0.8e-7,
        );
        // H = (I + W)(I + eps) - I with W skew: a rotation to first order.
        let h = w + eps + w * eps;
        let a = h + h.transpose() + h.transpose() * h;
        let exact = 0.5 * (a - a * a / 2.0 + a * a * a / 3.0 - a * a * a * a / 4.0);
        let exact = strain_from_tensor(&exact);
        let new = LogStrain::from_displacement_gradient(&h).unwrap().strain();
        let old = LogStrain::new(&(Mat3::identity() + a)).unwrap().strain();
        let rel = |e: Voigt| (e - exact).amax() / exact.amax();
        println!(
            "relative strain error: from H {:e}, from C {:e}",
            rel(new),
            rel(old)
        );
        assert!(rel(new) < 1e-12, "from H: {:e}", rel(new));
        // The test can tell: the rounded C loses six more digits.
        assert!(rel(old) > 1e-11, "from C: {:e}", rel(old));
    }

    /// `𝒫` and `ℒ` against central differences of `E(E_GL)` and of `𝒫ᵀT`; the step
    /// 1e-6 gives a truncation error ~1e-12 and a round-off error ~1e-10.
    #[test]
    fn derivatives_match_central_differences() {
        let t = Voigt::new(300.0, -120.0, 50.0, 80.0, -40.0, 25.0);
        let h = 1e-6;
        for f in cases() {
            let c = c_of(&f);
            let ls = LogStrain::new(&c).unwrap();
            let (p, l) = (ls.projection(), ls.curvature(&t));
            for n in 0..6 {
                let mut e = Voigt::zeros();
                e[n] = h;
                let dc = strain_to_tensor(&e) * 2.0;
                let plus = LogStrain::new(&(c + dc)).unwrap();
                let minus = LogStrain::new(&(c - dc)).unwrap();
                let dp = (plus.strain() - minus.strain()) / (2.0 * h);
                assert!(
                    (dp - p.column(n)).amax() < 1e-8,
                    "P column {n}: {dp} vs {}",
                    p.column(n)
                );
                let ds = (plus.projection().transpose() * t - minus.projection().transpose() * t)
                    / (2.0 * h);
                assert!(
                    (ds - l.column(n)).amax() < 1e-6 * t.amax(),
                    "L column {n}: {ds} vs {}",
                    l.column(n)
                );
            }
        }
    }

    /// The finite-strain tangent `∂S/∂E_GL` of the log-strain material against central
    /// differences of its stress update `S(E_GL)` (from the same committed state), for
    /// Hencky elasticity and for Hill48 plasticity with Swift hardening, at a general
    /// deformation and at one with two equal stretches. Step 1e-7 on strains of order
    /// 0.1-0.5: truncation ~1e-14 relative, round-off ~1e-16 x 500 MPa / 1e-7 ~ 1e-6 MPa
    /// against entries ~1e4-1e5 MPa, so 1e-6 relative to the largest entry is a real check.
    #[test]
    fn finite_tangent_matches_central_differences() {
        use crate::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};
        let elastic = LinearElastic::new(70e3, 0.33).unwrap();
        let plastic = ElastoPlastic::new(
            elastic,
            Hill48::from_lankford(0.7, 1.3, 2.1)
                .unwrap()
                .with_rolling_angle(0.3)
                .unwrap(),
            Hardening::swift(500.0, 0.01, 0.22).unwrap(),
        );
        let materials: [&dyn Material; 2] = [&elastic, &plastic];
        let deformations = [
            Mat3::new(1.25, 0.1, -0.05, 0.03, 0.9, 0.08, -0.1, 0.05, 0.93),
            Mat3::from_diagonal(&[1.4, 1.0 / 1.4f64.sqrt(), 1.0 / 1.4f64.sqrt()].into()),
        ];
        for (mi, m) in materials.iter().enumerate() {
            for f in &deformations {
                // A committed plastic state part of the way there (elastic for Hencky).
                let mut committed = PointState::default();
                let f_half = (Mat3::identity() + f) * 0.5;
                let mut tmp = committed;
                m.update_finite(&f_half, &committed, &mut tmp).unwrap();
                committed = tmp;
                let mut trial = committed;
                let resp = m.update_finite(f, &committed, &mut trial).unwrap();
                if mi == 1 {
                    assert!(trial.eq_plastic_strain > committed.eq_plastic_strain + 0.01);
                }
                let c = f.transpose() * f;
                let eig = SymmetricEigen::new(c);
                // F(E_GL) as the symmetric square root U of C: S depends on C only.
                let sqrt = |c: &Mat3| {
                    let e = SymmetricEigen::new(*c);
                    e.eigenvectors
                        * Mat3::from_diagonal(&e.eigenvalues.map(f64::sqrt))
                        * e.eigenvectors.transpose()
                };
                assert!(eig.eigenvalues.min() > 0.0);
                let h = 1e-7;
                let scale = resp.tangent.amax();
                for n in 0..6 {
                    let mut e = Voigt::zeros();
                    e[n] = h;
                    let dc = strain_to_tensor(&e) * 2.0;
                    let s_at = |c: &Mat3| {
                        let mut t = committed;
                        m.update_finite(&sqrt(c), &committed, &mut t).unwrap().pk2
                    };
                    let fd = (s_at(&(c + dc)) - s_at(&(c - dc))) / (2.0 * h);
                    let err = (fd - resp.tangent.column(n)).amax() / scale;
                    assert!(
                        err < 1e-6,
                        "material {mi}, column {n}: relative error {err:e}"
                    );
                }
            }
        }
    }
}
