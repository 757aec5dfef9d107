//! Placement of a tool's surface in the global frame.

use crate::geometry::{Mat3, Projection, RigidSurface, SurfaceHint, Vec3};

/// Rigid placement of a surface: a global point is `x = R x_local + t`, `R` a rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub rotation: Mat3,
    pub translation: Vec3,
}

impl Default for Pose {
    fn default() -> Pose {
        Pose {
            rotation: Mat3::identity(),
            translation: Vec3::zeros(),
        }
    }
}

impl Pose {
    /// The identity placement.
    pub fn identity() -> Pose {
        Pose::default()
    }

    pub fn from_translation(translation: Vec3) -> Pose {
        Pose {
            translation,
            ..Pose::default()
        }
    }

    /// Rotation by `angle` (radians, right-handed) about the axis through `point` along
    /// the unit vector `axis`, then translation by `translation`:
    /// `x = R (p - point) + point + translation`.
    pub fn about_axis(point: &Vec3, axis: &Vec3, angle: f64, translation: &Vec3) -> Pose {
        let r = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(*axis), angle)
            .into_inner();
        Pose {
            rotation: r,
            translation: point - r * point + translation,
        }
    }

    /// Global point to the surface's frame: `R^T (x - t)`.
    pub fn to_local(&self, x: &Vec3) -> Vec3 {
        self.rotation.tr_mul(&(x - self.translation))
    }

    /// Surface-frame point to global: `R p + t`.
    pub fn to_global_point(&self, p: &Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }

    /// Surface-frame vector (normal, direction) to global: `R v`.
    pub fn to_global_vector(&self, v: &Vec3) -> Vec3 {
        self.rotation * v
    }

    /// Global direction to the surface frame: `R^T v`.
    pub fn to_local_vector(&self, v: &Vec3) -> Vec3 {
        self.rotation.tr_mul(v)
    }

    /// Surface-frame tensor to global: `R G R^T`. For the normal gradient this follows from
    /// `n(x) = R n_local(R^T (x - t))`.
    pub fn to_global_matrix(&self, g: &Mat3) -> Mat3 {
        self.rotation * g * self.rotation.transpose()
    }
}

/// Closest-point projection of the global point `x` on `surface` placed at `pose`.
///
/// `x` is mapped to the surface's frame, projected, and the foot, normal and normal
/// gradient are mapped back; the gap and the hint are frame-independent.
pub fn project_posed(
    surface: &dyn RigidSurface,
    pose: &Pose,
    x: &Vec3,
    hint: Option<&SurfaceHint>,
) -> Option<Projection> {
    let local = surface.project(&pose.to_local(x), hint)?;
    Some(Projection {
        foot: pose.to_global_point(&local.foot),
        normal: pose.to_global_vector(&local.normal),
        gap: local.gap,
        normal_gradient: pose.to_global_matrix(&local.normal_gradient),
        hint: local.hint,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::*;
    use crate::geometry::{Cylinder, Plane, Sphere};

    fn surfaces() -> Vec<Box<dyn RigidSurface>> {
        vec![
            Box::new(Plane::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, -1.0, 2.0)).unwrap()),
            Box::new(
                Cylinder::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 1.0), 2.0).unwrap(),
            ),
            Box::new(Sphere::new(Vec3::new(-1.0, 0.5, 0.0), 1.5).unwrap()),
        ]
    }

    #[test]
    fn pose_maps_round_trip() {
        let pose = Pose::from_translation(Vec3::new(3.0, -2.0, 1.5));
        let x = Vec3::new(0.25, 4.0, -7.0);
        assert_eq!(pose.to_global_point(&pose.to_local(&x)), x);
        assert_eq!(pose.to_local(&x), Vec3::new(-2.75, 6.0, -8.5));
        assert_eq!(pose.to_global_vector(&x), x);
        assert_eq!(Pose::identity().to_local(&x), x);
    }

    /// Moving the tool by t and the point by t leaves gap and normal unchanged, moves the foot by t.
    #[test]
    fn posed_projection_is_the_translated_projection() {
        let mut rng = Rng::new(41);
        let t = Vec3::new(3.0, -2.0, 1.5);
        let pose = Pose::from_translation(t);
        for surface in surfaces() {
            for _ in 0..100 {
                let x = rng.vec3(4.0);
                let local = surface.project(&x, None).unwrap();
                let posed = project_posed(surface.as_ref(), &pose, &(x + t), None).unwrap();
                assert_projection_consistent(&posed, &(x + t));
                assert!((posed.foot - (local.foot + t)).norm() < 1e-12);
                assert!((posed.normal - local.normal).norm() < 1e-12);
                assert!((posed.gap - local.gap).abs() < 1e-12);
            }
        }
    }

    /// Points at signed distance -0.6..2 from each posed surface (radii are 1.5 and 2).
    #[test]
    fn normal_gradient_through_pose_matches_finite_differences() {
        let mut rng = Rng::new(42);
        let t = Vec3::new(3.0, -2.0, 1.5);
        let pose = Pose::from_translation(t);
        for surface in surfaces() {
            let project = |y: &Vec3| project_posed(surface.as_ref(), &pose, y, None);
            let (mut inside, mut outside) = (0, 0);
            for _ in 0..200 {
                let seed = surface.project(&rng.vec3(4.0), None).unwrap();
                let d = rng.uniform(-0.6, 2.0);
                let x = t + seed.foot + seed.normal * d;
                assert_gradient_matches_fd(&project, &x);
                if project(&x).unwrap().gap < 0.0 {
                    inside += 1;
                } else {
                    outside += 1;
                }
            }
            assert!(inside > 30 && outside > 30, "{}", surface.describe());
        }
    }

    /// A rotated and translated surface: the posed projection is the rotated local one,
    /// and its normal gradient matches finite differences.
    #[test]
    fn rotated_pose_maps_projection_and_gradient() {
        let mut rng = Rng::new(43);
        let pose = Pose::about_axis(
            &Vec3::new(1.0, 2.0, -1.0),
            &Vec3::new(0.3, -0.5, 1.0).normalize(),
            0.7,
            &Vec3::new(-2.0, 0.5, 1.0),
        );
        assert!((pose.rotation.transpose() * pose.rotation - Mat3::identity()).norm() < 1e-15);
        for surface in surfaces() {
            let project = |y: &Vec3| project_posed(surface.as_ref(), &pose, y, None);
            for _ in 0..100 {
                let x = rng.vec3(4.0);
                let local = surface.project(&x, None).unwrap();
                let xg = pose.to_global_point(&x);
                let posed = project(&xg).unwrap();
                assert_projection_consistent(&posed, &xg);
                assert!((posed.foot - pose.to_global_point(&local.foot)).norm() < 1e-12);
                assert!((posed.normal - pose.rotation * local.normal).norm() < 1e-12);
                assert!((posed.gap - local.gap).abs() < 1e-12);
                assert!((pose.to_local(&xg) - x).norm() < 1e-13);
                assert_gradient_matches_fd(&project, &xg);
            }
        }
    }

    #[test]
    fn undefined_projection_stays_undefined() {
        let sphere = Sphere::new(Vec3::zeros(), 1.0).unwrap();
        let t = Vec3::new(1.0, 2.0, 3.0);
        assert!(project_posed(&sphere, &Pose::from_translation(t), &t, None).is_none());
    }
}
