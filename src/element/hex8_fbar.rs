//! The 8-node hexahedron for finite strain: total Lagrangian, with the F-bar volumetric
//! treatment (de Souza Neto, Perić, Dutko & Owen, IJSS 33, 1996).
//!
//! # Kinematics
//!
//! With the reference gradients `b_a = ∇_X N_a` at a Gauss point and `b⁰_a` at the element
//! centre, `F = I + Σ_a u_a ⊗ b_a`, `F₀ = I + Σ_a u_a ⊗ b⁰_a`, `J = det F`, `J₀ = det F₀`,
//!
//! ```text
//! F̄ = r F,     r = (J₀ / J)^⅓,     det F̄ = J₀.
//! ```
//!
//! The isochoric part of `F` is kept at each of the 2x2x2 Gauss points; the volume change
//! is the centre's, one volumetric constraint per element, so nearly incompressible
//! (plastic) flow does not lock. The material sees `F̄` only
//! ([`Material::update_finite_displacement_gradient`], given `F̄ - I` formed without
//! round-off from `I`: second Piola-Kirchhoff `S̄` and `ℂ = ∂S̄/∂Ē_GL`).
//!
//! # Weak form (variationally consistent F-bar)
//!
//! The internal virtual work is `δW = ∫ P̄ : δF̄ dV₀` with `P̄ = F̄ S̄`, i.e. the exact
//! variation of the stored energy `∫ ψ(F̄(u)) dV₀` for a hyperelastic material. In spatial
//! terms (`g_a = F⁻ᵀ b_a`, `g⁰_a = F₀⁻ᵀ b⁰_a`, `τ̄ = F̄ S̄ F̄ᵀ`)
//!
//! ```text
//! f_a = ∫ [ dev(τ̄) g_a + ⅓ tr(τ̄) g⁰_a ] dV₀,
//! ```
//!
//! the deviatoric Kirchhoff stress with the point's gradient and the pressure with the
//! centre's: the finite-strain counterpart of B-bar. (de Souza Neto et al. integrate
//! `σ(F̄) : ∇ₓδu` over the current volume instead; both share the kinematic constraint
//! that removes locking and coincide at small strain. This form was chosen because its
//! tangent is the exact second variation, symmetric for hyperelastic materials, and its
//! internal work is exactly the elastic energy's rate, which the energy balance uses.)
//!
//! # Consistent tangent
//!
//! Differentiating `F̄` (9-vectors, row-major `F̄_iJ`; dof `(a, k)` = node `a`, direction
//! `k`): `∂F̄/∂u_ak = r (e_k ⊗ b_a) + r q_ak F` with `q_ak = ⅓ (g⁰_a - g_a)_k`
//! (`d ln J = g_a·du_a`). Then
//!
//! ```text
//! K = ∫ Gᵀ 𝔸 G + r [ (P̄:F)(q qᵀ + H) + q wᵀ + w qᵀ ] dV₀,
//! 𝔸 = ∂P̄/∂F̄ = I ⊗ S̄ (geometric) + Mᵀ ℂ M,   M = ∂Ē_GL/∂F̄ (6x9),
//! w_ak = (P̄ b_a)_k,   H_(ak)(cl) = ⅓ (g_a,l g_c,k - g⁰_a,l g⁰_c,k)
//! ```
//!
//! (`H = d² ln r`, from `d² ln J [dF₁, dF₂] = -tr(F⁻¹dF₁F⁻¹dF₂)`). Non-symmetric only
//! through `ℂ` for non-associative models; checked against central differences of the
//! internal force in the tests. With `fbar = false` (`r = 1`, `q = H = 0`) this is the plain
//! fully integrated total-Lagrangian hexahedron, which locks: kept as the reference of the
//! locking test.

use nalgebra::{SMatrix, SVector};

use super::hex8::{checked_inputs, jacobian, shape_derivatives, DOFS, NODES, POINTS};
use super::{prefix, Element, ElementResponse, Hex8};
use crate::geometry::{Mat3, Vec3};
use crate::material::{stress_to_tensor, Material, PointState};
use crate::{Error, Result};

/// Voigt index pairs `[xx, yy, zz, xy, yz, zx]`.
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)];

