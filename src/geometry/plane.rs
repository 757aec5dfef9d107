//! Infinite plane: the tool fills the half-space behind its normal.

use super::*;
use crate::Result;

/// Plane through `p` with unit outward normal `n`; the tool is the half-space
/// `n . (x - p) < 0`.
///
/// Projection of `x`: gap `d_n = n . (x - p)`, foot `x - d_n n`, normal `n` everywhere,
/// so the normal gradient `dn/dx` is zero.
#[derive(Debug, Clone)]
pub struct Plane {
    point: Vec3,
    normal: Vec3,
}

impl Plane {
    /// Plane through `point` with outward `normal` (normalised here). Errs if `point` is
    /// not finite or `normal` is zero or not finite.
    pub fn new(point: Vec3, normal: Vec3) -> Result<Plane> {
        Ok(Plane {
            point: finite_vec3("plane point", &point)?,
            normal: unit_vec3("plane normal", &normal)?,
        })
    }

    pub fn point(&self) -> Vec3 {
        self.point
    }

    /// Unit outward normal.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }
}

impl RigidSurface for Plane {
    fn project(&self, x: &Vec3, _hint: Option<&SurfaceHint>) -> Option<Projection> {
        let gap = self.normal.dot(&(x - self.point));
        Some(Projection {
            foot: x - self.normal * gap,
            normal: self.normal,
            gap,
            normal_gradient: Mat3::zeros(),
            hint: SurfaceHint::default(),
        })
    }

    fn analytic_shape(&self) -> Option<AnalyticShape> {
        Some(AnalyticShape::Plane {
            point: self.point,
            normal: self.normal,
        })
    }

    fn describe(&self) -> String {
        format!(
            "plane through {} with normal {}",
            fmt_vec3(&self.point),
            fmt_vec3(&self.normal)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::*;

    fn random_plane(rng: &mut Rng) -> Plane {
        Plane::new(rng.vec3(5.0), rng.vec3(3.0)).unwrap()
    }

    /// Points built as (surface point) + d n must project back to that surface point with gap d.
    #[test]
    fn projection_of_random_points_is_consistent() {
        let mut rng = Rng::new(11);
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..200 {
            let plane = random_plane(&mut rng);
            let n = plane.normal();
            let t = n.cross(&rng.unit_vec3());
            let on_surface = plane.point() + t * rng.uniform(-4.0, 4.0);
            let d = rng.uniform(-3.0, 3.0);
            let x = on_surface + n * d;
            let p = plane.project(&x, None).unwrap();
            assert_projection_consistent(&p, &x);
            assert!(
                n.dot(&(p.foot - plane.point())).abs() < 1e-12,
                "foot off the plane"
            );
            assert!((p.foot - on_surface).norm() < 1e-12);
            assert!((p.gap - d).abs() < 1e-12);
            if d < 0.0 {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        assert!(inside > 50 && outside > 50);
    }

    #[test]
    fn normal_gradient_is_zero_and_matches_finite_differences() {
        let mut rng = Rng::new(12);
        for _ in 0..100 {
            let plane = random_plane(&mut rng);
            let x = rng.vec3(8.0);
            assert_eq!(
                plane.project(&x, None).unwrap().normal_gradient,
                Mat3::zeros()
            );
            assert_gradient_matches_fd(&|y| plane.project(y, None), &x);
        }
    }

    #[test]
    fn normal_is_normalised() {
        let plane = Plane::new(Vec3::zeros(), Vec3::new(0.0, 0.0, 1e-200)).unwrap();
        assert_eq!(plane.normal(), Vec3::new(0.0, 0.0, 1.0));
        let plane = Plane::new(Vec3::zeros(), Vec3::new(3.0, 0.0, 4.0)).unwrap();
        assert!((plane.normal() - Vec3::new(0.6, 0.0, 0.8)).norm() < 1e-15);
    }

    #[test]
    fn invalid_parameters_are_rejected() {
        let err = Plane::new(Vec3::zeros(), Vec3::zeros())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("plane normal = (0, 0, 0) must be non-zero"),
            "{err}"
        );
        let err = Plane::new(Vec3::zeros(), Vec3::new(f64::NAN, 0.0, 1.0))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("plane normal = (NaN, 0, 1) must be finite"),
            "{err}"
        );
        let err = Plane::new(Vec3::new(0.0, f64::INFINITY, 0.0), Vec3::z())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("plane point = (0, inf, 0) must be finite"),
            "{err}"
        );
    }

    #[test]
    fn describe_names_the_parameters() {
        let plane = Plane::new(Vec3::new(1.0, 2.0, 3.0), Vec3::z()).unwrap();
        assert_eq!(
            plane.describe(),
            "plane through (1, 2, 3) with normal (0, 0, 1)"
        );
    }
}
