//! summary.json's `settings`: every solver setting in force for the run, the defaults
//! included, under the keys and value names of `sim.settings(#{ ... })`, so that two runs
//! can be told apart from their summaries alone.
//!
//! Settings whose default depends on the run are written as resolved: `dt_min` (end time
//! x 1e-6), `dt_max` (the end time) and `dt_initial` (end time / increments). Nothing is
//! computed here beyond that; the values are the model's `SolverSettings` as the solver
//! reads them.

use crate::solver::SolverSettings;
use serde_json::{json, Value};

/// The settings object of summary.json (see the module doc).
pub fn settings_json(s: &SolverSettings) -> Value {
    let step = &s.stepping;
    let c = &s.contact;
    let nominal_dt = s.end_time / s.increments.max(1) as f64;
    json!({
        "increments": s.increments,
        "end_time": s.end_time,
        "max_iterations": s.max_iterations,
        "max_cutbacks": s.max_cutbacks,
        "force_tolerance": s.force_rel_tol,
        "force_abs_tolerance": s.force_abs_tol,
        "contact_tolerance": s.contact_tol,
        "kinematics": s.kinematics.name(),
        "fbar": s.fbar,
        "element": s.element.name(),
        "thickness_points": s.thickness_points,
        "enforcement": snake(c.enforcement),
        "frame": snake(c.frame),
        "curvature": c.curvature,
        "friction_update": snake(c.friction_update),
        "r_fraction": c.r_fraction,
        "eliminate_multipliers": s.eliminate_multipliers,
        "linear_solver": snake(s.linear_solver),
        "extrapolate": s.extrapolate,
        "status_prediction": s.status_prediction,
        "threads": s.threads,
        "step_control": snake(step.mode),
        "dt_min": step.dt_min(s.end_time),
        "dt_max": step.dt_max(s.end_time),
        "dt_initial": step.dt_initial.unwrap_or(nominal_dt),
        "max_plastic_strain_increment": step.max_plastic_strain_increment,
        "max_rotation_increment": step.max_rotation_increment,
        // JSON has no infinity: the default (no limit) is written as the string "inf".
        "max_slip_increment": finite_or_text(step.max_slip_increment),
        "target_iterations": step.target_iterations,
        "step_growth": step.growth,
        "line_search": step.line_search,
        "anti_cycling": snake(step.anti_cycling),
        "cycle_flips": step.cycle_flips,
        "rollback_depth": step.rollback_depth,
        "last_resort": step.last_resort,
    })
}

/// A unit variant's name as a script writes it: `AugmentedLagrangian` -> "augmented_lagrangian".
fn snake(value: impl std::fmt::Debug) -> String {
    let mut out = String::new();
    for (i, ch) in format!("{value:?}").chars().enumerate() {
        if ch.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(ch.to_ascii_lowercase());
    }
    out
}

fn finite_or_text(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        json!(x.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names of the variants are the ones a script writes (that every solver key of
    /// `sim.settings` is in the object: tests/summary_settings.rs).
    #[test]
    fn every_solver_key_is_written_under_its_script_name() {
        let v = settings_json(&SolverSettings::default());
        let map = v.as_object().unwrap();
        assert_eq!(map["enforcement"], "augmented_lagrangian");
        assert_eq!(map["frame"], "every_iteration");
        assert_eq!(map["linear_solver"], "symmetric_lu");
        assert_eq!(map["step_control"], "fixed");
        assert_eq!(map["max_slip_increment"], "inf");
    }
}
