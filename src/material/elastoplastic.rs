//! Small-strain elastoplasticity: isotropic linear elasticity, Hill48 (or von Mises)
//! yield, associative flow, isotropic hardening, closest-point return mapping and the
//! consistent tangent.
//!
//! # Equations (Voigt; strains with engineering shear, stresses with tensor shear)
//!
//! Additive split `ε = εe + εp`, `σ = D εe = D (ε - εp)`. With the committed plastic
//! strain `εp_n` and equivalent plastic strain `ε̄p_n`, the elastic trial stress is
//! `σ_tr = D (ε - εp_n)`. If `φ(σ_tr) <= σ_y(ε̄p_n)` the step is elastic. Otherwise the
//! backward-Euler (closest-point) return solves, for `σ` and the multiplier `Δλ >= 0`,
//!
//! ```text
//! r = S σ - S σ_tr + Δλ n(σ) = 0        (S = D⁻¹, n = ∂φ/∂σ = Pσ/φ)
//! f = φ(σ) - σ_y(ε̄p_n + Δλ)   = 0
//! ```
//!
//! by Newton on the full 7x7 system (the flow direction of Hill48 changes along the
//! return, so there is no scalar radial return as for von Mises), with the Jacobian
//!
//! ```text
//! | S + Δλ ∂n/∂σ   n  |      ∂n/∂σ = (P - n nᵀ)/φ,   h = σ_y'(ε̄p_n + Δλ),
//! | nᵀ            -h  |
//! ```
//!
//! and a backtracking line search on the residual norm for large steps. Then
//! `εp = ε - Sσ`, `ε̄p = ε̄p_n + Δλ` (`σ·ε̇p = λ̇ φ`: `Δλ` is work-conjugate to `φ`).
//!
//! # Consistent tangent
//!
//! Linearising the converged equations in `ε` (`S dσ_tr = dε`) gives, with
//! `Ξ = (S + Δλ ∂n/∂σ)⁻¹`,
//!
//! ```text
//! D_alg = Ξ - (Ξ n)(Ξ n)ᵀ / (nᵀ Ξ n + h),
//! ```
//!
//! symmetric because the flow is associative. It is what makes the global Newton
//! iteration converge quadratically.
//!
//! # Solution
//!
//! Because `φ` is quadratic and the elasticity linear, the 7 x 7 system reduces to one
//! scalar equation in the generalised eigenbasis of `(P, S)`, computed once per material
//! (`material::spectral_return`: a safeguarded scalar Newton, the tangent in closed form).
//! The Newton iteration on the full 7 x 7 system above is kept as the fallback should the
//! scalar one not converge, and as the reference the tests compare against.

use nalgebra::{SMatrix, SVector};

use super::kinematic::Isotropic;
use super::spectral_return::SpectralReturn;
use super::{
    Chaboche, Hardening, Hill48, Kinematics, LinearElastic, Material, PointState, Tangent, Voigt,
};
use crate::{Error, Result};

/// Relative yield tolerance: a trial stress within this fraction of the yield stress is
/// elastic (avoids a return mapping of zero length from round-off on the yield surface).
const YIELD_TOL: f64 = 1e-12;
/// Relative tolerance of the return-mapping residual (in stress units, relative to the
/// largest of the yield stress, the trial equivalent stress and the largest trial stress
/// component).
const RETURN_TOL: f64 = 1e-12;
/// Relative tolerance of the scalar return's yield residual (relative to the larger of the
/// yield stress and the trial equivalent stress): two orders below [`RETURN_TOL`], which the
/// scalar iteration reaches at no cost (quadratic convergence, ~3 flops more per step).
const SCALAR_TOL: f64 = 1e-14;
/// Iteration limit of the return mapping.
const MAX_ITER: usize = 60;

/// Small-strain elastoplastic material: [`LinearElastic`] elasticity, [`Hill48`] yield
/// (von Mises with [`Hill48::von_mises`]), [`Hardening`] isotropic hardening of the yield
/// stress in the equivalent plastic strain. See the module documentation for the math.
#[derive(Clone, Debug, PartialEq)]
pub struct ElastoPlastic {
    elastic: LinearElastic,
    yield_function: Hill48,
    hardening: Hardening,
    /// The eigenbasis of `(P, S)` (None only if `S` were not positive definite, which
    /// [`LinearElastic`]'s admissible parameters exclude).
    spectral: Option<SpectralReturn>,
    /// Kinematic hardening (`material::kinematic`), None for purely isotropic hardening
    /// (whose code path is then exactly the one without this field).
    kinematic: Option<Chaboche>,
}

