//! The generalised Newton method on (u, lambda) for one increment: residual norms and the
//! merit function, the divergence guard, anti-cycling (freeze and release) and the linear
//! solve of each iteration.
//!
//! [`Newton`] is a value that borrows, immutably, the parts of the committed state an
//! increment reads (its fields are the whole list), so a trial cannot touch committed
//! state: it returns a [`Trial`] that the simulation commits or drops. The wing's other
//! files add the steps of one iteration to it: the predictor (`predictor`), the line
//! search (`line_search`), status prediction (`status_prediction`), anti-cycling
//! (`cycling`) and pseudo-transient continuation (`pseudo_transient`).

pub mod cycling;
pub mod line_search;
pub mod predictor;
pub mod pseudo_transient;
pub mod status_prediction;

use crate::contact::ContactNodeState;
use crate::contact::{ContactStatus, FrameUpdate};
use crate::error::Failure;
use crate::geometry::Vec3;
use crate::interrupt::Interrupt;
use crate::material::PointState;
use crate::solver::assembly::force_control;
use crate::solver::assembly::DofMap;
use crate::solver::assembly::{Evaluation, FrozenFrame, IncrementContext, PhaseTimes};
use crate::solver::linear::condense::Condenser;
use crate::solver::linear::LinearSolver;
use crate::solver::model::Model;
use crate::solver::newton::cycling::{CyclingMonitor, CyclingNode};
use crate::solver::newton::pseudo_transient::PseudoTransient;
use crate::solver::settings::{SolverSettings, StepSettings};
use crate::solver::sparse::SparsePattern;
use crate::{Error, Result};
use std::sync::Arc;
use std::time::Instant;

/// Consecutive merit increases that count as divergence.
const DIVERGENCE_ITERATIONS: usize = 3;
/// How many times a converged frozen state may be released and frozen again in one
/// increment (see `cycling`); after that the free law alone decides.
const MAX_RELEASES: usize = 3;
/// How many times the first force residual of an attempt (above the tolerance) its force
/// residual may reach from the second iterate on, in a model with force-controlled tools
/// that all pressed at the committed state, before the attempt counts as diverging (see
/// [`DivergenceGuard`]).
const FORCE_GROWTH_LIMIT: f64 = 3.0;
/// How much larger than the unextrapolated start's merit the extrapolated start's may be
/// before it is dropped (see `Newton::first_iterate`).
const EXTRAPOLATION_GUARD: f64 = 10.0;

/// One increment's Newton solve, borrowing what it reads of the model and of the committed
/// state (built by `Simulation::newton`). Everything an attempt changes lives in its own
/// copies (the iterate, the [`IncrementContext`]) and leaves in the [`Trial`].
pub struct Newton<'a> {
    pub(crate) model: &'a Model,
    pub(crate) dofs: &'a DofMap,
    pub(crate) pattern: &'a Arc<SparsePattern>,
    /// Whether each unknown is prescribed (a Dirichlet row).
    pub(crate) is_fixed: &'a [bool],
    /// The rows of `is_fixed` held at their committed values (a step's supports,
    /// `simulation::release`): every iterate starts there.
    pub(crate) held: &'a [usize],
    /// The multiplier elimination, when there is one.
    pub(crate) condenser: Option<&'a Condenser>,
    /// The committed time and unknowns [u, lambda].
    pub(crate) time: f64,
    pub(crate) x: &'a [f64],
    /// Committed material point states, contact states per tool and candidate, and what
    /// the elements remembered at the last converged iterate (`ElementMemory`).
    pub(crate) points: &'a [PointState],
    pub(crate) contact: &'a [Vec<ContactNodeState>],
    pub(crate) committed_memory: &'a [f64],
    /// The committed state's element forces, when kept (`committed_residual`).
    pub(crate) committed_forces: Option<&'a [f64]>,
    /// The committed forces were dropped by a restore (restart or rollback), where the run
    /// that reached this state had them: the element pass that recovers them is timed but
    /// not counted, so that a restarted run counts the evaluations of the uninterrupted one.
    pub(crate) forces_lost_by_restore: bool,
    /// The last converged increment (dt, change of the displacements), for the predictor.
    pub(crate) last_step: Option<&'a (f64, Vec<f64>)>,
    /// Stop request polled between iterations.
    pub(crate) interrupt: &'a Interrupt,
}

impl<'a> Newton<'a> {
    /// The evaluation context of an increment to `time` against the committed state.
    pub(crate) fn context(
        &self,
        time: f64,
        frozen: Option<Vec<Vec<Option<FrozenFrame>>>>,
    ) -> IncrementContext<'a> {
        IncrementContext {
            model: self.model,
            dofs: self.dofs,
            pattern: self.pattern.clone(),
            time,
            poses: self
                .model
                .contacts
                .iter()
                .map(|c| c.tool.pose(time))
                .collect(),
            committed_points: self.points,
            committed_contact: self.contact,
            committed_x: self.x,
            frozen,
            is_fixed: self.is_fixed,
            forced: None,
            element_memory: self.committed_memory.to_vec().into(),
            keep_element_jacobian: self.model.settings.status_prediction > 0,
            element_buffers: Default::default(),
        }
    }

    /// `Error::Interrupted` once a stop was requested, or once the process's peak memory
    /// passed the run's bound (`Interrupt::memory_over`: the flag stays down, so callers
    /// tell the two apart); the committed state stays.
    pub(crate) fn check_interrupt(&self) -> Result<()> {
        let why = if self.interrupt.is_raised() {
            self.interrupt.reason()
        } else if let Some(over) = self.interrupt.memory_over() {
            over
        } else {
            return Ok(());
        };
        Err(Error::Interrupted(format!(
            "{why}; the increment from t = {} was abandoned",
            self.time
        )))
    }

    /// Committed displacement of a node.
    fn displacement(&self, node: usize) -> Vec3 {
        Vec3::new(self.x[3 * node], self.x[3 * node + 1], self.x[3 * node + 2])
    }
}

