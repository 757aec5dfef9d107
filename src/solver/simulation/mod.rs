//! The incremental stepper: pseudo-time increments, each solved by a generalised Newton
//! method on (u, lambda), with commit of history variables on convergence and rollback
//! (halving the increment) on failure. Nothing committed is ever lost: a failed increment
//! leaves the last converged state untouched.

pub mod checkpoint;
pub mod energy;
pub mod kinematics_check;
pub mod release;
pub mod section_angles;
pub mod springback;
pub mod step_control;
pub mod step_end;
pub mod stepping;
pub mod strokes;
pub mod tool_fields;

use crate::contact::{ContactNodeState, ContactStatus, FrameUpdate, FrictionInput};
use crate::geometry::Vec3;
use crate::material::PointState;
use crate::solver::assembly::force_control;
use crate::solver::assembly::{DofMap, Evaluation, EvaluationCounts, PhaseTimes};
use crate::solver::linear::condense::Condenser;
use crate::solver::linear::{LinearSolver, Solver};
use crate::solver::model::{steps, Model};
use crate::solver::newton::cycling::CyclingNode;
use crate::solver::newton::{IterationRecord, Newton, Trial};
use crate::solver::simulation::checkpoint::SavedState;
use crate::solver::simulation::energy::{EnergyBalance, EnergyMemory};
use crate::solver::simulation::step_control::{
    schedule_stops, IncrementMeasures, Limit, StepController,
};
use crate::solver::sparse::SparsePattern;
use crate::{Error, Result};
use std::collections::VecDeque;
use std::sync::Arc;

/// What one converged increment did.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct IncrementReport {
    pub index: usize,
    /// The step of the process this increment belongs to (`None` without steps).
    #[serde(default)]
    pub step: Option<usize>,
    /// The stroke of a production run this increment belongs to, from 1 (`model::strokes`).
    #[serde(default = "first_stroke")]
    pub stroke: usize,
    pub time: f64,
    pub dt: f64,
    /// Number of linear solves.
    pub iterations: usize,
    /// Residuals before each solve and at convergence.
    pub residuals: Vec<IterationRecord>,
    /// Halvings needed before this increment converged.
    pub cutbacks: usize,
    /// Total force on each tool (force the body exerts on the tool), in tool order.
    pub tool_forces: Vec<[f64; 3]>,
    /// Offset of each tool along its force-control axis (0 for kinematic tools).
    pub tool_offsets: Vec<f64>,
    pub active_nodes: usize,
    pub slipping_nodes: usize,
    /// Energy balance after this increment.
    pub energy: EnergyBalance,
    /// Adaptive stepping: converged trials rejected because an increment limit was exceeded.
    pub rejected: usize,
    /// Adaptive stepping: the largest plastic strain, rotation and slip increments.
    pub measures: IncrementMeasures,
    /// Adaptive stepping: what limited the next increment, and its size.
    pub limit: Limit,
    pub next_dt: f64,
    /// Backtracking steps of the line search over the increment's iterations.
    pub line_search_cuts: usize,
    /// Nodes whose contact status cycled within the increment.
    pub cycling: Vec<CyclingNode>,
    /// Anything the user should know about this increment.
    pub warnings: Vec<String>,
    /// Why each failed attempt before this increment was cut back ("t = .. (dt = ..): the
    /// error"), one per cutback counted in `cutbacks`.
    #[serde(default)]
    pub cutback_reasons: Vec<String>,
    /// The kind of each failure in `cutback_reasons`, in the same order.
    #[serde(default)]
    pub cutback_kinds: Vec<crate::error::Failure>,
    /// The last resort that got this increment through after Newton failed at the
    /// smallest part the cut-backs allow (module `stepping`); `None` for Newton's own.
    #[serde(default)]
    pub last_resort: Option<String>,
    /// Newton iterations (steps solved) of the attempts not kept before this increment
    /// converged: attempts cut back, a status-prediction attempt retried plainly, failed
    /// last resorts, converged trials the step control rejected. Their work is the run's
    /// (phase times) but not in `iterations`. Like `cutbacks`: per part in `history`, over
    /// the nominal increment's parts in the report fixed stepping's `step` returns.
    #[serde(default)]
    pub discarded_iterations: usize,
    /// Whether this increment met its step's condition (`Step::until`) and so ended the
    /// step (module `step_end`).
    #[serde(default)]
    pub until_met: bool,
    /// Set when this increment reached its step's end without the step's condition: what
    /// was asked and what was reached. The run stops there (module `step_end`).
    #[serde(default)]
    pub until_missed: Option<String>,
}

/// The stroke of reports written before strokes existed.
fn first_stroke() -> usize {
    1
}

