//! Energy accounting of converged increments: work of tools, loads and supports by the
//! trapezoidal rule against the stored elastic energy and the plastic and frictional
//! dissipation.

use crate::geometry::Vec3;
use crate::solver::assembly::force_control;
use crate::solver::assembly::Evaluation;
use crate::solver::simulation::Simulation;

impl Simulation {
    /// Updates the energy balance with one converged increment: trapezoidal rule for the
    /// work of tools, loads, supports and for the frictional dissipation; the elastic energy
    /// is a state function.
    pub(super) fn account_energy(
        &mut self,
        t_new: f64,
        x: &[f64],
        eval: &Evaluation,
        tool_forces: &[[f64; 3]],
        dissipated: &[f64],
        normal_work: &[f64],
    ) -> EnergyBalance {
        let n_u = 3 * self.dofs.n_nodes;
        let e = &mut self.energy;
        let last = &self.energy_memory;
        for d in 0..n_u {
            let du = x[d] - self.x[d];
            e.support_work += 0.5 * (last.support_forces[d] + eval.support_forces[d]) * du;
            e.load_work += 0.5 * (last.external_forces[d] + eval.f_ext[d]) * du;
        }
        for c in 0..self.model.contacts.len() {
            let travel = force_control::pose(&self.model, &self.dofs, c, t_new, x).translation
                - force_control::pose(&self.model, &self.dofs, c, self.time, &self.x).translation;
            let force = Vec3::from(tool_forces[c]);
            // The body pushes the tool with +lambda, the tool the body with -lambda.
            e.tool_work -= 0.5 * (last.tool_forces[c] + force).dot(&travel);
            e.frictional_dissipation[c] += dissipated[c];
            // The tool's trapezoidal work credits a contact force over the whole
            // increment's travel; the part spent on the relative normal motion (a gap
            // closing within the increment) is not work done on the body.
            e.tool_work -= normal_work[c];
            e.normal_contact_work += normal_work[c];
        }
        // The element was checked when the simulation was set up.
        if let Ok(element) = self.model.element() {
            e.elastic_energy = crate::element::total_strain_energy(
                &self.model.mesh,
                element,
                &eval.trial_points,
                self.model.material.as_ref(),
            )
            .unwrap_or(f64::NAN);
            e.plastic_dissipation = crate::element::total_plastic_dissipation(
                &self.model.mesh,
                element,
                &eval.trial_points,
            )
            .unwrap_or(f64::NAN);
        }
        let input = e.tool_work + e.load_work + e.support_work;
        let stored: f64 =
            e.elastic_energy + e.plastic_dissipation + e.frictional_dissipation.iter().sum::<f64>();
        let scale =
            (e.tool_work.abs() + e.load_work.abs() + e.support_work.abs()).max(stored.abs());
        e.relative_error = if scale > 0.0 {
            (input - stored) / scale
        } else {
            0.0
        };
        self.energy_memory = EnergyMemory {
            support_forces: eval.support_forces.clone(),
            external_forces: eval.f_ext.clone(),
            tool_forces: tool_forces.iter().map(|f| Vec3::from(*f)).collect(),
        };
        e.clone()
    }
}

/// Energy bookkeeping of a run, cumulative from t = 0.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct EnergyBalance {
    /// Work done on the body by the tools' motion.
    pub tool_work: f64,
    /// Work of the applied loads.
    pub load_work: f64,
    /// Work of the supports at prescribed (non-zero) displacements.
    pub support_work: f64,
    /// Elastic energy stored in the body now.
    pub elastic_energy: f64,
    /// Plastic work dissipated in the body so far (trapezoidal per increment, see
    /// `PointState::plastic_dissipation`).
    pub plastic_dissipation: f64,
    /// Frictional dissipation per tool: sum over the contact nodes and increments of
    /// lambda_t . delta_t, the converged tangential force times the tangential slip
    /// increment (exactly zero for frictionless contact). The nodes' frictional work Psi
    /// (the friction law's variable) is the same product, each increment's term clipped
    /// at zero.
    pub frictional_dissipation: Vec<f64>,
    /// Work of the normal contact forces on the relative motion of the contact nodes and
    /// the tools, 1/2 (lambda_n + lambda_{n+1}) . delta - lambda_t . delta_t summed over
    /// nodes and increments: zero for the exact solution, picked up by the trapezoidal
    /// rule where a gap closes within an increment (and stored by penalty penetration).
    /// It is taken out of `tool_work` (not work done on the body), so it is not a term
    /// of the balance; reported to show the size of that correction.
    #[serde(default)]
    pub normal_contact_work: f64,
    /// (work in - stored - dissipated) / scale.
    pub relative_error: f64,
}

/// Forces at the end of the last increment, for the trapezoidal rule.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct EnergyMemory {
    pub(super) support_forces: Vec<f64>,
    pub(super) external_forces: Vec<f64>,
    pub(super) tool_forces: Vec<Vec3>,
}
