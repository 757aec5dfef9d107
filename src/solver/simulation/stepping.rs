//! Stepping: how an increment is attempted, cut back, and tried by the last resorts
//! before a run stops.
//!
//! Fixed stepping halves a failed part of the nominal increment (at most `max_cutbacks`
//! times in a row, never below `dt_min`, the rest of the increment tried whole first
//! after a converged part); adaptive stepping halves down to `dt_min` and grows after easy
//! increments (`step_control`). Where the smallest part still fails, two last attempts at
//! it come before the run stops (setting `last_resort`, on by default), each with
//! [`LAST_RESORT_ITERATIONS`] and no divergence guard:
//!
//! 1. [`Attempt::LongPlain`]: the plain semi-smooth Newton (no status prediction). Where a
//!    few nodes touch a tool by almost nothing, Newton's march over their statuses can
//!    need more iterations than the regular budget (the U-channel's first increment at zero
//!    gap without cut-backs: 25 iterations, converged, where the regular attempts stop at
//!    30 and 20).
//! 2. [`Attempt::Continuation`]: pseudo-transient continuation (`pseudo_transient`),
//!    which damps the soft modes a full Newton step throws across a near-mechanism.
//!
//! Under fixed stepping, where both fail on the smallest part, both are tried on the rest of
//! the increment whole (a hard instant can be easier to step over than to stop just past,
//! as for the regular attempts in `step_fixed`).
//!
//! Both solve the same equations to the same tolerances; an increment that needed one says
//! so in its report (`last_resort`, a warning). Every run whose increments converge
//! without them keeps its increments bit for bit: they start only where the run would
//! have stopped.

use crate::error::Failure;
use crate::solver::assembly::PhaseTimes;
use crate::solver::linear::LinearSolver;
use crate::solver::newton::{Attempt, Trial};
use crate::solver::settings::StepMode;
use crate::solver::simulation::step_control::{IncrementMeasures, Limit, StepController};
use crate::solver::simulation::{IncrementReport, Simulation};
use crate::{Error, Result};

/// Newton iterations of the plain retry of an increment that failed with status
/// prediction (the plain retries that converged on the 25 x 25 x 1 paper cup took at most
/// 15).
const PLAIN_RETRY_ITERATIONS: usize = 20;

/// Newton iterations of each last resort.
pub(super) const LAST_RESORT_ITERATIONS: usize = 80;

/// Failures after which a smaller increment, or a last resort, may succeed.
fn retryable(err: &Error) -> bool {
    matches!(err, Error::NoConvergence { .. } | Error::LinearSolver(_))
}

/// The failure of an increment that no cutback or last resort got through: the kind of its
/// last attempt's failure (and whether a status cycled there), with `message`.
fn increment_failure(last: &Error, message: String) -> Error {
    let (kind, cycling) = last.failure();
    Error::NoConvergence {
        kind,
        cycling,
        message,
    }
}

/// The attempts an increment cut back before it converged: why each failed (one line each)
/// and the kind of each failure.
#[derive(Default)]
struct Cutbacks {
    reasons: Vec<String>,
    kinds: Vec<Failure>,
}

impl Cutbacks {
    /// Records the attempt to `t_new`, of size `dt`, that failed with `err`.
    fn record(&mut self, t_new: f64, dt: f64, err: &Error) {
        self.reasons.push(cutback_reason(t_new, dt, err));
        self.kinds.push(err.failure().0);
    }

    fn count(&self) -> usize {
        self.reasons.len()
    }

    /// Gives `report` the cutbacks from the `from`-th on.
    fn report_since(&self, from: usize, report: &mut IncrementReport) {
        report.cutbacks = self.count() - from;
        report.cutback_reasons = self.reasons[from..].to_vec();
        report.cutback_kinds = self.kinds[from..].to_vec();
    }
}

/// One line on a failed attempt: where it was tried and why it failed.
fn cutback_reason(t_new: f64, dt: f64, err: &Error) -> String {
    format!("t = {t_new} (dt = {dt}): {}", bare(err))
}

/// One line on a failed attempt at the smallest part, naming the attempt.
fn attempt_failure(attempt: Attempt, t_new: f64, dt: f64, err: &Error) -> String {
    format!("{}: {}", attempt.name(), cutback_reason(t_new, dt, err))
}