/// Model plus its evolving, committed solution.
pub struct Simulation {
    pub model: Model,
    pub(super) dofs: DofMap,
    pub(super) pattern: Arc<SparsePattern>,
    /// The prescribed rows of the increment under way or last committed: the Dirichlet
    /// conditions' and its step's supports (`release`).
    pub(super) is_fixed: Vec<bool>,
    /// The prescribed rows of the Dirichlet conditions alone.
    pub(super) base_fixed: Vec<bool>,
    /// The rows a step's supports hold at their committed values in that increment.
    pub(super) held: Vec<usize>,
    /// Whether some step has supports or ramps tools off (`release`).
    pub(super) has_release_steps: bool,
    /// The force schedules of the force-controlled tools as the model gave them, before
    /// a ramp-off step rewrote them (`release`).
    pub(super) base_forces: Vec<Option<crate::tool::ScalarSchedule>>,
    /// The node positions where loading ended, kept for the springback measures
    /// (`springback`); in checkpoints once kept.
    pub(super) loaded_shape: Option<Vec<Vec3>>,
    /// The springback of each release step completed (`springback`).
    pub(super) springback: Vec<springback::Springback>,
    pub(super) linear: Solver,
    /// What the elements remembered at the last converged iterate (their linearisation
    /// there), where every attempt of the next increment starts
    /// ([`crate::solver::assembly::ElementMemory`]); empty before the first increment.
    pub(super) committed_memory: Vec<f64>,
    /// The elements' internal forces at the committed state (the converged evaluation's),
    /// so that the extrapolation guard's evaluation at the committed unknowns needs no
    /// element pass (`Newton::committed_residual`); `None` before the first increment
    /// and after a restore.
    pub(super) committed_forces: Option<Vec<f64>>,
    /// `committed_forces` were dropped by a restore of a state that had them
    /// (`Newton::forces_lost_by_restore`).
    pub(super) forces_lost_by_restore: bool,
    pub(super) condenser: Option<Condenser>,
    /// Committed unknowns [u, lambda].
    pub(super) x: Vec<f64>,
    pub(super) points: Vec<PointState>,
    pub(super) contact: Vec<Vec<ContactNodeState>>,
    pub(super) time: f64,
    pub(super) increments_done: usize,
    pub history: Vec<IncrementReport>,
    /// Time and evaluations of every attempt so far: accepted increments, and the attempts
    /// that failed (cut back) or that adaptive stepping rejected.
    pub phase_times: PhaseTimes,
    /// `phase_times`' counts at the last committed increment (checkpoints carry them: the
    /// attempts after it are redone by a restarted run).
    pub(super) committed_counts: EvaluationCounts,
    pub(super) energy: EnergyBalance,
    pub(super) energy_memory: EnergyMemory,
    pub(super) controller: StepController,
    /// Schedule breakpoints and the end time: adaptive increments land on them.
    pub(super) stops: Vec<f64>,
    /// Committed states before the last increments, for `rollback`.
    pub(super) saved: VecDeque<SavedState>,
    /// Last converged increment (dt, change of the displacements), for the extrapolating
    /// predictor.
    pub(super) last_step: Option<(f64, Vec<f64>)>,
    /// Stop request polled between Newton iterations (see `crate::interrupt`).
    pub(super) interrupt: crate::interrupt::Interrupt,
    /// Whether the run has explained contact-status cycling to the user (once per run).
    pub(super) cycling_explained: bool,
    /// Newton steps of attempts not kept since the last accepted increment
    /// ([`IncrementReport::discarded_iterations`]).
    pub(super) discarded_steps: usize,
    /// Whether the run has explained a step limit exceeded at the minimum step (in full
    /// once per run; later increments get one short line each).
    pub(super) limit_explained: bool,
    /// Increments in a row held at the floor dt_min (`step_control`, "Crawl floor"); not
    /// kept in checkpoints: a restart counts afresh.
    pub(super) at_floor: usize,
    /// The tools' schedules as the model gave them, before steps ended early changed
    /// them (module `step_end`).
    pub(super) base_schedules: Vec<crate::tool::Schedule>,
    /// Steps ended by their condition: (step, time of the increment that met it), in
    /// order. Part of the committed state.
    pub(super) step_ends: Vec<(usize, f64)>,
    /// Tool-side fields of each tool that asks for them (`Tool::fields`), accumulated in
    /// `commit`.
    pub(super) tool_fields: Vec<Option<tool_fields::ContactFields>>,
    /// The current stroke, from 0 (module `strokes`). Part of the committed state.
    pub(super) stroke: usize,
    /// Per tool whose friction reads the tool's work (`FrictionLaw::ToolWork`): its work
    /// per area frozen at the start of the stroke. Part of the committed state.
    pub(super) tool_work_frozen: Vec<Option<Vec<f64>>>,
    /// Per tool: the wear depth per cell its surface is worn by (`tool::worn`), set when
    /// a stroke starts with a geometry update (module `strokes`); `None`: the exact
    /// surface. Part of the committed state; mirrored in `model.contacts[c].tool.worn`.
    pub(super) tool_wear_applied: Vec<Option<Vec<f64>>>,
    /// The state `new` built, where every stroke after the first starts; kept only when
    /// several strokes are simulated.
    pub(super) initial: Option<Box<SavedState>>,
}

