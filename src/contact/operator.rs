//! The nodal Alart-Curnier frictional-contact operator (paper eqs. 20-27) and its consistent
//! Jacobian, curvature terms included (eqs. 28-36, derived here in a compact form).
//!
//! Per contact node, with current position `x`, multiplier `lambda` (the force the node
//! exerts on the tool; `lambda_n <= 0` in contact), closest-point projection on the tool
//! (foot `p`, outward normal `n`, gap `d = n.(x - p)`, normal gradient `G = dn/dx`) and slip
//! reference point `x_ref`:
//!
//! ```text
//! delta   = x - x_ref,   delta_t = (I - n n^T) delta
//! g       = d n + delta_t
//! sigma   = lambda + r g,   sigma_n = sigma . n,   sigma_t = sigma - sigma_n n
//! gap   (sigma_n > 0):                     F_equi = 0
//! stick (|sigma_t| + mu sigma_n <= 0):     F_equi = sigma
//! slip  (otherwise):                       F_equi = sigma_n (n - mu t),  t = sigma_t/|sigma_t|
//! F_suppl = -(lambda - F_equi) / r         (eq. 23, all statuses)
//! ```
//!
//! Derivatives (with `dd/dx = n^T`, exact for a closest-point projection):
//!
//! ```text
//! dg/dx       = A = I + (d - n.delta) G - n delta^T G
//! dsigma/dx   = r A,                dsigma/dlambda = I
//! dsigma_n/dx = r n^T A + sigma^T G, dsigma_n/dlambda = n^T
//! dsigma_t    = dsigma - n dsigma_n - sigma_n G dx
//! dt          = (I - t t^T) dsigma_t / |sigma_t|
//! dF_equi(slip) = (n - mu t) dsigma_n + sigma_n G dx - mu sigma_n dt
//! ```
//!
//! The boundary cases go to contact: a node touching the tool with zero multiplier
//! (sigma = 0, e.g. a block resting on a plane before it is loaded) sticks, which gives
//! Newton a non-singular first iteration instead of a free rigid-body mode.
//!
//! Every term containing `G` is a curvature term; with `curvature = false` they are dropped
//! from the Jacobian (the residual keeps the exact geometry), which is what a code without
//! curvature terms does and what the studies compare against.
//!
//! Cost: a few dozen 3x3 products per node, O(1).

use crate::geometry::{Mat3, Projection, Vec3};

/// Contact status of one node, decided by the augmented multiplier.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum ContactStatus {
    #[default]
    Gap,
    Stick,
    Slip,
}

impl ContactStatus {
    /// Numeric code for output: 0 gap, 1 stick, 2 slip.
    pub fn code(self) -> f64 {
        match self {
            ContactStatus::Gap => 0.0,
            ContactStatus::Stick => 1.0,
            ContactStatus::Slip => 2.0,
        }
    }

    pub fn is_active(self) -> bool {
        self != ContactStatus::Gap
    }
}

/// Residual and Jacobian blocks of one contact node.
#[derive(Clone, Copy, Debug)]
pub struct NodalContact {
    pub status: ContactStatus,
    /// Contribution to the node's equilibrium equation.
    pub f_equi: Vec3,
    /// The supplementary (multiplier) equation.
    pub f_suppl: Vec3,
    /// dF_equi/dx, dF_equi/dlambda, dF_suppl/dx, dF_suppl/dlambda.
    pub equi_x: Mat3,
    pub equi_lambda: Mat3,
    pub suppl_x: Mat3,
    pub suppl_lambda: Mat3,
    /// Tangential slip increment delta_t at this state (for frictional work).
    pub slip_increment: Vec3,
    /// Tangential part of F_equi (the friction force on the tool): sigma_t in stick,
    /// -mu sigma_n t in slip, exactly zero for mu = 0 and in a gap (for frictional work).
    pub tangential_force: Vec3,
    /// The augmented multiplier and its linearisation, from which the status at a nearby
    /// state is predicted (`solver::status_prediction`); None where the node has no
    /// projection on the tool (it stays in gap).
    pub sigma_model: Option<SigmaModel>,
}

