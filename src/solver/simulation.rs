//! The incremental stepper: pseudo-time increments, each solved by a generalised Newton
//! method on (u, lambda), with commit of history variables on convergence and rollback
//! (halving the increment) on failure. Nothing committed is ever lost: a failed increment
//! leaves the last converged state untouched.

use super::assembly::{DofMap, Evaluation, FrozenFrame, IncrementContext, PhaseTimes};
use super::checkpoint::SavedState;
use super::condense::Condenser;
use super::cycling::{CyclingMonitor, CyclingNode};
use super::force_control;
use super::linear::{FaerLu, LinearSolver};
use super::model::Model;
use super::sparse::SparsePattern;
use super::step_control::{schedule_stops, IncrementMeasures, Limit, StepController, StepMode};
use crate::contact::{ContactNodeState, ContactStatus, FrameUpdate, FrictionInput};
use crate::element::{Element, Hex8};
use crate::geometry::Vec3;
use crate::material::PointState;
use crate::{Error, Result};
use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

/// Consecutive merit increases that count as divergence.
const DIVERGENCE_ITERATIONS: usize = 3;
/// Halvings of the line search (smallest step 1/16 of the Newton step).
const LINE_SEARCH_CUTS: usize = 4;
/// How many times a converged frozen state may be released and frozen again in one
/// increment (see `cycling`); after that the free law alone decides.
const MAX_RELEASES: usize = 3;

/// One Newton iteration's residual norms.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct IterationRecord {
    /// Force residual (2-norm over free displacement dofs) divided by the reference force.
    pub force_rel: f64,
    /// Force residual 2-norm (force units).
    pub force: f64,
    /// Contact residual (max |F_suppl|, length units).
    pub contact: f64,
}

/// What one converged increment did.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct IncrementReport {
    pub index: usize,
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
}

/// A converged Newton solve of one increment, not yet committed.
struct Trial {
    x: Vec<f64>,
    eval: Evaluation,
    iterations: usize,
    residuals: Vec<IterationRecord>,
    times: PhaseTimes,
    cycling: Vec<CyclingNode>,
    line_search_cuts: usize,
}

/// Failures after which a smaller increment may succeed.
fn retryable(err: &Error) -> bool {
    matches!(err, Error::NoConvergence(_) | Error::LinearSolver(_))
}

/// An error's message without its kind prefix, for nesting in another message.
fn bare(err: &Error) -> String {
    match err {
        Error::NoConvergence(m) | Error::LinearSolver(m) | Error::Input(m) | Error::Script(m) => {
            m.clone()
        }
        other => other.to_string(),
    }
}

/// Model plus its evolving, committed solution.
pub struct Simulation {
    pub model: Model,
    dofs: DofMap,
    pattern: Arc<SparsePattern>,
    is_fixed: Vec<bool>,
    linear: FaerLu,
    condenser: Option<Condenser>,
    /// Committed unknowns [u, lambda].
    x: Vec<f64>,
    points: Vec<PointState>,
    contact: Vec<Vec<ContactNodeState>>,
    time: f64,
    increments_done: usize,
    pub history: Vec<IncrementReport>,
    pub phase_times: PhaseTimes,
    energy: EnergyBalance,
    energy_memory: EnergyMemory,
    controller: StepController,
    /// Schedule breakpoints and the end time: adaptive increments land on them.
    stops: Vec<f64>,
    /// Committed states before the last increments, for `rollback`.
    saved: VecDeque<SavedState>,
    /// Last converged increment (dt, change of the displacements), for the extrapolating
    /// predictor.
    last_step: Option<(f64, Vec<f64>)>,
}