/// The total-Lagrangian 8-node hexahedron, F-bar by default; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hex8FBar {
    /// `false`: no volumetric modification (locks for nearly incompressible flow).
    pub fbar: bool,
}

impl Default for Hex8FBar {
    fn default() -> Self {
        Hex8FBar { fbar: true }
    }
}

/// The displacement gradient `H = Σ u_a ⊗ b_a` (`F = I + H`). Kept apart from `F`:
/// strains of `10⁻⁶` (a stiff sheet in bending) would keep only ~10 digits in `I + H`,
/// and the material forms its strain from `H` (see `material::log_strain`).
fn displacement_gradient(u: &[Vec3; NODES], b: &[Vec3; NODES]) -> Mat3 {
    (0..NODES).fold(Mat3::zeros(), |h, a| h + u[a] * b[a].transpose())
}

/// `ln det(I + h)` from `det(I + h) - 1 = tr h + ½((tr h)² - tr h²) + det h`, to the
/// relative precision of `h` (no cancellation against 1). `det(I + h) > 0` is the caller's.
fn ln_det_one_plus(h: &Mat3) -> f64 {
    let tr = h.trace();
    (tr + 0.5 * (tr * tr - (h * h).trace()) + h.determinant()).ln_1p()
}

/// Inverse-transpose of a deformation gradient with a positive determinant.
fn inverse_transpose(f: &Mat3, what: &str) -> Result<(Mat3, f64)> {
    let det = f.determinant();
    match f.try_inverse() {
        Some(inv) if det > 0.0 && det.is_finite() => Ok((inv.transpose(), det)),
        _ => Err(Error::NoConvergence(format!(
            "det F = {det} at {what} (element turned inside out)"
        ))),
    }
}

/// Centre gradients `b⁰_a` of the reference element.
fn centre_gradients(x: &[Vec3; NODES]) -> Result<[Vec3; NODES]> {
    let xi = Vec3::zeros();
    let j = jacobian(x, &xi);
    let det = j.determinant();
    let inv_t = match j.try_inverse() {
        Some(inv) if det > 0.0 && det.is_finite() => inv.transpose(),
        _ => {
            return Err(Error::input(
                "Jacobian determinant at the element centre",
                det,
                "must be > 0 (inverted or degenerate element)",
            ))
        }
    };
    let dn = shape_derivatives(&xi);
    Ok(std::array::from_fn(|a| inv_t * dn[a]))
}

impl Element<DOFS> for Hex8FBar {
    fn node_count(&self) -> usize {
        NODES
    }

    fn point_count(&self) -> usize {
        POINTS
    }