impl Simulation {
    /// Sets up unknowns and initial history. Fails on an invalid model.
    pub fn new(mut model: Model) -> Result<Self> {
        model.mesh.validate()?;
        let fraction = model.settings.contact.r_fraction;
        if !(fraction > 0.0 && fraction.is_finite()) {
            return Err(Error::input("r_fraction", fraction, "must be > 0"));
        }
        model.settle_default_r();
        if model.settings.increments == 0 {
            return Err(Error::input("number of increments", 0, "must be >= 1"));
        }
        if !(model.settings.end_time > 0.0 && model.settings.end_time.is_finite()) {
            return Err(Error::input(
                "end time",
                model.settings.end_time,
                "must be > 0",
            ));
        }
        steps::validate(&model.steps)?;
        if let Some(last) = model.steps.last() {
            if last.end != model.settings.end_time {
                return Err(Error::input(
                    &format!("last step ('{}') end time", last.name),
                    last.end,
                    &format!("must equal the end time {}", model.settings.end_time),
                ));
            }
        }
        force_control::check(&model)?;
        release::resolve_supports(&mut model)?;
        strokes::check(&model)?;
        let dofs = DofMap::new(&model);
        let groups = crate::solver::linear::condense::elimination_groups(&model, &dofs);
        let pattern = Arc::new(dofs.pattern(&model).with_groups(groups));
        let (is_fixed, fixed_in_some_step) = release::fixed_rows(&model, dofs.n_dofs);
        let element = model.element()?;
        if model.settings.element == crate::element::ElementKind::SolidShell {
            crate::element::solid_shell::check_columns(&model.mesh)?;
        }
        let points = vec![PointState::default(); model.mesh.hexes.len() * element.point_count()];
        let contact = model
            .contacts
            .iter()
            .map(|c| {
                let pose = c.tool.pose(0.0);
                c.candidates
                    .iter()
                    .zip(&c.areas)
                    .map(|(node, area)| {
                        let x0 = model.mesh.nodes[*node];
                        let mut s = ContactNodeState {
                            x_ref_local: pose.to_local(&x0),
                            ..Default::default()
                        };
                        if let Some(p) = c.tool.project(&pose, &x0, None) {
                            s.hint = Some(p.hint);
                            s.gap = p.gap;
                            s.normal = p.normal;
                        }
                        s.mu = c.tool.friction.initial_mu(*area);
                        s
                    })
                    .collect()
            })
            .collect();
        let tool_fields = model
            .contacts
            .iter()
            .map(|c| tool_fields::ContactFields::new(c, &model.mesh))
            .collect::<Result<Vec<_>>>()?;
        let dofs_nodes = dofs.n_nodes;
        let initial_f_ext = model.external_forces(0.0);
        let condenser = if model.settings.eliminate_multipliers {
            Condenser::new(&model, &dofs, &pattern, &fixed_in_some_step)
        } else {
            None
        };
        model.settings.stepping.validate(model.settings.end_time)?;
        let tool_work_frozen = (model.contacts.iter().zip(&tool_fields))
            .map(|(c, f)| match (&c.tool.friction, f) {
                (crate::contact::FrictionLaw::ToolWork(_), Some(f)) => {
                    Some(vec![0.0; f.fields.len()])
                }
                _ => None,
            })
            .collect();
        let mut sim = Simulation {
            controller: StepController::new(&model),
            stops: schedule_stops(&model),
            saved: VecDeque::new(),
            condenser,
            x: vec![0.0; dofs.n_dofs],
            dofs,
            pattern,
            base_fixed: is_fixed.clone(),
            is_fixed,
            held: Vec::new(),
            has_release_steps: model
                .steps
                .iter()
                .any(|s| !s.supports.is_empty() || !s.ramp_off.is_empty() || s.release),
            loaded_shape: None,
            springback: Vec::new(),
            base_forces: model
                .contacts
                .iter()
                .map(|c| c.tool.force_control.as_ref().map(|f| f.force.clone()))
                .collect(),
            linear: Solver::new(model.settings.linear_solver),
            committed_memory: Vec::new(),
            committed_forces: None,
            forces_lost_by_restore: false,
            points,
            contact,
            time: 0.0,
            increments_done: 0,
            history: Vec::new(),
            phase_times: PhaseTimes::default(),
            committed_counts: EvaluationCounts::default(),
            energy: EnergyBalance {
                frictional_dissipation: vec![0.0; model.contacts.len()],
                ..Default::default()
            },
            last_step: None,
            interrupt: crate::interrupt::Interrupt::new(),
            cycling_explained: false,
            discarded_steps: 0,
            limit_explained: false,
            at_floor: 0,
            base_schedules: model
                .contacts
                .iter()
                .map(|c| c.tool.schedule.clone())
                .collect(),
            step_ends: Vec::new(),
            tool_fields,
            stroke: 0,
            tool_work_frozen,
            tool_wear_applied: vec![None; model.contacts.len()],
            initial: None,
            energy_memory: EnergyMemory {
                support_forces: vec![0.0; 3 * dofs_nodes],
                external_forces: initial_f_ext,
                tool_forces: vec![Vec3::zeros(); model.contacts.len()],
            },
            model,
        };
        if sim.model.strokes.simulated > 1 {
            sim.initial = Some(Box::new(sim.saved_state()));
        }
        Ok(sim)
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    /// Whether the run has ended: the end time reached in the last simulated stroke.
    pub fn is_finished(&self) -> bool {
        self.stroke_done() && self.is_last_stroke()
    }

    /// Fixed stepping's increment: `end_time / increments`, or in a process of steps the
    /// current step's length over its increments.
    pub fn nominal_dt(&self) -> f64 {
        match steps::next_step(&self.model.steps, self.time) {
            Some(k) => steps::nominal_dt(&self.model.steps, k),
            None => self.model.settings.end_time / self.model.settings.increments as f64,
        }
    }

    /// The index of the step the next increment falls in (`None` without steps).
    pub fn current_step(&self) -> Option<usize> {
        steps::next_step(&self.model.steps, self.time)
    }

    /// Where fixed stepping's next nominal increment ends: `time + nominal_dt`, not past
    /// the end time nor past the end of the current step.
    pub(super) fn fixed_target(&self) -> f64 {
        let target = (self.time + self.nominal_dt()).min(self.model.settings.end_time);
        match steps::next_step(&self.model.steps, self.time) {
            Some(k) => steps::land_on_end(&self.model.steps, k, target),
            None => target,
        }
    }

    /// Committed displacement of a node.
    pub fn displacement(&self, node: usize) -> Vec3 {
        Vec3::new(self.x[3 * node], self.x[3 * node + 1], self.x[3 * node + 2])
    }

    /// Committed displacements, 3 per node.
    pub fn displacements(&self) -> &[f64] {
        &self.x[..3 * self.dofs.n_nodes]
    }

    pub fn points(&self) -> &[PointState] {
        &self.points
    }

    /// Committed contact states of tool `c`, in the order of its candidate nodes.
    pub fn contact_states(&self, c: usize) -> &[ContactNodeState] {
        &self.contact[c]
    }

    /// Offset of tool `c` along its force-control axis at the committed state (0 for a
    /// kinematic tool).
    pub fn tool_offset(&self, c: usize) -> f64 {
        force_control::offset(&self.dofs, c, &self.x)
    }

    /// Translation of tool `c` at the committed state (schedule plus force-control offset).
    pub fn tool_position(&self, c: usize) -> Vec3 {
        force_control::pose(&self.model, &self.dofs, c, self.time, &self.x).translation
    }

    /// Pose of tool `c` at the committed state (schedule plus force-control offset).
    pub fn tool_pose(&self, c: usize) -> crate::tool::Pose {
        force_control::pose(&self.model, &self.dofs, c, self.time, &self.x)
    }

    /// Total force on tool `c` at the committed state (sum of multipliers).
    pub fn tool_force(&self, c: usize) -> Vec3 {
        self.contact[c].iter().map(|s| s.lambda).sum()
    }

    /// Reaction force on the nodes of a Dirichlet node set at the committed state.
    pub fn reaction(&mut self, nodes: &[usize]) -> Result<Vec3> {
        let eval = self.evaluate_at(self.time, &self.x.clone())?;
        let mut in_set = vec![false; self.dofs.n_nodes];
        let mut r = Vec3::zeros();
        for &node in nodes {
            in_set[node] = true;
            for i in 0..3 {
                r[i] += eval.f_int[3 * node + i] - eval.f_ext[3 * node + i];
            }
        }
        // Contact forces on these nodes also load the support.
        for (c, contact) in self.model.contacts.iter().enumerate() {
            for (k, &node) in contact.candidates.iter().enumerate() {
                if in_set[node] {
                    r += eval.nodal[c][k].0.f_equi;
                }
            }
        }
        Ok(r)
    }

    /// The Newton solver of the next increment, borrowing the committed state.
    pub(crate) fn newton(&self) -> Newton<'_> {
        Newton {
            model: &self.model,
            dofs: &self.dofs,
            pattern: &self.pattern,
            is_fixed: &self.is_fixed,
            held: &self.held,
            condenser: self.condenser.as_ref(),
            time: self.time,
            x: &self.x,
            points: &self.points,
            contact: &self.contact,
            committed_memory: &self.committed_memory,
            committed_forces: self.committed_forces.as_deref(),
            forces_lost_by_restore: self.forces_lost_by_restore,
            last_step: self.last_step.as_ref(),
            interrupt: &self.interrupt,
        }
    }