/// Result of a return mapping: stress, multiplier increment and consistent tangent.
struct Return {
    stress: Voigt,
    dlambda: f64,
    tangent: Tangent,
}

impl ElastoPlastic {
    /// Combines validated components (each constructor already checks its parameters).
    pub fn new(elastic: LinearElastic, yield_function: Hill48, hardening: Hardening) -> Self {
        let spectral = SpectralReturn::new(&yield_function.matrix(), &elastic.compliance());
        ElastoPlastic {
            elastic,
            yield_function,
            hardening,
            spectral,
            kinematic: None,
        }
    }

    /// The same material with the kinematic hardening `law` on top of its isotropic law
    /// (mixed hardening, `material::kinematic`).
    pub fn with_kinematic(self, law: Chaboche) -> Self {
        ElastoPlastic {
            kinematic: Some(law),
            ..self
        }
    }

    /// The kinematic hardening law, if any.
    pub fn kinematic(&self) -> Option<&Chaboche> {
        self.kinematic.as_ref()
    }

    /// The elastic part.
    pub fn elastic(&self) -> &LinearElastic {
        &self.elastic
    }

    /// The yield function.
    pub fn yield_function(&self) -> &Hill48 {
        &self.yield_function
    }

    /// The hardening law.
    pub fn hardening(&self) -> &Hardening {
        &self.hardening
    }

    /// Yield function value `f = φ(σ) - σ_y(ε̄p)` of a state (`<= 0` inside the surface).
    pub fn yield_value(&self, state: &PointState) -> f64 {
        self.yield_function
            .equivalent_stress(&(state.stress - state.total_back_stress()))
            - self.hardening.yield_stress(state.eq_plastic_strain)
    }

    /// Closest-point return of the trial stress `sig_tr` from `ε̄p_n = ebar_n`: the scalar
    /// return in the eigenbasis, else the general one. Without `tangent` the returned
    /// tangent is left zero (a residual-only evaluation).
    fn return_map(&self, sig_tr: &Voigt, ebar_n: f64, sy_n: f64, tangent: bool) -> Result<Return> {
        if let Some(sr) = &self.spectral {
            let phi_tr = self.yield_function.equivalent_stress(sig_tr);
            let tol = SCALAR_TOL * phi_tr.max(sy_n);
            if let Some(pt) = sr.solve(sig_tr, ebar_n, sy_n, &self.hardening, tol) {
                let tangent = if tangent {
                    sr.tangent(&pt, self.hardening.slope(ebar_n + pt.dlambda))
                } else {
                    Tangent::zeros()
                };
                return Ok(Return {
                    stress: pt.stress,
                    dlambda: pt.dlambda,
                    tangent,
                });
            }
        }
        self.return_map_general(sig_tr, ebar_n, sy_n)
    }