    fn evaluate(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
    ) -> Result<ElementResponse<DOFS>> {
        let (x, u, geo) = checked_inputs(ref_coords, u, committed, trial)?;
        let b0 = centre_gradients(&x)?;
        let h0 = displacement_gradient(&u, &b0);
        let (f0_inv_t, _) = inverse_transpose(&(Mat3::identity() + h0), "the element centre")?;
        let ln_j0 = ln_det_one_plus(&h0);
        let g0: [Vec3; NODES] = std::array::from_fn(|a| f0_inv_t * b0[a]);

        let mut force = SVector::<f64, DOFS>::zeros();
        let mut stiffness = SMatrix::<f64, DOFS, DOFS>::zeros();
        for gp in 0..POINTS {
            let b = &geo.grad[gp];
            let h = displacement_gradient(&u, b);
            let f = Mat3::identity() + h;
            let (f_inv_t, _) = inverse_transpose(&f, &format!("integration point {gp}"))?;
            let g: [Vec3; NODES] = std::array::from_fn(|a| f_inv_t * b[a]);
            // r - 1 = expm1(⅓ ln(J₀/J)), kept to the precision of the strains.
            let (r_minus_one, q) = if self.fbar {
                let q = SVector::<f64, DOFS>::from_fn(|i, _| {
                    (g0[i / 3][i % 3] - g[i / 3][i % 3]) / 3.0
                });
                (((ln_j0 - ln_det_one_plus(&h)) / 3.0).exp_m1(), q)
            } else {
                (0.0, SVector::<f64, DOFS>::zeros())
            };
            let r = 1.0 + r_minus_one;
            let fb = f * r;
            // F̄ - I = (r - 1) I + r H.
            let hb = Mat3::identity() * r_minus_one + h * r;
            let resp = material
                .update_finite_displacement_gradient(&hb, &committed[gp], &mut trial[gp])
                .map_err(|e| prefix(e, &format!("integration point {gp}")))?;
            let s = stress_to_tensor(&resp.pk2);
            let p = fb * s;
            let p9 = SVector::<f64, 9>::from_fn(|i, _| p[(i / 3, i % 3)]);

            // G = ∂F̄/∂u (9 x 24).
            let mut gm = SMatrix::<f64, 9, DOFS>::zeros();
            for (a, ba) in b.iter().enumerate() {
                for k in 0..3 {
                    let col = 3 * a + k;
                    for jj in 0..3 {
                        gm[(3 * k + jj, col)] += r * ba[jj];
                    }
                    if self.fbar {
                        for i in 0..9 {
                            gm[(i, col)] += r * q[col] * f[(i / 3, i % 3)];
                        }
                    }
                }
            }
            // 𝔸 = I ⊗ S̄ + Mᵀ ℂ M.
            let mut m = SMatrix::<f64, 6, 9>::zeros();
            for (v, &(ii, jj)) in PAIRS.iter().enumerate() {
                for i in 0..3 {
                    if ii == jj {
                        m[(v, 3 * i + ii)] += fb[(i, ii)];
                    } else {
                        m[(v, 3 * i + jj)] += fb[(i, ii)];
                        m[(v, 3 * i + ii)] += fb[(i, jj)];
                    }
                }
            }
            let mut a9 = m.transpose() * resp.tangent * m;
            for i in 0..3 {
                for jj in 0..3 {
                    for l in 0..3 {
                        a9[(3 * i + jj, 3 * i + l)] += s[(l, jj)];
                    }
                }
            }
            let dv = geo.dvol[gp];
            force += gm.transpose() * (p9 * dv);
            stiffness += gm.transpose() * (a9 * gm) * dv;
            if self.fbar {
                // P̄ : ∂²F̄/∂u∂u.
                let pf = p.component_mul(&f).sum();
                let w = SVector::<f64, DOFS>::from_fn(|i, _| (p * b[i / 3])[i % 3]);
                let mut extra = q * q.transpose() * pf + q * w.transpose() + w * q.transpose();
                for a in 0..NODES {
                    for k in 0..3 {
                        for c in 0..NODES {
                            for l in 0..3 {
                                extra[(3 * a + k, 3 * c + l)] +=
                                    pf * (g[a][l] * g[c][k] - g0[a][l] * g0[c][k]) / 3.0;
                            }
                        }
                    }
                }
                stiffness += extra * (r * dv);
            }
        }
        Ok(ElementResponse { force, stiffness })
    }

    fn point_volumes(&self, ref_coords: &[Vec3]) -> Result<Vec<f64>> {
        Hex8.point_volumes(ref_coords)
    }