    /// Solves J dx = -R at the committed state's model (`Newton::newton_step`).
    pub fn newton_step(
        &self,
        eval: &Evaluation,
        linear: &mut dyn LinearSolver,
    ) -> Result<Vec<f64>> {
        self.newton().newton_step(eval, linear)
    }

    /// The multiplier elimination, when there is one.
    pub fn condenser(&self) -> Option<&Condenser> {
        self.condenser.as_ref()
    }

    /// Multiplier unknowns eliminated before each linear solve.
    pub fn eliminated_multipliers(&self) -> usize {
        self.condenser.as_ref().map_or(0, |c| c.eliminated_count())
    }

    /// How many symbolic LU analyses were done: one per sparsity pattern, not per iteration.
    pub fn symbolic_analyses(&self) -> usize {
        self.linear.symbolic_analyses()
    }

    /// How many numeric factorizations ran on several threads (setting `threads`).
    pub fn split_factorizations(&self) -> usize {
        self.linear.split_factorizations()
    }

    /// Committed unknowns [u, lambda].
    pub fn unknowns(&self) -> &[f64] {
        &self.x
    }

    /// Residual and Jacobian at time `time` for trial unknowns `x` against the committed
    /// history (what Newton sees; used to check the Jacobian by finite differences).
    pub fn evaluate_at(&self, time: f64, x: &[f64]) -> Result<Evaluation> {
        let mut t = PhaseTimes::default();
        self.newton().context(time, None).evaluate(x, &mut t)
    }

