//! Piecewise-linear functions of pseudo-time: tool translations, prescribed displacements
//! and loads.

use std::ops::{Add, Mul, Sub};

use super::Pose;
use crate::geometry::{finite_vec3, unit_vec3, Vec3};
use crate::{Error, Result};

/// Tool motion against pseudo-time: a translation linear between the points `(t_i, u_i)`,
/// equal to the first value before `t_0` and to the last value after the last time; and
/// optionally a rotation about a fixed axis by an angle piecewise linear in time (same
/// rules), applied before the translation.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    points: Vec<(f64, Vec3)>,
    rotation: Option<AxisRotation>,
}

/// Rotation of a tool about the axis through `point` along the unit vector `axis`, by the
/// angle `angle(t)` (radians, right-handed about `axis`).
#[derive(Clone, Debug, PartialEq)]
pub struct AxisRotation {
    pub point: Vec3,
    pub axis: Vec3,
    pub angle: ScalarSchedule,
}

impl Schedule {
    /// Requires at least one point, finite times and translations, and strictly increasing
    /// times; the error names the offending index.
    pub fn new(points: Vec<(f64, Vec3)>) -> Result<Schedule> {
        check_times("schedule", points.iter().map(|p| p.0))?;
        for (i, (_, u)) in points.iter().enumerate() {
            finite_vec3(&format!("schedule translation[{i}]"), u)?;
        }
        Ok(Schedule {
            points,
            rotation: None,
        })
    }

    /// A tool that never moves.
    pub fn fixed() -> Schedule {
        Schedule {
            points: vec![(0.0, Vec3::zeros())],
            rotation: None,
        }
    }

    /// The same translation, plus a rotation about the axis through `point` along `axis`
    /// by the piecewise-linear angle `(t_i, angle_i)` in degrees. Errs on a zero or
    /// non-finite axis or point, and on bad times or angles (naming the index).
    pub fn with_rotation(
        mut self,
        point: Vec3,
        axis: Vec3,
        angles_deg: Vec<(f64, f64)>,
    ) -> Result<Schedule> {
        let point = finite_vec3("rotation axis point", &point)?;
        let axis = unit_vec3("rotation axis", &axis)?;
        let angle = ScalarSchedule::new(
            angles_deg
                .into_iter()
                .map(|(t, a)| (t, a.to_radians()))
                .collect(),
        )
        .map_err(|e| match e {
            Error::Input(m) => Error::Input(format!("rotation {m}")),
            other => other,
        })?;
        self.rotation = Some(AxisRotation { point, axis, angle });
        Ok(self)
    }

    /// The same translation with `rotation` (validated when it was made).
    pub fn keeping_rotation(mut self, rotation: Option<AxisRotation>) -> Schedule {
        self.rotation = rotation;
        self
    }

    pub fn rotation(&self) -> Option<&AxisRotation> {
        self.rotation.as_ref()
    }

    /// The tool's placement at time `t`: `x = R(t) (p - a) + a + u(t)`.
    pub fn pose(&self, t: f64) -> Pose {
        let u = self.translation(t);
        match &self.rotation {
            None => Pose::from_translation(u),
            Some(r) => Pose::about_axis(&r.point, &r.axis, r.angle.value(t), &u),
        }
    }

    /// Translation at time `t` (a NaN time gives the first translation).
    pub fn translation(&self, t: f64) -> Vec3 {
        interpolate(&self.points, t)
    }

    /// Time of the last point (of translation or rotation).
    pub fn end_time(&self) -> f64 {
        let rotation_end = self.rotation.as_ref().map_or(0.0, |r| r.angle.end_time());
        end_time(&self.points).max(rotation_end)
    }

    pub fn points(&self) -> &[(f64, Vec3)] {
        &self.points
    }

    /// The schedule of a tool that stops at `from` and holds there until `to` (a step
    /// ended early at `from`, its rest skipped): `u(from)` on `[from, to]`, and after `to`
    /// the old motion shifted by `u(from) - u(to)`, so that it goes on from where the tool
    /// stopped. Unchanged for `from >= to`; the rotation is kept as it is.
    pub fn held_between(&self, from: f64, to: f64) -> Schedule {
        if from >= to {
            return self.clone();
        }
        let held = self.translation(from);
        let shift = held - self.translation(to);
        let mut points: Vec<(f64, Vec3)> =
            self.points.iter().copied().filter(|p| p.0 < from).collect();
        points.push((from, held));
        points.push((to, held));
        points.extend(
            (self.points.iter())
                .filter(|p| p.0 > to)
                .map(|&(t, u)| (t, u + shift)),
        );
        Schedule {
            points,
            rotation: self.rotation.clone(),
        }
    }
}