    /// The Newton iteration on the full 7 x 7 system (module docs), with a backtracking
    /// line search.
    fn return_map_general(&self, sig_tr: &Voigt, ebar_n: f64, sy_n: f64) -> Result<Return> {
        let p = self.yield_function.matrix();
        let s = self.elastic.compliance();
        // Scale the strain-like residual rows by E so that all 7 residuals are stresses.
        let e = self.elastic.young();
        let eps_tr = s * sig_tr;
        let phi_tr = self.yield_function.equivalent_stress(sig_tr);
        // The residual's round-off scales with the whole stress, hydrostatic part included
        // (a large pressure in nearly incompressible flow does not enter φ but does enter
        // S σ), so the tolerance does too.
        let tol = RETURN_TOL * phi_tr.max(sy_n).max(sig_tr.amax());

        let residual = |sig: &Voigt, dl: f64| -> Option<SVector<f64, 7>> {
            let phi = self.yield_function.equivalent_stress(sig);
            if !(phi > 0.0) || !phi.is_finite() {
                return None;
            }
            let n = p * sig / phi;
            let r = (s * sig - eps_tr + n * dl) * e;
            let f = phi - self.hardening.yield_stress(ebar_n + dl);
            Some(SVector::<f64, 7>::from_iterator(
                r.iter().copied().chain(std::iter::once(f)),
            ))
        };

        let (mut sig, mut dl) = (*sig_tr, 0.0);
        let mut res = residual(&sig, dl).ok_or_else(|| self.failure(sig_tr, "zero trial"))?;
        for _ in 0..MAX_ITER {
            if res.amax() <= tol {
                return Ok(self.converged(sig, dl, ebar_n));
            }
            let phi = self.yield_function.equivalent_stress(&sig);
            let n = p * sig / phi;
            let h = self.hardening.slope(ebar_n + dl);
            let a = s + (p - n * n.transpose()) * (dl / phi);
            let mut jac = SMatrix::<f64, 7, 7>::zeros();
            jac.fixed_view_mut::<6, 6>(0, 0).copy_from(&(a * e));
            jac.fixed_view_mut::<6, 1>(0, 6).copy_from(&(n * e));
            jac.fixed_view_mut::<1, 6>(6, 0).copy_from(&n.transpose());
            jac[(6, 6)] = -h;
            let step = solve_dense(jac, -res)
                .ok_or_else(|| self.failure(sig_tr, "singular return-mapping Jacobian"))?;
            // Backtracking: accept the first step length that reduces the residual norm.
            let norm = res.norm();
            let mut alpha = 1.0;
            loop {
                let trial_sig = sig + step.fixed_rows::<6>(0) * alpha;
                // Δλ >= 0 keeps the hardening law in its domain (ε̄p >= ε̄p_n).
                let trial_dl = (dl + step[6] * alpha).max(0.0);
                if let Some(r) = residual(&trial_sig, trial_dl) {
                    if r.norm() < norm || alpha < 1e-6 {
                        sig = trial_sig;
                        dl = trial_dl;
                        res = r;
                        break;
                    }
                }
                alpha *= 0.5;
                if alpha < 1e-10 {
                    return Err(self.failure(sig_tr, "line search failed"));
                }
            }
        }
        if res.amax() <= tol {
            return Ok(self.converged(sig, dl, ebar_n));
        }
        Err(self.failure(
            sig_tr,
            &format!(
                "no convergence in {MAX_ITER} iterations, residual {:e}",
                res.amax()
            ),
        ))
    }

    /// Consistent tangent at the converged return (see the module docs).
    fn converged(&self, sig: Voigt, dl: f64, ebar_n: f64) -> Return {
        let p = self.yield_function.matrix();
        let phi = self.yield_function.equivalent_stress(&sig);
        let n = p * sig / phi;
        let h = self.hardening.slope(ebar_n + dl);
        let a = self.elastic.compliance() + (p - n * n.transpose()) * (dl / phi);
        // `a` is symmetric positive definite (S SPD, P - nnᵀ PSD by Cauchy-Schwarz in the
        // P inner product), so Cholesky cannot fail for admissible parameters.
        let xi = match a.cholesky() {
            Some(c) => c.inverse(),
            None => a.try_inverse().unwrap_or_else(|| self.elastic.tangent()),
        };
        let xn = xi * n;
        let mut tangent = xi - xn * xn.transpose() / (n.dot(&xn) + h);
        tangent = (tangent + tangent.transpose()) * 0.5;
        Return {
            stress: sig,
            dlambda: dl,
            tangent,
        }
    }

    fn failure(&self, sig_tr: &Voigt, why: &str) -> Error {
        Error::no_convergence(
            crate::error::Failure::Local,
            format!(
                "return mapping ({}, {}): {why}; trial stress {:?}",
                self.yield_function.describe(),
                self.hardening.describe(),
                sig_tr.as_slice()
            ),
        )
    }
}

/// Solves `a x = b` by Gaussian elimination with partial pivoting, in place on the stack
/// (the return mapping's 7 x 7 Newton system: nalgebra's generic LU spent most of the
/// plastic point's time in bookkeeping). None when a pivot is exactly zero (singular), as
/// nalgebra's `LU::solve`.
fn solve_dense<const N: usize>(
    mut a: SMatrix<f64, N, N>,
    mut b: SVector<f64, N>,
) -> Option<SVector<f64, N>> {
    for col in 0..N {
        let pivot = (col..N).max_by(|&i, &j| a[(i, col)].abs().total_cmp(&a[(j, col)].abs()))?;
        if a[(pivot, col)] == 0.0 {
            return None;
        }
        if pivot != col {
            a.swap_rows(pivot, col);
            b.swap_rows(pivot, col);
        }
        let d = a[(col, col)];
        for row in col + 1..N {
            let factor = a[(row, col)] / d;
            if factor != 0.0 {
                for c in col + 1..N {
                    a[(row, c)] -= factor * a[(col, c)];
                }
                b[row] -= factor * b[col];
            }
        }
    }
    for col in (0..N).rev() {
        let mut v = b[col];
        for c in col + 1..N {
            v -= a[(col, c)] * b[c];
        }
        b[col] = v / a[(col, col)];
    }
    Some(b)
}