/// `sigma = lambda + r g` at the evaluated state and its first-order change,
/// `sigma + dsigma_x du + dlambda` (the normal held fixed), with the status law's mu and r.
#[derive(Clone, Copy, Debug, Default)]
pub struct SigmaModel {
    pub sigma: Vec3,
    pub dsigma_x: Mat3,
    pub normal: Vec3,
    pub mu: f64,
    pub r: f64,
}

impl SigmaModel {
    /// The exact operator's status at `sigma + dsigma_x du + dlambda`: what the node's
    /// status becomes after the Newton step (du, dlambda) if the operator were linear.
    /// A change from `current` counts only beyond `APEX_BAND r` of the boundary crossed
    /// (round-off-sized moves, e.g. of a node touching with a zero multiplier, keep the
    /// status: the prediction must not depend on the linear solver's round-off).
    pub fn predicted_status(
        &self,
        du: &Vec3,
        dlambda: &Vec3,
        current: ContactStatus,
    ) -> ContactStatus {
        let s = self.sigma + self.dsigma_x * du + dlambda;
        let predicted = status_of(&s, &self.normal, self.mu);
        let sigma_n = s.dot(&self.normal);
        let cone = (s - self.normal * sigma_n).norm() + self.mu * sigma_n;
        let band = APEX_BAND * self.r;
        let clear = match (current, predicted) {
            (a, b) if a == b => true,
            (ContactStatus::Gap, _) | (_, ContactStatus::Gap) => sigma_n.abs() > band,
            _ => cone.abs() > band,
        };
        if clear {
            predicted
        } else {
            current
        }
    }
}

/// Gap when sigma_n > 0, stick inside the Coulomb cone, slip outside.
fn status_of(sigma: &Vec3, n: &Vec3, mu: f64) -> ContactStatus {
    let sigma_n = sigma.dot(n);
    let sigma_t = sigma - n * sigma_n;
    if sigma_n > 0.0 {
        ContactStatus::Gap
    } else if sigma_t.norm() + mu * sigma_n <= 0.0 {
        ContactStatus::Stick
    } else {
        ContactStatus::Slip
    }
}

/// Inputs of the nodal operator besides the geometry.
#[derive(Clone, Copy, Debug)]
pub struct OperatorParams {
    /// Augmentation parameter r > 0 (a stiffness, force/length).
    pub r: f64,
    /// Friction coefficient, held fixed during the increment.
    pub mu: f64,
    /// Include the normal-gradient (curvature) terms in the Jacobian.
    pub curvature: bool,
    /// Gradient of mu with respect to x and lambda when mu depends on the increment's own
    /// frictional work (implicit friction update); zero otherwise.
    pub dmu_dx: Vec3,
    pub dmu_dlambda: Vec3,
    /// Status imposed instead of the one the augmented multiplier selects (anti-cycling,
    /// see `solver::cycling`); a forced slip with a vanishing tangential trial force falls
    /// back to stick, whose force is then the same.
    pub forced: Option<ContactStatus>,
}

impl OperatorParams {
    /// Parameters with mu held fixed during the increment.
    pub fn fixed_mu(r: f64, mu: f64, curvature: bool) -> Self {
        OperatorParams {
            r,
            mu,
            curvature,
            dmu_dx: Vec3::zeros(),
            dmu_dlambda: Vec3::zeros(),
            forced: None,
        }
    }
}

/// |sigma| / r (a length) below which a node sits at the apex of the Coulomb cone: the
/// default contact tolerance, so that only gaps and multipliers at round-off level count.
const APEX_BAND: f64 = 1e-9;