impl Simulation {
    /// Sets up unknowns and initial history. Fails on an invalid model.
    pub fn new(model: Model) -> Result<Self> {
        model.mesh.validate()?;
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
        force_control::check(&model)?;
        let dofs = DofMap::new(&model);
        let pattern = Arc::new(dofs.pattern(&model));
        let mut is_fixed = vec![false; dofs.n_dofs];
        for bc in &model.dirichlet {
            for &node in &bc.nodes {
                is_fixed[3 * node + bc.component] = true;
            }
        }
        let points = vec![PointState::default(); model.mesh.hexes.len() * Hex8.point_count()];
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
        let dofs_nodes = dofs.n_nodes;
        let initial_f_ext = model.external_forces(0.0);
        let condenser = if model.settings.eliminate_multipliers {
            Condenser::new(&model, &dofs, &pattern, &is_fixed)
        } else {
            None
        };
        model.settings.stepping.validate(model.settings.end_time)?;
        Ok(Simulation {
            controller: StepController::new(&model),
            stops: schedule_stops(&model),
            saved: VecDeque::new(),
            condenser,
            x: vec![0.0; dofs.n_dofs],
            dofs,
            pattern,
            is_fixed,
            linear: FaerLu::default(),
            points,
            contact,
            time: 0.0,
            increments_done: 0,
            history: Vec::new(),
            phase_times: PhaseTimes::default(),
            energy: EnergyBalance {
                frictional_dissipation: vec![0.0; model.contacts.len()],
                ..Default::default()
            },
            last_step: None,
            energy_memory: EnergyMemory {
                support_forces: vec![0.0; 3 * dofs_nodes],
                external_forces: initial_f_ext,
                tool_forces: vec![Vec3::zeros(); model.contacts.len()],
            },
            model,
        })
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    pub fn is_finished(&self) -> bool {
        self.time >= self.model.settings.end_time * (1.0 - 1e-12)
    }

    pub fn nominal_dt(&self) -> f64 {
        self.model.settings.end_time / self.model.settings.increments as f64
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

    fn context(
        &self,
        time: f64,
        frozen: Option<Vec<Vec<Option<FrozenFrame>>>>,
    ) -> IncrementContext<'_> {
        IncrementContext {
            model: &self.model,
            dofs: &self.dofs,
            pattern: self.pattern.clone(),
            time,
            poses: self
                .model
                .contacts
                .iter()
                .map(|c| c.tool.pose(time))
                .collect(),
            committed_points: &self.points,
            committed_contact: &self.contact,
            frozen,
            is_fixed: &self.is_fixed,
            forced: None,
        }
    }

    /// Solves J dx = -R, through the condensed system when multipliers are eliminated.
    pub fn newton_step(&self, eval: &Evaluation, linear: &mut FaerLu) -> Result<Vec<f64>> {
        // Tool offsets couple to every node of their tool: kept out of the sparse LU.
        let border: Vec<usize> = self.dofs.tool_offset.iter().flatten().copied().collect();
        match &self.condenser {
            Some(c) => c.solve(&eval.jacobian, &eval.residual, &border, linear),
            None => {
                let mut rhs: Vec<f64> = eval.residual.iter().map(|v| -v).collect();
                linear.solve_bordered(&eval.jacobian, &mut rhs, &border)?;
                Ok(rhs)
            }
        }
    }

    /// Multiplier unknowns eliminated before each linear solve.
    pub fn eliminated_multipliers(&self) -> usize {
        self.condenser.as_ref().map_or(0, |c| c.eliminated_count())
    }

    /// How many symbolic LU analyses were done: one per sparsity pattern, not per iteration.
    pub fn symbolic_analyses(&self) -> usize {
        self.linear.symbolic_count
    }

    /// Committed unknowns [u, lambda].
    pub fn unknowns(&self) -> &[f64] {
        &self.x
    }

    /// Residual and Jacobian at time `time` for trial unknowns `x` against the committed
    /// history (what Newton sees; used to check the Jacobian by finite differences).
    pub fn evaluate_at(&self, time: f64, x: &[f64]) -> Result<Evaluation> {
        let mut t = PhaseTimes::default();
        self.context(time, None).evaluate(x, &mut t)
    }

    /// Advances one increment. Fixed stepping: one nominal increment, halved on failure up
    /// to `max_cutbacks` times (the sub-increments are all in `history`). Adaptive stepping:
    /// one increment of the size the controller chose (see `step_control`).
    pub fn step(&mut self) -> Result<IncrementReport> {
        if self.is_finished() {
            return Err(Error::Input(format!(
                "the simulation already reached its end time {}",
                self.model.settings.end_time
            )));
        }
        match self.model.settings.stepping.mode {
            StepMode::Fixed => self.step_fixed(),
            StepMode::Adaptive => self.step_adaptive(),
        }
    }

    fn step_fixed(&mut self) -> Result<IncrementReport> {
        let target = (self.time + self.nominal_dt()).min(self.model.settings.end_time);
        let mut dt = target - self.time;
        let mut cutbacks = 0;
        loop {
            let t_new = if dt >= target - self.time {
                target
            } else {
                self.time + dt
            };
            match self.try_increment(t_new) {
                Ok(trial) => {
                    let mut report = self.accept(t_new, trial);
                    report.cutbacks = cutbacks;
                    self.history.push(report.clone());
                    if t_new < target {
                        // Finish the nominal increment with the reduced size.
                        continue;
                    }
                    return Ok(report);
                }
                Err(err) if retryable(&err) && cutbacks < self.model.settings.max_cutbacks => {
                    cutbacks += 1;
                    dt *= 0.5;
                }
                Err(err) => {
                    return Err(Error::NoConvergence(format!(
                        "increment {} from t = {} with dt = {dt} after {cutbacks} cutbacks: {}",
                        self.increments_done + 1,
                        self.time,
                        bare(&err)
                    )))
                }
            }
        }
    }

    fn step_adaptive(&mut self) -> Result<IncrementReport> {
        let step = self.model.settings.stepping.clone();
        let end = self.model.settings.end_time;
        let dt_min = step.dt_min(end);
        let mut dt = self.controller.dt.max(dt_min);
        let (mut cutbacks, mut rejected) = (0, 0);
        loop {
            let t_new = StepController::next_time(self.time, dt, &self.stops);
            let dt_used = t_new - self.time;
            match self.try_increment(t_new) {
                Ok(trial) => {
                    let measures = self.measures(&trial);
                    let verdict = self
                        .controller
                        .assess(&step, end, dt_used, &measures, trial.iterations);
                    if !verdict.accept {
                        rejected += 1;
                        dt = verdict.next_dt;
                        continue;
                    }
                    let mut report = self.accept(t_new, trial);
                    report.cutbacks = cutbacks;
                    report.rejected = rejected;
                    report.measures = measures;
                    report.limit = verdict.limit;
                    let (ratio, which) = measures.ratio(&step);
                    if ratio < 1.0 {
                        report.warnings.push(format!(
                            "{which:?} increment exceeds its limit by a factor {:.3} at the minimum step",
                            1.0 / ratio
                        ));
                    }
                    // No growth right after a cutback.
                    let next = if cutbacks > 0 {
                        verdict.next_dt.min(dt_used.max(dt_min))
                    } else {
                        verdict.next_dt
                    };
                    self.controller = StepController {
                        dt: next,
                        limit: verdict.limit,
                    };
                    report.next_dt = next;
                    self.history.push(report.clone());
                    return Ok(report);
                }
                Err(err) if retryable(&err) && dt_used > dt_min * (1.0 + 1e-9) => {
                    cutbacks += 1;
                    dt = (0.5 * dt_used).max(dt_min);
                    self.controller.limit = Limit::Divergence;
                }
                Err(err) => {
                    return Err(Error::NoConvergence(format!(
                        "increment {} from t = {} cannot be completed at the minimum step dt = {dt_used:.6e} (dt_min = {dt_min:.6e}) after {cutbacks} cutbacks: {}",
                        self.increments_done + 1,
                        self.time,
                        bare(&err)
                    )))
                }
            }
        }
    }

    /// Largest plastic strain, rotation and slip increments of a converged trial.
    fn measures(&self, trial: &Trial) -> IncrementMeasures {
        let mut m = IncrementMeasures::from_points(&self.points, &trial.eval.trial_points);
        for (c, contact) in self.model.contacts.iter().enumerate() {
            for (k, &node) in contact.candidates.iter().enumerate() {
                let (res, _) = &trial.eval.nodal[c][k];
                if res.status.is_active() {
                    m.add_slip(node, res.slip_increment.norm());
                }
            }
        }
        m
    }

    /// Commits a converged trial (keeping the state it replaces for `rollback`).
    fn accept(&mut self, t_new: f64, trial: Trial) -> IncrementReport {
        let depth = self.model.settings.stepping.rollback_depth;
        if depth > 0 {
            if self.saved.len() >= depth {
                self.saved.pop_front();
            }
            let state = self.saved_state();
            self.saved.push_back(state);
        }
        self.phase_times.elements += trial.times.elements;
        self.phase_times.contact += trial.times.contact;
        self.phase_times.factorization_and_solve += trial.times.factorization_and_solve;
        let mut report = self.commit(
            t_new,
            trial.x,
            trial.eval,
            trial.iterations,
            trial.residuals,
        );
        report.line_search_cuts = trial.line_search_cuts;
        if !trial.cycling.is_empty() {
            let nodes: Vec<String> = trial
                .cycling
                .iter()
                .map(|n| {
                    format!(
                        "{}:{} ({} flips{})",
                        self.model.contacts[n.tool].tool.name,
                        n.node,
                        n.flips,
                        n.frozen
                            .as_ref()
                            .map(|s| format!(", frozen {s}"))
                            .unwrap_or_default()
                    )
                })
                .collect();
            // A long run prints this every increment: name the first few nodes only (the
            // full list is in the report), and the free-law residual only when statuses
            // were frozen (otherwise it is the converged residual).
            const SHOWN: usize = 8;
            let more = nodes.len().saturating_sub(SHOWN);
            let frozen = trial.cycling.iter().any(|n| n.frozen.is_some());
            report.warnings.push(format!(
                "contact status cycled at {} node(s): {}{}{}",
                nodes.len(),
                nodes[..nodes.len().min(SHOWN)].join(", "),
                if more > 0 { format!(" and {more} more") } else { String::new() },
                // Frozen statuses are always released before an increment is accepted, so
                // the last residual is the free law's.
                match report.residuals.last().filter(|_| frozen) {
                    Some(free) => format!(
                        "; free-law residual at the converged state: force {:.3e} relative, contact {:.3e}",
                        free.force_rel, free.contact
                    ),
                    None => String::new(),
                }
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

    /// Newton's method for the increment ending at `t_new`, nothing committed.
    fn try_increment(&mut self, t_new: f64) -> Result<Trial> {
        // The factorization cache lives outside `self` while the context borrows it.
        let mut linear = std::mem::take(&mut self.linear);
        let outcome = self.newton(t_new, &mut linear);
        self.linear = linear;
        outcome
    }

    /// Residual norms of an evaluation (the convergence measures and the merit function).
    fn residual_record(&self, eval: &Evaluation, weights: &[f64]) -> (IterationRecord, f64, f64) {
        let settings = &self.model.settings;
        let n_u = 3 * self.dofs.n_nodes;
        let force = norm(&eval.residual[..n_u]);
        let reference = norm(&eval.f_int)
            .max(norm(&eval.f_ext))
            .max(settings.force_abs_tol);
        let contact = eval.residual[n_u..]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        // Merit: the full residual with the contact rows (lengths) scaled by r (forces). An
        // approach row is a travel to first touch, not an error to reduce: left out.
        let approach_rows: Vec<usize> = (0..self.model.contacts.len())
            .filter(|&c| force_control::approaching(&self.model, c, &eval.nodal))
            .filter_map(|c| self.dofs.tool_offset[c])
            .collect();
        let merit = (force * force
            + eval.residual[n_u..]
                .iter()
                .zip(weights)
                .enumerate()
                .filter(|(i, _)| !approach_rows.contains(&(n_u + i)))
                .map(|(_, (v, w))| (v * w).powi(2))
                .sum::<f64>())
        .sqrt();
        (
            IterationRecord {
                force_rel: force / reference,
                force,
                contact,
            },
            merit,
            reference,
        )
    }

    /// Where the residual is largest: the three nodes with the largest force residual and
    /// the contact pair with the largest constraint residual.
    fn locate(&self, eval: &Evaluation) -> String {
        let mut nodes: Vec<(usize, f64)> = (0..self.dofs.n_nodes)
            .map(|n| (n, norm(&eval.residual[3 * n..3 * n + 3])))
            .collect();
        nodes.sort_by(|a, b| b.1.total_cmp(&a.1));
        let mut text = format!(
            "largest force residual at node(s) {}",
            nodes
                .iter()
                .take(3)
                .map(|(n, r)| format!("{n} ({r:.3e})"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        let mut worst: Option<(usize, usize, f64)> = None;
        for (c, contact) in self.model.contacts.iter().enumerate() {
            if let Some(off) = self.dofs.lambda_offset[c] {
                for (k, &node) in contact.candidates.iter().enumerate() {
                    let r = norm(&eval.residual[off + 3 * k..off + 3 * k + 3]);
                    if worst.is_none_or(|w| r > w.2) {
                        worst = Some((c, node, r));
                    }
                }
            }
        }
        if let Some((c, node, r)) = worst {
            text += &format!(
                "; largest contact residual at node {node} on tool '{}' ({r:.3e})",
                self.model.contacts[c].tool.name
            );
        }
        text
    }

    fn newton(&self, t_new: f64, linear: &mut FaerLu) -> Result<Trial> {
        let settings = self.model.settings.clone();
        let step = &settings.stepping;
        let mut x = self.x.clone();
        let frozen = match settings.contact.frame {
            FrameUpdate::EveryIteration => None,
            FrameUpdate::Frozen => Some(self.frozen_frames(t_new)),
        };
        let mut ctx = self.context(t_new, frozen);
        let n_u = 3 * self.dofs.n_nodes;
        let mut weights = vec![0.0; self.dofs.n_dofs - n_u];
        for (c, contact) in self.model.contacts.iter().enumerate() {
            if let Some(off) = self.dofs.lambda_offset[c] {
                for (k, r) in contact.r.iter().enumerate() {
                    weights[off - n_u + 3 * k..off - n_u + 3 * k + 3].fill(*r);
                }
            }
            // A force-controlled tool's force row (a length: force error / r_s) enters the
            // merit times r_s, as a force error; its approach row does not (see
            // `residual_record`).
            if let Some(s) = self.dofs.tool_offset[c] {
                weights[s - n_u] = force_control::row_scale(&self.model, c);
            }
        }
        // While a force-controlled tool's force comes on, the body's residual rises from
        // zero for several iterations by design: there, only a residual grown a millionfold
        // counts as divergence, not a run of increases.
        let force_controlled = self.dofs.tool_offset.iter().any(Option::is_some);
        let sizes: Vec<usize> = self
            .model
            .contacts
            .iter()
            .map(|c| c.candidates.len())
            .collect();
        let mut monitor = CyclingMonitor::new(&sizes, step.anti_cycling, step.cycle_flips);
        let node_of = |c: usize, k: usize| self.model.contacts[c].candidates[k];
        let mut times = PhaseTimes::default();
        // The last increment's displacement change, scaled to this step: in forming the
        // sheet keeps moving the way it moved, so the first iterate starts near the right
        // contact statuses (from the committed state, Newton has to rediscover the whole
        // active set, tens of iterations on a drawn sheet).
        if let (true, Some((dt_last, dx))) = (settings.extrapolate, &self.last_step) {
            let ratio = (t_new - self.time) / dt_last;
            for (xi, d) in x[..n_u].iter_mut().zip(dx) {
                *xi += ratio * d;
            }
        }
        self.dirichlet_predictor(&ctx, t_new, &mut x, linear, &mut times)?;
        for bc in &self.model.dirichlet {
            let v = bc.value.value(t_new);
            for &node in &bc.nodes {
                x[3 * node + bc.component] = v;
            }
        }
        let mut residuals = Vec::new();
        let mut merits: Vec<f64> = Vec::new();
        let mut iterations = 0;
        let mut line_search_cuts = 0;
        let mut eval = ctx.evaluate(&x, &mut times)?;
        // Merits before a freeze belong to another problem: divergence is judged after it.
        let mut window_start = 0;
        let mut releases = 0;
        loop {
            if monitor.observe(|c, k| eval.nodal[c][k].0.status) {
                ctx.forced = monitor.forced();
                eval = ctx.evaluate(&x, &mut times)?;
                window_start = merits.len();
            }
            let (rec, merit, reference) = self.residual_record(&eval, &weights);
            residuals.push(rec);
            merits.push(merit);
            let cycling_note = || {
                let r = monitor.report(node_of);
                if r.is_empty() {
                    String::new()
                } else {
                    format!(
                        "; status cycling at node(s) {:?}",
                        r.iter().map(|n| n.node).collect::<Vec<_>>()
                    )
                }
            };
            if !(rec.force.is_finite() && rec.contact.is_finite()) {
                return Err(Error::NoConvergence(format!(
                    "non-finite residual at iteration {iterations}"
                )));
            }
            let force_ok = rec.force <= settings.force_rel_tol * reference
                || rec.force <= settings.force_abs_tol;
            if force_ok && rec.contact <= settings.contact_tol {
                // Converged with frozen statuses: only the free law's solution counts, so
                // Newton goes on unfrozen from this state, near the solution. After the
                // last allowed release nothing is frozen again, so no frozen state is
                // ever accepted.
                if ctx.forced.is_some() {
                    releases += 1;
                    monitor.release(releases < MAX_RELEASES);
                    ctx.forced = None;
                    eval = ctx.evaluate(&x, &mut times)?;
                    window_start = merits.len();
                    continue;
                }
                break;
            }
            if iterations >= settings.max_iterations {
                return Err(Error::NoConvergence(format!(
                    "{iterations} Newton iterations without convergence (force residual {:.3e} relative, contact residual {:.3e}); {}{}",
                    rec.force_rel,
                    rec.contact,
                    self.locate(&eval),
                    cycling_note()
                )));
            }
            // Growth is measured from the first residual above the tolerance: an increment
            // driven only by a force-controlled tool starts from a zero (or round-off) force
            // residual, which is no scale for growth.
            let first = residuals
                .iter()
                .map(|r| r.force_rel)
                .find(|&v| v > settings.force_rel_tol)
                .unwrap_or(f64::INFINITY);
            let first_merit = merits.iter().copied().find(|&v| v > 0.0).unwrap_or(0.0);
            let grew = !force_controlled
                && merits.len() > window_start + DIVERGENCE_ITERATIONS
                && merits[merits.len() - 1 - DIVERGENCE_ITERATIONS..]
                    .windows(2)
                    .all(|w| w[1] > w[0])
                && merit > first_merit
                // Growth of a force residual already below its tolerance is round-off.
                && !force_ok;
            if grew || (iterations >= 4 && rec.force_rel > 1e6 * first) {
                return Err(Error::NoConvergence(format!(
                    "Newton diverges (force residual grew to {:.3e} relative); {}{}",
                    rec.force_rel,
                    self.locate(&eval),
                    cycling_note()
                )));
            }
            let ts = Instant::now();
            let dx = self.newton_step(&eval, linear)?;
            times.factorization_and_solve += ts.elapsed().as_secs_f64();
            // A step that brings a force-controlled tool to first touch is taken whole: the
            // merit cannot judge it (its force row only starts to count once touching).
            let approach = (0..self.model.contacts.len())
                .any(|c| force_control::approaching(&self.model, c, &eval.nodal));
            let (x_new, eval_new, cuts) = self.line_search(
                &ctx,
                &x,
                &dx,
                if approach { f64::INFINITY } else { merit },
                monitor.damping(),
                &weights,
                &mut times,
            )?;
            line_search_cuts += cuts;
            x = x_new;
            eval = eval_new;
            iterations += 1;
        }
        Ok(Trial {
            x,
            eval,
            iterations,
            residuals,
            times,
            cycling: monitor.report(node_of),
            line_search_cuts,
        })
    }

    /// Backtracking (Armijo) line search on the merit function |R|: the step `alpha dx` with
    /// the first alpha in `alpha0, alpha0/2, ...` (down to `alpha0/16`) that reduces the merit
    /// by the factor `1 - 1e-4 alpha`; failing that, the trial with the smallest merit. A
    /// trial that inverts an element counts as an infinite merit. With the line search off,
    /// the step `alpha0 dx` is taken. Returns the new unknowns, their evaluation and the
    /// number of backtracking steps.
    #[allow(clippy::too_many_arguments)]
    fn line_search(
        &self,
        ctx: &IncrementContext<'_>,
        x: &[f64],
        dx: &[f64],
        merit0: f64,
        alpha0: f64,
        weights: &[f64],
        times: &mut PhaseTimes,
    ) -> Result<(Vec<f64>, Evaluation, usize)> {
        let trial_x =
            |alpha: f64| -> Vec<f64> { x.iter().zip(dx).map(|(xi, d)| xi + alpha * d).collect() };
        if !self.model.settings.stepping.line_search {
            let xn = trial_x(alpha0);
            let e = ctx.evaluate(&xn, times)?;
            return Ok((xn, e, 0));
        }
        let mut alpha = alpha0;
        let mut best: Option<(f64, Vec<f64>, Evaluation)> = None;
        let mut last_err = None;
        for cut in 0..=LINE_SEARCH_CUTS {
            let xn = trial_x(alpha);
            // The full step, usually accepted, is evaluated whole; a cut only for its
            // residual, and whole once accepted.
            let evaluated = if cut == 0 {
                ctx.evaluate(&xn, times)
            } else {
                ctx.evaluate_residual(&xn, times)
            };
            match evaluated {
                Ok(e) => {
                    let m = self.residual_record(&e, weights).1;
                    if m.is_finite() && m <= (1.0 - 1e-4 * alpha) * merit0 {
                        let e = if e.has_jacobian() {
                            e
                        } else {
                            ctx.evaluate(&xn, times)?
                        };
                        return Ok((xn, e, cut));
                    }
                    if m.is_finite() && best.as_ref().is_none_or(|b| m < b.0) {
                        best = Some((m, xn, e));
                    }
                }
                Err(err) => last_err = Some(err),
            }
            alpha *= 0.5;
        }
        match (best, last_err) {
            (Some((_, xn, e)), _) => {
                let e = if e.has_jacobian() {
                    e
                } else {
                    ctx.evaluate(&xn, times)?
                };
                Ok((xn, e, LINE_SEARCH_CUTS))
            }
            (None, Some(err)) => Err(err),
            (None, None) => Err(Error::NoConvergence(
                "non-finite residual at every line-search step".into(),
            )),
        }
    }

    /// Linearised Dirichlet predictor: when prescribed values change, the first update
    /// solves the tangent system at the committed state with the prescribed increments as
    /// its constraint rows, so the increment's jump spreads over the body instead of
    /// straining only the elements next to the moved nodes (such a first iterate can
    /// carry a plastic body far outside Newton's basin). For a linear problem the
    /// predictor is the solution.
    fn dirichlet_predictor(
        &self,
        ctx: &IncrementContext<'_>,
        t_new: f64,
        x: &mut [f64],
        linear: &mut FaerLu,
        times: &mut PhaseTimes,
    ) -> Result<()> {
        let jumps: Vec<(usize, f64)> = self
            .model
            .dirichlet
            .iter()
            .filter(|bc| bc.value.value(t_new) != bc.value.value(self.time))
            .flat_map(|bc| {
                let v = bc.value.value(t_new);
                bc.nodes.iter().map(move |&n| (3 * n + bc.component, v))
            })
            .collect();
        if jumps.is_empty() {
            return Ok(());
        }
        let mut eval = ctx.evaluate(x, times)?;
        for &(d, v) in &jumps {
            eval.residual[d] = x[d] - v;
        }
        let ts = Instant::now();
        let dx = self.newton_step(&eval, linear)?;
        times.factorization_and_solve += ts.elapsed().as_secs_f64();
        for (xi, d) in x.iter_mut().zip(&dx) {
            *xi += d;
        }
        Ok(())
    }

    fn frozen_frames(&self, t_new: f64) -> Vec<Vec<Option<FrozenFrame>>> {
        self.model
            .contacts
            .iter()
            .enumerate()
            .map(|(c, contact)| {
                let pose = force_control::pose(&self.model, &self.dofs, c, t_new, &self.x);
                contact
                    .candidates
                    .iter()
                    .enumerate()
                    .map(|(k, &node)| {
                        let xn = self.model.mesh.nodes[node] + self.displacement(node);
                        let hint = self.contact[c][k].hint;
                        contact
                            .tool
                            .project(&pose, &xn, hint.as_ref())
                            .map(|p| FrozenFrame {
                                foot_local: pose.to_local(&p.foot),
                                normal_local: pose.to_local_vector(&p.normal),
                            })
                    })
                    .collect()
            })
            .collect()
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
        let (mut active, mut slipping) = (0, 0);
        for (c, contact) in self.model.contacts.iter().enumerate() {
            let pose = force_control::pose(&self.model, &self.dofs, c, t_new, &x);
            let mut total = Vec3::zeros();
            for (k, &node) in contact.candidates.iter().enumerate() {
                let (res, proj) = &eval.nodal[c][k];
                let s = &mut self.contact[c][k];
                let previous_status = s.status;
                let xn = self.model.mesh.nodes[node]
                    + Vec3::new(x[3 * node], x[3 * node + 1], x[3 * node + 2]);
                // Work of the contact force on the relative motion, by the trapezoidal rule
                // like every other work term (Psi below follows the paper instead).
                let relative_motion = xn - pose.to_global_point(&s.x_ref_local);
                dissipated[c] += 0.5 * (s.lambda + res.f_equi).dot(&relative_motion);
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
                }
                s.theta = contact
                    .tool
                    .friction
                    .bernstein()
                    .map_or(0.0, |law| law.theta(s.work, area));
                total += s.lambda;
            }
            tool_forces.push([total.x, total.y, total.z]);
        }
        let energy = self.account_energy(t_new, &x, &eval, &tool_forces, &dissipated);
        let tool_offsets = (0..self.model.contacts.len())
            .map(|c| force_control::offset(&self.dofs, c, &x))
            .collect();
        let dt = t_new - self.time;
        let n_u = 3 * self.dofs.n_nodes;
        let du = x[..n_u].iter().zip(&self.x[..n_u]).map(|(a, b)| a - b);
        self.last_step = Some((dt, du.collect()));
        self.x = x;
        self.points = eval.trial_points;
        self.time = t_new;
        self.increments_done += 1;
        IncrementReport {
            index: self.increments_done,
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
        }
    }

    /// Updates the energy balance with one converged increment: trapezoidal rule for the
    /// work of tools, loads, supports and for the frictional dissipation; the elastic energy
    /// is a state function.
    fn account_energy(
        &mut self,
        t_new: f64,
        x: &[f64],
        eval: &Evaluation,
        tool_forces: &[[f64; 3]],
        dissipated: &[f64],
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
        }
        let element =
            crate::element::hexahedron(self.model.settings.kinematics, self.model.settings.fbar);
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
        {
            return Err(Error::Input(
                "enforcement, eliminate_multipliers, kinematics and fbar cannot change once the simulation has started"
                    .into(),
            ));
        }
        settings.stepping.validate(settings.end_time)?;
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
    /// Frictional dissipation per tool: the work of the contact forces on the slip,
    /// 1/2 (lambda_n + lambda_{n+1}) . delta per node and increment, the same trapezoidal
    /// rule as the other work terms, which makes the balance exact for elastic bodies. The
    /// nodes' frictional work Psi (the friction law's variable) uses the paper's
    /// lambda_{n+1} . delta_t and differs from it where the force changes within an
    /// increment (a stick-slip transition, a changing mu).
    pub frictional_dissipation: Vec<f64>,
    /// (work in - stored - dissipated) / scale.
    pub relative_error: f64,
}

/// Forces at the end of the last increment, for the trapezoidal rule.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct EnergyMemory {
    support_forces: Vec<f64>,
    external_forces: Vec<f64>,
    tool_forces: Vec<Vec3>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}
