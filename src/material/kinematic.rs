//! Kinematic hardening: the Chaboche law, a sum of one to three Armstrong-Frederick back
//! stresses, and the closest-point return of the mixed isotropic-kinematic model it makes
//! with Hill48 (or von Mises) yield and any isotropic law of `material::hardening`.
//!
//! # Law (Voigt: stresses with tensor shear, strains with engineering shear)
//!
//! The yield surface is centred on the total back stress `X = Σ X_i`:
//!
//! ```text
//! f = φ(σ - X) - σ_y(p) <= 0,        ε̇p = λ̇ n,   n = ∂φ/∂σ = P ξ / φ(ξ),   ξ = σ - X,
//! Ẋ_i = (2/3) C_i W ε̇p - γ_i X_i ṗ,    ṗ = λ̇,        W = diag(1, 1, 1, ½, ½, ½),
//! ```
//!
//! `W` turning the engineering plastic strain into the tensor the back stress is. Each
//! term saturates at `C_i/γ_i` (`γ_i = 0`: Prager's linear law). In uniaxial tension of a
//! von Mises material along x the effective back stress `x = X_xx - X_yy` obeys
//! `dx_i = (C_i - γ_i x_i) dεp` with `dp = |dεp|`, whose closed form along a branch of
//! constant direction `s = ±1` starting at `x_i0` is
//!
//! ```text
//! x_i = s C_i/γ_i + (x_i0 - s C_i/γ_i) exp(-γ_i |εp - εp0|),
//! ```
//!
//! the law the cyclic tests compare against.
//!
//! # Return map (backward Euler)
//!
//! From the committed `σ_n`, `X_i,n`, `p_n` and the elastic trial `σ_tr = D (ε - εp_n)`,
//! with `Δλ = Δp` and the flow direction `n` at the end of the step,
//!
//! ```text
//! σ   = σ_tr - Δλ D n,
//! X_i = a_i (X_i,n + (2/3) C_i Δλ W n),      a_i = 1 / (1 + γ_i Δλ),
//! ```
//!
//! so the relative stress `ξ = σ - X` and `Δλ` solve the 7 equations
//!
//! ```text
//! R = ξ - ξ_tr(Δλ) + Δλ K(Δλ) n(ξ) = 0,     ξ_tr = σ_tr - Σ a_i X_i,n,
//!                                            K = D + c W,  c = Σ (2/3) C_i a_i,
//! f = φ(ξ) - σ_y(p_n + Δλ)         = 0,
//! ```
//!
//! by Newton from `(ξ_tr(0), 0)` with a backtracking line search on `|(R, f)|`, with the
//! Jacobian (`N = ∂n/∂ξ = (P - n nᵀ)/φ`, `h = σ_y'`)
//!
//! ```text
//! J = | I + Δλ K N                                  ∂R/∂Δλ |
//!     | nᵀ                                          -h     |,
//! ∂R/∂Δλ = -Σ γ_i a_i² X_i,n + K n + Δλ c' W n,    c' = -Σ (2/3) C_i γ_i a_i².
//! ```
//!
//! # Consistent tangent
//!
//! `σ_tr` enters only through `R` (`∂R/∂σ_tr = -I`, `dσ_tr = D dε`), so at the converged
//! point `J [dξ; dΔλ] = [D dε; 0]`, and from `σ = σ_tr - Δλ D n(ξ)`
//!
//! ```text
//! D_alg = D - D [ n, Δλ N ] J⁻¹ [D; 0].
//! ```
//!
//! It is not symmetric when some `γ_i > 0` (the dynamic recovery term is not associated
//! with a potential): the elements and linear solvers take non-symmetric tangents.
//!
//! # Finite strain
//!
//! The model is applied unchanged to the logarithmic strain by
//! `material::log_strain::lagrangian_update` (as isotropic elastoplasticity): the back
//! stresses are then tensors of the Lagrangian log space, work-conjugate to the
//! logarithmic strain like the stress `T` they are subtracted from, and follow the body's
//! rotation exactly (material axes, as Hill48's).

use nalgebra::{SMatrix, SVector};

use super::{Hardening, Hill48, Tangent, Voigt, BACK_STRESSES};
use crate::{Error, Result};