/// Why an increment failed at its smallest part: the attempts before the last, then the
/// last one's error.
fn failure_text(failures: &[String], attempt: Attempt, err: &Error) -> String {
    if failures.is_empty() {
        bare(err)
    } else {
        format!("{}; {}: {}", failures.join("; "), attempt.name(), bare(err))
    }
}

/// Marks the report of an increment that only a last resort got through (its name, and a
/// warning with the attempts that failed before it); nothing for a regular attempt.
fn note_last_resort(report: &mut IncrementReport, attempt: Attempt, failures: &[String]) {
    if attempt == Attempt::Regular {
        return;
    }
    report.last_resort = Some(attempt.name().to_string());
    report.warnings.push(format!(
        "increment {} to t = {} converged by the last resort '{}' after {}; the state solves the same equations to the same tolerances (docs/convergence.md, \"When a run stops\")",
        report.index,
        report.time,
        attempt.name(),
        failures.join("; ")
    ));
}

/// An error's message without its kind prefix, for nesting in another message.
pub(super) fn bare(err: &Error) -> String {
    match err {
        Error::NoConvergence { message: m, .. }
        | Error::LinearSolver(m)
        | Error::Input(m)
        | Error::Script(m) => m.clone(),
        other => other.to_string(),
    }
}

impl Simulation {
    /// Advances one increment. Fixed stepping: one nominal increment, halved on failure up
    /// to `max_cutbacks` times (the sub-increments are all in `history`, each counting the
    /// cutbacks made before it was reached, so that their sum is the run's number of failed
    /// attempts; the returned report counts the whole nominal increment's). Adaptive
    /// stepping: one increment of the size the controller chose (see `step_control`).
    pub fn step(&mut self) -> Result<IncrementReport> {
        self.check_interrupt()?;
        if let Some(missed) = self.missed_condition() {
            return Err(Error::Input(missed));
        }
        if self.is_finished() {
            return Err(Error::Input(format!(
                "the simulation already reached its end time {}",
                self.model.settings.end_time
            )));
        }
        if self.stroke_done() {
            // A production run: the next stroke on a new blank (module `strokes`).
            self.start_next_stroke()?;
        }
        let report = match self.model.settings.stepping.mode {
            StepMode::Fixed => self.step_fixed(),
            StepMode::Adaptive => self.step_adaptive(),
        }?;
        if self.is_finished() && self.model.strokes.extrapolated() {
            self.extrapolate_tool_fields();
        }
        Ok(report)
    }