/// Evaluates the operator at `x`, `lambda` for the projection `proj` of `x` on the tool.
pub fn alart_curnier(
    x: &Vec3,
    x_ref: &Vec3,
    lambda: &Vec3,
    proj: &Projection,
    params: &OperatorParams,
) -> NodalContact {
    let OperatorParams {
        r, mu, curvature, ..
    } = *params;
    let n = proj.normal;
    let d = proj.gap;
    let g_mat = if curvature {
        proj.normal_gradient
    } else {
        Mat3::zeros()
    };
    let ident = Mat3::identity();
    let nn = n * n.transpose();

    let delta = x - x_ref;
    let delta_t = delta - n * n.dot(&delta);
    let g = n * d + delta_t;
    let sigma = lambda + g * r;
    let sigma_n = sigma.dot(&n);
    let sigma_t = sigma - n * sigma_n;

    let a = ident + g_mat * (d - n.dot(&delta)) - n * (delta.transpose() * g_mat);
    let dsigma_x = a * r;
    let dsigma_n_x = n.transpose() * dsigma_x + sigma.transpose() * g_mat;

    let natural = status_of(&sigma, &n, mu);
    let chosen = match params.forced {
        Some(ContactStatus::Slip) if sigma_t.norm() == 0.0 => ContactStatus::Stick,
        Some(s) => s,
        None => natural,
    };
    let (status, f_equi, equi_x, equi_lambda, tangential_force) = if chosen == ContactStatus::Gap {
        (
            ContactStatus::Gap,
            Vec3::zeros(),
            Mat3::zeros(),
            Mat3::zeros(),
            Vec3::zeros(),
        )
    } else if chosen == ContactStatus::Stick {
        (ContactStatus::Stick, sigma, dsigma_x, ident, sigma_t)
    } else {
        let st_norm = sigma_t.norm();
        let t = sigma_t / st_norm;
        let dsigma_t_x = dsigma_x - n * dsigma_n_x - g_mat * sigma_n;
        let dsigma_t_l = ident - nn;
        let proj_t = (ident - t * t.transpose()) / st_norm;
        let dt_x = proj_t * dsigma_t_x;
        let dt_l = proj_t * dsigma_t_l;
        let n_mu_t = n - t * mu;
        let f = n_mu_t * sigma_n;
        // With an implicit friction update mu itself varies: - sigma_n t (dmu)^T.
        let fx = n_mu_t * dsigma_n_x + g_mat * sigma_n
            - dt_x * (mu * sigma_n)
            - t * params.dmu_dx.transpose() * sigma_n;
        let fl = n_mu_t * n.transpose()
            - dt_l * (mu * sigma_n)
            - t * params.dmu_dlambda.transpose() * sigma_n;
        (ContactStatus::Slip, f, fx, fl, -t * (mu * sigma_n))
    };

    // At the apex of the cone (a node touching with a zero multiplier, |sigma| within
    // round-off of zero) gap, stick and slip meet and their Jacobians differ wildly: stick
    // glues the node to the tool in all three directions, gap frees it. A barely touching
    // node then flips between them from one iterate to the next. The frictionless normal
    // element n (n^T dsigma), which lies in the convex hull of the slip Jacobians there, says
    // "may press, may slide": the residual (hence the solution) is unchanged.
    let apex = params.forced.is_none() && sigma.norm() <= APEX_BAND * r;
    let (equi_x, equi_lambda) = if apex {
        (n * dsigma_n_x, nn)
    } else {
        (equi_x, equi_lambda)
    };

    NodalContact {
        status,
        f_equi,
        f_suppl: (f_equi - lambda) / r,
        equi_x,
        equi_lambda,
        suppl_x: equi_x / r,
        suppl_lambda: (equi_lambda - ident) / r,
        slip_increment: delta_t,
        tangential_force,
        sigma_model: Some(SigmaModel {
            sigma,
            dsigma_x,
            normal: n,
            mu,
            r,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Projection, SurfaceHint};
    // The finite-difference check of the Jacobian in every status, on a plane, a cylinder
    // and a sphere, is tests/contact_jacobian.rs.

    #[test]
    fn a_node_touching_with_zero_multiplier_gets_the_frictionless_normal_jacobian() {
        // Zero gap, zero multiplier, no motion: sigma = 0, the apex of the cone. The force is
        // zero whatever the status; the Jacobian constrains the normal direction only.
        let n = Vec3::new(0.0, 0.6, 0.8);
        let proj = Projection {
            foot: Vec3::new(1.0, 2.0, 3.0),
            normal: n,
            gap: 0.0,
            normal_gradient: Mat3::zeros(),
            hint: SurfaceHint::default(),
        };
        let x = Vec3::new(1.0, 2.0, 3.0);
        let p = OperatorParams::fixed_mu(10.0, 0.3, false);
        let res = alart_curnier(&x, &x, &Vec3::zeros(), &proj, &p);
        assert_eq!(res.f_equi, Vec3::zeros());
        let nn = n * n.transpose();
        assert!((res.equi_lambda - nn).norm() < 1e-15);
        assert!((res.equi_x - nn * 10.0).norm() < 1e-13);
        // Away from the apex (a multiplier of 1e-3 N) the operator is the usual one.
        let res = alart_curnier(&x, &x, &(n * -1e-3), &proj, &p);
        assert_eq!(res.status, ContactStatus::Stick);
        assert!((res.equi_lambda - Mat3::identity()).norm() < 1e-15);
    }

    #[test]
    fn predicted_status_is_the_status_after_the_step_on_a_plane() {
        // On a plane without curvature sigma is affine in (x, lambda): the first-order model
        // is exact, so the predicted status is the operator's status at the stepped state.
        let proj = |x: &Vec3| Projection {
            foot: Vec3::new(x[0], x[1], 0.0),
            normal: Vec3::z(),
            gap: x[2],
            normal_gradient: Mat3::zeros(),
            hint: SurfaceHint::default(),
        };
        let p = OperatorParams::fixed_mu(100.0, 0.3, false);
        let x_ref = Vec3::zeros();
        let start = [
            (Vec3::new(0.0, 0.0, 0.01), Vec3::zeros()),
            (Vec3::new(0.001, 0.0, -0.01), Vec3::new(0.0, 0.0, -5.0)),
            (Vec3::new(0.05, 0.0, -0.01), Vec3::new(1.0, 0.0, -5.0)),
        ];
        let steps = [
            (Vec3::new(0.0, 0.0, -0.03), Vec3::zeros()),
            (Vec3::new(0.04, -0.02, 0.0), Vec3::new(0.0, 0.5, 0.0)),
            (Vec3::new(0.0, 0.0, 0.03), Vec3::new(0.0, 0.0, 4.0)),
            (Vec3::new(-0.05, 0.0, 0.0), Vec3::new(-1.0, 0.0, 0.0)),
        ];
        let mut changed = 0;
        for (x, l) in start {
            let here = alart_curnier(&x, &x_ref, &l, &proj(&x), &p);
            let model = here.sigma_model.expect("a projection");
            for (du, dl) in steps {
                let (xs, ls) = (x + du, l + dl);
                let there = alart_curnier(&xs, &x_ref, &ls, &proj(&xs), &p);
                assert_eq!(model.predicted_status(&du, &dl, here.status), there.status);
                changed += usize::from(there.status != here.status);
            }
            // A round-off-sized move keeps the status, whatever side it lands on.
            let at_apex = alart_curnier(&x_ref, &x_ref, &Vec3::zeros(), &proj(&x_ref), &p);
            let m = at_apex.sigma_model.unwrap();
            let tiny = Vec3::new(0.0, 0.0, 1e-14);
            assert_eq!(
                m.predicted_status(&tiny, &Vec3::zeros(), at_apex.status),
                at_apex.status
            );
        }
        assert!(
            changed >= 6,
            "the steps cross status boundaries ({changed})"
        );
    }

    #[test]
    fn converged_slip_state_satisfies_coulomb() {
        // At a root of F_suppl in slip: lambda = F_equi, |lambda_t| = -mu lambda_n.
        let n = Vec3::z();
        let proj = Projection {
            foot: Vec3::zeros(),
            normal: n,
            gap: 0.0,
            normal_gradient: Mat3::zeros(),
            hint: SurfaceHint::default(),
        };
        let p = OperatorParams::fixed_mu(10.0, 0.25, true);
        let lambda = Vec3::new(0.25 * 4.0, 0.0, -4.0);
        let x = Vec3::new(0.3, 0.0, 0.0);
        let res = alart_curnier(&x, &Vec3::zeros(), &lambda, &proj, &p);
        assert_eq!(res.status, ContactStatus::Slip);
        assert!(res.f_suppl.norm() < 1e-14);
        assert!((res.f_equi - lambda).norm() < 1e-14);
    }
}