    /// Connects a stop request: a raised flag abandons the increment under way at its next
    /// Newton iteration (`Error::Interrupted`); the committed state stays the last
    /// converged one.
    pub fn set_interrupt(&mut self, interrupt: crate::interrupt::Interrupt) {
        self.interrupt = interrupt;
    }

    pub(super) fn check_interrupt(&self) -> Result<()> {
        self.newton().check_interrupt()
    }

    /// Commits a converged trial (keeping the state it replaces for `rollback`).
    pub(super) fn accept(&mut self, t_new: f64, trial: Trial) -> IncrementReport {
        let depth = self.model.settings.stepping.rollback_depth;
        if depth > 0 {
            if self.saved.len() >= depth {
                self.saved.pop_front();
            }
            let state = self.saved_state();
            self.saved.push_back(state);
        }
        self.phase_times.add(&trial.times);
        self.committed_counts = self.phase_times.counts();
        // The accepted attempt's steps are its iterations; the rest of its `times` (a
        // status-prediction attempt before a plain retry) was discarded.
        let discarded = std::mem::take(&mut self.discarded_steps)
            + trial.times.newton_steps.saturating_sub(trial.iterations);
        self.committed_memory = trial.element_memory;
        let kinematics_warning = (self.model.settings.kinematics
            == crate::element::StrainTheory::Small)
            .then(|| {
                crate::solver::simulation::kinematics_check::small_strain_warning(
                    &self.points,
                    &trial.eval.trial_points,
                    self.points.len() / self.model.mesh.hexes.len().max(1),
                )
            })
            .flatten();
        let mut report = self.commit(
            t_new,
            trial.x,
            trial.eval,
            trial.iterations,
            trial.residuals,
        );
        report.line_search_cuts = trial.line_search_cuts;
        report.discarded_iterations = discarded;
        report.warnings.extend(kinematics_warning);
        // Cycling is worth one explanation per run, not one line per increment: the nodes
        // of every increment are in its report and in history.csv (cycling_nodes).
        if !trial.cycling.is_empty() && !self.cycling_explained {
            self.cycling_explained = true;
            report.warnings.push(cycling_warning(
                &self.model,
                &trial.cycling,
                self.model.settings.stepping.anti_cycling,
            ));
        }
        report.cycling = trial.cycling;
        report
    }

    /// Undoes the last `n` converged increments (at most as many as were kept: settings
    /// `rollback_depth`). Returns the time reached.
    pub fn rollback(&mut self, n: usize) -> Result<f64> {
        if n == 0 || n > self.saved.len() {
            return Err(Error::Input(format!(
                "cannot roll back {n} increment(s): {} converged state(s) are kept (setting rollback_depth = {})",
                self.saved.len(),
                self.model.settings.stepping.rollback_depth
            )));
        }
        // A production run's strokes are separate blanks: the state kept before a stroke's
        // first increment is the stroke's start, and no rollback goes past it (the frames
        // and rows of the stroke before are not its own).
        let target = &self.saved[self.saved.len() - n];
        if target.stroke != self.stroke {
            return Err(Error::Input(format!(
                "cannot roll back {n} increment(s): that goes past the start of stroke {} (a new blank); at most {} in this stroke",
                self.stroke + 1,
                self.saved.iter().rev().take_while(|s| s.stroke == self.stroke).count()
            )));
        }
        let mut state = None;
        for _ in 0..n {
            state = self.saved.pop_back();
        }
        self.restore_state(state.expect("n >= 1 states popped"));
        Ok(self.time)
    }

