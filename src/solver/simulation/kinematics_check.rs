//! A warning for small-strain runs that rotate too far for the small-strain theory.
//!
//! Under small kinematics the strain is `sym ∇u`: a rigid rotation by θ reads as a stretch
//! of about θ²/2 (1 - cos θ), so a sheet bent over a tool picks up spurious strains, and
//! with them spurious stresses and plastic flow, that grow with the square of the rotation.
//! At θ = 0.1 rad that error is 5e-3, several times a sheet metal's yield strain (1-3e-3):
//! a forming script that forgets `kinematics: "finite"` gets results that look plausible
//! and are wrong. The limit sits above the local rotations of contact scenes that are
//! small-strain problems by design (the elastic cylinder drag turns its surface cells by
//! 0.07 rad under the roller) and far below a sheet bent over a tool radius (order 1 rad). The check is cheap (one pass over the integration points per increment) and
//! fires once per run, at the increment where the largest rotation first crosses the limit.

use crate::geometry::Mat3;
use crate::material::PointState;

/// Rotation (radians) above which the small-strain theory's spurious strain `θ²/2`
/// is several times a metal's yield strain.
pub const SMALL_STRAIN_ROTATION_LIMIT: f64 = 0.1;

/// Largest infinitesimal rotation `|axial(skew ∇u)|` over the points, and the point's
/// index. Small-strain elements store `F = I + ∇u`, so `skew F = skew ∇u`.
pub fn largest_rotation(points: &[PointState]) -> (f64, usize) {
    let mut worst = (0.0, 0);
    for (i, p) in points.iter().enumerate() {
        let angle = infinitesimal_rotation(&p.deformation_gradient);
        if angle > worst.0 {
            worst = (angle, i);
        }
    }
    worst
}

fn infinitesimal_rotation(f: &Mat3) -> f64 {
    let w = [
        f[(2, 1)] - f[(1, 2)],
        f[(0, 2)] - f[(2, 0)],
        f[(1, 0)] - f[(0, 1)],
    ];
    0.5 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt()
}

/// How [`small_strain_warning`] begins: the script layer, which turns the warning into an
/// error where the script never chose its kinematics, recognises it by this constant (the
/// warning and the constant live together, so they cannot drift apart).
pub const SMALL_STRAIN_WARNING_START: &str = "small-strain kinematics";

/// The warning, when the largest rotation crosses the limit between the committed points
/// `before` and the newly converged `after` (so it is given once per run, and again only
/// if a run unloads below the limit and rotates past it once more).
pub fn small_strain_warning(
    before: &[PointState],
    after: &[PointState],
    points_per_element: usize,
) -> Option<String> {
    let (old, _) = largest_rotation(before);
    let (new, point) = largest_rotation(after);
    if old >= SMALL_STRAIN_ROTATION_LIMIT || new < SMALL_STRAIN_ROTATION_LIMIT {
        return None;
    }
    let element = point / points_per_element.max(1);
    Some(format!(
        "{SMALL_STRAIN_WARNING_START} (the engine's default) with a rotation of {new:.3} rad at element {element}: the small-strain strain sym(grad u) reads a rotation by θ as a \
         stretch of about θ²/2 = {:.1e}, so stresses and plastic flow from here on carry that \
         error. A sheet that bends over tools, or any large deflection, needs \
         sim.settings(#{{ kinematics: \"finite\" }}).",
        0.5 * new * new
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rotated(theta: f64) -> PointState {
        let (s, c) = theta.sin_cos();
        PointState {
            deformation_gradient: Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
            ..PointState::default()
        }
    }

    #[test]
    fn rotation_of_a_rigid_turn_is_its_angle_to_first_order() {
        // skew part of a rotation by θ is sin θ: the measure is sin θ.
        let p = rotated(0.2);
        assert!((largest_rotation(&[p]).0 - 0.2f64.sin()).abs() < 1e-15);
        let stretched = PointState {
            deformation_gradient: Mat3::new(1.3, 0.1, 0.0, 0.1, 0.9, 0.0, 0.0, 0.0, 1.0),
            ..PointState::default()
        };
        assert_eq!(largest_rotation(&[stretched]).0, 0.0);
    }

    #[test]
    fn warns_once_when_the_limit_is_crossed() {
        let small = vec![rotated(0.01); 16];
        let mut large = small.clone();
        large[9] = rotated(0.3);
        let text = small_strain_warning(&small, &large, 8).expect("crossing warns");
        assert!(
            text.contains("element 1") && text.contains("0.296 rad"),
            "{text}"
        );
        assert!(text.contains("kinematics: \"finite\""), "{text}");
        // Already past the limit: no repeat; below it: nothing.
        assert!(small_strain_warning(&large, &large, 8).is_none());
        assert!(small_strain_warning(&small, &small, 8).is_none());
    }
}