/// Relative tolerance of the return's residual (stress units, relative to the largest of
/// the yield stress, the trial equivalent stress and the largest trial stress component),
/// as the isotropic general return's.
const RETURN_TOL: f64 = 1e-12;
/// Newton iterations of the return.
const MAX_ITER: usize = 60;

/// The Chaboche kinematic hardening law: one to three Armstrong-Frederick terms
/// `(C_i, γ_i)`; see the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct Chaboche {
    terms: Vec<(f64, f64)>,
}

/// Engineering strain to tensor components: `W v`.
fn tensor_of_strain(v: &Voigt) -> Voigt {
    Voigt::new(v[0], v[1], v[2], 0.5 * v[3], 0.5 * v[4], 0.5 * v[5])
}

/// A converged return of the mixed model.
pub(super) struct KinematicReturn {
    pub stress: Voigt,
    pub back_stress: [Voigt; BACK_STRESSES],
    pub dlambda: f64,
    /// Zero when the tangent was not asked for.
    pub tangent: Tangent,
}

/// What the return needs of the isotropic part of the model.
pub(super) struct Isotropic<'a> {
    /// Elastic stiffness `D`.
    pub stiffness: &'a Tangent,
    pub yield_function: &'a Hill48,
    pub hardening: &'a Hardening,
}

impl Chaboche {
    /// From the terms `(C_i, γ_i)`: one to three, each `C_i > 0` and `γ_i >= 0`, finite.
    /// Errors name the term and the value.
    pub fn new(terms: &[(f64, f64)]) -> Result<Self> {
        if terms.is_empty() || terms.len() > BACK_STRESSES {
            return Err(Error::input(
                "Chaboche number of terms",
                terms.len(),
                &format!("must be 1 to {BACK_STRESSES} ([C, gamma] pairs)"),
            ));
        }
        for (i, &(c, g)) in terms.iter().enumerate() {
            let k = i + 1;
            if !c.is_finite() || c <= 0.0 {
                return Err(Error::input(
                    &format!("Chaboche term {k} C"),
                    c,
                    "must be finite and > 0",
                ));
            }
            if !g.is_finite() || g < 0.0 {
                return Err(Error::input(
                    &format!("Chaboche term {k} gamma"),
                    g,
                    "must be finite and >= 0",
                ));
            }
        }
        Ok(Chaboche {
            terms: terms.to_vec(),
        })
    }

    /// The terms `(C_i, γ_i)`.
    pub fn terms(&self) -> &[(f64, f64)] {
        &self.terms
    }

    /// A short description for logs.
    pub fn describe(&self) -> String {
        let t: Vec<String> = self
            .terms
            .iter()
            .map(|(c, g)| format!("[C={c} gamma={g}]"))
            .collect();
        format!("Chaboche {}", t.join(" "))
    }

    /// `a_i = 1/(1 + γ_i Δλ)` (unused terms 0).
    fn factors(&self, dl: f64) -> [f64; BACK_STRESSES] {
        std::array::from_fn(|i| self.terms.get(i).map_or(0.0, |t| 1.0 / (1.0 + t.1 * dl)))
    }

    /// `ξ_tr(Δλ)`, `c(Δλ)`, `c'(Δλ)` and `dξ_tr/dΔλ` (module docs).
    fn trial_terms(
        &self,
        sig_tr: &Voigt,
        back_n: &[Voigt; BACK_STRESSES],
        dl: f64,
    ) -> (Voigt, f64, f64, Voigt) {
        let a = self.factors(dl);
        let (mut xi_tr, mut c, mut dc, mut dxi) = (*sig_tr, 0.0, 0.0, Voigt::zeros());
        for (i, &(ci, gi)) in self.terms.iter().enumerate() {
            xi_tr -= back_n[i] * a[i];
            c += 2.0 / 3.0 * ci * a[i];
            dc -= 2.0 / 3.0 * ci * gi * a[i] * a[i];
            dxi += back_n[i] * (gi * a[i] * a[i]);
        }
        (xi_tr, c, dc, dxi)
    }

