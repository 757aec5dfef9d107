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
            Step {
                name: "closing".into(),
                end: 1.0,
                increments: 4,
            },
            Step {
                name: "drawing".into(),
                end: 21.0,
                increments: 40,
            },
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
        assert!(validate(&steps()).is_ok());
    }
}
