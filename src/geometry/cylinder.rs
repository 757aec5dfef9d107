//! Infinite solid circular cylinder.

use super::*;
use crate::Result;

/// Infinite circular cylinder of radius `R` around the line through `c` with unit direction
/// `a`. The tool is the inside; the outward normal points away from the axis.
///
/// With `P_a = I - a a^T` (projector across the axis) and `rho = |P_a (x - c)|`:
/// - normal `n = P_a (x - c) / rho`,
/// - foot `c + a a^T (x - c) + R n`,
/// - gap `d_n = rho - R` (negative inside),
/// - normal gradient `dn/dx = (P_a - n n^T) / rho`.
///
/// Undefined (`None`) for points within `1e-12 R` of the axis.
#[derive(Debug, Clone)]
pub struct Cylinder {
    axis_point: Vec3,
    axis_direction: Vec3,
    radius: f64,
}

impl Cylinder {
    /// Cylinder around the axis through `axis_point` along `axis_direction` (normalised
    /// here). Errs if a vector is not finite, the direction is zero, or `radius` is not
    /// finite and > 0.
    pub fn new(axis_point: Vec3, axis_direction: Vec3, radius: f64) -> Result<Cylinder> {
        Ok(Cylinder {
            axis_point: finite_vec3("cylinder axis point", &axis_point)?,
            axis_direction: unit_vec3("cylinder axis direction", &axis_direction)?,
            radius: positive_length("cylinder radius", radius)?,
        })
    }

    pub fn axis_point(&self) -> Vec3 {
        self.axis_point
    }

    /// Unit axis direction.
    pub fn axis_direction(&self) -> Vec3 {
        self.axis_direction
    }

    pub fn radius(&self) -> f64 {
        self.radius
    }
}

impl RigidSurface for Cylinder {
    fn project(&self, x: &Vec3, _hint: Option<&SurfaceHint>) -> Option<Projection> {
        let a = self.axis_direction;
        let rel = x - self.axis_point;
        let along = a * a.dot(&rel);
        let across = rel - along;
        let rho = across.norm();
        if rho < 1e-12 * self.radius {
            return None;
        }
        let n = across / rho;
        let p_a = Mat3::identity() - a * a.transpose();
        Some(Projection {
            foot: self.axis_point + along + n * self.radius,
            normal: n,
            gap: rho - self.radius,
            normal_gradient: (p_a - n * n.transpose()) / rho,
            hint: SurfaceHint::default(),
        })
    }

    fn analytic_shape(&self) -> Option<AnalyticShape> {
        Some(AnalyticShape::Cylinder {
            axis_point: self.axis_point,
            axis: self.axis_direction,
            radius: self.radius,
        })
    }