/// Scalar piecewise-linear function of pseudo-time (prescribed displacement values,
/// loads), with the same rules as [`Schedule`].
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarSchedule {
    points: Vec<(f64, f64)>,
}

impl ScalarSchedule {
    /// Requires at least one point, finite times and values, and strictly increasing times.
    pub fn new(points: Vec<(f64, f64)>) -> Result<ScalarSchedule> {
        check_times("schedule", points.iter().map(|p| p.0))?;
        for (i, &(_, v)) in points.iter().enumerate() {
            if !v.is_finite() {
                return Err(Error::input(
                    &format!("schedule value[{i}]"),
                    v,
                    "must be finite",
                ));
            }
        }
        Ok(ScalarSchedule { points })
    }

    /// The value `v` at all times. Infallible like [`Schedule::fixed`], so `v` is not
    /// checked: validate user input with [`ScalarSchedule::new`] instead.
    pub fn constant(v: f64) -> ScalarSchedule {
        ScalarSchedule {
            points: vec![(0.0, v)],
        }
    }

    /// Value at time `t` (a NaN time gives the first value).
    pub fn value(&self, t: f64) -> f64 {
        interpolate(&self.points, t)
    }

    /// Time of the last point.
    /// The smallest value the schedule takes (it is piecewise linear, so at one of its points).
    pub fn min_value(&self) -> f64 {
        self.points
            .iter()
            .map(|p| p.1)
            .fold(f64::INFINITY, f64::min)
    }

    pub fn end_time(&self) -> f64 {
        end_time(&self.points)
    }

    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }
}

/// At least one time, all finite, strictly increasing.
fn check_times(what: &str, times: impl Iterator<Item = f64>) -> Result<()> {
    let mut count = 0;
    let mut previous = f64::NEG_INFINITY;
    for (i, t) in times.enumerate() {
        count += 1;
        if !t.is_finite() {
            return Err(Error::input(
                &format!("{what} time[{i}]"),
                t,
                "must be finite",
            ));
        }
        if i > 0 && t <= previous {
            return Err(Error::input(
                &format!("{what} time[{i}]"),
                t,
                &format!("must be greater than time[{}] = {previous}", i - 1),
            ));
        }
        previous = t;
    }
    if count == 0 {
        return Err(Error::input(
            &format!("{what} point count"),
            0,
            "must be at least 1",
        ));
    }
    Ok(())
}

/// `points` is non-empty with increasing times (checked at construction).
fn interpolate<T>(points: &[(f64, T)], t: f64) -> T
where
    T: Copy + Add<Output = T> + Sub<Output = T> + Mul<f64, Output = T>,
{
    // Index of the first point strictly after t; 0 also for a NaN t.
    let i = points.partition_point(|p| p.0 <= t);
    if i == 0 {
        return points[0].1;
    }
    if i == points.len() {
        return points[i - 1].1;
    }
    let (t0, v0) = points[i - 1];
    let (t1, v1) = points[i];
    v0 + (v1 - v0) * ((t - t0) / (t1 - t0))
}

