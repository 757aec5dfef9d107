//! A material point in homogeneous uniaxial stress, driven by strain: the driver of every
//! uniaxial check (a hardening curve, Lankford coefficients, a tension-compression cycle).
//!
//! Mathematics. Uniaxial stress of magnitude `s` along the unit vector `a` at `angle` to x
//! is `σ = s q` with `q = [c², s², 0, cs, 0, 0]` (Voigt, tensor shear): `q` also gives the
//! normal strain along `a` as `q·ε` (engineering shear), so one vector serves both. For each
//! target `e_k` the mixed problem `σ(ε) − s q = 0`, `q·ε − e_k = 0` in the seven unknowns
//! `(ε, s)` is solved by Newton with the material's consistent tangent `D = ∂σ/∂ε`:
//!
//! ```text
//! [ D   −q ] [Δε]     [σ(ε) − s q]
//! [ qᵀ   0 ] [Δs] = − [q·ε − e_k ]
//! ```
//!
//! All other stress components are zero at convergence (plane stress `σzz = 0` included).
//! With the consistent tangent the iteration converges quadratically; it stops at a stress
//! residual of 1e-10 relative to `max(|s|, 1)` and a strain residual of 1e-15, which is what
//! lets tests compare r-values and yield stresses to 1e-6. Cost: one 7 x 7 LU per iteration.

use super::{Material, PointState, Voigt};
use crate::{Error, Result};
use nalgebra::{SMatrix, SVector};

/// The direction vector `q = [c², s², 0, cs, 0, 0]` of uniaxial stress at `angle` (radians)
/// to x, in the x-y plane.
pub fn uniaxial_direction(angle: f64) -> Voigt {
    let (s, c) = angle.sin_cos();
    Voigt::new(c * c, s * s, 0.0, c * s, 0.0, 0.0)
}

/// Drives `material` from its initial state through the normal strains `targets` along `q`
/// (see the module doc) in uniaxial stress; returns the committed state after each target.
/// Errors: the material's update fails, or Newton does not converge in 40 iterations
/// (naming the target).
pub fn uniaxial_stress_path(
    material: &dyn Material,
    q: Voigt,
    targets: &[f64],
) -> Result<Vec<PointState>> {
    let mut committed = material.initial_state();
    let mut states = Vec::with_capacity(targets.len());
    for (k, &target) in targets.iter().enumerate() {
        committed = uniaxial_step(material, q, &committed, target).ok_or_else(|| {
            Error::input(
                &format!("uniaxial strain target {k}"),
                target,
                "was not reached in 40 Newton iterations",
            )
        })??;
        states.push(committed);
    }
    Ok(states)
}

/// One target of [`uniaxial_stress_path`]: `None` if Newton did not converge.
fn uniaxial_step(
    material: &dyn Material,
    q: Voigt,
    committed: &PointState,
    target: f64,
) -> Option<Result<PointState>> {
    let kin = super::Kinematics::from_strain;
    let (mut eps, mut s, mut trial) = (committed.strain, q.dot(&committed.stress), *committed);
    for _ in 0..40 {
        let d = match material.update(&kin(eps), committed, &mut trial) {
            Ok(d) => d,
            Err(e) => return Some(Err(e)),
        };
        let r_sig = trial.stress - q * s;
        let r_eps = q.dot(&eps) - target;
        if r_sig.amax() <= 1e-10 * s.abs().max(1.0) && r_eps.abs() < 1e-15 {
            return Some(Ok(trial));
        }
        let mut jac = SMatrix::<f64, 7, 7>::zeros();
        jac.fixed_view_mut::<6, 6>(0, 0).copy_from(&d);
        jac.fixed_view_mut::<6, 1>(0, 6).copy_from(&(-q));
        jac.fixed_view_mut::<1, 6>(6, 0).copy_from(&q.transpose());
        let rhs =
            -SVector::<f64, 7>::from_iterator(r_sig.iter().copied().chain(std::iter::once(r_eps)));
        let dx = jac.lu().solve(&rhs)?;
        eps += dx.fixed_rows::<6>(0);
        s += dx[6];
    }
    None
}
