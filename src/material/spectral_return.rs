//! Closest-point return of a quadratic yield function `φ(σ)² = σᵀPσ` (Hill48, von Mises)
//! with linear elasticity, reduced to one scalar equation through the generalised
//! eigenbasis of `(P, S)`.
//!
//! # Reduction
//!
//! The backward-Euler return (see `material::elastoplastic`) solves
//! `S(σ - σ_tr) + Δλ Pσ/φ = 0`, `φ(σ) = σ_y(ε̄p_n + Δλ)`. With `γ = Δλ/φ` the first equation
//! is linear in `σ`: `(S + γP) σ = S σ_tr`. Let `V` hold the generalised eigenvectors
//! `P v_i = μ_i S v_i` normalised so that `Vᵀ S V = I`, `Vᵀ P V = diag(μ)` (`μ_i >= 0`;
//! zero on the hydrostatic direction, which `P` does not see). Then, with `c = Vᵀ S σ_tr`
//! and `d_i = 1/(1 + γ μ_i)`,
//!
//! ```text
//! σ(γ)  = V (d ∘ c),        φ(γ)² = Σ μ_i c_i² d_i²,        Δλ(γ) = γ φ(γ),
//! g(γ)  = φ(γ) - σ_y(ε̄p_n + γ φ(γ)) = 0.
//! ```
//!
//! `φ` decreases and `Δλ` increases strictly with `γ` (`d(γφ)/dγ = Σ μ c² d³ / φ > 0`), so
//! for a non-softening law `g` is strictly decreasing: one root in `γ > 0` when the trial
//! state is outside the surface. Newton on `g` from `γ = 0` (for von Mises with a concave
//! law `g` is convex and Newton increases monotonically), safeguarded by the bracket it
//! keeps (a step leaving it bisects). Per iteration: ~20 flops and one hardening call,
//! instead of a 7 x 7 solve with a line search.
//!
//! # Consistent tangent
//!
//! `D = Ξ - (Ξn)(Ξn)ᵀ/(nᵀΞn + h)` with `Ξ = (S + γP - γ n nᵀ)⁻¹` (the elastoplastic module's
//! form). With `A⁻¹ = (S + γP)⁻¹ = V diag(d) Vᵀ`, `a = A⁻¹ n`, `s = nᵀ a` and Sherman-Morrison,
//! `Ξ n = a/(1 - γs)`, `nᵀΞn = s/(1 - γs)`, and the two rank-one terms fold into one:
//!
//! ```text
//! D = V diag(d) Vᵀ + κ a aᵀ,        κ = (γh - 1) / (s + h (1 - γs)),
//! ```
//!
//! (`1 - γs = Σ w_i d_i > 0` with weights `w_i = μ_i c_i² d_i² / φ²` summing to one), with
//! `Vᵀn = μ ∘ d ∘ c / φ`: ~300 flops, against a 6 x 6 Cholesky inverse and products.
//! Symmetric by construction.

use nalgebra::SymmetricEigen;

use super::{Hardening, Tangent, Voigt};

/// Newton iterations before the caller falls back to the general return.
const MAX_ITER: usize = 60;

/// The generalised eigenbasis of a yield matrix `P` against a compliance `S`; see the
/// module docs. Built once per material.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralReturn {
    /// `V`, columns the eigenvectors (`Vᵀ S V = I`).
    v: Tangent,
    /// `Vᵀ S`: `c = Vᵀ S σ_tr`.
    vt_s: Tangent,
    /// Eigenvalues `μ_i >= 0` (those below `1e-12` of the largest set to exactly 0, so the
    /// hydrostatic stress passes through unchanged).
    mu: [f64; 6],
}

/// A converged return.
pub struct SpectralPoint {
    pub stress: Voigt,
    /// `Δλ = γ φ`.
    pub dlambda: f64,
    /// `γ = Δλ/φ`.
    gamma: f64,
    /// `φ` at the returned stress.
    phi: f64,
    /// `d ∘ c` (the stress in the eigenbasis).
    dc: [f64; 6],
    /// `d_i`.
    d: [f64; 6],
}

impl SpectralReturn {
    /// From the yield matrix `p` (symmetric positive semi-definite) and the compliance `s`
    /// (symmetric positive definite). None if `s` is not positive definite.
    pub fn new(p: &Tangent, s: &Tangent) -> Option<Self> {
        let l = s.cholesky()?.l();
        let l_inv = l.try_inverse()?;
        let m = l_inv * p * l_inv.transpose();
        let eig = SymmetricEigen::new((m + m.transpose()) * 0.5);
        let v = l_inv.transpose() * eig.eigenvectors;
        let largest = eig.eigenvalues.amax();
        let mu = std::array::from_fn(|i| {
            let e = eig.eigenvalues[i];
            if e <= 1e-12 * largest {
                0.0
            } else {
                e
            }
        });
        Some(SpectralReturn {
            v,
            vt_s: v.transpose() * s,
            mu,
        })
    }

