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
//!
//! # Kernel
//!
//! The same tangent, grouped so that nothing larger than `24 x 9` is formed per point.
//! With `B` the `9 x 24` matrix of `∂F/∂u` (column `(a, k)` is `e_k ⊗ b_a`: three
//! non-zeros) and `f` = `F` as a 9-vector, `G = r (B + f qᵀ)`, so
//!
//! ```text
//! Gᵀ 𝔸 G = r² [ Bᵀ𝔸B + (Bᵀ𝔸f) qᵀ + q (fᵀ𝔸B) + (fᵀ𝔸f) q qᵀ ],
//! K/dV₀  = r² Bᵀ𝔸B + α qᵀ + q βᵀ + (r P̄:F / 3)(g_a,l g_c,k - g⁰_a,l g⁰_c,k),
//! α = r² Bᵀ𝔸f + r w,     β = r² (fᵀ𝔸B)ᵀ + r w + (r² fᵀ𝔸f + r P̄:F) q,
//! ```
//!
//! `Bᵀ𝔸B` through `Z = Bᵀ𝔸` (`24 x 9`, three products per entry) and then three more
//! per stiffness entry. Per point: ~0.8k multiplications for `𝔸`, ~0.6k for `Z`, ~5k for
//! the `576` entries (against ~8k and four `24 x 24` temporaries in the plain
//! `Gᵀ (𝔸 G)` form). The force is `f_a = r (w_a + q_a P̄:F)`.

use super::hex8::{
    checked_inputs, cleared_outputs, jacobian, response_through_into, shape_derivatives, DOFS,
    NODES, POINTS,
};
use super::{prefix, Element, ElementResponse, Hex8};
use crate::geometry::{Mat3, Vec3};
use crate::material::{stress_to_tensor, Material, PointState, Tangent};
use crate::{Error, Result};

/// Voigt index pairs `[xx, yy, zz, xy, yz, zx]`.
pub(super) const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)];

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
pub(super) fn displacement_gradient(u: &[Vec3; NODES], b: &[Vec3; NODES]) -> Mat3 {
    (0..NODES).fold(Mat3::zeros(), |h, a| h + u[a] * b[a].transpose())
}

/// `ln det(I + h)` from `det(I + h) - 1 = tr h + ½((tr h)² - tr h²) + det h`, to the
/// relative precision of `h` (no cancellation against 1). `det(I + h) > 0` is the caller's.
pub(super) fn ln_det_one_plus(h: &Mat3) -> f64 {
    let tr = h.trace();
    (tr + 0.5 * (tr * tr - (h * h).trace()) + h.determinant()).ln_1p()
}

/// Inverse-transpose of a deformation gradient with a positive determinant; `what` names
/// the place for the error (built only on failure).
pub(super) fn inverse_transpose(f: &Mat3, what: impl Fn() -> String) -> Result<(Mat3, f64)> {
    let det = f.determinant();
    match f.try_inverse() {
        Some(inv) if det > 0.0 && det.is_finite() => Ok((inv.transpose(), det)),
        _ => Err(Error::no_convergence(
            crate::error::Failure::Local,
            format!("det F = {det} at {} (element turned inside out)", what()),
        )),
    }
}

/// Centre gradients `b⁰_a` of the reference element.
pub(super) fn centre_gradients(x: &[Vec3; NODES]) -> Result<[Vec3; NODES]> {
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

/// What the tangent of one integration point needs (see the module docs, "Kernel").
struct PointKernel<'a> {
    fb: &'a Mat3,
    f: &'a Mat3,
    s: &'a Mat3,
    c: &'a Tangent,
    b: &'a [Vec3; NODES],
    g: &'a [Vec3; NODES],
    g0: &'a [Vec3; NODES],
    r: f64,
    q: &'a [f64; DOFS],
    w: &'a [f64; DOFS],
    pf: f64,
    fbar: bool,
}