impl ElastoPlastic {
    /// [`Material::update`], with the tangent only when `tangent` (else the zero matrix).
    fn update_with(
        &self,
        kin: &Kinematics,
        committed: &PointState,
        trial: &mut PointState,
        tangent: bool,
    ) -> Result<Tangent> {
        if !kin.strain.iter().all(|v| v.is_finite()) {
            // A diverging Newton iterate, not bad user input: the solver cuts back.
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                format!(
                    "non-finite strain {:?} at an integration point",
                    kin.strain.as_slice()
                ),
            ));
        }
        if let Some(law) = &self.kinematic {
            return self.update_kinematic(law, kin, committed, trial, tangent);
        }
        let ebar_n = committed.eq_plastic_strain;
        let sig_tr = self
            .elastic
            .stress(&(kin.strain - committed.plastic_strain));
        let base = PointState {
            strain: kin.strain,
            deformation_gradient: kin.deformation_gradient,
            ..*committed
        };
        let sy = self.hardening.yield_stress(ebar_n);
        if self.yield_function.equivalent_stress(&sig_tr) - sy <= YIELD_TOL * sy {
            *trial = PointState {
                stress: sig_tr,
                ..base
            };
            return Ok(self.elastic.tangent());
        }
        let ret = self.return_map(&sig_tr, ebar_n, sy, tangent)?;
        // ε - Sσ rather than εp_n + Δλ n: exactly consistent with σ = D(ε - εp).
        let plastic_strain = kin.strain - self.elastic.compliance() * ret.stress;
        *trial = PointState {
            stress: ret.stress,
            plastic_strain,
            eq_plastic_strain: ebar_n + ret.dlambda,
            // Trapezoidal, like the external work, so that the balance
            // W_ext = Ψe + D_p closes exactly for a small-strain body.
            plastic_dissipation: committed.plastic_dissipation
                + 0.5
                    * (committed.stress + ret.stress)
                        .dot(&(plastic_strain - committed.plastic_strain)),
            ..base
        };
        Ok(ret.tangent)
    }

    /// [`update_with`](Self::update_with) under mixed hardening: the yield function of
    /// `σ - X`, the back stresses updated by the return of `material::kinematic`.
    fn update_kinematic(
        &self,
        law: &Chaboche,
        kin: &Kinematics,
        committed: &PointState,
        trial: &mut PointState,
        tangent: bool,
    ) -> Result<Tangent> {
        let ebar_n = committed.eq_plastic_strain;
        let sig_tr = self
            .elastic
            .stress(&(kin.strain - committed.plastic_strain));
        let base = PointState {
            strain: kin.strain,
            deformation_gradient: kin.deformation_gradient,
            ..*committed
        };
        let sy = self.hardening.yield_stress(ebar_n);
        let relative = sig_tr - committed.total_back_stress();
        if self.yield_function.equivalent_stress(&relative) - sy <= YIELD_TOL * sy {
            *trial = PointState {
                stress: sig_tr,
                ..base
            };
            return Ok(self.elastic.tangent());
        }
        let stiffness = self.elastic.tangent();
        let iso = Isotropic {
            stiffness: &stiffness,
            yield_function: &self.yield_function,
            hardening: &self.hardening,
        };
        let ret = law.return_map(&iso, &sig_tr, &committed.back_stress, ebar_n, tangent)?;
        let plastic_strain = kin.strain - self.elastic.compliance() * ret.stress;
        *trial = PointState {
            stress: ret.stress,
            plastic_strain,
            eq_plastic_strain: ebar_n + ret.dlambda,
            back_stress: ret.back_stress,
            // The plastic work ∫ σ·dεp (dissipated plus stored in the back stresses),
            // trapezoidal as in the isotropic case, so that W_ext = Ψe + W_p still closes.
            plastic_dissipation: committed.plastic_dissipation
                + 0.5
                    * (committed.stress + ret.stress)
                        .dot(&(plastic_strain - committed.plastic_strain)),
            ..base
        };
        Ok(ret.tangent)
    }
}

