//! Automatic increment control in the spirit of the R_min strategy (Yamada et al.; Menezes &
//! Teodosiu): the size of the next increment is bounded by limits on what one increment may
//! change, and by how hard Newton had to work.
//!
//! After an increment of size `dt` converged, the measured increments are compared with
//! their limits:
//!
//! ```text
//! R_p   = max_plastic_strain_increment / max over points  |Δε̄_p|
//! R_rot = max_rotation_increment       / max over points  angle(polar(F_{n+1} F_n^-1))
//! R_s   = max_slip_increment           / max over contact nodes |δ_t|
//! R_it  = target_iterations / iterations
//! R     = min(R_p, R_rot, R_s)
//! ```
//!
//! If `R < 1` a limit is exceeded: the increment is rejected (nothing is committed) and
//! retried from the last converged state with `dt * max(0.9 R, 1/4)`, unless `dt` is
//! already the minimum, where it is accepted with the excess reported. Otherwise it is
//! committed and the next increment is `dt * clamp(min(0.9 R, R_it), 1/2, growth)`, so
//! steps grow again after easy convergence. A Newton failure (non-finite or growing
//! residual, too many iterations, an inverted element, a failed linear solve) halves `dt`;
//! below `dt_min` the run stops. The increments are adapted so that every breakpoint of a
//! schedule (tools, prescribed displacements, loads) and the end time are hit exactly:
//! a remaining interval shorter than two increments is split evenly, which avoids slivers.
//!
//! "fixed" stepping keeps `end_time / increments` with halving cutbacks on failure; it is
//! the default, so the verification tests keep their exact increment sequences.
//!
//! **Crawl floor.** An increment is *held at the floor* when it was taken at `dt_min` and
//! the control wanted a smaller one: a limit exceeded even at `dt_min` (`R < 1`), or a cutback
//! down to it. Each such increment advances the run by `dt_min` only (10^-6 of the run at the
//! default), so a run held there for [`CRAWL_INCREMENTS`] increments in a row stops with the
//! reason (the setting `dt_min`, the number of increments at it, the time reached): going on
//! would cost up to `(end_time - t) / dt_min` more increments (hours for a block dragged off
//! a tool's edge) for a process followed no better than the limits it keeps exceeding. The
//! stop keeps everything computed, as other stops do (summary.json, final checkpoint). A
//! run that leaves the floor resets the count; steps at `dt_min` chosen on purpose
//! (`dt_max = dt_min`) with no limit exceeded are not held there and never counted.

use crate::material::PointState;
use crate::solver::model::Model;
use crate::solver::settings::StepSettings;
use serde::{Deserialize, Serialize};

/// Which criterion set the size of the next increment (a number in history.csv).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Limit {
    #[default]
    None,
    PlasticStrain,
    Rotation,
    Slip,
    Iterations,
    MaxStep,
    Divergence,
}

impl Limit {
    /// 0 none, 1 plastic strain, 2 rotation, 3 slip, 4 iterations, 5 dt_max, 6 divergence.
    pub fn code(self) -> f64 {
        self as u8 as f64
    }
}

/// Largest increments of one trial increment and where they occur.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct IncrementMeasures {
    pub plastic_strain: f64,
    /// Integration point (element * points per element + point) of the largest increment.
    pub plastic_point: usize,
    /// Radians.
    pub rotation: f64,
    pub rotation_point: usize,
    pub slip: f64,
    /// Mesh node of the largest slip.
    pub slip_node: usize,
}

impl IncrementMeasures {
    /// Equivalent plastic strain and rotation increments between committed and trial states.
    pub fn from_points(committed: &[PointState], trial: &[PointState]) -> Self {
        let mut m = IncrementMeasures::default();
        for (i, (old, new)) in committed.iter().zip(trial).enumerate() {
            let dp = (new.eq_plastic_strain - old.eq_plastic_strain).abs();
            if dp > m.plastic_strain {
                m.plastic_strain = dp;
                m.plastic_point = i;
            }
            let angle = rotation_increment(&old.deformation_gradient, &new.deformation_gradient);
            if angle > m.rotation {
                m.rotation = angle;
                m.rotation_point = i;
            }
        }
        m
    }