impl PointKernel<'_> {
    /// Adds `dv` times the point's tangent to the column-major `k`.
    ///
    /// The build targets baseline x86-64 (two-lane SSE2); where the processor has AVX2
    /// the same code runs compiled for it (four lanes), chosen at run time. Only the
    /// instruction width changes: the same products and sums in the same order (no fused
    /// multiply-add, which would round differently), so both give the same bits.
    fn add_to(&self, k: &mut [f64; DOFS * DOFS], dv: f64) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2 (checked just above).
            unsafe { self.add_to_avx2(k, dv) };
            return;
        }
        self.add_to_portable(k, dv);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn add_to_avx2(&self, k: &mut [f64; DOFS * DOFS], dv: f64) {
        self.add_to_portable(k, dv);
    }

    #[inline(always)]
    fn add_to_portable(&self, k: &mut [f64; DOFS * DOFS], dv: f64) {
        let (fb, b, r) = (self.fb, self.b, self.r);
        // M = ∂Ē_GL/∂F̄ (6 x 9, row-major 9-vectors of F̄).
        let mut m = [[0.0; 9]; 6];
        for (v, &(ii, jj)) in PAIRS.iter().enumerate() {
            for i in 0..3 {
                if ii == jj {
                    m[v][3 * i + ii] += fb[(i, ii)];
                } else {
                    m[v][3 * i + jj] += fb[(i, ii)];
                    m[v][3 * i + ii] += fb[(i, jj)];
                }
            }
        }
        // 𝔸 = Mᵀ ℂ M + I ⊗ S̄ (9 x 9).
        let mut cm = [[0.0; 9]; 6];
        for (v, row) in cm.iter_mut().enumerate() {
            for (col, out) in row.iter_mut().enumerate() {
                *out = (0..6).map(|t| self.c[(v, t)] * m[t][col]).sum();
            }
        }
        let mut a9 = [[0.0; 9]; 9];
        for (row, out) in a9.iter_mut().enumerate() {
            for (col, o) in out.iter_mut().enumerate() {
                *o = (0..6).map(|v| m[v][row] * cm[v][col]).sum();
            }
        }
        for i in 0..3 {
            for jj in 0..3 {
                for l in 0..3 {
                    a9[3 * i + jj][3 * i + l] += self.s[(l, jj)];
                }
            }
        }
        // Z = Bᵀ 𝔸 (24 x 9), B = ∂F/∂u: column (a, k) is e_k ⊗ b_a. Stored transposed
        // (`zt[col][row]`), so that the loops over the 24 rows of a stiffness column below
        // run over contiguous memory and vectorise.
        let mut zt = [[0.0; DOFS]; 9];
        for a in 0..NODES {
            for kk in 0..3 {
                let row = &a9[3 * kk..3 * kk + 3];
                for (col, out) in zt.iter_mut().enumerate() {
                    out[3 * a + kk] =
                        b[a][0] * row[0][col] + b[a][1] * row[1][col] + b[a][2] * row[2][col];
                }
            }
        }
        let r2dv = r * r * dv;
        if !self.fbar {
            for c in 0..NODES {
                for l in 0..3 {
                    let col = &mut k[(3 * c + l) * DOFS..(3 * c + l + 1) * DOFS];
                    let (z0, z1, z2) = (&zt[3 * l], &zt[3 * l + 1], &zt[3 * l + 2]);
                    for i in 0..DOFS {
                        let bb = z0[i] * b[c][0] + z1[i] * b[c][1] + z2[i] * b[c][2];
                        col[i] += r2dv * bb;
                    }
                }
            }
            return;
        }
        // G = r (B + f qᵀ) with f = F as a 9-vector: the rank-2 terms of Gᵀ 𝔸 G and of
        // P̄ : ∂²F̄ combine into α qᵀ + q βᵀ (module docs).
        let (q, w, pf) = (self.q, self.w, self.pf);
        let f9: [f64; 9] = std::array::from_fn(|i| self.f[(i / 3, i % 3)]);
        let af: [f64; 9] = std::array::from_fn(|i| (0..9).map(|j| a9[i][j] * f9[j]).sum());
        let fa: [f64; 9] = std::array::from_fn(|j| (0..9).map(|i| f9[i] * a9[i][j]).sum());
        let phi: f64 = (0..9).map(|i| f9[i] * af[i]).sum();
        let r2 = r * r;
        let alpha: [f64; DOFS] = std::array::from_fn(|i| {
            let (a, kk) = (i / 3, i % 3);
            let v1 = b[a][0] * af[3 * kk] + b[a][1] * af[3 * kk + 1] + b[a][2] * af[3 * kk + 2];
            (r2 * v1 + r * w[i]) * dv
        });
        let beta: [f64; DOFS] = std::array::from_fn(|i| {
            let (c, l) = (i / 3, i % 3);
            let v2 = fa[3 * l] * b[c][0] + fa[3 * l + 1] * b[c][1] + fa[3 * l + 2] * b[c][2];
            (r2 * v2 + r * w[i] + (r2 * phi + r * pf) * q[i]) * dv
        });
        let h = r * pf / 3.0 * dv;
        let (g, g0) = (self.g, self.g0);
        // The H term of entry (i, j) = ((a, kk), (c, l)) is `h g_a,l g_c,kk - h g⁰_a,l g⁰_c,kk`:
        // per column, two products of 24-vectors, `hg[l][i] = h g_a,l` and
        // `gc[c][i] = g_c,kk` (the same products in the same order as entry by entry).
        let hg: [[f64; DOFS]; 3] =
            std::array::from_fn(|l| std::array::from_fn(|i| h * g[i / 3][l]));
        let hg0: [[f64; DOFS]; 3] =
            std::array::from_fn(|l| std::array::from_fn(|i| h * g0[i / 3][l]));
        for c in 0..NODES {
            let gc: [f64; DOFS] = std::array::from_fn(|i| g[c][i % 3]);
            let g0c: [f64; DOFS] = std::array::from_fn(|i| g0[c][i % 3]);
            for l in 0..3 {
                let j = 3 * c + l;
                let col = &mut k[j * DOFS..(j + 1) * DOFS];
                let (qj, bj) = (q[j], beta[j]);
                let (z0, z1, z2) = (&zt[3 * l], &zt[3 * l + 1], &zt[3 * l + 2]);
                let (hgl, hg0l) = (&hg[l], &hg0[l]);
                for i in 0..DOFS {
                    let bb = z0[i] * b[c][0] + z1[i] * b[c][1] + z2[i] * b[c][2];
                    col[i] +=
                        r2dv * bb + alpha[i] * qj + q[i] * bj + (hgl[i] * gc[i] - hg0l[i] * g0c[i]);
                }
            }
        }
    }
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
        response_through_into(self, ref_coords, u, committed, trial, material)
    }

    /// The kernel (module docs, "Kernel"): fixed-size stack arrays, the force and the
    /// tangent accumulated straight into the caller's buffers; no tangent work at all for a
    /// residual-only call (`stiffness = None`).
    fn evaluate_into(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
        force: &mut [f64],
        stiffness: Option<&mut [f64]>,
    ) -> Result<()> {
        let (force, mut stiffness) = cleared_outputs(force, stiffness)?;
        let (x, u, geo) = checked_inputs(ref_coords, u, committed, trial)?;
        let b0 = centre_gradients(&x)?;
        let h0 = displacement_gradient(&u, &b0);
        let (f0_inv_t, _) =
            inverse_transpose(&(Mat3::identity() + h0), || "the element centre".into())?;
        let ln_j0 = ln_det_one_plus(&h0);
        let g0: [Vec3; NODES] = std::array::from_fn(|a| f0_inv_t * b0[a]);
        for gp in 0..POINTS {
            let b = &geo.grad[gp];
            let h = displacement_gradient(&u, b);
            let f = Mat3::identity() + h;
            let (f_inv_t, _) = inverse_transpose(&f, || format!("integration point {gp}"))?;
            let g: [Vec3; NODES] = std::array::from_fn(|a| f_inv_t * b[a]);
            let mut q = [0.0; DOFS];
            // r - 1 = expm1(⅓ ln(J₀/J)), kept to the precision of the strains.
            let r_minus_one = if self.fbar {
                for a in 0..NODES {
                    for k in 0..3 {
                        q[3 * a + k] = (g0[a][k] - g[a][k]) / 3.0;
                    }
                }
                ((ln_j0 - ln_det_one_plus(&h)) / 3.0).exp_m1()
            } else {
                0.0
            };
            let r = 1.0 + r_minus_one;
            let fb = f * r;
            // F̄ - I = (r - 1) I + r H.
            let hb = Mat3::identity() * r_minus_one + h * r;
            let at_point = |e| prefix(e, &format!("integration point {gp}"));
            // Residual only: the material's stress part alone (the same stress, bit for bit).
            let (pk2, c) = if stiffness.is_some() {
                let resp = material
                    .update_finite_displacement_gradient(&hb, &committed[gp], &mut trial[gp])
                    .map_err(at_point)?;
                (resp.pk2, resp.tangent)
            } else {
                let pk2 = material
                    .update_finite_stress(&hb, &committed[gp], &mut trial[gp])
                    .map_err(at_point)?;
                (pk2, Tangent::zeros())
            };
            let s = stress_to_tensor(&pk2);
            let p = fb * s;
            let pf = p.component_mul(&f).sum();
            let w: [f64; DOFS] = std::array::from_fn(|i| (p * b[i / 3])[i % 3]);
            let dv = geo.dvol[gp];
            for i in 0..DOFS {
                force[i] += r * (w[i] + q[i] * pf) * dv;
            }
            if let Some(k) = stiffness.as_deref_mut() {
                let kernel = PointKernel {
                    fb: &fb,
                    f: &f,
                    s: &s,
                    c: &c,
                    b,
                    g: &g,
                    g0: &g0,
                    r,
                    q: &q,
                    w: &w,
                    pf,
                    fbar: self.fbar,
                };
                kernel.add_to(k, dv);
            }
        }
        Ok(())
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
    use nalgebra::SVector;

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

    /// The tuned kernel against the original one (`hex8_fbar_reference`), F-bar and plain,
    /// elastic and plastic, on a distorted element at a large random displacement, after a
    /// committed half step: same math in another order, so equal to round-off. 1e-13
    /// relative to the largest entry (the sums have ~100 terms of mixed sign: ~1e-15 each).
    #[test]
    fn kernel_equals_the_reference_kernel() {
        let x = distorted_element();
        let elastic = LinearElastic::new(70e3, 0.33).unwrap();
        let plastic = hill_swift();
        let materials: [&dyn Material; 2] = [&elastic, &plastic];
        for seed in [11, 12, 13] {
            let mut rng = Lcg(seed);
            let u: [Vec3; 8] = std::array::from_fn(|_| rng.vec() * 0.12);
            for fbar in [true, false] {
                let el = Hex8FBar { fbar };
                for (mi, m) in materials.iter().enumerate() {
                    let (committed, new, new_trial) = two_steps(&el, &x, &u, *m);
                    let mut old_trial = committed;
                    let old = super::super::hex8_fbar_reference::evaluate(
                        &el,
                        &x,
                        &u,
                        &committed,
                        &mut old_trial,
                        *m,
                    )
                    .unwrap();
                    let df = (new.force - old.force).amax() / old.force.amax();
                    let dk = (new.stiffness - old.stiffness).amax() / old.stiffness.amax();
                    assert!(
                        df < 1e-13,
                        "seed {seed} fbar {fbar} material {mi}: force {df:e}"
                    );
                    assert!(
                        dk < 1e-13,
                        "seed {seed} fbar {fbar} material {mi}: tangent {dk:e}"
                    );
                    assert_eq!(new_trial, old_trial, "the point states are the same");
                    if mi == 1 {
                        assert!(new_trial.iter().all(|t| t.eq_plastic_strain > 0.0));
                    }
                }
            }
        }
    }

    /// A residual-only call writes the same force (bit for bit) and the same states as a
    /// call with the tangent; wrong buffer lengths are input errors, not panics.
    #[test]
    fn residual_only_call_gives_the_same_force() {
        let x = distorted_element();
        let mut rng = Lcg(5);
        let u: [Vec3; 8] = std::array::from_fn(|_| rng.vec() * 0.1);
        let m = hill_swift();
        let el = Hex8FBar::default();
        let committed = [PointState::default(); POINTS];
        let (mut t1, mut t2) = (committed, committed);
        let full = el.evaluate(&x, &u, &committed, &mut t1, &m).unwrap();
        let mut force = [7.0; DOFS];
        el.evaluate_into(&x, &u, &committed, &mut t2, &m, &mut force, None)
            .unwrap();
        assert_eq!(force.as_slice(), full.force.as_slice());
        assert_eq!(t1, t2);
        let mut short = [0.0; DOFS - 1];
        let err = el
            .evaluate_into(&x, &u, &committed, &mut t2, &m, &mut short, None)
            .unwrap_err();
        assert!(err.to_string().contains("length of force"), "{err}");
        let mut k = vec![0.0; DOFS * DOFS - 3];
        let err = el
            .evaluate_into(&x, &u, &committed, &mut t2, &m, &mut force, Some(&mut k))
            .unwrap_err();
        assert!(err.to_string().contains("length of stiffness"), "{err}");
    }
}