    /// `∫ ψ(T) dV₀` with the log-space stress (Hencky energy of the elastic log strain).
    fn strain_energy(
        &self,
        ref_coords: &[Vec3],
        states: &[PointState],
        material: &dyn Material,
    ) -> Result<f64> {
        self.integrate(ref_coords, states, &|s| {
            material.elastic_energy_density(&PointState {
                stress: s.log_stress,
                ..*s
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::element::hex8::tests::{distorted_element, Lcg};
    use crate::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};

    fn hill_swift() -> ElastoPlastic {
        ElastoPlastic::new(
            LinearElastic::new(70e3, 0.33).unwrap(),
            Hill48::from_lankford(0.7, 1.3, 2.1).unwrap(),
            Hardening::swift(500.0, 0.01, 0.22).unwrap(),
        )
    }

    /// Evaluates at `u / 2`, commits, evaluates at `u`: the second call starts from a
    /// history (plastic for the elastoplastic material).
    fn two_steps(
        el: &Hex8FBar,
        x: &[Vec3; 8],
        u: &[Vec3; 8],
        m: &dyn Material,
    ) -> (
        [PointState; POINTS],
        ElementResponse<DOFS>,
        [PointState; POINTS],
    ) {
        let half = u.map(|v| v * 0.5);
        let mut committed = [PointState::default(); POINTS];
        let mut trial = committed;
        el.evaluate(x, &half, &committed, &mut trial, m).unwrap();
        committed = trial;
        let resp = el.evaluate(x, u, &committed, &mut trial, m).unwrap();
        (committed, resp, trial)
    }

    /// The element stiffness against central differences of the internal force, F-bar and
    /// plain, Hencky-elastic and Hill48-plastic, on a distorted element at a large random
    /// displacement (strains ~0.2, rotations ~0.2 rad). Step 1e-7 (element size ~1):
    /// truncation ~1e-14, round-off ~1e-16 x |f| / 1e-7 ~ 1e-9 |K|; 1e-6 relative to the
    /// largest entry.
    #[test]
    fn stiffness_matches_central_differences_of_the_force() {
        let x = distorted_element();
        let mut rng = Lcg(11);
        let u: [Vec3; 8] = std::array::from_fn(|_| rng.vec() * 0.12);
        let elastic = LinearElastic::new(70e3, 0.33).unwrap();
        let plastic = hill_swift();
        let materials: [&dyn Material; 2] = [&elastic, &plastic];
        for fbar in [true, false] {
            let el = Hex8FBar { fbar };
            for (mi, m) in materials.iter().enumerate() {
                let (committed, resp, trial) = two_steps(&el, &x, &u, *m);
                if mi == 1 {
                    assert!(trial
                        .iter()
                        .zip(&committed)
                        .all(|(t, c)| t.eq_plastic_strain > c.eq_plastic_strain));
                }
                let scale = resp.stiffness.amax();
                let h = 1e-7;
                let mut worst: f64 = 0.0;
                for d in 0..DOFS {
                    let force_at = |delta: f64| {
                        let mut up = u;
                        up[d / 3][d % 3] += delta;
                        let mut t = committed;
                        el.evaluate(&x, &up, &committed, &mut t, *m).unwrap().force
                    };
                    let fd = (force_at(h) - force_at(-h)) / (2.0 * h);
                    worst = worst.max((fd - resp.stiffness.column(d)).amax() / scale);
                }
                assert!(worst < 1e-6, "fbar {fbar}, material {mi}: {worst:e}");
            }
        }
    }

    /// Rigid-body motions give no force, and under a homogeneous deformation F-bar changes
    /// nothing (F̄ = F): the force equals the plain element's, and both equal the exact
    /// ∫ P grad N for the uniform first Piola-Kirchhoff stress.
    #[test]
    fn rigid_motion_and_homogeneous_deformation() {
        let x = distorted_element();
        let m = LinearElastic::new(70e3, 0.33).unwrap();
        let r = nalgebra::Rotation3::from_euler_angles(0.4, -0.9, 1.3).into_inner();
        let u = x.map(|p| r * p + Vec3::new(0.3, -0.2, 0.1) - p);
        let (_, resp, _) = two_steps(&Hex8FBar::default(), &x, &u, &m);
        assert!(resp.force.amax() < 1e-8, "{}", resp.force.amax());
        // On a parallelepiped the centre gradients are the mean gradients, so the
        // pressure term ∫ p g⁰_a equals ∫ p g_a (on a distorted element they differ: the
        // centre is not the mean).
        let shape = Mat3::new(1.0, 0.2, 0.1, 0.0, 0.8, -0.1, 0.05, 0.0, 0.5);
        let x = crate::mesh::HEX_CORNERS.map(|c| shape * Vec3::new(c[0], c[1], c[2]));
        let f = Mat3::new(1.2, 0.1, 0.0, -0.05, 0.9, 0.1, 0.02, 0.0, 1.05);
        let u = x.map(|p| f * p - p);
        let (_, a, _) = two_steps(&Hex8FBar::default(), &x, &u, &m);
        let (_, b, _) = two_steps(&Hex8FBar { fbar: false }, &x, &u, &m);
        assert!((a.force - b.force).amax() < 1e-10 * a.force.amax());
        // Rigid rotation of the whole deformed body: the stiffness has 3 rotational and
        // 3 translational zero modes only at a stress-free state; here check the 3
        // translations, which are exact zero modes at any state.
        for k in 0..3 {
            let t = SVector::<f64, DOFS>::from_fn(|i, _| if i % 3 == k { 1.0 } else { 0.0 });
            assert!((a.stiffness * t).amax() < 1e-8 * a.stiffness.amax());
        }
    }
}