    /// Adds a contact node's slip increment |δ_t|.
    pub fn add_slip(&mut self, node: usize, slip: f64) {
        if slip > self.slip {
            self.slip = slip;
            self.slip_node = node;
        }
    }

    /// R = min over limits of limit / measured (infinite when nothing moved), and which
    /// limit attains it.
    pub fn ratio(&self, s: &StepSettings) -> (f64, Limit) {
        let mut best = (f64::INFINITY, Limit::None);
        for (limit, measured, which) in [
            (
                s.max_plastic_strain_increment,
                self.plastic_strain,
                Limit::PlasticStrain,
            ),
            (s.max_rotation_increment, self.rotation, Limit::Rotation),
            (s.max_slip_increment, self.slip, Limit::Slip),
        ] {
            if measured > 0.0 && limit / measured < best.0 {
                best = (limit / measured, which);
            }
        }
        best
    }
}

/// Increments in a row held at the floor `dt_min` after which a run stops (module doc): at
/// most 100 dt_min of progress bought with as many full Newton solves. A run passing a hard
/// spot (a contact switch, a tool's edge) leaves the floor within a few increments (the
/// step doubles after an easy one), far fewer than this.
pub const CRAWL_INCREMENTS: usize = 100;

/// The reason of a crawl stop: the setting, the increments at it, the time reached. The
/// reason comes first, on a line of its own (it is what a person reads of a stop); the
/// figures, the rule and what to do follow on indented lines.
pub fn crawl_message(dt_min: f64, increments: usize, time: f64, end_time: f64) -> String {
    format!(
        "the run crawls at the minimum step dt_min = {dt_min:e}: {increments} increments in a row\n  \
         it reached t = {time:.6e} of end_time = {end_time}; the rest would take up to {} more \
         increments\n  \
         the rule: a stop after {CRAWL_INCREMENTS} increments in a row held at dt_min (setting \
         dt_min) by an exceeded limit or a cutback\n  \
         look at the last state (checkpoints/final.json, the column step_limit of history.csv) \
         for what holds the step back; raise dt_min to go on in coarser steps",
        ((end_time - time) / dt_min).ceil().max(0.0)
    )
}

/// The warning of an increment whose step limit even the minimum step exceeds: which limit
/// and by how much; the first of a run (`explain`) also says whether the result is sound
/// and what to do.
pub fn limit_warning(which: Limit, factor: f64, dt_min: f64, explain: bool) -> String {
    let (what, setting, column) = match which {
        Limit::PlasticStrain => (
            "equivalent plastic strain",
            "max_plastic_strain_increment",
            "max_plastic_strain_increment",
        ),
        Limit::Rotation => (
            "rotation",
            "max_rotation_increment",
            "max_rotation_increment [rad]",
        ),
        _ => ("slip", "max_slip_increment", "max_slip_increment"),
    };
    if !explain {
        return format!(
            "the {what} increment exceeds its limit ({setting}) by a factor {factor:.3} at the minimum step (explained at the first such increment)"
        );
    }
    format!(
        "the {what} increment exceeds its limit ({setting}) by a factor {factor:.3} even at the minimum step dt_min = {dt_min:e}. \
         The increment is accepted: Newton converged to its tolerances, so the result is sound, but the process is followed in coarser steps than the limit asks. \
         If that matters, lower dt_min (or raise {setting} if the coarser steps are acceptable). \
         Not repeated: the measure of every increment is the column {column} of history.csv."
    )
}

/// Rotation increment (radians) at an integration point: the polar rotation angle of
/// f = F_new F_old^-1 where both gradients are well inside the physical range
/// (det F >= 1/2), else the infinitesimal rotation |axial(skew(F_new - F_old))|, which
/// equals it to first order and stays meaningful (linear in the increment) for the
/// small-strain elements, whose F = I + grad u is not a true deformation gradient once
/// grad u is large.
pub fn rotation_increment(f_old: &crate::geometry::Mat3, f_new: &crate::geometry::Mat3) -> f64 {
    if f_old.determinant() >= 0.5 && f_new.determinant() >= 0.5 {
        incremental_rotation(f_old, f_new)
    } else {
        let d = f_new - f_old;
        0.5 * crate::geometry::Vec3::new(
            d[(2, 1)] - d[(1, 2)],
            d[(0, 2)] - d[(2, 0)],
            d[(1, 0)] - d[(0, 1)],
        )
        .norm()
    }
}