    /// The return of the trial stress `sig_tr` from the committed back stresses `back_n`
    /// and equivalent plastic strain `ebar_n` (the trial is outside the surface), with the
    /// consistent tangent when `tangent` (module docs). Errors: no convergence, named as
    /// a local failure so that the solver cuts back.
    pub(super) fn return_map(
        &self,
        iso: &Isotropic,
        sig_tr: &Voigt,
        back_n: &[Voigt; BACK_STRESSES],
        ebar_n: f64,
        tangent: bool,
    ) -> Result<KinematicReturn> {
        let p = iso.yield_function.matrix();
        let d = iso.stiffness;
        let sy_n = iso.hardening.yield_stress(ebar_n);
        let xi0 = self.trial_terms(sig_tr, back_n, 0.0).0;
        let phi_tr = iso.yield_function.equivalent_stress(&xi0);
        let tol = RETURN_TOL * phi_tr.max(sy_n).max(sig_tr.amax());
        let residual = |xi: &Voigt, dl: f64| -> Option<SVector<f64, 7>> {
            let phi = iso.yield_function.equivalent_stress(xi);
            if !(phi > 0.0) || !phi.is_finite() || !dl.is_finite() {
                return None;
            }
            let n = p * xi / phi;
            let (xi_tr, c, _, _) = self.trial_terms(sig_tr, back_n, dl);
            let r = xi - xi_tr + (d * n + tensor_of_strain(&n) * c) * dl;
            let f = phi - iso.hardening.yield_stress(ebar_n + dl);
            Some(SVector::<f64, 7>::from_iterator(
                r.iter().copied().chain(std::iter::once(f)),
            ))
        };
        let (mut xi, mut dl) = (xi0, 0.0);
        let mut res = residual(&xi, dl).ok_or_else(|| failure(iso, self, sig_tr, "zero trial"))?;
        for _ in 0..MAX_ITER {
            if res.amax() <= tol {
                return Ok(self.converged(iso, sig_tr, back_n, xi, dl, ebar_n, tangent));
            }
            let jac = self.jacobian(iso, sig_tr, back_n, &xi, dl, ebar_n);
            let step = jac
                .lu()
                .solve(&(-res))
                .ok_or_else(|| failure(iso, self, sig_tr, "singular return Jacobian"))?;
            // Backtracking: the first step length that reduces the residual norm.
            let norm = res.norm();
            let mut alpha = 1.0;
            loop {
                let t_xi = xi + step.fixed_rows::<6>(0) * alpha;
                // Δλ >= 0 keeps the hardening law in its domain.
                let t_dl = (dl + step[6] * alpha).max(0.0);
                if let Some(r) = residual(&t_xi, t_dl) {
                    if r.norm() < norm || alpha < 1e-6 {
                        (xi, dl, res) = (t_xi, t_dl, r);
                        break;
                    }
                }
                alpha *= 0.5;
                if alpha < 1e-10 {
                    return Err(failure(iso, self, sig_tr, "line search failed"));
                }
            }
        }
        if res.amax() <= tol {
            return Ok(self.converged(iso, sig_tr, back_n, xi, dl, ebar_n, tangent));
        }
        Err(failure(
            iso,
            self,
            sig_tr,
            &format!(
                "no convergence in {MAX_ITER} iterations, residual {:e}",
                res.amax()
            ),
        ))
    }

    /// The 7 x 7 Jacobian `J` of `(R, f)` in `(ξ, Δλ)` (module docs).
    fn jacobian(
        &self,
        iso: &Isotropic,
        sig_tr: &Voigt,
        back_n: &[Voigt; BACK_STRESSES],
        xi: &Voigt,
        dl: f64,
        ebar_n: f64,
    ) -> SMatrix<f64, 7, 7> {
        let p = iso.yield_function.matrix();
        let phi = iso.yield_function.equivalent_stress(xi);
        let n = p * xi / phi;
        let nn = (p - n * n.transpose()) / phi;
        let (_, c, dc, dxi) = self.trial_terms(sig_tr, back_n, dl);
        let w = Tangent::from_diagonal(&Voigt::new(1.0, 1.0, 1.0, 0.5, 0.5, 0.5));
        let k = iso.stiffness + w * c;
        let mut jac = SMatrix::<f64, 7, 7>::zeros();
        jac.fixed_view_mut::<6, 6>(0, 0)
            .copy_from(&(Tangent::identity() + k * nn * dl));
        let col = -dxi + k * n + tensor_of_strain(&n) * (dl * dc);
        jac.fixed_view_mut::<6, 1>(0, 6).copy_from(&col);
        jac.fixed_view_mut::<1, 6>(6, 0).copy_from(&n.transpose());
        jac[(6, 6)] = -iso.hardening.slope(ebar_n + dl);
        jac
    }

