//! Force control of tools: for each force-controlled tool one scalar unknown `s` (the
//! tool's offset along its unit axis `a`) is appended to the unknown vector after the
//! displacements and multipliers, and one equation fixes the tool's force.
//!
//! Pose: `T(t, s) = T_sched(t) + s a`. Every quantity of a contact node against the tool
//! (projection, gap, slip reference `x_ref = T + x_ref_local`) depends on the node position
//! `x` only through `x - T`, so the derivatives with respect to `s` are exact copies of the
//! position derivatives:
//!
//! ```text
//! d F_equi  / ds = -(dF_equi/dx) a,      d F_suppl / ds = -(dF_suppl/dx) a
//! ```
//!
//! Equation of the tool (the force the tool applies to the body along `a` equals the
//! schedule; the body pushes the tool with `+lambda`, see `Simulation::tool_force`):
//!
//! ```text
//! R_s = ( -a . sum_k lambda_k - F(t) ) / r_s,     dR_s/dlambda_k = -a^T / r_s
//! ```
//!
//! The multipliers rather than the `F_equi` are summed: both agree at convergence
//! (`F_suppl = 0`) and the multipliers make the row linear. Dividing by `r_s`, the mean
//! augmentation parameter of the tool's nodes, makes `R_s` a length like the other
//! multiplier rows, so the Newton contact tolerance covers it: at convergence the force
//! error is at most `r_s * contact_tol`.
//!
//! A tool touching no node leaves `s` undetermined (the column of `s` is zero). Then the
//! row is replaced by the approach equation `s - s_now = min_k d_k / (n_k . a)`: one Newton
//! step brings the tool into touch with the nearest node along its axis, which then counts
//! as sticking with zero multiplier (the operator's boundary rule) and the force equation
//! takes over. If no node lies ahead along the axis the solve stops with an error naming
//! the tool.
//!
//! Outside the windows of its force control (a step where the tool is kinematic again,
//! `tool::ForceControl::windows`) the row holds the offset: `R_s = s - s_committed`, so
//! the tool follows its schedule shifted by the offset it had.
//!
//! The multipliers of a force-controlled tool are condensed out like the others (see
//! `condense`): each node's multiplier equations still give `dl = rhs1 - K_a du` (the `s`
//! terms cancel in `R1 - r R2` because `dF_suppl/ds = (dF_equi/ds) / r`), and the force row
//! receives that substitution.

use crate::contact::{Enforcement, NodalContact};
use crate::geometry::{Projection, Vec3};
use crate::solver::assembly::dofs::DofMap;
use crate::solver::assembly::slots::ForceControlSlots;
use crate::solver::model::Model;
use crate::tool::Pose;
use crate::{Error, Result};

/// Refuses force control where it cannot work (penalty has no multiplier unknowns).
pub fn check(model: &Model) -> Result<()> {
    for c in &model.contacts {
        if c.tool.force_control.is_some()
            && model.settings.contact.enforcement == Enforcement::Penalty
        {
            return Err(Error::Input(format!(
                "tool '{}' is force-controlled, which needs the augmented Lagrangian enforcement (not penalty)",
                c.tool.name
            )));
        }
    }
    Ok(())
}

/// The offset `s` of tool `c` in the unknowns `x` (0 for a kinematic tool).
pub fn offset(dofs: &DofMap, c: usize, x: &[f64]) -> f64 {
    dofs.tool_offset[c].map_or(0.0, |d| x[d])
}

/// `scheduled` moved by the offset of tool `c` in `x`.
pub fn shifted(scheduled: &Pose, model: &Model, dofs: &DofMap, c: usize, x: &[f64]) -> Pose {
    match &model.contacts[c].tool.force_control {
        Some(fc) => {
            // The offset moves the tool along its axis; a scheduled rotation stays.
            let mut pose = *scheduled;
            pose.translation += fc.axis * offset(dofs, c, x);
            pose
        }
        None => *scheduled,
    }
}

/// The pose of tool `c` at time `t` for the unknowns `x`.
pub fn pose(model: &Model, dofs: &DofMap, c: usize, t: f64, x: &[f64]) -> Pose {
    shifted(&model.contacts[c].tool.pose(t), model, dofs, c, x)
}

/// Adds the `s` column of one candidate of force-controlled tool `c` at its precomputed
/// positions `column` (see `ForceControlSlots`): `values[column[i]] += -(∂r/∂x · axis)_i`.
pub fn add_node_column(
    values: &mut [f64],
    model: &Model,
    c: usize,
    column: &[usize; 6],
    result: &NodalContact,
) {
    let Some(fc) = &model.contacts[c].tool.force_control else {
        return;
    };
    let equi = -(result.equi_x * fc.axis);
    let suppl = -(result.suppl_x * fc.axis);
    for i in 0..3 {
        values[column[i]] += equi[i];
        values[column[3 + i]] += suppl[i];
    }
}

