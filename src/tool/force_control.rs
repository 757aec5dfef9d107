//! Force control of a tool: instead of following its schedule exactly, the tool also moves by
//! an unknown offset `s` along a fixed axis, chosen so that the force it applies to the body
//! along that axis equals a scheduled value (a blankholder force). The solver side is
//! `solver::force_control`.

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
}