    /// Stress, back stresses and (when asked) the consistent tangent at the converged
    /// `(ξ, Δλ)` (module docs).
    #[allow(clippy::too_many_arguments)]
    fn converged(
        &self,
        iso: &Isotropic,
        sig_tr: &Voigt,
        back_n: &[Voigt; BACK_STRESSES],
        xi: Voigt,
        dl: f64,
        ebar_n: f64,
        tangent: bool,
    ) -> KinematicReturn {
        let p = iso.yield_function.matrix();
        let d = iso.stiffness;
        let phi = iso.yield_function.equivalent_stress(&xi);
        let n = p * xi / phi;
        let a = self.factors(dl);
        let wn = tensor_of_strain(&n);
        let back_stress: [Voigt; BACK_STRESSES] = std::array::from_fn(|i| {
            self.terms.get(i).map_or(Voigt::zeros(), |&(c, _)| {
                (back_n[i] + wn * (2.0 / 3.0 * c * dl)) * a[i]
            })
        });
        let stress = sig_tr - d * n * dl;
        let mut t = Tangent::zeros();
        if tangent {
            t = *d;
            let jac = self.jacobian(iso, sig_tr, back_n, &xi, dl, ebar_n);
            let mut rhs = SMatrix::<f64, 7, 6>::zeros();
            rhs.fixed_view_mut::<6, 6>(0, 0).copy_from(d);
            // J is regular at a converged return (Newton solved with it on the way there);
            // were it not, the elastic stiffness above is a safe descent direction.
            if let Some(g) = jac.lu().solve(&rhs) {
                let nn = (p - n * n.transpose()) / phi;
                let dn = nn * g.fixed_rows::<6>(0) * dl + n * g.fixed_rows::<1>(6);
                t = d - d * dn;
            }
        }
        KinematicReturn {
            stress,
            back_stress,
            dlambda: dl,
            tangent: t,
        }
    }
}