    /// One nominal increment of fixed stepping, in parts where Newton fails: a failed
    /// attempt is halved (at most `max_cutbacks` times in a row, never below `dt_min`), a
    /// converged part is followed by one of its size, and where such a part fails the rest
    /// of the nominal increment is tried whole before any further halving.
    ///
    /// Why the rest whole: a hard spot can be a single instant, where a barely touching
    /// flange lifts off a tool, and a part ending just there fails where a longer one over
    /// it converges. The solid-shell paper cup (25 x 25 x 1) met one at 7.8 mm: its parts
    /// of a sixteenth of the step ran into it and it got through only after seven
    /// halvings; with the rest tried whole and halved afresh it gets over it under the
    /// engine's budget (test `the_solid_shell_paper_cup_steps_over_its_flange_lift_off`).
    /// Trying the rest whole after every converged part (not only after a failed one)
    /// also did, but changed the U-channel's increments enough to take one to 30
    /// iterations. Every converged part is at least `dt_min`, so an increment ends.
    fn step_fixed(&mut self) -> Result<IncrementReport> {
        let target = self.fixed_target();
        let dt_min = self
            .model
            .settings
            .stepping
            .dt_min(self.model.settings.end_time);
        let mut dt = target - self.time;
        let (mut in_a_row, mut recorded) = (0, 0);
        let mut cutbacks = Cutbacks::default();
        // Over the parts, as `cutbacks` (the rows in `history` have each part's own).
        let mut discarded = 0;
        let start = self.time;
        let mut rest_tried = false;
        // The attempt at the part under way, and why the attempts before it at the same
        // part failed (the last resorts; empty for a regular attempt).
        let mut attempt = Attempt::Regular;
        let mut failures: Vec<String> = Vec::new();
        // Whether the last resorts have gone on to the rest of the increment whole.
        let mut resorts_on_rest = false;
        loop {
            let t_new = if dt >= target - self.time {
                target
            } else {
                self.time + dt
            };
            match self.try_increment(t_new, attempt) {
                Ok(trial) => {
                    let mut report = self.accept(t_new, trial);
                    self.end_step_on_condition(&mut report);
                    self.measure_springback(report.step);
                    note_last_resort(&mut report, attempt, &failures);
                    attempt = Attempt::Regular;
                    failures.clear();
                    resorts_on_rest = false;
                    cutbacks.report_since(recorded, &mut report);
                    recorded = cutbacks.count();
                    discarded += report.discarded_iterations;
                    self.history.push(report.clone());
                    if t_new < target && !report.until_met {
                        // The next part keeps this one's size; the rest is tried whole only
                        // where such a part fails (below).
                        in_a_row = 0;
                        rest_tried = false;
                        continue;
                    }
                    cutbacks.report_since(0, &mut report);
                    report.discarded_iterations = discarded;
                    return Ok(report);
                }
                Err(err @ Error::Interrupted(_)) => return Err(err),
                Err(err)
                    if retryable(&err)
                        && attempt == Attempt::Regular
                        && !rest_tried
                        && self.time > start
                        && t_new < target =>
                {
                    cutbacks.record(t_new, t_new - self.time, &err);
                    rest_tried = true;
                    dt = target - self.time;
                }
                Err(err)
                    if retryable(&err)
                        && attempt == Attempt::Regular
                        && in_a_row < self.model.settings.max_cutbacks
                        && 0.5 * dt >= dt_min =>
                {
                    cutbacks.record(t_new, t_new - self.time, &err);
                    in_a_row += 1;
                    dt *= 0.5;
                }
                Err(err) => {
                    let dt_part = t_new - self.time;
                    match self.next_attempt(attempt, &err) {
                        Some(next) => {
                            failures.push(attempt_failure(attempt, t_new, dt_part, &err));
                            attempt = next;
                        }
                        // Both failed on the smallest part: the last resorts on the rest
                        // of the increment whole, as the regular attempts do above (only
                        // after the continuation, so never with `last_resort` off).
                        None if attempt == Attempt::Continuation
                            && retryable(&err)
                            && !resorts_on_rest
                            && t_new < target =>
                        {
                            failures.push(attempt_failure(attempt, t_new, dt_part, &err));
                            attempt = Attempt::LongPlain;
                            resorts_on_rest = true;
                            dt = target - self.time;
                        }
                        None => {
                            return Err(increment_failure(
                                &err,
                                format!(
                                    "increment {} from t = {} with dt = {dt} after {} cutbacks: {}",
                                    self.increments_done + 1,
                                    self.time,
                                    cutbacks.count(),
                                    failure_text(&failures, attempt, &err)
                                ),
                            ))
                        }
                    }
                }
            }
        }
    }

