//! Force control of a tool: instead of following its schedule exactly, the tool also moves by
//! an unknown offset `s` along a fixed axis, chosen so that the force it applies to the body
//! along that axis equals a scheduled value (a blankholder force). The solver side is
//! `solver::force_control`.
//!
//! In a process of steps a tool may be force-controlled in some steps only: `windows`
//! lists the intervals `(t0, t1]` of pseudo-time where the force equation holds (empty:
//! always). Outside them the tool is kinematic again, its offset held at the value it had
//! (`s = s_committed`), so that its position stays continuous when control switches.

use super::schedule::ScalarSchedule;
use crate::geometry::Vec3;
use crate::{Error, Result};

/// The axis (unit vector) and the force schedule of a force-controlled tool.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceControl {
    /// Unit direction in which the tool pushes; the pose is the scheduled translation plus
    /// `s * axis`.
    pub axis: Vec3,
    /// Force the tool applies to the body along `axis` (force units, > 0 pushes).
    pub force: ScalarSchedule,
    /// Intervals `(t0, t1]` of pseudo-time where the force equation holds; empty: always.
    pub windows: Vec<(f64, f64)>,
}

impl ForceControl {
    /// `axis` need not be unit length but must be finite and non-zero.
    pub fn new(axis: Vec3, force: ScalarSchedule) -> Result<Self> {
        let len = axis.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(Error::input(
                "force-control axis",
                format!("[{}, {}, {}]", axis.x, axis.y, axis.z),
                "must be a finite, non-zero vector",
            ));
        }
        // Contact only pushes: a negative force along the axis cannot be applied through it,
        // and the tool would leave the body (the run "finishing" with a force of 0).
        let least = force.min_value();
        if least < 0.0 {
            return Err(Error::input(
                "force-control force",
                least,
                "must be >= 0: the tool pushes the body along the axis through contact; \
                 to push the other way, reverse the axis",
            ));
        }
        Ok(ForceControl {
            axis: axis / len,
            force,
            windows: Vec::new(),
        })
    }

    /// Whether the force equation holds for an increment ending at `t` (else the offset
    /// is held). A relative round-off of `t` at a window's end counts as inside.
    pub fn active_at(&self, t: f64) -> bool {
        self.windows.is_empty()
            || self.windows.iter().any(|&(a, b)| {
                let tol = 1e-12 * b.abs().max(1.0);
                t > a + tol && t <= b + tol
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_is_normalised_and_zero_refused() {
        let f =
            ForceControl::new(Vec3::new(0.0, 0.0, -2.0), ScalarSchedule::constant(1.0)).unwrap();
        assert_eq!(f.axis, Vec3::new(0.0, 0.0, -1.0));
        let err = ForceControl::new(Vec3::zeros(), ScalarSchedule::constant(1.0)).unwrap_err();
        assert!(err.to_string().contains("force-control axis"), "{err}");
    }

    #[test]
    fn a_pulling_force_is_refused() {
        let axis = Vec3::new(0.0, 0.0, -1.0);
        let err = ForceControl::new(axis, ScalarSchedule::constant(-10.0)).unwrap_err();
        assert!(
            err.to_string()
                .contains("force-control force = -10 must be >= 0"),
            "{err}"
        );
        let ramp = ScalarSchedule::new(vec![(0.0, 5.0), (1.0, -1.0)]).unwrap();
        assert!(ForceControl::new(axis, ramp).is_err());
        assert!(ForceControl::new(axis, ScalarSchedule::constant(0.0)).is_ok());
    }

    #[test]
    fn windows_say_when_the_force_acts() {
        let mut f = ForceControl::new(Vec3::z(), ScalarSchedule::constant(1.0)).unwrap();
        assert!(f.active_at(0.0) && f.active_at(7.0), "no windows: always");
        f.windows = vec![(0.0, 1.0), (3.0, 4.0)];
        assert!(!f.active_at(0.0), "a window is open at its start");
        assert!(f.active_at(0.5) && f.active_at(1.0) && f.active_at(4.0));
        assert!(!f.active_at(2.0) && !f.active_at(4.5));
    }
}