/// Rotation angle (radians) of the polar decomposition of the incremental deformation
/// gradient f = F_new F_old^-1: R = U V^T from f = U S V^T, angle = acos((tr R - 1) / 2).
/// A singular F_old (not a deformation) gives 0.
pub fn incremental_rotation(f_old: &crate::geometry::Mat3, f_new: &crate::geometry::Mat3) -> f64 {
    let Some(inv) = f_old.try_inverse() else {
        return 0.0;
    };
    let f = f_new * inv;
    let svd = f.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return 0.0;
    };
    let mut r = u * v_t;
    if r.determinant() < 0.0 {
        // An inverted increment: the rotation is that of the proper part.
        let mut u = u;
        u.column_mut(2).neg_mut();
        r = u * v_t;
    }
    ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0).acos()
}

/// The controller's memory between increments (part of a checkpoint).
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct StepController {
    /// Size of the next increment.
    pub dt: f64,
    /// What limited it.
    pub limit: Limit,
}

/// Verdict on a converged trial increment.
#[derive(Clone, Copy, Debug)]
pub struct Assessment {
    pub accept: bool,
    /// Increment to try next (the retry if rejected).
    pub next_dt: f64,
    pub limit: Limit,
}

impl StepController {
    pub fn new(model: &Model) -> Self {
        let s = &model.settings;
        let nominal = s.end_time / s.increments.max(1) as f64;
        let dt = s.stepping.dt_initial.unwrap_or(nominal);
        StepController {
            dt: dt
                .min(s.stepping.dt_max(s.end_time))
                .max(s.stepping.dt_min(s.end_time)),
            limit: Limit::None,
        }
    }

    /// End of the next increment from `t` of (at most) size `dt`: lands exactly on the next
    /// breakpoint in `stops` (sorted, last = end time), splitting a remainder shorter than
    /// two increments evenly.
    pub fn next_time(t: f64, dt: f64, stops: &[f64]) -> f64 {
        let scale = stops.last().copied().unwrap_or(1.0).abs().max(1e-300);
        let stop = stops
            .iter()
            .copied()
            .find(|&s| s > t + 1e-12 * scale)
            .unwrap_or(t + dt);
        let remaining = stop - t;
        if remaining <= dt * (1.0 + 1e-9) {
            stop
        } else if remaining < 2.0 * dt {
            t + 0.5 * remaining
        } else {
            t + dt
        }
    }

    /// Judges a converged trial of size `dt` that needed `iterations` Newton iterations.
    pub fn assess(
        &self,
        settings: &StepSettings,
        end_time: f64,
        dt: f64,
        measures: &IncrementMeasures,
        iterations: usize,
    ) -> Assessment {
        let dt_min = settings.dt_min(end_time);
        let dt_max = settings.dt_max(end_time);
        let (r, limit) = measures.ratio(settings);
        if r < 1.0 && dt > dt_min * (1.0 + 1e-9) {
            return Assessment {
                accept: false,
                next_dt: (dt * (0.9 * r).max(0.25)).max(dt_min),
                limit,
            };
        }
        let r_it = settings.target_iterations as f64 / iterations.max(1) as f64;
        let (mut factor, mut which) = if 0.9 * r < r_it {
            (0.9 * r, limit)
        } else {
            (r_it, Limit::Iterations)
        };
        if factor > settings.growth {
            factor = settings.growth;
            which = Limit::Iterations;
        }
        factor = factor.max(0.5);
        let mut next = dt * factor;
        if next >= dt_max {
            next = dt_max;
            which = Limit::MaxStep;
        }
        Assessment {
            accept: true,
            next_dt: next.max(dt_min),
            limit: which,
        }
    }
}