/// Whether tool `c` is force-controlled at `time` and touches no node in `nodal`: its row
/// is then the approach equation, not the force equation.
pub fn approaching(
    model: &Model,
    c: usize,
    time: f64,
    nodal: &[Vec<(NodalContact, Option<Projection>)>],
) -> bool {
    active(model, c, time) && !nodal[c].iter().any(|(r, _)| r.status.is_active())
}

/// Whether tool `c` is force-controlled at `time` (not held between its windows).
pub fn active(model: &Model, c: usize, time: f64) -> bool {
    model.contacts[c]
        .tool
        .force_control
        .as_ref()
        .is_some_and(|fc| fc.active_at(time))
}

/// Approach: the smallest travel of force-controlled tool `c` along its axis that closes
/// a gap (the offset change that brings it into touch with the nearest node ahead of it),
/// `None` if no node lies ahead or the tool is not force-controlled. O(candidates).
pub fn approach_travel(
    model: &Model,
    c: usize,
    nodal: &[Vec<(NodalContact, Option<Projection>)>],
) -> Option<f64> {
    let fc = model.contacts[c].tool.force_control.as_ref()?;
    nodal[c]
        .iter()
        .filter_map(|(_, p)| p.as_ref())
        .filter(|p| p.normal.dot(&fc.axis) > 1e-3)
        .map(|p| p.gap / p.normal.dot(&fc.axis))
        .min_by(f64::total_cmp)
}

/// Mean augmentation parameter of tool `c`: the scale of its force row.
pub fn row_scale(model: &Model, c: usize) -> f64 {
    let r = &model.contacts[c].r;
    r.iter().sum::<f64>() / r.len().max(1) as f64
}

/// Adds the force equation of every force-controlled tool (or its approach equation when
/// the tool touches nothing) at time `time`: its residual into `residual` and its Jacobian
/// entries into the matrix values `jac`, at their precomputed positions `slots` (per tool),
/// each only where given (a residual-only evaluation has no matrix; completing one
/// with its Jacobian needs no residual). `nodal` is the evaluation's per-node output;
/// `committed` the committed unknowns (the offset a tool between its windows holds).
#[allow(clippy::too_many_arguments)]
pub fn add_force_rows(
    model: &Model,
    dofs: &DofMap,
    time: f64,
    x: &[f64],
    committed: &[f64],
    nodal: &[Vec<(NodalContact, Option<Projection>)>],
    slots: &[Option<ForceControlSlots>],
    mut residual: Option<&mut [f64]>,
    mut jac: Option<&mut [f64]>,
) -> Result<()> {
    for (c, contact) in model.contacts.iter().enumerate() {
        let (Some(s), Some(off), Some(fc), Some(fs)) = (
            dofs.tool_offset[c],
            dofs.lambda_offset[c],
            &contact.tool.force_control,
            &slots[c],
        ) else {
            continue;
        };
        if !fc.active_at(time) {
            // Kinematic in this step: the offset stays where it was.
            if let Some(residual) = residual.as_deref_mut() {
                residual[s] = x[s] - committed.get(s).copied().unwrap_or(0.0);
            }
            if let Some(jac) = jac.as_deref_mut() {
                jac[fs.diagonal] += 1.0;
            }
        } else if !approaching(model, c, time, nodal) {
            let r_s = row_scale(model, c);
            let mut pushed = 0.0;
            for k in 0..contact.candidates.len() {
                let l = off + 3 * k;
                let lambda = Vec3::new(x[l], x[l + 1], x[l + 2]);
                pushed -= fc.axis.dot(&lambda);
                if let Some(jac) = jac.as_deref_mut() {
                    for j in 0..3 {
                        jac[fs.row[k][j]] += -fc.axis[j] / r_s;
                    }
                }
            }
            if let Some(residual) = residual.as_deref_mut() {
                residual[s] = (pushed - fc.force.value(time)) / r_s;
            }
        } else {
            let travel = approach_travel(model, c, nodal).ok_or_else(|| {
                Error::no_convergence(crate::error::Failure::Local, format!(
                    "force-controlled tool '{}' touches no node and no node lies ahead of it along its axis [{}, {}, {}]: its position is undetermined",
                    contact.tool.name, fc.axis.x, fc.axis.y, fc.axis.z
                ))
            })?;
            if let Some(residual) = residual.as_deref_mut() {
                residual[s] = -travel;
            }
            if let Some(jac) = jac.as_deref_mut() {
                jac[fs.diagonal] += 1.0;
            }
        }
    }
    Ok(())
}
