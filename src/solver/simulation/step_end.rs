//! Steps that end on a condition (`Step::until`): a tool's contact force reaching a value,
//! or the tool losing contact.
//!
//! After each accepted increment ending at `t` in step `k` (interval `(t_{k-1}, t_k]`) with
//! a condition on tool `c`, the condition is evaluated on the committed state: the force
//! `|F_c| = |sum_i lambda_i|` over the tool's candidate nodes against the asked value, or
//! the number of active nodes (status stick or slip) against zero. The first increment
//! meeting it ends the step. If `t < t_k`, the rest of the step is skipped: every tool's
//! translation becomes `u(t)` on `[t, t_k]` and `u(s) + u(t) - u(t_k)` for `s > t_k`
//! (`Schedule::held_between`), and the committed time jumps to `t_k`. Nothing moves in the
//! jump (the tools' poses at `t_k` are those at `t`), so the committed state is still a
//! converged one; the next step starts from it and its moves are relative to it. Loads and
//! prescribed displacements scheduled in pseudo-time are not shifted: they take their
//! values at `t_k` (a process in steps drives the tools only).
//!
//! The list of steps ended early, `(k, t)`, is committed state: rollback and checkpoints
//! keep it, and the schedules are rebuilt from the model's own and that list, so a run
//! restarted anywhere repeats the uninterrupted one bit for bit.
//!
//! An increment that reaches `t_k` without the condition is marked
//! (`IncrementReport::until_missed`, naming the step, the condition and what was reached),
//! and the next `Simulation::step` refuses to go on: a process whose step did not do what
//! it was meant to (a punch that never touched, a holder force never reached) would go on
//! from a state the user did not ask for.

use crate::solver::model::steps;
use crate::solver::simulation::step_control::schedule_stops;
use crate::solver::simulation::{IncrementReport, Simulation};
use crate::{Error, Result};

impl Simulation {
    /// Evaluates the condition of the step of the increment just committed (`report`):
    /// met, the step ends here (the time jumps to its end); not met at the step's end,
    /// the report says so. Nothing for steps without a condition.
    pub(super) fn end_step_on_condition(&mut self, report: &mut IncrementReport) {
        let Some(k) = report.step else { return };
        let step = &self.model.steps[k];
        let Some(until) = step.until.clone() else {
            return;
        };
        let end = step.end;
        let active = self.contact[until.tool]
            .iter()
            .filter(|s| s.status.is_active())
            .count();
        let force = report.tool_forces[until.tool];
        let name = &self.model.contacts[until.tool].tool.name;
        if until.met(force, active) {
            report.until_met = true;
            let mut ends = self.step_ends.clone();
            ends.push((k, report.time));
            self.set_step_ends(ends);
            self.time = self.time.max(end);
        } else if self.is_finished() || steps::next_step(&self.model.steps, self.time) != Some(k) {
            let magnitude = force.iter().map(|f| f * f).sum::<f64>().sqrt();
            report.until_missed = Some(format!(
                "step {k} ('{}') reached its end t = {end} without its condition ({}): at its end tool '{name}' has {active} node(s) in contact and a force of {magnitude:.6e}; lengthen the step (duration, move) or change the condition",
                step.name,
                until.describe(name),
            ));
        }
    }

    /// Makes `ends` the steps ended early and rebuilds the tools' schedules from the
    /// model's own (`base_schedules`) and them, in order.
    /// Nothing changes when no step has ended early before or after (runs without
    /// conditions keep their schedules as they are).
    pub(crate) fn set_step_ends(&mut self, ends: Vec<(usize, f64)>) {
        if ends.is_empty() && self.step_ends.is_empty() {
            return;
        }
        for (c, base) in self.base_schedules.iter().enumerate() {
            let mut schedule = base.clone();
            for &(k, t) in &ends {
                schedule = schedule.held_between(t, self.model.steps[k].end);
            }
            self.model.contacts[c].tool.schedule = schedule;
        }
        self.step_ends = ends;
        self.stops = schedule_stops(&self.model);
    }

    /// Checks a checkpoint's list of steps ended early against the model: known steps
    /// with a condition, in order, each time inside its step.
    pub(crate) fn check_step_ends(&self, ends: &[(usize, f64)]) -> Result<()> {
        let list = &self.model.steps;
        let mut previous = None;
        for (i, &(k, t)) in ends.iter().enumerate() {
            let fault = if k >= list.len() || list[k].until.is_none() {
                Some(format!(
                    "names step {k}, which has no condition (end_when) in the script"
                ))
            } else if previous.is_some_and(|p| k <= p) {
                Some("is not after the step before it".to_string())
            } else if !(t.is_finite() && t > steps::start(list, k) && t <= list[k].end) {
                Some(format!(
                    "has the time {t} outside step {k} ('{}')",
                    list[k].name
                ))
            } else {
                None
            };
            if let Some(fault) = fault {
                return Err(Error::Input(format!(
                    "the checkpoint's state.step_ends[{i}] = [{k}, {t}] {fault} (the file was edited, or the script's steps changed)"
                )));
            }
            previous = Some(k);
        }
        Ok(())
    }

    /// The steps ended early by their condition: (step index, time of the increment that
    /// met it), in order.
    pub fn step_ends(&self) -> &[(usize, f64)] {
        &self.step_ends
    }

    /// The message of the last increment if it reached its step's end without the
    /// step's condition (the run cannot go on from there).
    pub(super) fn missed_condition(&self) -> Option<String> {
        self.history.last().and_then(|r| r.until_missed.clone())
    }
}