fn failure(iso: &Isotropic, law: &Chaboche, sig_tr: &Voigt, why: &str) -> Error {
    Error::no_convergence(
        crate::error::Failure::Local,
        format!(
            "return mapping ({}, {}, {}): {why}; trial stress {:?}",
            iso.yield_function.describe(),
            iso.hardening.describe(),
            law.describe(),
            sig_tr.as_slice()
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Mat3;
    use crate::material::{
        strain_to_tensor, ElastoPlastic, Kinematics, LinearElastic, Material, PointState,
    };
    use nalgebra::SymmetricEigen;

    fn steel(hardening: Hardening, yf: Hill48, terms: &[(f64, f64)]) -> ElastoPlastic {
        ElastoPlastic::new(LinearElastic::new(210e3, 0.3).unwrap(), yf, hardening)
            .with_kinematic(Chaboche::new(terms).unwrap())
    }

    fn anisotropic() -> Hill48 {
        Hill48::from_lankford(0.7, 1.3, 2.1)
            .unwrap()
            .with_rolling_angle(0.3)
            .unwrap()
    }

    /// Uniaxial stress along x driven by `εxx` through `targets` (the strain at the end of
    /// each increment): per increment, Newton with the consistent tangent on the mixed
    /// problem `σ = s e_x`, `εxx = target`. Returns the committed states.
    fn uniaxial(m: &ElastoPlastic, targets: &[f64]) -> Vec<PointState> {
        super::super::uniaxial_stress_path(m, super::super::uniaxial_direction(0.0), targets)
            .unwrap()
    }

    /// Strain targets 0 -> +amp -> -amp -> +amp in `per_branch` increments per `amp`.
    fn cycle(amp: f64, per_branch: usize) -> Vec<f64> {
        let de = amp / per_branch as f64;
        let mut t = Vec::new();
        let mut e = 0.0;
        for (dir, count) in [
            (1.0, per_branch),
            (-1.0, 2 * per_branch),
            (1.0, 2 * per_branch),
        ] {
            for _ in 0..count {
                e += dir * de;
                t.push(e);
            }
        }
        t
    }

    /// Largest difference between the computed uniaxial stress and back stress and the
    /// closed form of the Armstrong-Frederick law (module docs), `x = Σ x_i`,
    /// `σ = x + s σ_y(p)`, over the plastic
    /// increments of `states`; the closed form is continued branch by branch from each
    /// reversal's plastic strain. Also returns the number of reversals seen.
    fn closed_form_error(
        terms: &[(f64, f64)],
        hardening: &Hardening,
        states: &[PointState],
    ) -> (f64, usize) {
        let mut x: Vec<f64> = vec![0.0; terms.len()];
        let (mut ep0, mut dir, mut reversals) = (0.0, 0.0, 0);
        let mut x0 = x.clone();
        let (mut prev_ep, mut worst) = (0.0, 0.0f64);
        for st in states {
            let ep = st.plastic_strain[0];
            let dep = ep - prev_ep;
            prev_ep = ep;
            if dep.abs() < 1e-14 {
                continue;
            }
            let s = dep.signum();
            if s != dir {
                // A new branch: it starts where the last plastic increment ended.
                if dir != 0.0 {
                    reversals += 1;
                }
                ep0 = ep - dep;
                x0 = x.clone();
                dir = s;
            }
            for (i, &(c, g)) in terms.iter().enumerate() {
                let run = (ep - ep0).abs();
                x[i] = if g == 0.0 {
                    x0[i] + s * c * run
                } else {
                    s * c / g + (x0[i] - s * c / g) * (-g * run).exp()
                };
            }
            let expect = x.iter().sum::<f64>() + s * hardening.yield_stress(st.eq_plastic_strain);
            worst = worst.max((st.stress[0] - expect).abs());
            // Uniaxial von Mises: the back stress is (2/3 x, -1/3 x, -1/3 x) of x = Xxx - Xyy.
            let xt = st.total_back_stress();
            worst = worst.max((xt[0] - xt[1] - x.iter().sum::<f64>()).abs());
        }
        (worst, reversals)
    }

    /// Prager's linear law (`γ = 0`) with linear isotropic hardening: backward Euler is
    /// exact along a straight branch, so the cyclic curve equals the closed form to the
    /// driver's tolerance (1e-10 relative on ~500 MPa).
    #[test]
    fn linear_kinematic_cycle_equals_the_closed_form() {
        let terms = [(20e3, 0.0)];
        let hardening = Hardening::linear(250.0, 1000.0).unwrap();
        let m = steel(hardening.clone(), Hill48::von_mises(), &terms);
        let states = uniaxial(&m, &cycle(0.02, 40));
        let (err, reversals) = closed_form_error(&terms, &hardening, &states);
        assert_eq!(reversals, 2);
        assert!(err < 1e-7, "{err:e} MPa");
        // The Bauschinger effect: reverse yield well below the forward stress in magnitude.
        let peak = states[39].stress[0];
        assert!(peak > 500.0, "{peak}");
    }

    /// Armstrong-Frederick terms (`γ > 0`), with and without isotropic hardening: backward
    /// Euler is first-order accurate in the plastic increment (its local error is
    /// `(x - sC/γ)(γΔp)²/2`), so the error against the closed form is bounded by
    /// `Σ C_i Δp_max` and halves with the increment; both are checked.
    #[test]
    fn armstrong_frederick_cycle_converges_to_the_closed_form() {
        let cases = [
            (vec![(60e3, 400.0)], Hardening::linear(250.0, 0.0).unwrap()),
            (
                vec![(60e3, 400.0), (8e3, 40.0), (1e3, 0.0)],
                Hardening::voce(200.0, 80.0, 15.0).unwrap(),
            ),
        ];
        for (terms, hardening) in cases {
            let m = steel(hardening.clone(), Hill48::von_mises(), &terms);
            let amp = 0.02;
            let mut errors = Vec::new();
            for per_branch in [100, 200] {
                let states = uniaxial(&m, &cycle(amp, per_branch));
                let (err, reversals) = closed_form_error(&terms, &hardening, &states);
                assert_eq!(reversals, 2);
                let dp = amp / per_branch as f64;
                let bound: f64 = terms.iter().map(|t| t.0 * dp).sum();
                assert!(err < bound, "{err} >= {bound} MPa");
                errors.push(err);
            }
            let ratio = errors[1] / errors[0];
            assert!((0.4..0.6).contains(&ratio), "first order: {errors:?}");
        }
    }

    /// A committed state with back stresses (two increments in different directions),
    /// then the tangent at `eps` against central differences (step 1e-7 on strains ~1e-2:
    /// truncation ~1e-14 relative, round-off ~1e-16 x 1e3 MPa / 1e-7 ~ 1e-6 MPa on entries
    /// ~1e5 MPa; 1e-6 relative to the largest entry is a real check).
    fn check_small_strain_tangent(m: &ElastoPlastic, eps: Voigt) {
        let history = [
            Voigt::new(0.01, -0.004, -0.003, 0.006, -0.002, 0.003),
            Voigt::new(-0.002, 0.003, -0.003, -0.004, 0.001, 0.0),
        ];
        check_tangent_after(m, &history, eps);
    }

    /// The committed state reached through the strains `history` (one increment each),
    /// then the tangent at `eps` against central differences (tolerance as
    /// `check_small_strain_tangent`'s). Returns the committed and the trial state.
    fn check_tangent_after(
        m: &ElastoPlastic,
        history: &[Voigt],
        eps: Voigt,
    ) -> (PointState, PointState) {
        let mut committed = m.initial_state();
        for &history in history {
            let mut next = committed;
            m.update(&Kinematics::from_strain(history), &committed, &mut next)
                .unwrap();
            committed = next;
        }
        assert!(committed.total_back_stress().amax() > 1.0);
        let mut trial = committed;
        let d = m
            .update(&Kinematics::from_strain(eps), &committed, &mut trial)
            .unwrap();
        assert!(trial.eq_plastic_strain > committed.eq_plastic_strain);
        let h = 1e-7;
        let fd = Tangent::from_fn(|i, j| {
            let at = |sign: f64| {
                let mut e = eps;
                e[j] += sign * h;
                let mut t = committed;
                m.update(&Kinematics::from_strain(e), &committed, &mut t)
                    .unwrap();
                t.stress[i]
            };
            (at(1.0) - at(-1.0)) / (2.0 * h)
        });
        let err = (d - fd).amax() / d.amax();
        assert!(err < 1e-6, "{}: relative error {err:e}", m.describe());
        // Softer than elastic, and the return is on the shifted surface.
        assert!((d - m.elastic_tangent()).amax() > 1e-3 * d.amax());
        let sy = m.hardening().yield_stress(trial.eq_plastic_strain);
        assert!(m.yield_value(&trial).abs() < 1e-9 * sy);
        (committed, trial)
    }

    /// Reversed flow (issue 47: the release after bending over a die radius): strained
    /// in tension with shear, then back, so that the trial's plastic strain increment
    /// points against the committed back stress (`dεp . X < 0`, checked). Once with the
    /// reversal inside the trial increment (elastic unloading, then reverse yielding on the
    /// shifted surface) and once after a committed increment back (the back stress not yet
    /// turned: the reversal is small against the saturation strain 1/γ). Every
    /// isotropic law, von Mises and Hill48, one to three terms.
    #[test]
    fn tangent_at_reversed_flow_equals_central_differences() {
        let forward = Voigt::new(0.012, -0.005, -0.006, 0.008, 0.001, -0.002);
        let back = |f: f64| forward * f;
        let cases: [(&[Voigt], Voigt); 2] =
            [(&[forward], back(0.3)), (&[forward, back(0.7)], back(0.5))];
        let term_sets: [&[(f64, f64)]; 2] =
            [&[(30e3, 200.0)], &[(30e3, 200.0), (5e3, 20.0), (2e3, 0.0)]];
        for yf in [Hill48::von_mises(), anisotropic()] {
            for law in laws() {
                for terms in term_sets {
                    let m = steel(law.clone(), yf, terms);
                    for (history, eps) in cases {
                        let (committed, trial) = check_tangent_after(&m, history, eps);
                        let dep = trial.plastic_strain - committed.plastic_strain;
                        let x = committed.total_back_stress();
                        assert!(
                            dep.dot(&x) < -1e-3 * dep.norm() * x.norm(),
                            "{}: the flow is not reversed",
                            m.describe()
                        );
                    }
                }
            }
        }
    }

    /// The same at finite strain (log-strain extension): a stretch with shear, then
    /// partly back, the tangent `dS/dE_GL` against central differences of `S(C)` as in
    /// `finite_strain_tangent_equals_central_differences`.
    #[test]
    fn finite_strain_tangent_at_reversed_flow_equals_central_differences() {
        let stretch = |a: f64| {
            Mat3::new(
                1.0 + a,
                0.5 * a,
                0.0,
                0.0,
                1.0 - 0.4 * a,
                0.1 * a,
                0.0,
                0.0,
                1.0 - 0.5 * a,
            )
        };
        for yf in [Hill48::von_mises(), anisotropic()] {
            let m = steel(
                Hardening::swift(500.0, 0.01, 0.22).unwrap(),
                yf,
                &[(30e3, 200.0), (5e3, 20.0)],
            );
            let mut committed = PointState::default();
            for g in [stretch(0.02), stretch(0.016)] {
                let mut t = committed;
                m.update_finite(&g, &committed, &mut t).unwrap();
                committed = t;
            }
            let f = stretch(0.012);
            let mut trial = committed;
            let resp = m.update_finite(&f, &committed, &mut trial).unwrap();
            let dep = trial.plastic_strain - committed.plastic_strain;
            let x = committed.total_back_stress();
            assert!(trial.eq_plastic_strain > committed.eq_plastic_strain);
            assert!(dep.dot(&x) < -1e-3 * dep.norm() * x.norm(), "flow reversed");
            let c = f.transpose() * f;
            let h = 1e-7;
            let scale = resp.tangent.amax();
            let s_at = |c: &Mat3| {
                let e = SymmetricEigen::new(*c);
                let u = e.eigenvectors
                    * Mat3::from_diagonal(&e.eigenvalues.map(f64::sqrt))
                    * e.eigenvectors.transpose();
                let mut t = committed;
                m.update_finite(&u, &committed, &mut t).unwrap().pk2
            };
            for n in 0..6 {
                let mut e = Voigt::zeros();
                e[n] = h;
                let dc = strain_to_tensor(&e) * 2.0;
                let fd = (s_at(&(c + dc)) - s_at(&(c - dc))) / (2.0 * h);
                let err = (fd - resp.tangent.column(n)).amax() / scale;
                assert!(err < 1e-6, "{}: column {n}: {err:e}", yf.describe());
            }
        }
    }

    fn laws() -> Vec<Hardening> {
        vec![
            Hardening::swift(500.0, 0.01, 0.22).unwrap(),
            Hardening::voce(200.0, 100.0, 8.0).unwrap(),
            Hardening::linear(250.0, 1000.0).unwrap(),
            Hardening::tabulated(vec![0.0, 0.05, 0.2], vec![250.0, 320.0, 400.0]).unwrap(),
        ]
    }

    #[test]
    fn small_strain_tangent_equals_central_differences() {
        let term_sets: [&[(f64, f64)]; 3] = [
            &[(30e3, 200.0)],
            &[(30e3, 200.0), (5e3, 20.0)],
            &[(30e3, 200.0), (5e3, 20.0), (2e3, 0.0)],
        ];
        for yf in [Hill48::von_mises(), anisotropic()] {
            for law in laws() {
                for terms in term_sets {
                    let m = steel(law.clone(), yf, terms);
                    check_small_strain_tangent(
                        &m,
                        Voigt::new(0.014, -0.002, -0.006, 0.01, 0.001, 0.004),
                    );
                }
            }
        }
    }

    /// `∂S/∂E_GL` under finite strain (the log-strain extension) against central
    /// differences of `S(C)`, as `log_strain`'s test of the isotropic model: step 1e-7 on
    /// strains 0.1-0.4, so 1e-6 relative to the largest entry.
    #[test]
    fn finite_strain_tangent_equals_central_differences() {
        let f = Mat3::new(1.25, 0.1, -0.05, 0.03, 0.9, 0.08, -0.1, 0.05, 0.93);
        let sqrt = |c: &Mat3| {
            let e = SymmetricEigen::new(*c);
            e.eigenvectors
                * Mat3::from_diagonal(&e.eigenvalues.map(f64::sqrt))
                * e.eigenvectors.transpose()
        };
        for yf in [Hill48::von_mises(), anisotropic()] {
            let m = steel(
                Hardening::swift(500.0, 0.01, 0.22).unwrap(),
                yf,
                &[(30e3, 200.0), (5e3, 20.0)],
            );
            // Committed: part of the way there, then reversed a little (back stresses set).
            let mut committed = PointState::default();
            for g in [(Mat3::identity() + f) * 0.5, Mat3::identity() * 1.02] {
                let mut t = committed;
                m.update_finite(&g, &committed, &mut t).unwrap();
                committed = t;
            }
            assert!(committed.total_back_stress().amax() > 1.0);
            let mut trial = committed;
            let resp = m.update_finite(&f, &committed, &mut trial).unwrap();
            assert!(trial.eq_plastic_strain > committed.eq_plastic_strain + 0.01);
            let c = f.transpose() * f;
            let h = 1e-7;
            let scale = resp.tangent.amax();
            let s_at = |c: &Mat3| {
                let mut t = committed;
                m.update_finite(&sqrt(c), &committed, &mut t).unwrap().pk2
            };
            for n in 0..6 {
                let mut e = Voigt::zeros();
                e[n] = h;
                let dc = strain_to_tensor(&e) * 2.0;
                let fd = (s_at(&(c + dc)) - s_at(&(c - dc))) / (2.0 * h);
                let err = (fd - resp.tangent.column(n)).amax() / scale;
                assert!(err < 1e-6, "{}: column {n}: {err:e}", yf.describe());
            }
        }
    }

    /// One large step (as a wild Newton iterate): the return converges onto the shifted
    /// surface and each back stress satisfies its backward-Euler update.
    #[test]
    fn large_step_returns_onto_the_shifted_surface() {
        let terms = [(60e3, 400.0), (8e3, 40.0)];
        for yf in [Hill48::von_mises(), anisotropic()] {
            let m = steel(Hardening::swift(500.0, 0.01, 0.22).unwrap(), yf, &terms);
            let eps = Voigt::new(0.3, -0.1, -0.2, 0.1, 0.05, -0.02);
            let mut st = PointState::default();
            m.update(
                &Kinematics::from_strain(eps),
                &PointState::default(),
                &mut st,
            )
            .unwrap();
            let sy = m.hardening().yield_stress(st.eq_plastic_strain);
            assert!(m.yield_value(&st).abs() < 1e-9 * sy);
            let dl = st.eq_plastic_strain;
            let xi = st.stress - st.total_back_stress();
            let n = yf.matrix() * xi / yf.equivalent_stress(&xi);
            for (i, &(c, g)) in terms.iter().enumerate() {
                let expect = tensor_of_strain(&n) * (2.0 / 3.0 * c * dl / (1.0 + g * dl));
                assert!((st.back_stress[i] - expect).amax() < 1e-9 * c / g);
            }
            assert_eq!(st.back_stress[2], Voigt::zeros());
        }
    }

    /// Without a kinematic law nothing is written for the back stresses (checkpoints of
    /// isotropic runs unchanged), and with one they round-trip bit for bit.
    #[test]
    fn back_stresses_are_serialised_only_when_present() {
        let iso = PointState::default();
        let json = serde_json::to_string(&iso).unwrap();
        assert!(!json.contains("back_stress"));
        assert_eq!(serde_json::from_str::<PointState>(&json).unwrap(), iso);
        let m = steel(
            Hardening::linear(250.0, 0.0).unwrap(),
            anisotropic(),
            &[(1e4, 50.0)],
        );
        let mut st = PointState::default();
        m.update(
            &Kinematics::from_strain(Voigt::new(0.01, -0.002, 0.0, 0.003, 0.0, 0.0)),
            &PointState::default(),
            &mut st,
        )
        .unwrap();
        let json = serde_json::to_string(&st).unwrap();
        assert!(json.contains("back_stress"));
        assert_eq!(serde_json::from_str::<PointState>(&json).unwrap(), st);
    }

    #[test]
    fn bad_constants_are_errors_naming_the_value() {
        let msg = |t: &[(f64, f64)]| Chaboche::new(t).unwrap_err().to_string();
        let m = msg(&[(1e4, 10.0), (-5.0, 1.0)]);
        assert!(
            m.contains("Chaboche term 2 C = -5") && m.contains("> 0"),
            "{m}"
        );
        let m = msg(&[(1e4, -3.0)]);
        assert!(
            m.contains("Chaboche term 1 gamma = -3") && m.contains(">= 0"),
            "{m}"
        );
        let m = msg(&[(1e4, f64::NAN)]);
        assert!(m.contains("gamma = NaN"), "{m}");
        let m = msg(&[(1.0, 1.0); 4]);
        assert!(
            m.contains("Chaboche number of terms = 4") && m.contains("1 to 3"),
            "{m}"
        );
        assert!(msg(&[]).contains("number of terms = 0"));
        assert!(Chaboche::new(&[(1e4, 0.0)]).is_ok());
    }
}