/// Every breakpoint of the model's schedules in (0, end_time], sorted, ending with the end
/// time: increments land exactly on them.
pub fn schedule_stops(model: &Model) -> Vec<f64> {
    let end = model.settings.end_time;
    let mut stops: Vec<f64> = Vec::new();
    for c in &model.contacts {
        stops.extend(c.tool.schedule.points().iter().map(|p| p.0));
        if let Some(r) = c.tool.schedule.rotation() {
            stops.extend(r.angle.points().iter().map(|p| p.0));
        }
    }
    for d in &model.dirichlet {
        stops.extend(d.value.points().iter().map(|p| p.0));
    }
    for l in &model.loads {
        stops.extend(l.scale.points().iter().map(|p| p.0));
    }
    // A step ends where the process changes: adaptive increments land there too.
    stops.extend(model.steps.iter().map(|s| s.end));
    stops.retain(|&t| t > 0.0 && t < end);
    stops.push(end);
    stops.sort_by(f64::total_cmp);
    stops.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * end);
    stops
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Mat3, Vec3};

    #[test]
    fn polar_rotation_angle_of_rotation_times_stretch() {
        // f = R(0.3 about an oblique axis) * symmetric stretch: the polar angle is 0.3.
        let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
        let rot = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), 0.3);
        let stretch = Mat3::new(1.1, 0.05, 0.0, 0.05, 0.95, 0.02, 0.0, 0.02, 1.03);
        let f_old = Mat3::new(1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.2, 0.0, 1.0);
        let f_new = rot.matrix() * stretch * f_old;
        let angle = incremental_rotation(&f_old, &f_new);
        // Round-off of an SVD of a well-conditioned 3x3 matrix.
        assert!((angle - 0.3).abs() < 1e-12, "{angle}");
        assert!(incremental_rotation(&f_old, &(stretch * f_old)) < 1e-12);
    }

    #[test]
    fn landing_on_breakpoints_without_slivers() {
        let stops = [1.0, 3.0];
        assert_eq!(StepController::next_time(0.0, 0.4, &stops), 0.4);
        // 0.8 -> 1.0 is shorter than one increment: land.
        assert_eq!(StepController::next_time(0.8, 0.4, &stops), 1.0);
        // 0.5 -> 1.0 is 1.25 increments: split evenly.
        assert_eq!(StepController::next_time(0.5, 0.4, &stops), 0.75);
        assert_eq!(StepController::next_time(1.0, 5.0, &stops), 3.0);
    }

    #[test]
    fn limits_reject_and_easy_steps_grow() {
        let s = StepSettings {
            max_slip_increment: 0.1,
            ..StepSettings::default()
        };
        let ctl = StepController {
            dt: 0.2,
            limit: Limit::None,
        };
        let mut m = IncrementMeasures::default();
        m.add_slip(7, 0.4);
        let a = ctl.assess(&s, 3.0, 0.2, &m, 3);
        assert!(!a.accept);
        assert_eq!(a.limit, Limit::Slip);
        // 0.9 * 0.25 < 1/4 -> the floor 1/4.
        assert!((a.next_dt - 0.05).abs() < 1e-15);
        let mut easy = IncrementMeasures::default();
        easy.add_slip(7, 0.01);
        let a = ctl.assess(&s, 3.0, 0.2, &easy, 2);
        assert!(a.accept);
        assert!((a.next_dt - 0.4).abs() < 1e-15, "growth capped at 2");
        // At dt_min an excess is accepted (and reported by the caller).
        let a = ctl.assess(&s, 3.0, 3e-6, &m, 3);
        assert!(a.accept);
    }

    #[test]
    fn a_limit_exceeded_at_dt_min_is_explained_once_then_named_briefly() {
        let first = limit_warning(Limit::Slip, 2.5, 0.1, true);
        for needed in [
            "max_slip_increment",
            "2.500",
            "dt_min = 1e-1",
            "sound",
            "history.csv",
        ] {
            assert!(first.contains(needed), "{needed:?} missing from {first:?}");
        }
        let later = limit_warning(Limit::Rotation, 1.25, 0.1, false);
        assert!(later.contains("max_rotation_increment") && later.contains("1.250"));
        assert!(
            !later.contains("sound") && later.len() < first.len() / 2,
            "{later:?}"
        );
    }
}
