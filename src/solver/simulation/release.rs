//! Release steps: supports that act in chosen steps only, and tools whose last force is
//! ramped off (issue 47).
//!
//! **Supports of a step** (`Step::supports`, with the 3-2-1 default resolved here when the
//! simulation starts, `rigid_modes::three_two_one`). A support holds a node component where
//! it is: in every increment `(t_n, t_{n+1}]` that ends in the step, `u_{n+1} = u_n` for that
//! component (a Dirichlet row with the committed value; the iterate starts there,
//! `Newton::held`). Its reaction is the residual of its row, as for any Dirichlet
//! condition (`Simulation::reaction`). The prescribed rows of an increment are those of the
//! model's Dirichlet conditions and of the supports of the step the increment ends in
//! (`is_fixed`, set before each attempt); the multiplier elimination, planned once, keeps
//! every node some step supports out of its eliminated nodes (so its plan holds in all
//! steps). Being incremental, a support needs no value of its own: the committed
//! displacements say where it holds, and a restart inside the step holds the same.
//!
//! **Ramping a tool off** (`Step::ramp_off`): the tool is force-controlled in the step along
//! its force-control axis `a`, and its force goes linearly from its last value to zero at
//! the step's end `t_e`. Memoryless, so that a restart anywhere repeats the run bit for bit:
//! before each attempt at an increment `(t_n, t_{n+1}]`, the force schedule of the tool on
//! the step is the line from `(t_n, F_n)` to `(t_e, 0)`, where `F_n = max(0, -a . sum_k
//! lambda_k)` is the committed force the tool applies along `a` (the force equation's
//! left-hand side, `assembly::force_control`). Since the committed state satisfies its force
//! equation, `F_n` is the line's value at `t_n` within the contact tolerance, and
//!
//! ```text
//! F(t_{n+1}) = F_n (t_e - t_{n+1}) / (t_e - t_n)
//! ```
//!
//! is the linear ramp from the step's first force to zero: monotone, without a jump, zero
//! at `t_e`. The tool's schedule outside the step is the one the model gave
//! (`base_forces`).

use crate::geometry::Vec3;
use crate::solver::model::{rigid_modes, steps, Model};
use crate::solver::simulation::Simulation;
use crate::tool::ScalarSchedule;
use crate::{Error, Result};

/// Adds the 3-2-1 default supports to the steps that ask for them and checks every
/// release step: its supports (the Dirichlet conditions and its own) must leave no
/// rigid-body mode free, and a support's nodes must exist.
pub(super) fn resolve_supports(model: &mut Model) -> Result<()> {
    let n_nodes = model.mesh.nodes.len();
    for k in 0..model.steps.len() {
        let step = &model.steps[k];
        for s in &step.supports {
            if let Some(&n) = s.nodes.iter().find(|&&n| n >= n_nodes) {
                return Err(Error::Input(format!(
                    "step {k} ('{}') support '{}': node {n} is not in the mesh ({n_nodes} nodes)",
                    step.name, s.label
                )));
            }
        }
        if step.three_two_one {
            let chosen = rigid_modes::three_two_one(model, k);
            let step = &mut model.steps[k];
            for (n, component) in chosen {
                step.supports.push(steps::Support {
                    label: "3-2-1".to_string(),
                    nodes: vec![n],
                    component,
                });
            }
        }
        check_release(model, k)?;
    }
    Ok(())
}

/// A release step must hold the sheet statically determinate with its supports.
fn check_release(model: &Model, k: usize) -> Result<()> {
    let step = &model.steps[k];
    if !step.release {
        return Ok(());
    }
    let free = rigid_modes::free_rigid_body_modes_in_step(model, k);
    if free.is_empty() {
        return Ok(());
    }
    Err(Error::Input(format!(
        "step {k} ('{}') releases the sheet from every tool, but its supports leave {} rigid-body mode(s) free: {} (rotations about the nodes' centroid); fix them with sim.fix or the step's supports (`supports: [[set, \"xyz\"], ...]`, or `supports: \"3-2-1\"` for the default)",
        step.name,
        free.len(),
        free.join("; ")
    )))
}

/// The prescribed rows of the Dirichlet conditions alone (`base`) and with every step's
/// supports too (`all`, for the multiplier elimination's plan).
pub(super) fn fixed_rows(model: &Model, n_dofs: usize) -> (Vec<bool>, Vec<bool>) {
    let mut base = vec![false; n_dofs];
    for bc in &model.dirichlet {
        for &node in &bc.nodes {
            base[3 * node + bc.component] = true;
        }
    }
    let mut all = base.clone();
    for s in model.steps.iter().flat_map(|s| &s.supports) {
        for &node in &s.nodes {
            all[3 * node + s.component] = true;
        }
    }
    (base, all)
}

impl Simulation {
    /// Makes the prescribed rows and the ramped forces those of an increment ending at
    /// `t_new` from the committed state (module doc). Nothing changes in a run without
    /// step supports or ramps.
    pub(super) fn prepare_increment(&mut self, t_new: f64) {
        if !self.has_release_steps {
            return;
        }
        let step = steps::step_at(&self.model.steps, t_new);
        self.keep_loaded_shape(step);
        self.set_supports(step);
        if let Some(k) = step {
            self.ramp_forces(k);
        }
    }

    /// The prescribed rows and held components of step `step` (the Dirichlet conditions'
    /// alone outside steps).
    pub(super) fn set_supports(&mut self, step: Option<usize>) {
        self.is_fixed.clone_from(&self.base_fixed);
        self.held.clear();
        let Some(k) = step else { return };
        for s in &self.model.steps[k].supports {
            for &node in &s.nodes {
                let d = 3 * node + s.component;
                if !self.is_fixed[d] {
                    self.is_fixed[d] = true;
                    self.held.push(d);
                }
            }
        }
    }

    /// Each tool ramped off in step `k`: its force schedule on the step becomes the line from
    /// its committed force at the committed time to zero at the step's end.
    fn ramp_forces(&mut self, k: usize) {
        let end = self.model.steps[k].end;
        for c in self.model.steps[k].ramp_off.clone() {
            let (Some(base), Some(off)) = (&self.base_forces[c], self.dofs.lambda_offset[c]) else {
                continue;
            };
            let Some(fc) = &self.model.contacts[c].tool.force_control else {
                continue;
            };
            let start = steps::start(&self.model.steps, k);
            let n = self.model.contacts[c].candidates.len();
            let sum = (0..n).fold(Vec3::zeros(), |s, i| {
                let l = off + 3 * i;
                s + Vec3::new(self.x[l], self.x[l + 1], self.x[l + 2])
            });
            let now = self.time.max(start);
            let force = (-fc.axis.dot(&sum)).max(0.0);
            let mut points: Vec<(f64, f64)> = base
                .points()
                .iter()
                .copied()
                .filter(|p| p.0 < start)
                .collect();
            points.push((now, force));
            if now < end {
                points.push((end, 0.0));
            }
            points.extend(base.points().iter().copied().filter(|p| p.0 > end));
            if let Ok(schedule) = ScalarSchedule::new(points) {
                if let Some(fc) = self.model.contacts[c].tool.force_control.as_mut() {
                    fc.force = schedule;
                }
            }
        }
    }
}