    /// `φ(γ)` and `dφ/dγ` for the trial coordinates `c`.
    fn phi(&self, c: &[f64; 6], gamma: f64) -> (f64, f64) {
        let (mut phi2, mut dphi2) = (0.0, 0.0);
        for i in 0..6 {
            let d = 1.0 / (1.0 + gamma * self.mu[i]);
            let t = self.mu[i] * c[i] * c[i] * d * d;
            phi2 += t;
            dphi2 -= 2.0 * self.mu[i] * t * d;
        }
        let phi = phi2.sqrt();
        (phi, 0.5 * dphi2 / phi)
    }

    /// The return of `sig_tr` (outside the surface: `φ(σ_tr) > σ_y(ε̄p_n)`) from `ebar_n`,
    /// where the caller already has `sy_n = σ_y(ε̄p_n)`, converged to `|g| <= tol` (stress
    /// units) or to round-off in `γ`. None if Newton did not converge in its iterations
    /// (the caller then uses the general return).
    pub fn solve(
        &self,
        sig_tr: &Voigt,
        ebar_n: f64,
        sy_n: f64,
        hardening: &Hardening,
        tol: f64,
    ) -> Option<SpectralPoint> {
        let c: [f64; 6] = (self.vt_s * sig_tr).into();
        let (mut lo, mut hi) = (0.0f64, f64::INFINITY);
        let mut gamma = 0.0;
        for _ in 0..MAX_ITER {
            let (phi, dphi) = self.phi(&c, gamma);
            if !(phi > 0.0) || !phi.is_finite() {
                return None;
            }
            let dl = gamma * phi;
            // At γ = 0 (the first iterate) the hardening is at ε̄p_n, whose yield
            // stress the caller computed: the same values as a call, one power less.
            let (sy, h) = if gamma == 0.0 {
                (sy_n, hardening.slope_given_yield_stress(ebar_n, sy_n))
            } else {
                hardening.yield_stress_and_slope(ebar_n + dl)
            };
            let g = phi - sy;
            if g.abs() <= tol {
                return Some(self.point(&c, gamma, phi));
            }
            if g > 0.0 {
                lo = lo.max(gamma);
            } else {
                hi = hi.min(gamma);
            }
            let dg = dphi - h * (phi + gamma * dphi);
            let mut next = gamma - g / dg;
            if !(next > lo && next < hi) {
                next = if hi.is_finite() {
                    0.5 * (lo + hi)
                } else {
                    2.0 * lo.max(gamma)
                };
            }
            if (next - gamma).abs() <= 4.0 * f64::EPSILON * gamma {
                // Round-off in γ: as converged as the arithmetic allows.
                return Some(self.point(&c, gamma, phi));
            }
            gamma = next;
        }
        None
    }

    fn point(&self, c: &[f64; 6], gamma: f64, phi: f64) -> SpectralPoint {
        let d: [f64; 6] = std::array::from_fn(|i| 1.0 / (1.0 + gamma * self.mu[i]));
        let dc: [f64; 6] = std::array::from_fn(|i| d[i] * c[i]);
        SpectralPoint {
            stress: self.v * Voigt::from(dc),
            dlambda: gamma * phi,
            gamma,
            phi,
            dc,
            d,
        }
    }

    /// The consistent tangent at a converged return with hardening slope `h` there (module
    /// docs).
    pub fn tangent(&self, pt: &SpectralPoint, h: f64) -> Tangent {
        // Vᵀn = μ ∘ d ∘ c / φ;  a = V (d ∘ Vᵀn);  s = Σ d (Vᵀn)².
        let y: [f64; 6] = std::array::from_fn(|i| self.mu[i] * pt.dc[i] / pt.phi);
        let dy: [f64; 6] = std::array::from_fn(|i| pt.d[i] * y[i]);
        let s: f64 = (0..6).map(|i| dy[i] * y[i]).sum();
        let a = self.v * Voigt::from(dy);
        let kappa = (pt.gamma * h - 1.0) / (s + h * (1.0 - pt.gamma * s));
        let vd = Tangent::from_fn(|i, k| self.v[(i, k)] * pt.d[k]);
        let mut t = Tangent::zeros();
        for j in 0..6 {
            for i in j..6 {
                let mut sum = kappa * a[i] * a[j];
                for k in 0..6 {
                    sum += vd[(i, k)] * self.v[(j, k)];
                }
                t[(i, j)] = sum;
                t[(j, i)] = sum;
            }
        }
        t
    }
}