    /// Runs to the end time, calling `on_increment` after each converged increment.
    pub fn run(
        &mut self,
        mut on_increment: impl FnMut(&Simulation, &IncrementReport) -> Result<()>,
    ) -> Result<()> {
        while !self.is_finished() {
            let report = self.step()?;
            on_increment(self, &report)?;
        }
        Ok(())
    }

    fn commit(
        &mut self,
        t_new: f64,
        x: Vec<f64>,
        eval: Evaluation,
        iterations: usize,
        residuals: Vec<IterationRecord>,
    ) -> IncrementReport {
        let mut tool_forces = Vec::new();
        let mut dissipated = vec![0.0; self.model.contacts.len()];
        let mut normal_work = vec![0.0; self.model.contacts.len()];
        let (mut active, mut slipping) = (0, 0);
        for (c, contact) in self.model.contacts.iter().enumerate() {
            let pose = force_control::pose(&self.model, &self.dofs, c, t_new, &x);
            let mut total = Vec3::zeros();
            let with_fields = self.tool_fields[c].is_some();
            let mut loads = Vec::new();
            for (k, &node) in contact.candidates.iter().enumerate() {
                let (res, proj) = &eval.nodal[c][k];
                let s = &mut self.contact[c][k];
                let previous_status = s.status;
                let xn = self.model.mesh.nodes[node]
                    + Vec3::new(x[3 * node], x[3 * node + 1], x[3 * node + 2]);
                // Work of the contact force on the relative motion, by the trapezoidal rule
                // like every other work term (Psi below follows the paper instead).
                // Of it, friction dissipates lambda_t . delta_t (exactly 0 for mu = 0); the
                // rest is the normal force's work on the relative motion, zero for the exact
                // solution, which the trapezoidal rule picks up where a gap closes within
                // the increment (and penalty penetration stores).
                let relative_motion = xn - pose.to_global_point(&s.x_ref_local);
                let interface = 0.5 * (s.lambda + res.f_equi).dot(&relative_motion);
                let friction = res.tangential_force.dot(&res.slip_increment);
                dissipated[c] += friction;
                normal_work[c] += interface - friction;
                // The converged force on the tool is F_equi (= lambda for the mixed method).
                s.lambda = res.f_equi;
                s.status = res.status;
                // With a frozen frame the operator saw the tangent plane; the committed
                // geometry is the true projection on the tool.
                let true_proj = match self.model.settings.contact.frame {
                    FrameUpdate::Frozen => contact.tool.project(&pose, &xn, s.hint.as_ref()),
                    FrameUpdate::EveryIteration => *proj,
                };
                if let Some(p) = true_proj {
                    s.hint = Some(p.hint);
                    s.gap = p.gap;
                    s.normal = p.normal;
                }
                s.slip_increment = if res.status.is_active() {
                    res.slip_increment
                } else {
                    Vec3::zeros()
                };
                if res.status.is_active() {
                    let lambda_t = s.lambda - s.normal * s.lambda.dot(&s.normal);
                    s.work += lambda_t.dot(&res.slip_increment).max(0.0);
                    s.slip += res.slip_increment.norm();
                }
                if previous_status.is_active()
                    && res.status.is_active()
                    && previous_status != res.status
                {
                    s.flips += 1;
                }
                active += usize::from(res.status.is_active());
                slipping += usize::from(res.status == ContactStatus::Slip);
                s.x_ref_local = pose.to_local(&xn);
                let area = contact.areas[k];
                if let Some(mu) = contact.tool.friction.mu(&s.friction_input(area)) {
                    s.mu = mu;
                } else if let (
                    crate::contact::FrictionLaw::ToolWork(law),
                    Some(fields),
                    Some(frozen),
                ) = (
                    &contact.tool.friction,
                    &self.tool_fields[c],
                    &self.tool_work_frozen[c],
                ) {
                    // The tool's state frozen at the stroke's start (module `strokes`).
                    if let Some(mu) =
                        strokes::tool_state_mu(law, &fields.fields, frozen, s.hint.as_ref())
                    {
                        s.mu = mu;
                    }
                }
                s.theta = contact
                    .tool
                    .friction
                    .bernstein()
                    .map_or(0.0, |law| law.theta(s.work, area));
                total += s.lambda;
                if with_fields {
                    loads.push(crate::tool::surface_fields::NodeLoad {
                        work: friction,
                        normal_force: if res.status.is_active() {
                            (-s.lambda.dot(&s.normal)).max(0.0)
                        } else {
                            0.0
                        },
                        slip: s.slip_increment.norm(),
                    });
                }
            }
            tool_forces.push([total.x, total.y, total.z]);
            if let Some(fields) = self.tool_fields[c].as_mut() {
                let started = std::time::Instant::now();
                let position = |n: usize| {
                    self.model.mesh.nodes[n] + Vec3::new(x[3 * n], x[3 * n + 1], x[3 * n + 2])
                };
                fields.accumulate(
                    contact,
                    &pose,
                    position,
                    &self.contact[c],
                    &loads,
                    t_new - self.time,
                );
                self.phase_times.tool_fields += started.elapsed().as_secs_f64();
            }
        }
        let energy = self.account_energy(t_new, &x, &eval, &tool_forces, &dissipated, &normal_work);
        let tool_offsets = (0..self.model.contacts.len())
            .map(|c| force_control::offset(&self.dofs, c, &x))
            .collect();
        let dt = t_new - self.time;
        let n_u = 3 * self.dofs.n_nodes;
        let du = x[..n_u].iter().zip(&self.x[..n_u]).map(|(a, b)| a - b);
        self.last_step = Some((dt, du.collect()));
        self.x = x;
        self.points = eval.trial_points;
        self.committed_forces = Some(eval.f_int);
        self.forces_lost_by_restore = false;
        self.time = t_new;
        self.increments_done += 1;
        IncrementReport {
            index: self.increments_done,
            step: steps::step_at(&self.model.steps, t_new),
            stroke: self.stroke + 1,
            time: t_new,
            dt,
            iterations,
            residuals,
            cutbacks: 0,
            tool_forces,
            tool_offsets,
            active_nodes: active,
            slipping_nodes: slipping,
            energy,
            rejected: 0,
            measures: IncrementMeasures::default(),
            limit: Limit::None,
            next_dt: dt,
            line_search_cuts: 0,
            cycling: Vec::new(),
            warnings: Vec::new(),
            cutback_reasons: Vec::new(),
            cutback_kinds: Vec::new(),
            last_resort: None,
            discarded_iterations: 0,
            until_met: false,
            until_missed: None,
        }
    }

