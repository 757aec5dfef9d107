//! Solid sphere.

use super::*;
use crate::Result;

/// Solid sphere of radius `R` centred at `c`; the tool is the inside.
///
/// With `r = |x - c|`:
/// - normal `n = (x - c) / r`,
/// - foot `c + R n`,
/// - gap `d_n = r - R` (negative inside),
/// - normal gradient `dn/dx = (I - n n^T) / r`.
///
/// Undefined (`None`) for points within `1e-12 R` of the centre.
#[derive(Debug, Clone)]
pub struct Sphere {
    center: Vec3,
    radius: f64,
}

impl Sphere {
    /// Errs if `center` is not finite or `radius` is not finite and > 0.
    pub fn new(center: Vec3, radius: f64) -> Result<Sphere> {
        Ok(Sphere {
            center: finite_vec3("sphere center", &center)?,
            radius: positive_length("sphere radius", radius)?,
        })
    }

    pub fn center(&self) -> Vec3 {
        self.center
    }

    pub fn radius(&self) -> f64 {
        self.radius
    }
}

impl RigidSurface for Sphere {
    fn project(&self, x: &Vec3, _hint: Option<&SurfaceHint>) -> Option<Projection> {
        let rel = x - self.center;
        let r = rel.norm();
        if r < 1e-12 * self.radius {
            return None;
        }
        let n = rel / r;
        Some(Projection {
            foot: self.center + n * self.radius,
            normal: n,
            gap: r - self.radius,
            normal_gradient: (Mat3::identity() - n * n.transpose()) / r,
            hint: SurfaceHint::default(),
        })
    }

    fn analytic_shape(&self) -> Option<AnalyticShape> {
        Some(AnalyticShape::Sphere {
            centre: self.center,
            radius: self.radius,
        })
    }

    fn describe(&self) -> String {
        format!("sphere r={} center {}", self.radius, fmt_vec3(&self.center))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::*;

    fn random_sphere(rng: &mut Rng) -> Sphere {
        let r = rng.uniform(0.5, 5.0);
        Sphere::new(rng.vec3(5.0), r).unwrap()
    }

    /// A point at distance `R + d` from the centre, `d` in `[-0.8 R, 2 R]`, and the surface
    /// point it must project to.
    fn point_near(sphere: &Sphere, rng: &mut Rng) -> (Vec3, Vec3, f64) {
        let u = rng.unit_vec3();
        let r = sphere.radius();
        let d = rng.uniform(-0.8 * r, 2.0 * r);
        (sphere.center() + u * (r + d), sphere.center() + u * r, d)
    }

    #[test]
    fn projection_of_random_points_is_consistent() {
        let mut rng = Rng::new(31);
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..200 {
            let sphere = random_sphere(&mut rng);
            let (x, expected_foot, d) = point_near(&sphere, &mut rng);
            let p = sphere.project(&x, None).unwrap();
            assert_projection_consistent(&p, &x);
            assert!((p.foot - expected_foot).norm() < 1e-12 * (1.0 + x.norm()));
            assert!((p.gap - d).abs() < 1e-12 * (1.0 + x.norm()));
            let foot_r = (p.foot - sphere.center()).norm();
            assert!((foot_r - sphere.radius()).abs() < 1e-12 * (1.0 + x.norm()));
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
        let mut rng = Rng::new(32);
        let sphere = Sphere::new(Vec3::new(0.5, -1.0, 1.0), 3.0).unwrap();
        for _ in 0..500 {
            let x = rng.vec3(5.0);
            let p = sphere.project(&x, None).unwrap();
            assert_projection_consistent(&p, &x);
            let inside = (x - sphere.center()).norm_squared() < 9.0;
            assert_eq!(p.gap < 0.0, inside, "x = {x:?}, gap = {}", p.gap);
        }
    }

    #[test]
    fn normal_gradient_matches_finite_differences() {
        let mut rng = Rng::new(33);
        for _ in 0..200 {
            let sphere = random_sphere(&mut rng);
            let (x, _, _) = point_near(&sphere, &mut rng);
            assert_gradient_matches_fd(&|y| sphere.project(y, None), &x);
        }
    }

    #[test]
    fn centre_has_no_projection() {
        let sphere = Sphere::new(Vec3::new(1.0, 2.0, 3.0), 2.0).unwrap();
        assert!(sphere.project(&Vec3::new(1.0, 2.0, 3.0), None).is_none());
        assert!(sphere
            .project(&Vec3::new(1.0, 2.0, 3.0 + 1e-6), None)
            .is_some());
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let msg = |r: Result<Sphere>| r.unwrap_err().to_string();
        let err = msg(Sphere::new(Vec3::zeros(), 0.0));
        assert!(err.contains("sphere radius = 0 must be > 0"), "{err}");
        let err = msg(Sphere::new(Vec3::zeros(), -1.5));
        assert!(err.contains("sphere radius = -1.5 must be > 0"), "{err}");
        let err = msg(Sphere::new(Vec3::zeros(), f64::NEG_INFINITY));
        assert!(err.contains("sphere radius = -inf must be finite"), "{err}");
        let err = msg(Sphere::new(Vec3::new(0.0, 0.0, f64::NAN), 1.0));
        assert!(
            err.contains("sphere center = (0, 0, NaN) must be finite"),
            "{err}"
        );
    }

    #[test]
    fn describe_names_the_parameters() {
        let sphere = Sphere::new(Vec3::new(1.0, 0.0, -2.0), 0.25).unwrap();
        assert_eq!(sphere.describe(), "sphere r=0.25 center (1, 0, -2)");
    }
}