/// One Newton iteration's residual norms.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct IterationRecord {
    /// Force residual (2-norm over free displacement dofs) divided by the reference force.
    pub force_rel: f64,
    /// Force residual 2-norm (force units).
    pub force: f64,
    /// Contact residual (max |F_suppl|, length units).
    pub contact: f64,
    /// Contact pairs whose status differs from the previous iterate's (0 at the first
    /// iterate of an increment): Newton's local (quadratic) phase is the iterates after the
    /// last change.
    #[serde(default)]
    pub status_changes: usize,
    /// Material points that started or stopped yielding in this increment since the previous
    /// iterate (the material's own active set; 0 at the first iterate).
    #[serde(default)]
    pub yield_changes: usize,
    /// Whether this iterate was reached by a whole Newton step (no line-search cut; true at
    /// the first iterate).
    #[serde(default = "full_step_default")]
    pub full_step: bool,
    /// 2-norm of the displacement part of the Newton correction solved at this iterate (0
    /// at the converged iterate, where none is solved).
    #[serde(default)]
    pub correction: f64,
}

impl IterationRecord {
    /// The residual norms of an iterate (force against `reference`), as a whole step with
    /// no change and no correction yet: the Newton loop fills those in.
    fn new(force: f64, contact: f64, reference: f64) -> Self {
        IterationRecord {
            force_rel: force / reference,
            force,
            contact,
            status_changes: 0,
            yield_changes: 0,
            full_step: true,
            correction: 0.0,
        }
    }
}

fn full_step_default() -> bool {
    true
}

/// Which attempt at an increment a Newton iteration is (module `stepping`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Attempt {
    /// Newton as configured: status prediction, the settings' budget, the divergence guard.
    Regular,
    /// The first last resort at the smallest part: plain Newton (no status prediction), a
    /// longer budget, no divergence guard.
    LongPlain,
    /// The second: pseudo-transient continuation.
    Continuation,
}

impl Attempt {
    /// The attempt to make where this one failed at the smallest part.
    pub(super) fn next(self) -> Option<Attempt> {
        match self {
            Attempt::Regular => Some(Attempt::LongPlain),
            Attempt::LongPlain => Some(Attempt::Continuation),
            Attempt::Continuation => None,
        }
    }

    /// How reports and messages name it.
    pub(super) fn name(self) -> &'static str {
        match self {
            Attempt::Regular => "Newton",
            Attempt::LongPlain => "plain Newton with a longer budget",
            Attempt::Continuation => "pseudo-transient continuation",
        }
    }
}

/// What the divergence guards read of an attempt so far.
struct Progress<'r> {
    /// Every iterate's record, the current one last.
    residuals: &'r [IterationRecord],
    /// Every iterate's merit, the current one last.
    merits: &'r [f64],
    /// Where the merits that count for divergence start (after a freeze, a release or a
    /// step accepted by the contraction test).
    window_start: usize,
    /// Newton steps taken.
    iterations: usize,
}

/// The divergence guards of an attempt: a run of merit increases (models without force
/// control), a force residual grown a millionfold (any), and a force residual grown
/// `FORCE_GROWTH_LIMIT` times its first value (force-controlled models whose tools all
/// pressed at the committed state). The last resorts run without the first and the last.
struct DivergenceGuard {
    attempt: Attempt,
    /// While a force-controlled tool's force comes on, the body's residual rises from zero
    /// for several iterations by design: there, only a residual grown a millionfold counts
    /// as divergence, not a run of increases.
    force_controlled: bool,
    /// Once every such tool pressed at the committed state its force is on, and a force
    /// residual grown `FORCE_GROWTH_LIMIT` times its first value after two Newton steps is
    /// an attempt gone astray. Measured (BENCHMARKS.md): on the U-channel (tests/scenes,
    /// punch at zero gap) the attempts that converged stayed within 1.35 times their first
    /// force residual from the second iterate on, while 44 of the 76 that failed passed 3
    /// times and then spent 377 iterations before their end, at force residuals of
    /// 1e4-1e5 N where the solution's internal forces are 200 N; on the solid-shell
    /// benchmark cup the converged attempts stayed within 0.93 times. The first step may
    /// raise it more (a bent sheet's membrane forces: up to 5.1 times on that cup, in
    /// attempts that converged). A run of merit increases, the guard without force
    /// control, ended few of the U-channel's failing attempts.
    forces_on: bool,
}

impl DivergenceGuard {
    fn new(newton: &Newton<'_>, attempt: Attempt) -> Self {
        let offsets = &newton.dofs.tool_offset;
        let force_controlled = offsets.iter().any(Option::is_some);
        let forces_on = force_controlled
            && (0..newton.model.contacts.len())
                .filter(|&c| offsets[c].is_some())
                .all(|c| {
                    newton.contact[c]
                        .iter()
                        .any(|s| s.status != ContactStatus::Gap)
                });
        DivergenceGuard {
            attempt,
            force_controlled,
            forces_on,
        }
    }