fn end_time<T>(points: &[(f64, T)]) -> f64 {
    points.last().map_or(0.0, |p| p.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_schedule_stops_and_goes_on_from_where_it_stopped() {
        let s = Schedule::new(vec![
            (0.0, Vec3::zeros()),
            (2.0, Vec3::new(0.0, 0.0, -4.0)),
            (3.0, Vec3::new(0.0, 0.0, -3.0)),
        ])
        .unwrap();
        let h = s.held_between(1.0, 2.0);
        assert_eq!(h.translation(0.5), s.translation(0.5), "unchanged before");
        assert_eq!(h.translation(1.5), Vec3::new(0.0, 0.0, -2.0), "held");
        assert_eq!(h.translation(2.0), Vec3::new(0.0, 0.0, -2.0));
        // The next step's move (+1 over [2, 3]) from where the tool stopped.
        assert_eq!(h.translation(3.0), Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(s.held_between(2.0, 2.0), s);
    }

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    fn two_leg() -> Schedule {
        Schedule::new(vec![
            (0.0, v(0.0, 0.0, 0.0)),
            (1.0, v(0.0, 0.0, -2.0)),
            (3.0, v(4.0, 0.0, -2.0)),
        ])
        .unwrap()
    }

    #[test]
    fn translation_interpolates_between_points() {
        let s = two_leg();
        assert_eq!(s.translation(0.0), v(0.0, 0.0, 0.0));
        assert_eq!(s.translation(0.25), v(0.0, 0.0, -0.5));
        assert_eq!(s.translation(1.0), v(0.0, 0.0, -2.0));
        assert_eq!(s.translation(2.0), v(2.0, 0.0, -2.0));
        assert_eq!(s.translation(3.0), v(4.0, 0.0, -2.0));
        assert_eq!(s.end_time(), 3.0);
    }

    #[test]
    fn translation_extrapolates_constantly() {
        let s = two_leg();
        assert_eq!(s.translation(-5.0), v(0.0, 0.0, 0.0));
        assert_eq!(s.translation(10.0), v(4.0, 0.0, -2.0));
        let single = Schedule::new(vec![(2.0, v(1.0, 2.0, 3.0))]).unwrap();
        assert_eq!(single.translation(0.0), v(1.0, 2.0, 3.0));
        assert_eq!(single.translation(9.0), v(1.0, 2.0, 3.0));
        assert_eq!(single.end_time(), 2.0);
    }

    #[test]
    fn fixed_schedule_is_zero() {
        let s = Schedule::fixed();
        for t in [-1.0, 0.0, 0.5, 100.0] {
            assert_eq!(s.translation(t), Vec3::zeros());
        }
        assert_eq!(s.end_time(), 0.0);
    }

    #[test]
    fn decreasing_times_are_rejected_with_index() {
        let err = Schedule::new(vec![
            (0.0, Vec3::zeros()),
            (1.0, Vec3::zeros()),
            (0.5, Vec3::zeros()),
        ])
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("schedule time[2] = 0.5 must be greater than time[1] = 1"),
            "{err}"
        );
        let err = ScalarSchedule::new(vec![(0.0, 1.0), (0.0, 2.0)])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("schedule time[1] = 0 must be greater than time[0] = 0"),
            "{err}"
        );
    }

    #[test]
    fn empty_or_non_finite_schedules_are_rejected() {
        let err = Schedule::new(vec![]).unwrap_err().to_string();
        assert!(
            err.contains("schedule point count = 0 must be at least 1"),
            "{err}"
        );
        let err = ScalarSchedule::new(vec![]).unwrap_err().to_string();
        assert!(
            err.contains("schedule point count = 0 must be at least 1"),
            "{err}"
        );
        let err = Schedule::new(vec![(0.0, Vec3::zeros()), (f64::NAN, Vec3::zeros())])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("schedule time[1] = NaN must be finite"),
            "{err}"
        );
        let err = Schedule::new(vec![
            (0.0, Vec3::zeros()),
            (1.0, v(0.0, f64::INFINITY, 0.0)),
        ])
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("schedule translation[1] = (0, inf, 0) must be finite"),
            "{err}"
        );
        let err = ScalarSchedule::new(vec![(0.0, f64::NAN)])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("schedule value[0] = NaN must be finite"),
            "{err}"
        );
    }

    #[test]
    fn scalar_schedule_interpolates_and_extrapolates() {
        let s = ScalarSchedule::new(vec![(1.0, 10.0), (2.0, 20.0), (4.0, 0.0)]).unwrap();
        assert_eq!(s.value(0.0), 10.0);
        assert_eq!(s.value(1.5), 15.0);
        assert_eq!(s.value(3.0), 10.0);
        assert_eq!(s.value(5.0), 0.0);
        assert_eq!(s.end_time(), 4.0);
        let c = ScalarSchedule::constant(-3.5);
        assert_eq!(c.value(-1.0), -3.5);
        assert_eq!(c.value(7.0), -3.5);
    }

    #[test]
    fn rotation_interpolates_the_angle_about_the_axis() {
        let s = two_leg()
            .with_rotation(
                v(1.0, 0.0, 0.0),
                v(0.0, 0.0, 2.0),
                vec![(0.0, 0.0), (2.0, 90.0)],
            )
            .unwrap();
        // At t = 2: translation (2, 0, -2), quarter turn about the vertical axis through x = 1.
        let pose = s.pose(2.0);
        let p = pose.to_global_point(&v(2.0, 0.0, 0.0));
        assert!((p - v(1.0 + 2.0, 1.0, -2.0)).norm() < 1e-15);
        let half = s.pose(1.0).to_global_vector(&v(1.0, 0.0, 0.0));
        let c = std::f64::consts::FRAC_1_SQRT_2;
        assert!((half - v(c, c, 0.0)).norm() < 1e-15);
        assert_eq!(s.end_time(), 3.0);
        let err = Schedule::fixed()
            .with_rotation(v(0.0, 0.0, 0.0), v(0.0, 0.0, 0.0), vec![(0.0, 0.0)])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("rotation axis = (0, 0, 0) must be non-zero"),
            "{err}"
        );
        let err = Schedule::fixed()
            .with_rotation(
                v(0.0, 0.0, 0.0),
                v(0.0, 0.0, 1.0),
                vec![(1.0, 0.0), (0.5, 3.0)],
            )
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("rotation schedule time[1] = 0.5 must be greater than time[0] = 1"),
            "{err}"
        );
    }

    #[test]
    fn nan_time_does_not_panic() {
        assert_eq!(two_leg().translation(f64::NAN), Vec3::zeros());
    }
}