impl Material for ElastoPlastic {
    fn update(
        &self,
        kin: &Kinematics,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<Tangent> {
        self.update_with(kin, committed, trial, true)
    }

    /// The same trial state without the consistent tangent (a residual-only evaluation).
    fn update_stress(
        &self,
        kin: &Kinematics,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<()> {
        self.update_with(kin, committed, trial, false).map(|_| ())
    }

    fn elastic_tangent(&self) -> Tangent {
        self.elastic.tangent()
    }

    /// `½ εe·D εe = ½ σ·Sσ` with the elastic strain `εe = ε - εp`.
    fn elastic_energy_density(&self, state: &PointState) -> f64 {
        self.elastic.energy_density_of_stress(&state.stress)
    }

    /// Hill48's `φ` (von Mises for isotropic coefficients), in the material axes.
    /// Under kinematic hardening, of the stress relative to the back stress, `φ(σ - X)`.
    fn equivalent_stress(&self, state: &PointState, finite: bool) -> f64 {
        if self.kinematic.is_none() {
            return self
                .yield_function
                .equivalent_stress(state.material_stress(finite));
        }
        self.yield_function
            .equivalent_stress(&(state.material_stress(finite) - state.total_back_stress()))
    }

    fn hardening_exponent(&self) -> Option<f64> {
        match self.hardening {
            Hardening::Swift { n, .. } => Some(n),
            _ => None,
        }
    }

    fn describe(&self) -> String {
        let kinematic = self
            .kinematic
            .as_ref()
            .map_or(String::new(), |k| format!(", {}", k.describe()));
        format!(
            "elastoplastic E={} nu={}, {}, {}{kinematic}",
            self.elastic.young(),
            self.elastic.poisson(),
            self.yield_function.describe(),
            self.hardening.describe()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn swift() -> Hardening {
        Hardening::swift(500.0, 0.01, 0.22).unwrap()
    }

    /// The return mapping's dense solve against nalgebra's LU on a non-symmetric 7 x 7
    /// system whose first column needs a row swap (pivoting); a matrix with a zero column is
    /// None.
    /// Agreement to 1e-12 relative (condition number ~10: round-off ~1e-15).
    #[test]
    fn dense_solve_matches_lu_and_detects_singularity() {
        let a = SMatrix::<f64, 7, 7>::from_fn(|i, j| {
            if i == 0 && j == 0 {
                0.0
            } else {
                ((i * 7 + j * 3) % 11) as f64 / 11.0 + if i == j { 2.0 } else { 0.0 }
            }
        });
        let b = SVector::<f64, 7>::from_fn(|i, _| i as f64 - 2.5);
        let x = solve_dense(a, b).unwrap();
        let y = a.lu().solve(&b).unwrap();
        assert!((x - y).amax() < 1e-12 * y.amax(), "{x} {y}");
        let mut singular = a;
        singular.set_column(4, &SVector::<f64, 7>::zeros());
        assert!(solve_dense(singular, b).is_none());
    }

    /// The scalar return in the eigenbasis against the Newton iteration on the full 7 x 7
    /// system, on random trial stresses up to 20 times the yield stress, for von Mises,
    /// Hill48 (also with a turned rolling direction) and every hardening law: stress and
    /// Δλ to 1e-11 and the tangent to 1e-9 relative (the general return stops at a residual
    /// of 1e-12 of the stress scale; its tangent comes from a Cholesky inverse of a matrix
    /// of condition ~1e3).
    #[test]
    fn scalar_return_equals_the_general_return() {
        let mut seed = 12345u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let yields = [
            Hill48::von_mises(),
            anisotropic(),
            anisotropic().with_rolling_angle(0.6).unwrap(),
        ];
        let laws = [
            swift(),
            Hardening::voce(200.0, 100.0, 8.0).unwrap(),
            Hardening::linear(250.0, 1000.0).unwrap(),
            Hardening::tabulated(vec![0.0, 0.05, 0.2], vec![250.0, 320.0, 400.0]).unwrap(),
            Hardening::swift(500.0, 0.01, 0.0).unwrap(),
        ];
        let mut compared = 0;
        for yf in yields {
            for law in &laws {
                let m =
                    ElastoPlastic::new(LinearElastic::new(70e3, 0.33).unwrap(), yf, law.clone());
                for _ in 0..40 {
                    let ebar_n = 0.1 * (1.0 + rnd());
                    let sy = law.yield_stress(ebar_n);
                    let dir = Voigt::from_fn(|_, _| rnd());
                    let phi = yf.equivalent_stress(&dir);
                    let scale = sy * (1.2 + 10.0 * (1.0 + rnd())) / phi;
                    let sig_tr =
                        dir * scale + Voigt::new(1.0, 1.0, 1.0, 0.0, 0.0, 0.0) * (rnd() * sy);
                    let sy_n = m.hardening().yield_stress(ebar_n);
                    let fast = m.return_map(&sig_tr, ebar_n, sy_n, true).unwrap();
                    let general = m.return_map_general(&sig_tr, ebar_n, sy_n).unwrap();
                    let sig_scale = sig_tr.amax();
                    assert!(
                        (fast.stress - general.stress).amax() <= 1e-11 * sig_scale,
                        "{:?} {:?}",
                        fast.stress,
                        general.stress
                    );
                    assert!(
                        (fast.dlambda - general.dlambda).abs() <= 1e-11 * general.dlambda.max(1e-3),
                        "{} {}",
                        fast.dlambda,
                        general.dlambda
                    );
                    let t_scale = general.tangent.amax();
                    assert!(
                        (fast.tangent - general.tangent).amax() <= 1e-9 * t_scale,
                        "{}: {:e}",
                        m.describe(),
                        (fast.tangent - general.tangent).amax() / t_scale
                    );
                    // Residual-only: the same stress, bit for bit, and no tangent.
                    let stress_only = m.return_map(&sig_tr, ebar_n, sy_n, false).unwrap();
                    assert_eq!(stress_only.stress, fast.stress);
                    assert_eq!(stress_only.tangent, Tangent::zeros());
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, 600);
    }

    fn aluminium(yield_function: Hill48) -> ElastoPlastic {
        ElastoPlastic::new(
            LinearElastic::new(70e3, 0.33).unwrap(),
            yield_function,
            swift(),
        )
    }

    fn anisotropic() -> Hill48 {
        Hill48::from_lankford(0.7, 1.3, 2.1).unwrap()
    }

    /// Uniaxial stress along `angle` to x, its strain along the direction raised in
    /// `steps` equal increments up to `eps_max` (the shared driver,
    /// `material::uniaxial_stress_path`); the committed state after every step.
    fn uniaxial(m: &ElastoPlastic, angle: f64, eps_max: f64, steps: usize) -> Vec<PointState> {
        let targets: Vec<f64> = (1..=steps)
            .map(|k| eps_max * k as f64 / steps as f64)
            .collect();
        super::super::uniaxial_stress_path(m, super::super::uniaxial_direction(angle), &targets)
            .unwrap()
    }

    #[test]
    fn uniaxial_tension_reproduces_the_swift_curve() {
        for yf in [Hill48::von_mises(), anisotropic()] {
            let m = aluminium(yf);
            let states = uniaxial(&m, 0.0, 0.5, 100);
            let mut plastic_steps = 0;
            for st in &states {
                let sig = st.stress[0];
                let ep = st.plastic_strain[0];
                if ep <= 0.0 {
                    continue;
                }
                plastic_steps += 1;
                let expect = 500.0 * (0.01 + ep).powf(0.22);
                assert!(
                    (sig - expect).abs() <= 1e-6 * expect,
                    "{sig} vs {expect} at {ep}"
                );
                // Along the rolling direction the equivalent plastic strain is εp_xx.
                assert!((st.eq_plastic_strain - ep).abs() <= 1e-9);
                // Uniaxial: every other stress component vanishes.
                let others = st.stress.iter().skip(1).fold(0.0f64, |a, v| a.max(v.abs()));
                assert!(others <= 1e-8 * sig);
            }
            assert!(plastic_steps >= 99, "{plastic_steps}");
            let last = states.last().unwrap();
            assert!((last.strain[0] - 0.5).abs() < 1e-14);
        }
    }

    #[test]
    fn tension_at_0_45_90_degrees_gives_back_the_lankford_coefficients() {
        let (r0, r45, r90) = (0.7, 1.3, 2.1);
        let m = aluminium(Hill48::from_lankford(r0, r45, r90).unwrap());
        for (deg, r_expect) in [(0.0, r0), (45.0, r45), (90.0, r90)] {
            let angle = f64::to_radians(deg);
            let states = uniaxial(&m, angle, 0.1, 20);
            let (a, b) = (&states[states.len() - 2], &states[states.len() - 1]);
            let dep = b.plastic_strain - a.plastic_strain;
            // Width direction w = (-sin, cos, 0): ε_ww = s²εxx + c²εyy - cs γxy.
            let (s, c) = angle.sin_cos();
            let width = s * s * dep[0] + c * c * dep[1] - c * s * dep[3];
            let r = width / dep[2];
            assert!((r - r_expect).abs() <= 0.01 * r_expect, "{deg}°: r = {r}");
            // Exact for Hill48 (the flow direction is constant under uniaxial stress).
            assert!((r - r_expect).abs() <= 1e-6 * r_expect, "{deg}°: r = {r}");
            assert!(b.stress[2].abs() < 1e-6, "plane stress");
        }
    }

    /// Committed state with plastic history, then the tangent at `eps` from it against
    /// central differences of the stress update.
    fn check_tangent(m: &ElastoPlastic, eps: Voigt, expect_plastic: bool) {
        let history = Voigt::new(0.01, -0.004, -0.003, 0.006, -0.002, 0.003);
        let mut committed = m.initial_state();
        m.update(
            &Kinematics::from_strain(history),
            &PointState::default(),
            &mut committed,
        )
        .unwrap();
        assert!(committed.eq_plastic_strain > 0.0);
        let mut trial = committed;
        let d = m
            .update(&Kinematics::from_strain(eps), &committed, &mut trial)
            .unwrap();
        assert_eq!(
            trial.eq_plastic_strain > committed.eq_plastic_strain,
            expect_plastic
        );
        let h = 1e-6;
        let mut fd = Tangent::zeros();
        for j in 0..6 {
            let mut ep = eps;
            let mut em = eps;
            ep[j] += h;
            em[j] -= h;
            let (mut sp, mut sm) = (committed, committed);
            m.update(&Kinematics::from_strain(ep), &committed, &mut sp)
                .unwrap();
            m.update(&Kinematics::from_strain(em), &committed, &mut sm)
                .unwrap();
            fd.set_column(j, &((sp.stress - sm.stress) / (2.0 * h)));
        }
        let err = (d - fd).amax() / d.amax();
        assert!(err < 1e-6, "{}: relative error {err:e}", m.describe());
        if expect_plastic {
            // The plastic tangent is softer than the elastic one.
            assert!((d - m.elastic_tangent()).amax() > 1e-3 * d.amax());
        } else {
            assert_eq!(d, m.elastic_tangent());
        }
    }

    #[test]
    fn consistent_tangent_equals_central_differences() {
        for yf in [Hill48::von_mises(), anisotropic()] {
            let m = aluminium(yf);
            // Plastic: continued loading in another direction.
            check_tangent(
                &m,
                Voigt::new(0.014, -0.002, -0.006, 0.01, 0.001, 0.004),
                true,
            );
            // Elastic: unloading a little from the committed strain.
            check_tangent(
                &m,
                Voigt::new(0.0099, -0.004, -0.003, 0.006, -0.002, 0.003),
                false,
            );
        }
        // Other hardening laws, one large step far beyond yield.
        for hardening in [
            Hardening::voce(200.0, 100.0, 8.0).unwrap(),
            Hardening::linear(250.0, 1000.0).unwrap(),
            Hardening::swift(500.0, 0.01, 0.0).unwrap(),
            Hardening::tabulated(vec![0.0, 0.2], vec![250.0, 400.0]).unwrap(),
        ] {
            let m = ElastoPlastic::new(
                LinearElastic::new(210e3, 0.3).unwrap(),
                anisotropic(),
                hardening,
            );
            check_tangent(&m, Voigt::new(0.08, -0.03, -0.02, 0.04, 0.01, -0.02), true);
        }
    }

    #[test]
    fn one_large_step_returns_to_the_yield_surface() {
        // 50% strain in a single increment (as after a big Newton iterate): the line
        // search keeps the return mapping converging.
        let m = aluminium(anisotropic());
        for eps in [
            Voigt::new(0.5, -0.2, -0.3, 0.1, 0.0, 0.0),
            Voigt::new(-0.3, 0.4, -0.1, -0.2, 0.15, 0.05),
        ] {
            let mut st = PointState::default();
            m.update(
                &Kinematics::from_strain(eps),
                &PointState::default(),
                &mut st,
            )
            .unwrap();
            assert!(st.eq_plastic_strain > 0.1);
            let sy = m.hardening().yield_stress(st.eq_plastic_strain);
            assert!(m.yield_value(&st).abs() <= 1e-10 * sy);
            // Plastic work rate is positive: σ·Δεp = Δλ φ > 0.
            let work = st.stress.dot(&st.plastic_strain);
            assert!((work - st.eq_plastic_strain * sy).abs() <= 1e-8 * work.abs());
        }
    }

    #[test]
    fn von_mises_return_is_radial_and_energy_uses_the_elastic_strain() {
        let m = ElastoPlastic::new(
            LinearElastic::new(200e3, 0.3).unwrap(),
            Hill48::von_mises(),
            Hardening::linear(300.0, 2000.0).unwrap(),
        );
        let eps = Voigt::new(0.01, 0.002, -0.004, 0.003, 0.0, 0.001);
        let mut st = PointState::default();
        m.update(
            &Kinematics::from_strain(eps),
            &PointState::default(),
            &mut st,
        )
        .unwrap();
        // Radial return in closed form: Δλ = (q_tr - σy) / (3μ + H).
        let el = m.elastic();
        let sig_tr = el.stress(&eps);
        let q_tr = super::super::von_mises(&sig_tr);
        let dl = (q_tr - 300.0) / (3.0 * el.shear_modulus() + 2000.0);
        assert!((st.eq_plastic_strain - dl).abs() < 1e-12);
        assert!(m.yield_value(&st).abs() < 1e-8);
        // Same pressure as the trial (plastic flow is isochoric).
        let tr = |v: &Voigt| v[0] + v[1] + v[2];
        assert!((tr(&st.stress) - tr(&sig_tr)).abs() < 1e-8);
        assert!(tr(&st.plastic_strain).abs() < 1e-14);
        let ee = st.strain - st.plastic_strain;
        assert!((m.elastic_energy_density(&st) - el.energy_density(&ee)).abs() < 1e-10);
        let bad = Kinematics::from_strain(Voigt::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0));
        assert!(matches!(
            m.update(&bad, &PointState::default(), &mut st),
            Err(Error::NoConvergence { .. })
        ));
        assert!(m.describe().contains("Hill48 F=0.5"));
    }

    /// A nearly incompressible material under a large pressure: the trial stress seen in a
    /// diverging Newton iterate of a locking mesh (~1.4e6 MPa of pressure, 4 orders above
    /// the yield stress). The return mapping converges and lands on the yield surface,
    /// keeping the elastic pressure (plastic flow is isochoric).
    #[test]
    fn large_pressure_return_converges() {
        let m = ElastoPlastic::new(
            LinearElastic::new(70e3, 0.499).unwrap(),
            Hill48::von_mises(),
            Hardening::linear(200.0, 500.0).unwrap(),
        );
        let sig_tr = Voigt::new(
            1405976.7731217719,
            1402943.2723241525,
            1404307.3296416176,
            9.720063201559617e-7,
            -7.691844245015104e-7,
            1472.00659859707,
        );
        let eps = m.elastic().compliance() * sig_tr;
        let committed = m.initial_state();
        let mut trial = committed;
        m.update(&Kinematics::from_strain(eps), &committed, &mut trial)
            .unwrap();
        let sy = m.hardening().yield_stress(trial.eq_plastic_strain);
        assert!(trial.eq_plastic_strain > 0.01);
        assert!(
            m.yield_value(&trial).abs() < 1e-6 * sy,
            "{}",
            m.yield_value(&trial)
        );
        let p_tr = -(sig_tr[0] + sig_tr[1] + sig_tr[2]) / 3.0;
        let p = -(trial.stress[0] + trial.stress[1] + trial.stress[2]) / 3.0;
        assert!((p - p_tr).abs() < 1e-9 * p_tr.abs(), "{p} vs {p_tr}");
    }
}