    fn describe(&self) -> String {
        format!(
            "cylinder r={} axis {} through {}",
            self.radius,
            fmt_vec3(&self.axis_direction),
            fmt_vec3(&self.axis_point)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::*;

    fn random_cylinder(rng: &mut Rng) -> Cylinder {
        let r = rng.uniform(0.5, 5.0);
        Cylinder::new(rng.vec3(5.0), rng.vec3(2.0), r).unwrap()
    }

    /// A point at distance `R + d` from the axis, `d` in `[-0.8 R, 2 R]`, and the surface
    /// point it must project to.
    fn point_near(cyl: &Cylinder, rng: &mut Rng) -> (Vec3, Vec3, f64) {
        let a = cyl.axis_direction();
        let u = a.cross(&rng.unit_vec3()).normalize();
        let on_axis = cyl.axis_point() + a * rng.uniform(-5.0, 5.0);
        let r = cyl.radius();
        let d = rng.uniform(-0.8 * r, 2.0 * r);
        (on_axis + u * (r + d), on_axis + u * r, d)
    }

    #[test]
    fn projection_of_random_points_is_consistent() {
        let mut rng = Rng::new(21);
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..200 {
            let cyl = random_cylinder(&mut rng);
            let (x, expected_foot, d) = point_near(&cyl, &mut rng);
            let p = cyl.project(&x, None).unwrap();
            assert_projection_consistent(&p, &x);
            assert!((p.foot - expected_foot).norm() < 1e-12 * (1.0 + x.norm()));
            assert!((p.gap - d).abs() < 1e-12 * (1.0 + x.norm()));
            // Foot on the surface: its distance to the axis, |a x (foot - c)|, is R.
            let foot_rho = cyl
                .axis_direction()
                .cross(&(p.foot - cyl.axis_point()))
                .norm();
            assert!((foot_rho - cyl.radius()).abs() < 1e-12 * (1.0 + x.norm()));
            if d < 0.0 {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        assert!(inside > 50 && outside > 50);
    }

    /// Gap sign agrees with an independent inside test for points scattered in a box.
    #[test]
    fn gap_is_negative_exactly_inside() {
        let mut rng = Rng::new(22);
        let cyl = Cylinder::new(Vec3::new(1.0, -1.0, 0.5), Vec3::new(1.0, 2.0, -0.5), 2.0).unwrap();
        for _ in 0..500 {
            let x = rng.vec3(6.0);
            let p = cyl.project(&x, None).unwrap();
            assert_projection_consistent(&p, &x);
            let dist_to_axis = cyl.axis_direction().cross(&(x - cyl.axis_point())).norm();
            assert_eq!(
                p.gap < 0.0,
                dist_to_axis < 2.0,
                "x = {x:?}, gap = {}",
                p.gap
            );
        }
    }

    #[test]
    fn normal_gradient_matches_finite_differences() {
        let mut rng = Rng::new(23);
        for _ in 0..200 {
            let cyl = random_cylinder(&mut rng);
            let (x, _, _) = point_near(&cyl, &mut rng);
            assert_gradient_matches_fd(&|y| cyl.project(y, None), &x);
        }
    }

    #[test]
    fn point_on_axis_has_no_projection() {
        let cyl = Cylinder::new(Vec3::zeros(), Vec3::z(), 3.0).unwrap();
        assert!(cyl.project(&Vec3::new(0.0, 0.0, 7.0), None).is_none());
        assert!(cyl.project(&Vec3::new(1e-13, 0.0, 7.0), None).is_none());
        assert!(cyl.project(&Vec3::new(1e-9, 0.0, 7.0), None).is_some());
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let msg = |r: Result<Cylinder>| r.unwrap_err().to_string();
        let c = Vec3::zeros();
        let z = Vec3::z();
        let err = msg(Cylinder::new(c, z, 0.0));
        assert!(err.contains("cylinder radius = 0 must be > 0"), "{err}");
        let err = msg(Cylinder::new(c, z, -2.5));
        assert!(err.contains("cylinder radius = -2.5 must be > 0"), "{err}");
        let err = msg(Cylinder::new(c, z, f64::NAN));
        assert!(
            err.contains("cylinder radius = NaN must be finite"),
            "{err}"
        );
        let err = msg(Cylinder::new(c, z, f64::INFINITY));
        assert!(
            err.contains("cylinder radius = inf must be finite"),
            "{err}"
        );
        let err = msg(Cylinder::new(c, Vec3::zeros(), 1.0));
        assert!(
            err.contains("cylinder axis direction = (0, 0, 0) must be non-zero"),
            "{err}"
        );
        let err = msg(Cylinder::new(Vec3::new(f64::NAN, 0.0, 0.0), z, 1.0));
        assert!(
            err.contains("cylinder axis point = (NaN, 0, 0) must be finite"),
            "{err}"
        );
    }

    #[test]
    fn describe_names_the_parameters() {
        let cyl = Cylinder::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 2.0, 0.0), 5.0).unwrap();
        assert_eq!(
            cyl.describe(),
            "cylinder r=5 axis (0, 1, 0) through (0, 0, 1)"
        );
    }
}