    /// The committed state: what a checkpoint holds and `rollback` returns to.
    pub fn saved_state(&self) -> SavedState {
        SavedState {
            x: self.x.clone(),
            points: self.points.clone(),
            contact: self.contact.clone(),
            time: self.time,
            increments_done: self.increments_done,
            history_len: self.history.len(),
            energy: self.energy.clone(),
            energy_memory: self.energy_memory.clone(),
            controller: self.controller,
            last_step: self.last_step.clone(),
            element_memory: self.committed_memory.clone(),
            step_ends: self.step_ends.clone(),
            tool_fields: self
                .tool_fields
                .iter()
                .map(|f| f.as_ref().map(|f| f.fields.values.clone()))
                .collect(),
            stroke: self.stroke,
            tool_work_frozen: self.tool_work_frozen.clone(),
            tool_wear_applied: self.tool_wear_applied.clone(),
            loaded_shape: self.loaded_shape.clone(),
            springback: self.springback.clone(),
        }
    }

    /// Makes `state` the committed state (its shape must match this model: see
    /// `checkpoint::Checkpoint::restore`, which checks it).
    pub fn restore_state(&mut self, state: SavedState) {
        self.x = state.x;
        self.points = state.points;
        self.contact = state.contact;
        self.time = state.time;
        self.increments_done = state.increments_done;
        self.history.truncate(state.history_len);
        self.energy = state.energy;
        self.energy_memory = state.energy_memory;
        self.controller = state.controller;
        self.last_step = state.last_step;
        self.committed_memory = state.element_memory;
        self.committed_forces = None;
        self.forces_lost_by_restore = state.increments_done > 0;
        self.set_step_ends(state.step_ends);
        if self.has_release_steps {
            // The prescribed rows of the committed increment's step (`release`).
            self.set_supports(steps::step_at(&self.model.steps, self.time));
        }
        // Shapes were checked by `Checkpoint::restore` (or come from this simulation).
        for (fields, values) in self.tool_fields.iter_mut().zip(state.tool_fields) {
            if let (Some(f), Some(v)) = (fields.as_mut(), values) {
                f.fields.values = v;
            }
        }
        self.stroke = state.stroke;
        // Older checkpoints have no frozen work: the fields as restored (stroke 1: zero).
        if state.tool_work_frozen.len() == self.tool_work_frozen.len() {
            self.tool_work_frozen = state.tool_work_frozen;
        } else {
            self.tool_work_frozen = self.freeze_tool_work();
        }
        // Older checkpoints have no worn geometry: the exact tools.
        self.tool_wear_applied = if state.tool_wear_applied.len() == self.tool_wear_applied.len() {
            state.tool_wear_applied
        } else {
            vec![None; self.tool_wear_applied.len()]
        };
        self.set_worn_tools();
        self.loaded_shape = state.loaded_shape;
        self.springback = state.springback;
    }

