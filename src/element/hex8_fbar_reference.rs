//! The F-bar hexahedron's original kernel (nalgebra 9 x 24 and 24 x 24 products), kept
//! verbatim as the reference that the tuned kernel of [`super::hex8_fbar`] is tested
//! against (same math, different order of operations: equal to round-off), and that the
//! element microbenchmark (`examples/bench_element.rs`) times as "before".

use nalgebra::{SMatrix, SVector};

use super::hex8::{checked_inputs, DOFS, NODES, POINTS};
use super::hex8_fbar::{
    centre_gradients, displacement_gradient, inverse_transpose, ln_det_one_plus, Hex8FBar, PAIRS,
};
use super::{prefix, ElementResponse};
use crate::geometry::{Mat3, Vec3};
use crate::material::{stress_to_tensor, Material, PointState};
use crate::Result;

/// Internal force and tangent of `el`, computed as before the kernel was restructured.
pub fn evaluate(
    el: &Hex8FBar,
    ref_coords: &[Vec3],
    u: &[Vec3],
    committed: &[PointState],
    trial: &mut [PointState],
    material: &dyn Material,
) -> Result<ElementResponse<DOFS>> {
    let (x, u, geo) = checked_inputs(ref_coords, u, committed, trial)?;
    let b0 = centre_gradients(&x)?;
    // The strain from the displacement gradient, as the tuned kernel (round-off of small
    // strains, see `material::log_strain`); the rest is the original kernel.
    let h0 = displacement_gradient(&u, &b0);
    let (f0_inv_t, _) =
        inverse_transpose(&(Mat3::identity() + h0), || "the element centre".into())?;
    let ln_j0 = ln_det_one_plus(&h0);
    let g0: [Vec3; NODES] = std::array::from_fn(|a| f0_inv_t * b0[a]);

    let mut force = SVector::<f64, DOFS>::zeros();
    let mut stiffness = SMatrix::<f64, DOFS, DOFS>::zeros();
    for gp in 0..POINTS {
        let b = &geo.grad[gp];
        let h = displacement_gradient(&u, b);
        let f = Mat3::identity() + h;
        let (f_inv_t, _) = {
            // As before: the place name is formatted at every point, failure or not.
            let what = format!("integration point {gp}");
            inverse_transpose(&f, || what.clone())
        }?;
        let g: [Vec3; NODES] = std::array::from_fn(|a| f_inv_t * b[a]);
        let (r_minus_one, q) = if el.fbar {
            let q =
                SVector::<f64, DOFS>::from_fn(|i, _| (g0[i / 3][i % 3] - g[i / 3][i % 3]) / 3.0);
            (((ln_j0 - ln_det_one_plus(&h)) / 3.0).exp_m1(), q)
        } else {
            (0.0, SVector::<f64, DOFS>::zeros())
        };
        let r = 1.0 + r_minus_one;
        let fb = f * r;
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
                if el.fbar {
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
        if el.fbar {
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