    /// The kind and the description of the divergence of the last iterate of `progress`,
    /// if it diverges (`force_ok`: its force residual is within its tolerance, where growth
    /// is round-off).
    fn check(
        &self,
        progress: &Progress<'_>,
        settings: &SolverSettings,
        force_ok: bool,
    ) -> Option<(Failure, String)> {
        let Progress {
            residuals,
            merits,
            window_start,
            iterations,
        } = *progress;
        let rec = residuals.last()?;
        let merit = *merits.last()?;
        // Growth is measured from the first residual above the tolerance: an increment
        // driven only by a force-controlled tool starts from a zero (or round-off) force
        // residual, which is no scale for growth.
        let first_record = residuals
            .iter()
            .find(|r| r.force_rel > settings.force_rel_tol);
        let first = first_record.map_or(f64::INFINITY, |r| r.force_rel);
        let first_force = first_record.map_or(f64::INFINITY, |r| r.force);
        let first_merit = merits.iter().copied().find(|&v| v > 0.0).unwrap_or(0.0);
        let grew = self.attempt == Attempt::Regular
            && !self.force_controlled
            && merits.len() > window_start + DIVERGENCE_ITERATIONS
            && merits[merits.len() - 1 - DIVERGENCE_ITERATIONS..]
                .windows(2)
                .all(|w| w[1] > w[0])
            && merit > first_merit
            // Growth of a force residual already below its tolerance is round-off.
            && !force_ok;
        if grew || (iterations >= 4 && rec.force_rel > 1e6 * first) {
            return Some((
                Failure::Diverged,
                format!(
                    "Newton diverges (force residual grew to {:.3e} relative)",
                    rec.force_rel
                ),
            ));
        }
        if self.attempt == Attempt::Regular
            && self.forces_on
            && iterations >= 2
            && rec.force > FORCE_GROWTH_LIMIT * first_force
            && !force_ok
        {
            return Some((
                Failure::ForceGrowth,
                format!(
                    "Newton diverges (force residual grew to {:.1} times its first value, {:.3e} relative)",
                    rec.force / first_force,
                    rec.force_rel
                ),
            ));
        }
        None
    }
}

/// A converged Newton solve of one increment, not yet committed.
pub(super) struct Trial {
    pub(super) x: Vec<f64>,
    pub(super) eval: Evaluation,
    pub(super) iterations: usize,
    pub(super) residuals: Vec<IterationRecord>,
    pub(super) times: PhaseTimes,
    pub(super) cycling: Vec<CyclingNode>,
    pub(super) line_search_cuts: usize,
    /// What the elements remembered at the converged iterate.
    pub(super) element_memory: Vec<f64>,
}

/// Nodes listed by name in a cycling message; the rest are counted. On the 50 x 50 x 2
/// benchmark cup's first increment over a thousand nodes cycle, and the whole list made
/// each cutback reason (in summary.json and on the terminal) kilobytes long.
const LISTED_CYCLING_NODES: usize = 12;

/// The clause a failed increment's message gets for the nodes whose status cycled.
fn cycling_note(nodes: &[usize]) -> String {
    match nodes.len() {
        0 => String::new(),
        n if n <= LISTED_CYCLING_NODES => format!("; status cycling at node(s) {nodes:?}"),
        n => format!(
            "; status cycling at {n} node(s), among them {:?} and {} more",
            &nodes[..LISTED_CYCLING_NODES],
            n - LISTED_CYCLING_NODES
        ),
    }
}