    /// The tool-side fields of tool `c`, if it accumulates them (`Tool::fields`).
    pub fn tool_fields(&self, c: usize) -> Option<&crate::tool::ToolFields> {
        self.tool_fields[c].as_ref().map(|f| &f.fields)
    }

    /// Replaces the settings of a running simulation (after a rollback in the REPL, say).
    /// Settings that shape the unknowns (enforcement, multiplier elimination) cannot
    /// change once the simulation has started.
    pub fn change_settings(&mut self, settings: super::SolverSettings) -> Result<()> {
        let old = &self.model.settings;
        if settings.contact.enforcement != old.contact.enforcement
            || settings.eliminate_multipliers != old.eliminate_multipliers
            || settings.kinematics != old.kinematics
            || settings.fbar != old.fbar
            || settings.element != old.element
            || settings.thickness_points != old.thickness_points
        {
            return Err(Error::Input(
                "enforcement, eliminate_multipliers, kinematics, fbar, element and thickness_points cannot change once the simulation has started"
                    .into(),
            ));
        }
        settings.stepping.validate(settings.end_time)?;
        if settings.linear_solver != old.linear_solver {
            self.linear = Solver::new(settings.linear_solver);
        }
        let (lo, hi) = (
            settings.stepping.dt_min(settings.end_time),
            settings.stepping.dt_max(settings.end_time),
        );
        self.model.settings = settings;
        self.stops = schedule_stops(&self.model);
        self.controller.dt = self.controller.dt.clamp(lo, hi);
        Ok(())
    }

    /// Forgets the states kept for `rollback` (after loading a checkpoint).
    pub fn clear_rollback(&mut self) {
        self.saved.clear();
    }

    /// Committed states kept for `rollback`.
    pub fn rollback_available(&self) -> usize {
        self.saved.len()
    }

    /// The energy balance so far.
    pub fn energy(&self) -> &EnergyBalance {
        &self.energy
    }

    /// Friction inputs (work, slip, pressure, area) of every candidate node of tool `c`.
    pub fn friction_inputs(&self, c: usize) -> Vec<FrictionInput> {
        let contact = &self.model.contacts[c];
        self.contact[c]
            .iter()
            .zip(&contact.areas)
            .map(|(s, &area)| s.friction_input(area))
            .collect()
    }

    /// Sets the friction coefficients of tool `c`'s nodes for the next increment (for laws
    /// evaluated outside the library, such as script functions). Values must be >= 0.
    pub fn set_friction_coefficients(&mut self, c: usize, mu: &[f64]) -> Result<()> {
        if mu.len() != self.contact[c].len() {
            return Err(Error::Input(format!(
                "{} friction coefficients given for {} contact nodes",
                mu.len(),
                self.contact[c].len()
            )));
        }
        for (k, &m) in mu.iter().enumerate() {
            crate::contact::friction::check_mu(
                &format!("friction coefficient of contact node {k}"),
                m,
            )?;
        }
        for (s, &m) in self.contact[c].iter_mut().zip(mu) {
            s.mu = m;
        }
        Ok(())
    }
}

/// The one warning of a run about contact-status cycling, on one line: how many nodes, that
/// the result is sound, what to try, where the count per increment is. (Its increment and
/// time are in the prefix the script layer prints before every warning.)
fn cycling_warning(
    model: &Model,
    cycling: &[CyclingNode],
    treatment: crate::solver::settings::AntiCycling,
) -> String {
    // One line a person reads: what happens, that it costs only iterations (each increment
    // is accepted only when the unmodified friction law holds to the Newton tolerances),
    // what to try if it costs many, and where the count per increment is.
    const SHOWN: usize = 2;
    let nodes: Vec<String> = (cycling.iter().take(SHOWN))
        .map(|n| format!("{}:{}", model.contacts[n.tool].tool.name, n.node))
        .collect();
    let more = cycling.len().saturating_sub(SHOWN);
    let mut remedies = vec!["smaller steps"];
    if model.settings.status_prediction == 0 {
        remedies.push("status_prediction: 8");
    }
    if treatment == crate::solver::settings::AntiCycling::Off {
        remedies.push("anti_cycling: \"freeze\"");
    }
    format!(
        "the status of {} contact node(s) ({}{}) changes back and forth in Newton: results \
         unaffected, costs iterations; if many: {} (history.csv: cycling_nodes)",
        cycling.len(),
        nodes.join(", "),
        if more > 0 {
            format!(", +{more}")
        } else {
            String::new()
        },
        remedies.join(", "),
    )
}
