//! A process in named steps (closing, drawing, release): consecutive intervals of
//! pseudo-time, each with its own number of increments.
//!
//! Step `k` covers `(t_{k-1}, t_k]` with `t_{-1} = 0` and `t_k` its end time; the last end
//! is the model's end time. Everything a step changes (tool motions, which tools are under
//! force control) is compiled onto the pseudo-time axis by whoever builds the model (the
//! script layer): a tool's schedule is piecewise linear across the steps and its force
//! control has the windows of the steps where it acts (`tool::ForceControl::windows`).
//! So the committed state at a time says everything, and a checkpoint taken anywhere,
//! inside a step or at its end, restarts the same run.
//!
//! A step may end on a condition (`Step::until`): a tool's contact force reaching a value,
//! or the tool losing contact (no active candidate node). The step then ends at the first
//! increment meeting it, at `t_f <= t_k`; the rest of its pseudo-time `(t_f, t_k]` is
//! skipped: the committed time jumps to `t_k` and every tool holds there where it was at
//! `t_f` (its translation `u(t)` becomes `u(t_f)` on `[t_f, t_k]` and `u(t) + u(t_f) - u(t_k)`
//! after, `Schedule::held_between`), so the next step starts from the state reached and
//! its moves are relative to it. Which steps ended early, and when, is part of the
//! committed state (`Simulation::step_ends`, kept in checkpoints), so that a restart
//! rebuilds the same schedules. A step whose end is reached without its condition stops
//! the run (the increment report says so, `IncrementReport::until_missed`).
//!
//! A step may name supports (`Step::supports`): node components held where they are at
//! the step's start, for that step only (`u_{n+1} = u_n` at every increment of the step,
//! so a support never moves the sheet and a restart inside the step holds the same
//! values, which are committed state), or ask for the 3-2-1 default
//! (`Step::three_two_one`), chosen by `rigid_modes::three_two_one` from the mesh to remove
//! exactly the rigid-body modes the other conditions leave free. A step may ramp tools
//! off (`Step::ramp_off`): each named tool is force-controlled along its axis in the step
//! with a force going linearly from its last contact force to zero at the step's end
//! (solver `simulation::release`).
//!
//! Fixed stepping takes `(t_k - t_{k-1}) / n_k` in step `k` and never crosses a step end;
//! adaptive stepping lands on every step end (`step_control::schedule_stops`). An increment
//! ending at time `t` belongs to the step whose interval holds `t`.

use crate::{Error, Result};

/// One step of the process.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    pub name: String,
    /// Pseudo-time at the end of the step.
    pub end: f64,
    /// Nominal increments of fixed stepping in the step (>= 1).
    pub increments: usize,
    /// The condition ending the step before its end time, if any.
    pub until: Option<Until>,
    /// The step releases the sheet from every tool: its supports (the Dirichlet
    /// conditions) must then hold it statically determinate, which `Simulation::new`
    /// checks (`rigid_modes`).
    pub release: bool,
    /// Supports acting in this step only: node components held where they are.
    pub supports: Vec<Support>,
    /// Whether the step adds the 3-2-1 default supports (resolved into `supports` when
    /// the simulation starts).
    pub three_two_one: bool,
    /// Tools (indices into `Model::contacts`) whose force is ramped from its last value to
    /// zero over the step; each is force-controlled in the step (`ForceControl::windows`).
    pub ramp_off: Vec<usize>,
}

/// Components of nodes held where they are during one step.
#[derive(Clone, Debug, PartialEq)]
pub struct Support {
    /// Where it comes from, for messages: a set's name, `node 12` or `3-2-1`.
    pub label: String,
    pub nodes: Vec<usize>,
    /// 0, 1, 2 for x, y, z.
    pub component: usize,
}

impl Step {
    /// A step over `(previous end, end]` with `increments` and nothing else.
    pub fn plain(name: &str, end: f64, increments: usize) -> Step {
        Step {
            name: name.to_string(),
            end,
            increments,
            until: None,
            release: false,
            supports: Vec::new(),
            three_two_one: false,
            ramp_off: Vec::new(),
        }
    }
}

/// A condition ending a step: on tool `tool` (index into `Model::contacts`).
#[derive(Clone, Debug, PartialEq)]
pub struct Until {
    pub tool: usize,
    pub condition: Condition,
}

/// What ends a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Condition {
    /// The magnitude of the tool's total contact force `|sum lambda|` reaches this value
    /// (force units, > 0).
    Force(f64),
    /// No candidate node of the tool is in contact (status gap everywhere).
    ContactLost,
}

impl Until {
    /// Whether the condition holds for a tool with total contact force `force` and
    /// `active` nodes in contact.
    pub fn met(&self, force: [f64; 3], active: usize) -> bool {
        match self.condition {
            Condition::Force(f) => {
                (force[0] * force[0] + force[1] * force[1] + force[2] * force[2]).sqrt() >= f
            }
            Condition::ContactLost => active == 0,
        }
    }

    /// The condition in words, for messages: `tool 'punch' force >= 500` or `tool
    /// 'punch' contact lost`.
    pub fn describe(&self, tool_name: &str) -> String {
        match self.condition {
            Condition::Force(f) => format!("tool '{tool_name}' force >= {f}"),
            Condition::ContactLost => format!("tool '{tool_name}' contact lost"),
        }
    }
}

/// Relative tolerance on times: an increment ending this close to a step end ends there.
const TIME_TOL: f64 = 1e-12;