impl Newton<'_> {
    /// Solves J dx = -R, through the condensed system when multipliers are eliminated.
    pub fn newton_step(
        &self,
        eval: &Evaluation,
        linear: &mut dyn LinearSolver,
    ) -> Result<Vec<f64>> {
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

    /// The contraction test for a full Newton step `dx` that raised the merit `|R|`, from
    /// the state evaluated as `at_x` to the one evaluated as `trial`: the step is good if
    /// it changed no contact status (a smooth step; otherwise the merit decides) and the
    /// next Newton correction `dx' = -J(x + dx)⁻¹ R(x + dx)` is shorter,
    /// `Θ = |dx'| / |dx| <= 3/4` (displacement parts; Θ is the contraction factor of
    /// Newton's convergence theory, Deuflhard, *Newton Methods for Nonlinear Problems*,
    /// 2004, sec. 2.1). Returns `dx'` if so, for the next iteration.
    ///
    /// Why: the merit `|R|` weighs each mode by its stiffness. On a thin body the
    /// membrane stiffness exceeds the bending stiffness by `(L/t)²`, so the membrane
    /// forces of a first bending iterate (stretch `θ²/2` at rotation `θ`) raise `|R|` a
    /// hundred- to ten-thousandfold although the step is good: on a 100 x 10 x 1 steel
    /// cantilever under 1 N, `|R|` goes 0.43 -> 60 N while `|dx|` goes 0.81 -> 6e-4 mm.
    /// Backtracked steps then crawl and the run stopped as diverging; full steps converge
    /// in 3 iterations. Corrections measure the error in displacements, free of that
    /// scaling. The simplified correction `J(x)⁻¹ R(x + dx)` would be cheaper but misses
    /// the tension stiffening that the first step brings in (`Θ = 53` on a fine mesh that
    /// then converges quadratically). Cost: none when accepted (`dx'` is the next step).
    fn newton_contraction(
        &self,
        at_x: &Evaluation,
        trial: &Evaluation,
        dx: &[f64],
        linear: &mut dyn LinearSolver,
    ) -> Result<Option<Vec<f64>>> {
        let smooth = at_x.nodal.iter().zip(&trial.nodal).all(|(a, b)| {
            a.iter()
                .zip(b)
                .all(|((na, _), (nb, _))| na.status == nb.status)
        });
        if !smooth {
            return Ok(None);
        }
        let n_u = 3 * self.dofs.n_nodes;
        let next = self.newton_step(trial, linear)?;
        Ok((norm(&next[..n_u]) <= 0.75 * norm(&dx[..n_u])).then_some(next))
    }

    /// Residual norms of an evaluation (the convergence measures and the merit function).
    pub(super) fn residual_record(
        &self,
        eval: &Evaluation,
        weights: &[f64],
    ) -> (IterationRecord, f64, f64) {
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
            .filter(|&c| force_control::approaching(&self.model, c, eval.time, &eval.nodal))
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
            IterationRecord::new(force, contact, reference),
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

    /// The Dirichlet predictor and the prescribed values of the increment applied to a
    /// first iterate.
    fn start_iterate(
        &self,
        ctx: &IncrementContext<'_>,
        t_new: f64,
        x: &mut [f64],
        linear: &mut dyn LinearSolver,
        times: &mut PhaseTimes,
    ) -> Result<()> {
        for &d in self.held {
            x[d] = self.x[d];
        }
        self.dirichlet_predictor(ctx, t_new, x, linear, times)?;
        for bc in &self.model.dirichlet {
            let v = bc.value.value(t_new);
            for &node in &bc.nodes {
                x[3 * node + bc.component] = v;
            }
        }
        Ok(())
    }

    /// The residual-only evaluation at `plain`, the committed unknowns with this
    /// increment's prescribed values (the extrapolation guard's reference). Where those
    /// leave the displacements as committed, the elements' forces there are the committed
    /// state's, kept from its converged evaluation, and only loads and contact are
    /// evaluated: the elements do not run (on the 25 x 25 x 1 cup that pass was 60 of the
    /// run's 67 residual-only element evaluations). The guard compares merits tenfold
    /// apart, so the forces' round-off against a fresh pass (a zero increment from the
    /// committed state) cannot change its choice.
    fn committed_residual(
        &self,
        ctx: &IncrementContext<'_>,
        plain: &[f64],
        times: &mut PhaseTimes,
    ) -> Result<Evaluation> {
        let n_u = 3 * self.dofs.n_nodes;
        match &self.committed_forces {
            Some(f_int) if plain[..n_u] == self.x[..n_u] => {
                ctx.residual_with_forces(plain, f_int.to_vec(), times)
            }
            None if self.forces_lost_by_restore && plain[..n_u] == self.x[..n_u] => {
                let mut own = PhaseTimes::default();
                let eval = ctx.evaluate_residual(plain, &mut own)?;
                times.add_times(&own);
                Ok(eval)
            }
            _ => ctx.evaluate_residual(plain, times),
        }
    }

    /// Newton's method for the increment to `t_new`, with `prediction` status-prediction
    /// rounds per step (`Settings::status_prediction`, or 0 for the plain step) and at most
    /// `max_iterations` iterations. A last-resort `attempt` runs without the divergence
    /// guard; [`Attempt::Continuation`] solves each step from a shifted Jacobian
    /// ([`PseudoTransient`]).
    ///
    /// Each iteration: anti-cycling's freeze or release, the residual record, the
    /// convergence test, the budget and the divergence guards ([`DivergenceGuard`]), the
    /// Newton correction ([`Self::correction`]) and the line search with the contraction
    /// test ([`Self::search`]).
    pub(in crate::solver) fn solve(
        &self,
        t_new: f64,
        linear: &mut dyn LinearSolver,
        prediction: usize,
        max_iterations: usize,
        attempt: Attempt,
        times: &mut PhaseTimes,
    ) -> Result<Trial> {
        let mut continuation = (attempt == Attempt::Continuation).then(PseudoTransient::new);
        let mut settings = self.model.settings.clone();
        settings.status_prediction = prediction;
        settings.max_iterations = max_iterations;
        let step = &settings.stepping;
        let mut ctx = self.increment_context(t_new, settings.contact.frame);
        let n_u = 3 * self.dofs.n_nodes;
        let weights = self.merit_weights();
        let guard = DivergenceGuard::new(self, attempt);
        let mut monitor = self.cycling_monitor(step);
        let node_of = |c: usize, k: usize| self.model.contacts[c].candidates[k];
        let (mut x, mut eval) =
            self.first_iterate(&ctx, t_new, settings.extrapolate, &weights, linear, times)?;
        let mut residuals = Vec::new();
        let mut statuses: Vec<Vec<ContactStatus>> = Vec::new();
        let mut yielding: Vec<bool> = Vec::new();
        let mut arrived_whole = true;
        let mut merits: Vec<f64> = Vec::new();
        let mut iterations = 0;
        let mut line_search_cuts = 0;
        // Merits before a freeze belong to another problem: divergence is judged after it.
        let mut window_start = 0;
        let mut releases = 0;
        // The Newton correction at `eval`, when the contraction test already solved for it.
        let mut next_step: Option<Vec<f64>> = None;
        loop {
            self.check_interrupt()?;
            if monitor.observe(|c, k| eval.nodal[c][k].0.status) {
                ctx.forced = monitor.forced();
                eval = ctx.evaluate(&x, times)?;
                window_start = merits.len();
                next_step = None;
            }
            let (mut rec, merit, reference) = self.residual_record(&eval, &weights);
            rec.status_changes = status_changes(&mut statuses, &eval);
            rec.yield_changes = yield_changes(&mut yielding, self.points, &eval);
            rec.full_step = arrived_whole;
            residuals.push(rec);
            merits.push(merit);
            // A failure of this attempt: its kind, and the nodes whose status cycled named
            // at the end of its message.
            let failure = |kind: Failure, message: String| {
                let nodes: Vec<usize> = monitor.report(node_of).iter().map(|n| n.node).collect();
                Error::NoConvergence {
                    kind,
                    cycling: !nodes.is_empty(),
                    message: format!("{message}{}", cycling_note(&nodes)),
                }
            };
            if !(rec.force.is_finite() && rec.contact.is_finite()) {
                return Err(Error::no_convergence(
                    Failure::NonFinite,
                    format!("non-finite residual at iteration {iterations}"),
                ));
            }
            let force_ok = rec.force <= force_tolerance(&settings, reference);
            // An element whose local solve stopped early (an inexact iterate, see
            // `LocalSolve`) keeps Newton going: the next, smaller step makes it exact, so a
            // converged state is always the tight local tolerance's.
            if force_ok && rec.contact <= settings.contact_tol && eval.approximate_elements == 0 {
                // Converged with frozen statuses: only the free law's solution counts, so
                // Newton goes on unfrozen from this state, near the solution. After the
                // last allowed release nothing is frozen again, so no frozen state is
                // ever accepted.
                if ctx.forced.is_some() {
                    releases += 1;
                    monitor.release(releases < MAX_RELEASES);
                    ctx.forced = None;
                    eval = ctx.evaluate(&x, times)?;
                    window_start = merits.len();
                    next_step = None;
                    continue;
                }
                break;
            }
            if iterations >= settings.max_iterations {
                let what = format!(
                    "{iterations} Newton iterations without convergence (force residual {:.3e} relative, contact residual {:.3e})",
                    rec.force_rel, rec.contact
                );
                return Err(failure(
                    Failure::Stalled,
                    format!("{what}; {}", self.locate(&eval)),
                ));
            }
            let history = Progress {
                residuals: &residuals,
                merits: &merits,
                window_start,
                iterations,
            };
            if let Some((kind, what)) = guard.check(&history, &settings, force_ok) {
                return Err(failure(kind, format!("{what}; {}", self.locate(&eval))));
            }
            // An iterate evaluated for its residual only, expected to converge, that did not.
            if !eval.has_jacobian() {
                eval = ctx.complete(&x, eval, times)?;
            }
            let dx = self.correction(
                &mut ctx,
                &x,
                &mut eval,
                next_step.take(),
                continuation.as_mut(),
                merit,
                settings.status_prediction,
                linear,
                times,
            )?;
            if let Some(last) = residuals.last_mut() {
                last.correction = norm(&dx[..n_u]);
            }
            let converges = converges_next(&residuals, &settings, reference);
            let damping = monitor.damping();
            let (x_new, eval_new, cuts, contracted) = self.search(
                &ctx, &x, &dx, &eval, merit, damping, &weights, converges, linear, times,
            )?;
            // A full step accepted by the contraction test may raise |R|: the merits
            // before it are no scale for divergence.
            if contracted.is_some() {
                window_start = merits.len();
            }
            next_step = contracted;
            line_search_cuts += cuts;
            arrived_whole = cuts == 0 && damping == 1.0;
            x = x_new;
            eval = eval_new;
            iterations += 1;
        }
        Ok(Trial {
            x,
            eval,
            iterations,
            residuals,
            times: *times,
            cycling: monitor.report(node_of),
            line_search_cuts,
            element_memory: ctx.element_memory.into_inner(),
        })
    }

    /// The evaluation context of the increment to `t_new`, with the contact frames of the
    /// committed state kept through it under `FrameUpdate::Frozen`.
    fn increment_context(&self, t_new: f64, frame: FrameUpdate) -> IncrementContext<'_> {
        let frozen = match frame {
            FrameUpdate::EveryIteration => None,
            FrameUpdate::Frozen => Some(self.frozen_frames(t_new)),
        };
        self.context(t_new, frozen)
    }

    /// Anti-cycling's watch over every (tool, candidate) pair's status.
    fn cycling_monitor(&self, step: &StepSettings) -> CyclingMonitor {
        let sizes: Vec<usize> = self
            .model
            .contacts
            .iter()
            .map(|c| c.candidates.len())
            .collect();
        CyclingMonitor::new(&sizes, step.anti_cycling, step.cycle_flips)
    }

    /// The weights of the multiplier rows in the merit function: each contact row (a
    /// length) times its node's r, a force; a force-controlled tool's force row (a length:
    /// force error / r_s) times r_s, as a force error (its approach row does not count,
    /// see `residual_record`).
    fn merit_weights(&self) -> Vec<f64> {
        let n_u = 3 * self.dofs.n_nodes;
        let mut weights = vec![0.0; self.dofs.n_dofs - n_u];
        for (c, contact) in self.model.contacts.iter().enumerate() {
            if let Some(off) = self.dofs.lambda_offset[c] {
                for (k, r) in contact.r.iter().enumerate() {
                    weights[off - n_u + 3 * k..off - n_u + 3 * k + 3].fill(*r);
                }
            }
            if let Some(s) = self.dofs.tool_offset[c] {
                weights[s - n_u] = force_control::row_scale(self.model, c);
            }
        }
        weights
    }

    /// The first iterate of an increment to `t_new` and its evaluation: the committed
    /// unknowns, extrapolated from the last increment when `extrapolate` says so (unless
    /// that start's merit is tenfold the unextrapolated one's), with the Dirichlet
    /// predictor and the increment's prescribed values, force-controlled tools touching
    /// nothing seated on their nearest node.
    fn first_iterate(
        &self,
        ctx: &IncrementContext<'_>,
        t_new: f64,
        extrapolate: bool,
        weights: &[f64],
        linear: &mut dyn LinearSolver,
        times: &mut PhaseTimes,
    ) -> Result<(Vec<f64>, Evaluation)> {
        let mut x = self.x.to_vec();
        let unextrapolated = (extrapolate && self.last_step.is_some()).then(|| x.clone());
        if extrapolate {
            self.extrapolate(t_new, &mut x);
        }
        // Named in the error: a first iterate that cannot be evaluated (an element inverted
        // by the extrapolated guess, say) fails the attempt before Newton starts.
        let first = if unextrapolated.is_some() {
            "at the first iterate (extrapolated from the last increment)"
        } else {
            "at the first iterate"
        };
        let mut eval = self
            .start_iterate(ctx, t_new, &mut x, linear, times)
            .and_then(|()| ctx.evaluate(&x, times))
            .map_err(|err| crate::element::prefix(err, first))?;
        // The extrapolated start is a guess that the increment continues the last one's
        // motion. Where it does not (a rotating thin beam: continued linearly, a rotation
        // stretches the fibres, whose membrane stiffness is (L/t)^2 times the bending one),
        // it can start Newton far outside its basin: on a cantilever turning 0.25 rad per
        // increment the extrapolated start had 200 times the merit of the committed one and
        // the increment failed. So a start whose merit exceeds the unextrapolated start's
        // tenfold is dropped (one residual-only evaluation per increment; in forming the
        // extrapolated start is the better one by far: a tool moved without the sheet
        // penetrates it).
        if let Some(mut plain) = unextrapolated {
            self.start_iterate(ctx, t_new, &mut plain, linear, times)?;
            let merit_of = |e: &Evaluation| self.residual_record(e, weights).1;
            let extrapolated = merit_of(&eval);
            let committed = self
                .committed_residual(ctx, &plain, times)
                .map(|e| merit_of(&e))
                .unwrap_or(f64::INFINITY);
            if !(extrapolated <= EXTRAPOLATION_GUARD * committed) && committed.is_finite() {
                x = plain;
                eval = ctx.evaluate(&x, times)?;
            }
        }
        if self.seat_force_controlled_tools(&eval, &mut x) {
            eval = ctx.evaluate(&x, times)?;
        }
        Ok((x, eval))
    }

    /// The Newton correction at `x` (evaluated as `eval`, with its Jacobian): the one the
    /// contraction test already solved (`solved`), or one solved now, from the Jacobian
    /// shifted by pseudo-transient continuation when it runs; then re-solved with status
    /// prediction (`prediction` rounds), unless anti-cycling froze statuses, which are a
    /// problem of their own.
    #[allow(clippy::too_many_arguments)]
    fn correction(
        &self,
        ctx: &mut IncrementContext<'_>,
        x: &[f64],
        eval: &mut Evaluation,
        solved: Option<Vec<f64>>,
        continuation: Option<&mut PseudoTransient>,
        merit: f64,
        prediction: usize,
        linear: &mut dyn LinearSolver,
        times: &mut PhaseTimes,
    ) -> Result<Vec<f64>> {
        let n_u = 3 * self.dofs.n_nodes;
        times.newton_steps += 1;
        let ts = Instant::now();
        let dx = match (solved, continuation) {
            (Some(dx), _) => dx,
            (None, Some(ptc)) => {
                let sigma = ptc.shift(merit);
                PseudoTransient::step(self, eval, n_u, sigma, linear)?
            }
            (None, None) => self.newton_step(eval, linear)?,
        };
        let dx = if prediction > 0 && ctx.forced.is_none() {
            self.status_consistent_step(ctx, x, eval, dx, linear, times, prediction)?
        } else {
            dx
        };
        times.factorization_and_solve += ts.elapsed().as_secs_f64();
        Ok(dx)
    }

    /// The line search along `dx` from `x` (evaluated as `eval`, merit `merit`), scaled by
    /// anti-cycling's `damping`, with the contraction test for a full step that raises the
    /// merit ([`Self::newton_contraction`]); a step that brings a force-controlled tool to
    /// first touch is taken whole (the merit cannot judge it: its force row only starts to
    /// count once touching). `converges`: the next iterate is expected to converge
    /// ([`converges_next`]). Returns the new iterate, its evaluation, the line search's cuts
    /// and the next Newton correction when the contraction test solved it.
    #[allow(clippy::too_many_arguments)]
    fn search(
        &self,
        ctx: &IncrementContext<'_>,
        x: &[f64],
        dx: &[f64],
        eval: &Evaluation,
        merit: f64,
        damping: f64,
        weights: &[f64],
        converges: bool,
        linear: &mut dyn LinearSolver,
        times: &mut PhaseTimes,
    ) -> Result<(Vec<f64>, Evaluation, usize, Option<Vec<f64>>)> {
        let approach = (0..self.model.contacts.len())
            .any(|c| force_control::approaching(self.model, c, eval.time, &eval.nodal));
        let mut contracted = None;
        let mut contraction_time = 0.0;
        let (x_new, eval_new, cuts) = self.line_search(
            ctx,
            x,
            dx,
            if approach { f64::INFINITY } else { merit },
            damping,
            weights,
            &mut |trial| {
                let ts = Instant::now();
                contracted = self.newton_contraction(eval, trial, dx, linear)?;
                contraction_time += ts.elapsed().as_secs_f64();
                Ok(contracted.is_some())
            },
            converges,
            times,
        )?;
        times.factorization_and_solve += contraction_time;
        Ok((x_new, eval_new, cuts, contracted))
    }

    pub(super) fn frozen_frames(&self, t_new: f64) -> Vec<Vec<Option<FrozenFrame>>> {
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
}

/// The force residual an iterate converges at: the relative tolerance of `reference`, or
/// the absolute one, whichever is larger.
fn force_tolerance(settings: &SolverSettings, reference: f64) -> f64 {
    (settings.force_rel_tol * reference).max(settings.force_abs_tol)
}

/// How far below its tolerance Newton's quadratic model must put the next iterate's
/// residuals for [`converges_next`] to expect convergence.
const CONVERGENCE_MARGIN: f64 = 0.1;

/// Whether the iterate after the last of `records` is expected to converge, so that it is
/// evaluated for its residual first and its Jacobian computed only if it is needed after
/// all (a converged iterate's Jacobian is never used: one element tangent pass per
/// increment). Expected when the last iterate changed no contact status and no yielding
/// point and was a whole step, and the quadratic model of Newton's local phase,
/// `r_next = r^3 / r_prev^2` (`r = C r_prev^2`, the same `C` once more), puts both the
/// force and the contact residual below [`CONVERGENCE_MARGIN`] of their tolerances. Only
/// the cost depends on it: a residual-only evaluation completed afterwards equals a full
/// one bit for bit (`IncrementContext::complete`), and a wrong guess costs one
/// residual-only element pass.
fn converges_next(records: &[IterationRecord], settings: &SolverSettings, reference: f64) -> bool {
    let [.., before, last] = records else {
        return false;
    };
    if last.status_changes != 0 || last.yield_changes != 0 || !last.full_step {
        return false;
    }
    let below = |now: f64, before: f64, tolerance: f64| {
        let limit = CONVERGENCE_MARGIN * tolerance;
        now <= limit || (now < before && now.powi(3) <= limit * before * before)
    };
    below(
        last.force,
        before.force,
        force_tolerance(settings, reference),
    ) && below(last.contact, before.contact, settings.contact_tol)
}

/// How many contact pairs of `eval` have another status than in `previous` (none when
/// `previous` is empty, at the first iterate); `previous` becomes `eval`'s statuses.
fn status_changes(previous: &mut Vec<Vec<ContactStatus>>, eval: &Evaluation) -> usize {
    let now: Vec<Vec<ContactStatus>> = eval
        .nodal
        .iter()
        .map(|list| list.iter().map(|(n, _)| n.status).collect())
        .collect();
    let changes = previous
        .iter()
        .flatten()
        .zip(now.iter().flatten())
        .filter(|(a, b)| a != b)
        .count();
    *previous = now;
    changes
}

/// How many material points of `eval` yield (plastic strain grown over the committed
/// state) where they did not at the previous iterate, or the reverse; `previous` (empty at
/// the first iterate) becomes `eval`'s flags.
fn yield_changes(
    previous: &mut Vec<bool>,
    committed: &[crate::material::PointState],
    eval: &Evaluation,
) -> usize {
    let now: Vec<bool> = eval
        .trial_points
        .iter()
        .zip(committed)
        .map(|(t, c)| t.eq_plastic_strain > c.eq_plastic_strain)
        .collect();
    let changes = previous.iter().zip(&now).filter(|(a, b)| a != b).count();
    *previous = now;
    changes
}

/// Euclidean norm.
pub(super) fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;
    use crate::solver::test_models::strip_under_roller;
    use crate::solver::Simulation;
    use crate::tool::schedule::Schedule;

    /// The Hill48 strip under a rough roller pressed (to t = 0.5) and dragged (to 1), in
    /// 8 increments.
    fn pressed_and_dragged_strip() -> Simulation {
        let drag = Schedule::new(vec![
            (0.0, Vec3::zeros()),
            (0.5, Vec3::new(0.0, 0.0, -0.05)),
            (1.0, Vec3::new(1.0, 0.0, -0.05)),
        ])
        .unwrap();
        let mut model = strip_under_roller(100.0, 2.0, drag, None);
        model.settings.increments = 8;
        Simulation::new(model).unwrap()
    }

    /// The next increment's (0.125 after the committed time) context, its start iterate
    /// (predictor and prescribed values) and the solver that predicted it.
    fn next_increment_start<'a>(
        newton: &Newton<'a>,
        times: &mut PhaseTimes,
    ) -> (
        IncrementContext<'a>,
        Vec<f64>,
        crate::solver::linear::Solver,
    ) {
        let t_next = newton.time + 0.125;
        let ctx = newton.context(t_next, None);
        let mut x = newton.x.to_vec();
        let mut linear = crate::solver::linear::Solver::default();
        newton
            .start_iterate(&ctx, t_next, &mut x, &mut linear, times)
            .unwrap();
        (ctx, x, linear)
    }

    /// The extrapolation guard's reference without an element pass
    /// (`Newton::committed_residual`): after increments of a Hill48 strip (finite
    /// strain, yielding) pressed (four increments) and dragged (two) by a rough roller, the
    /// kept converged forces equal a fresh residual-only pass at the committed unknowns with
    /// the next increment's tools to round-off (a zero increment from the committed state),
    /// and so do the residuals; without kept forces (after a restore) the pass is run.
    #[test]
    fn the_guard_reference_from_kept_forces_is_a_fresh_pass() {
        let mut sim = pressed_and_dragged_strip();
        let mut times = PhaseTimes::default();
        for _ in 0..6 {
            sim.step().unwrap();
            let newton = sim.newton();
            let (ctx, plain, _) = next_increment_start(&newton, &mut times);
            let fresh = ctx.evaluate_residual(&plain, &mut times).unwrap();
            let kept = newton.committed_residual(&ctx, &plain, &mut times).unwrap();
            assert!(kept.trial_points.is_empty(), "the elements ran");
            let scale = norm(&fresh.f_int);
            let force_gap = fresh
                .f_int
                .iter()
                .zip(&kept.f_int)
                .map(|(a, b)| (a - b).abs());
            assert!(
                force_gap.fold(0.0, f64::max) <= 1e-12 * scale,
                "forces differ"
            );
            let residual_gap = fresh.residual.iter().zip(&kept.residual);
            assert!(
                residual_gap.map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) <= 1e-12 * scale,
                "residuals differ"
            );
            assert!(
                norm(&fresh.residual) > 1e-6 * scale,
                "the tools moved nothing"
            );
        }
        assert!(
            sim.points.iter().any(|p| p.eq_plastic_strain > 0.0),
            "the strip did not yield"
        );
        sim.restore_state(sim.saved_state());
        let newton = sim.newton();
        let t_next = newton.time + 0.125;
        let ctx = newton.context(t_next, None);
        let plain = newton.x.to_vec();
        let evaluated = newton.committed_residual(&ctx, &plain, &mut times).unwrap();
        assert!(
            !evaluated.trial_points.is_empty(),
            "a restore keeps no forces"
        );
    }

    /// A line search told to expect convergence (`residual_first`) evaluates the full
    /// step for its residual only and returns it without a Jacobian; completed, that
    /// evaluation is the plain line search's, bit for bit (residual, Jacobian, contact),
    /// at the same iterate. Checked on the first three Newton steps of increments of the
    /// Hill48 strip pressed and dragged by a rough roller.
    #[test]
    fn a_residual_first_step_completed_is_the_plain_one() {
        let mut sim = pressed_and_dragged_strip();
        let mut times = PhaseTimes::default();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let mut without_jacobian = 0;
        for _ in 0..5 {
            sim.step().unwrap();
            let newton = sim.newton();
            let (ctx, mut x, mut linear) = next_increment_start(&newton, &mut times);
            let weights = vec![0.0; sim.dofs.n_dofs - 3 * sim.dofs.n_nodes];
            // The first Newton steps of the increment, each searched both ways.
            for _ in 0..3 {
                let eval = ctx.evaluate(&x, &mut times).unwrap();
                let dx = newton.newton_step(&eval, &mut linear).unwrap();
                let merit = newton.residual_record(&eval, &weights).1;
                let mut search = |residual_first: bool| {
                    let mut never = |_: &Evaluation| Ok(false);
                    newton
                        .line_search(
                            &ctx,
                            &x,
                            &dx,
                            merit,
                            1.0,
                            &weights,
                            &mut never,
                            residual_first,
                            &mut times,
                        )
                        .unwrap()
                };
                let (x_plain, plain, cuts_plain) = search(false);
                let (x_first, first, cuts_first) = search(true);
                assert_eq!(bits(&x_plain), bits(&x_first));
                assert_eq!(cuts_plain, cuts_first);
                assert!(plain.has_jacobian());
                if cuts_first == 0 {
                    assert!(!first.has_jacobian(), "an accepted full step was completed");
                    without_jacobian += 1;
                }
                assert_eq!(bits(&plain.residual), bits(&first.residual));
                let completed = ctx.complete(&x_first, first, &mut times).unwrap();
                assert_eq!(
                    bits(&plain.jacobian.values),
                    bits(&completed.jacobian.values)
                );
                assert_eq!(plain.trial_points, completed.trial_points);
                x = x_plain;
            }
        }
        assert!(without_jacobian > 0, "no full step was accepted");
    }

    /// A failure carries its kind, not only a message: an increment whose Newton runs out of
    /// its budget (one iteration, no cutback, no last resort) fails as `Stalled` at the
    /// simulation's level, with the message that says so, and commits nothing.
    #[test]
    fn an_exhausted_budget_fails_as_stalled() {
        let mut sim = pressed_and_dragged_strip();
        let mut settings = sim.model.settings.clone();
        settings.max_iterations = 1;
        settings.max_cutbacks = 0;
        settings.stepping.last_resort = false;
        sim.change_settings(settings).unwrap();
        let err = sim.step().unwrap_err();
        assert_eq!(err.failure(), (Failure::Stalled, false), "{err}");
        assert!(
            err.to_string()
                .contains("Newton iterations without convergence"),
            "{err}"
        );
        assert_eq!(sim.time, 0.0);
        assert!(sim.history.is_empty());
    }

    /// The quadratic model expects convergence in Newton's local phase only.
    #[test]
    fn convergence_is_expected_in_the_quadratic_phase_only() {
        let settings = SolverSettings::default();
        let reference = 1e3;
        let tol = force_tolerance(&settings, reference);
        let record = |force: f64, contact: f64| IterationRecord::new(force, contact, reference);
        let ctol = settings.contact_tol;
        let quadratic = [record(1e3 * tol, 1e3 * ctol), record(tol, ctol)];
        assert!(converges_next(&quadratic, &settings, reference));
        // Linear convergence: the next residual stays near the tolerance.
        let linear = [record(2.0 * tol, 2.0 * ctol), record(1.5 * tol, 1.5 * ctol)];
        assert!(!converges_next(&linear, &settings, reference));
        // The contact residual lags.
        let lagging = [record(1e3 * tol, 2.0 * ctol), record(tol, 1.5 * ctol)];
        assert!(!converges_next(&lagging, &settings, reference));
        // A residual that grew.
        let grew = [record(tol, ctol), record(2.0 * tol, 0.0)];
        assert!(!converges_next(&grew, &settings, reference));
        assert!(!converges_next(&quadratic[1..], &settings, reference));
        let mut changed = quadratic;
        changed[1].status_changes = 3;
        assert!(!converges_next(&changed, &settings, reference));
        let mut cut = quadratic;
        cut[1].full_step = false;
        assert!(!converges_next(&cut, &settings, reference));
        let mut yielding = quadratic;
        yielding[1].yield_changes = 1;
        assert!(!converges_next(&yielding, &settings, reference));
    }

    #[test]
    fn a_long_cycling_list_is_cut_and_counted() {
        assert_eq!(cycling_note(&[]), "");
        assert_eq!(cycling_note(&[3, 7]), "; status cycling at node(s) [3, 7]");
        let many: Vec<usize> = (100..1300).collect();
        let note = cycling_note(&many);
        assert!(
            note.starts_with("; status cycling at 1200 node(s), among them [100, 101,"),
            "{note}"
        );
        assert!(note.ends_with("111] and 1188 more"), "{note}");
    }
}
