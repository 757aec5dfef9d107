//! Piecewise-linear functions of pseudo-time: tool translations, prescribed displacements
//! and loads.

use std::ops::{Add, Mul, Sub};

use crate::geometry::{finite_vec3, Vec3};
use crate::{Error, Result};

/// Tool translation against pseudo-time: linear between the points `(t_i, u_i)`, equal to
/// the first value before `t_0` and to the last value after the last time.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    points: Vec<(f64, Vec3)>,
}

impl Schedule {
    /// Requires at least one point, finite times and translations, and strictly increasing
    /// times; the error names the offending index.
    pub fn new(points: Vec<(f64, Vec3)>) -> Result<Schedule> {
        check_times("schedule", points.iter().map(|p| p.0))?;
        for (i, (_, u)) in points.iter().enumerate() {
            finite_vec3(&format!("schedule translation[{i}]"), u)?;
        }
        Ok(Schedule { points })
    }

    /// A tool that never moves.
    pub fn fixed() -> Schedule {
        Schedule {
            points: vec![(0.0, Vec3::zeros())],
        }
    }

    /// Translation at time `t` (a NaN time gives the first translation).
    pub fn translation(&self, t: f64) -> Vec3 {
        interpolate(&self.points, t)
    }

    /// Time of the last point.
    pub fn end_time(&self) -> f64 {
        end_time(&self.points)
    }

    pub fn points(&self) -> &[(f64, Vec3)] {
        &self.points
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
    fn nan_time_does_not_panic() {
        assert_eq!(two_leg().translation(f64::NAN), Vec3::zeros());
    }
}