/// Checks the steps: names non-empty and distinct, ends finite and strictly increasing
/// from above 0, increments at least 1. The error names the step (index and name).
pub fn validate(steps: &[Step]) -> Result<()> {
    let mut previous = 0.0;
    for (i, s) in steps.iter().enumerate() {
        let what = |field: &str| format!("step {i} ('{}') {field}", s.name);
        if s.name.trim().is_empty() {
            return Err(Error::input(
                &format!("step {i} name"),
                "\"\"",
                "must not be empty",
            ));
        }
        if steps[..i].iter().any(|o| o.name == s.name) {
            return Err(Error::input(
                &what("name"),
                &s.name,
                "is used by an earlier step",
            ));
        }
        if !(s.end.is_finite() && s.end > previous) {
            return Err(Error::input(
                &what("end time"),
                s.end,
                &format!("must be finite and greater than the previous step's end {previous}"),
            ));
        }
        if s.increments == 0 {
            return Err(Error::input(&what("increments"), 0, "must be >= 1"));
        }
        if let Some(Until {
            condition: Condition::Force(f),
            ..
        }) = s.until
        {
            if !(f.is_finite() && f > 0.0) {
                return Err(Error::input(
                    &what("until force"),
                    f,
                    "must be finite and > 0",
                ));
            }
        }
        previous = s.end;
    }
    Ok(())
}

/// Index of the step an increment ending at `t` belongs to (the last step beyond its end;
/// `None` without steps).
pub fn step_at(steps: &[Step], t: f64) -> Option<usize> {
    if steps.is_empty() {
        return None;
    }
    let scale = steps.last().map_or(1.0, |s| s.end.abs().max(1e-300));
    let k = steps
        .iter()
        .position(|s| t <= s.end + TIME_TOL * scale)
        .unwrap_or(steps.len() - 1);
    Some(k)
}

/// Index of the step the next increment from the committed time `t` falls in.
pub fn next_step(steps: &[Step], t: f64) -> Option<usize> {
    if steps.is_empty() {
        return None;
    }
    let scale = steps.last().map_or(1.0, |s| s.end.abs().max(1e-300));
    Some(
        steps
            .iter()
            .position(|s| t < s.end - TIME_TOL * scale)
            .unwrap_or(steps.len() - 1),
    )
}

/// Start time of step `k`.
pub fn start(steps: &[Step], k: usize) -> f64 {
    if k == 0 {
        0.0
    } else {
        steps[k - 1].end
    }
}

/// The nominal increment of fixed stepping in step `k`.
pub fn nominal_dt(steps: &[Step], k: usize) -> f64 {
    (steps[k].end - start(steps, k)) / steps[k].increments as f64
}

/// `target` moved onto the end of step `k` when it passes it or falls within a
/// round-off of it (so that no sliver of an increment is left before the step's end).
pub fn land_on_end(steps: &[Step], k: usize, target: f64) -> f64 {
    let end = steps[k].end;
    let slack = TIME_TOL * end.abs().max(1.0) * 1e3;
    if target > end - slack {
        end
    } else {
        target
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps() -> Vec<Step> {
        vec![
            Step::plain("closing", 1.0, 4),
            Step::plain("drawing", 21.0, 40),
        ]
    }

    #[test]
    fn increments_belong_to_the_step_holding_their_end() {
        let s = steps();
        assert_eq!(step_at(&s, 0.25), Some(0));
        assert_eq!(step_at(&s, 1.0), Some(0));
        assert_eq!(step_at(&s, 1.5), Some(1));
        assert_eq!(next_step(&s, 1.0), Some(1));
        assert_eq!(next_step(&s, 0.0), Some(0));
        assert_eq!(nominal_dt(&s, 0), 0.25);
        assert_eq!(nominal_dt(&s, 1), 0.5);
        // Four quarters summed in floating point land on 1 exactly.
        assert_eq!(land_on_end(&s, 0, 0.75 + 0.25 - 1e-16), 1.0);
        assert_eq!(land_on_end(&s, 0, 1.2), 1.0);
        assert_eq!(land_on_end(&s, 1, 1.5), 1.5);
        assert_eq!(step_at(&[], 1.0), None);
    }

    #[test]
    fn bad_steps_are_named() {
        let mut s = steps();
        s[1].end = 1.0;
        let e = validate(&s).unwrap_err().to_string();
        assert!(e.contains("step 1 ('drawing') end time"), "{e}");
        let mut s = steps();
        s[1].name = "closing".into();
        let e = validate(&s).unwrap_err().to_string();
        assert!(e.contains("step 1 ('closing') name"), "{e}");
        let mut s = steps();
        s[0].increments = 0;
        let e = validate(&s).unwrap_err().to_string();
        assert!(e.contains("step 0 ('closing') increments"), "{e}");
        let mut s = steps();
        s[1].until = Some(Until {
            tool: 0,
            condition: Condition::Force(-1.0),
        });
        let e = validate(&s).unwrap_err().to_string();
        assert!(e.contains("step 1 ('drawing') until force = -1"), "{e}");
        assert!(validate(&steps()).is_ok());
    }

    #[test]
    fn conditions_hold_at_their_threshold() {
        let force = Until {
            tool: 0,
            condition: Condition::Force(5.0),
        };
        assert!(force.met([3.0, 0.0, 4.0], 2), "|F| = 5 reaches 5");
        assert!(!force.met([3.0, 0.0, 3.9], 2));
        let lost = Until {
            tool: 0,
            condition: Condition::ContactLost,
        };
        assert!(lost.met([0.0; 3], 0) && !lost.met([0.0; 3], 1));
        assert_eq!(force.describe("punch"), "tool 'punch' force >= 5");
    }
}
