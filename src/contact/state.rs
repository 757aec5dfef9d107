//! Per-node contact history, committed only when an increment converges.

use super::{ContactStatus, FrictionInput};
use crate::geometry::{SurfaceHint, Vec3};

/// The committed state of one (tool, node) contact pair.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct ContactNodeState {
    /// Contact multiplier: the force the node exerts on the tool (lambda_n <= 0 in contact).
    pub lambda: Vec3,
    /// The node's last converged position in the tool's own frame: moved with the tool, it
    /// is the slip reference point x_ref of the next increment.
    pub x_ref_local: Vec3,
    /// Previous foot point, to warm-start the projection.
    pub hint: Option<SurfaceHint>,
    pub status: ContactStatus,
    /// Signed normal gap at the last converged state.
    pub gap: f64,
    /// Outward tool normal at the last converged foot point.
    pub normal: Vec3,
    /// Accumulated frictional work Psi = sum lambda_t . delta_t (force x length).
    pub work: f64,
    /// Accumulated slip length sum |delta_t| over increments in contact.
    pub slip: f64,
    /// theta of a work-dependent law (0 for other laws).
    pub theta: f64,
    /// How many times the committed status switched between stick and slip.
    pub flips: usize,
    /// Friction coefficient to use in the next increment.
    pub mu: f64,
    /// Tangential slip delta_t of the last converged increment (zero out of contact); for
    /// output only.
    #[serde(default)]
    pub slip_increment: Vec3,
}

impl ContactNodeState {
    /// Normal component of the multiplier (<= 0 in contact).
    pub fn lambda_n(&self) -> f64 {
        self.lambda.dot(&self.normal)
    }

    /// Norm of the tangential multiplier.
    pub fn lambda_t_norm(&self) -> f64 {
        (self.lambda - self.normal * self.lambda_n()).norm()
    }

    /// What a friction law sees of this node, whose tributary area is `area`.
    pub fn friction_input(&self, area: f64) -> FrictionInput {
        FrictionInput {
            work: self.work,
            slip: self.slip,
            pressure: -self.lambda_n() / area.max(f64::MIN_POSITIVE),
            area,
        }
    }
}