    fn step_adaptive(&mut self) -> Result<IncrementReport> {
        let step = self.model.settings.stepping.clone();
        let end = self.model.settings.end_time;
        let dt_min = step.dt_min(end);
        let mut dt = self.controller.dt.max(dt_min);
        let mut rejected = 0;
        let mut cutbacks = Cutbacks::default();
        // As in `step_fixed`.
        let mut attempt = Attempt::Regular;
        let mut failures: Vec<String> = Vec::new();
        loop {
            let t_new = StepController::next_time(self.time, dt, &self.stops);
            let dt_used = t_new - self.time;
            match self.try_increment(t_new, attempt) {
                Ok(trial) => {
                    let measures = self.measures(&trial);
                    let verdict = self
                        .controller
                        .assess(&step, end, dt_used, &measures, trial.iterations);
                    // A last resort's state is taken as it is: a smaller step is not allowed.
                    if !verdict.accept && attempt == Attempt::Regular {
                        self.discard(&trial.times);
                        rejected += 1;
                        dt = verdict.next_dt;
                        continue;
                    }
                    let mut report = self.accept(t_new, trial);
                    self.end_step_on_condition(&mut report);
                    self.measure_springback(report.step);
                    note_last_resort(&mut report, attempt, &failures);
                    cutbacks.report_since(0, &mut report);
                    report.rejected = rejected;
                    report.measures = measures;
                    report.limit = verdict.limit;
                    let (ratio, which) = measures.ratio(&step);
                    if ratio < 1.0 {
                        report.warnings.push(crate::solver::simulation::step_control::limit_warning(
                            which,
                            1.0 / ratio,
                            dt_min,
                            !std::mem::replace(&mut self.limit_explained, true),
                        ));
                    }
                    // No growth right after a cutback.
                    let next = if cutbacks.count() > 0 {
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
                    let held = dt_used <= dt_min * (1.0 + 1e-9)
                        && (ratio < 1.0 || cutbacks.count() > 0);
                    self.at_floor = if held { self.at_floor + 1 } else { 0 };
                    if self.at_floor >= crate::solver::simulation::step_control::CRAWL_INCREMENTS
                        && !self.is_finished()
                    {
                        // Committed and in history: the stop keeps this increment.
                        return Err(Error::no_convergence(
                            crate::error::Failure::Stalled,
                            crate::solver::simulation::step_control::crawl_message(
                                dt_min,
                                self.at_floor,
                                self.time,
                                end,
                            ),
                        ));
                    }
                    return Ok(report);
                }
                Err(err @ Error::Interrupted(_)) => return Err(err),
                Err(err)
                    if retryable(&err)
                        && attempt == Attempt::Regular
                        && dt_used > dt_min * (1.0 + 1e-9) =>
                {
                    cutbacks.record(t_new, dt_used, &err);
                    dt = (0.5 * dt_used).max(dt_min);
                    self.controller.limit = Limit::Divergence;
                }
                Err(err) => match self.next_attempt(attempt, &err) {
                    Some(next) => {
                        failures.push(attempt_failure(attempt, t_new, dt_used, &err));
                        attempt = next;
                    }
                    None => {
                        return Err(increment_failure(
                            &err,
                            format!(
                                "increment {} from t = {} cannot be completed at the minimum step dt = {dt_used:.6e} (dt_min = {dt_min:.6e}) after {} cutbacks: {}",
                                self.increments_done + 1,
                                self.time,
                                cutbacks.count(),
                                failure_text(&failures, attempt, &err)
                            ),
                        ))
                    }
                },
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

    /// Counts the work of an attempt not kept (failed, or rejected by the step control):
    /// the run's phase times, and the Newton steps the next accepted increment reports as
    /// discarded.
    fn discard(&mut self, times: &PhaseTimes) {
        self.phase_times.add(times);
        self.discarded_steps += times.newton_steps;
    }

    /// The attempt after `attempt` failed with `err` at the smallest part, if any.
    fn next_attempt(&self, attempt: Attempt, err: &Error) -> Option<Attempt> {
        if !(retryable(err) && self.model.settings.stepping.last_resort) {
            return None;
        }
        attempt.next()
    }

    /// Newton's method for the increment ending at `t_new`, nothing committed: the
    /// `attempt` says which (a last resort: no status prediction, [`LAST_RESORT_ITERATIONS`],
    /// no plain retry).
    fn try_increment(&mut self, t_new: f64, attempt: Attempt) -> Result<Trial> {
        self.prepare_increment(t_new);
        // The factorization cache lives outside `self` while the context borrows it.
        let mut linear = std::mem::take(&mut self.linear);
        linear.set_threads(crate::solver::assembly::worker_threads(
            self.model.settings.threads,
        ));
        let (prediction, budget) = match attempt {
            Attempt::Regular => (
                self.model.settings.status_prediction,
                self.model.settings.max_iterations,
            ),
            _ => (0, LAST_RESORT_ITERATIONS),
        };
        // Every attempt's time is the run's: a failed one's is counted here, an accepted
        // one's (with a failed predicted attempt before its plain retry) when committed.
        let mut spent = PhaseTimes::default();
        let mut outcome =
            self.newton()
                .solve(t_new, &mut linear, prediction, budget, attempt, &mut spent);
        // A re-solved step can lead far off where many nodes change status at once (no
        // merit check guards it, see `status_prediction`), and the increment then fails
        // where the plain Newton would not: it is tried once more, plainly, before any
        // cutback (25 x 25 x 1 paper cup to 30 mm: 9 cutbacks and 56 s without the retry,
        // none and 45 s with it; BENCHMARKS.md). With a short budget: where the plain
        // Newton cannot converge either (it cycles on the solid-shell cup), a retry with
        // the whole budget cost more than the cutback it was meant to avoid.
        if prediction > 0 && matches!(&outcome, Err(e) if retryable(e)) {
            outcome = self.newton().solve(
                t_new,
                &mut linear,
                0,
                budget.min(PLAIN_RETRY_ITERATIONS),
                Attempt::Regular,
                &mut spent,
            );
        }
        if outcome.is_err() {
            self.discard(&spent);
        }
        self.linear = linear;
        outcome
    }
}
