//! The nodal contact Jacobian against central finite differences, in each status (gap,
//! stick, slip), on a plane, a cylinder and a sphere, curvature terms on, through the same
//! tool projection the solver uses (tool moved away from the origin).

use std::sync::Arc;
use tribo::contact::{alart_curnier, ContactStatus, OperatorParams};
use tribo::geometry::{Cylinder, Plane, RigidSurface, Sphere, Vec3};
use tribo::tool::schedule::Schedule;
use tribo::tool::Tool;

fn moved_tool(surface: Arc<dyn RigidSurface>) -> Tool {
    let mut t = Tool::new("t", surface);
    t.schedule =
        Schedule::new(vec![(0.0, Vec3::zeros()), (1.0, Vec3::new(0.3, -0.2, 0.1))]).unwrap();
    t
}

/// Residual [F_equi, F_suppl] at (x, lambda), and the status.
fn residual(
    tool: &Tool,
    x: &Vec3,
    l: &Vec3,
    xr: &Vec3,
    p: &OperatorParams,
) -> (ContactStatus, [f64; 6]) {
    let pose = tool.pose(0.5);
    let proj = tool.project(&pose, x, None).expect("projection defined");
    let r = alart_curnier(x, xr, l, &proj, p);
    let mut out = [0.0; 6];
    for i in 0..3 {
        out[i] = r.f_equi[i];
        out[3 + i] = r.f_suppl[i];
    }
    (r.status, out)
}

/// The central-difference stencil of unknown `j` of (x, lambda): `((x, l) + h e_j, (x, l) - h e_j)`.
fn stencil(x: Vec3, l: Vec3, j: usize, h: f64) -> ((Vec3, Vec3), (Vec3, Vec3)) {
    let (mut xp, mut xm, mut lp, mut lm) = (x, x, l, l);
    if j < 3 {
        xp[j] += h;
        xm[j] -= h;
    } else {
        lp[j - 3] += h;
        lm[j - 3] -= h;
    }
    ((xp, lp), (xm, lm))
}

/// Worst relative mismatch between the analytic Jacobian and central differences.
fn fd_mismatch(tool: &Tool, x: Vec3, l: Vec3, xr: Vec3, expect: ContactStatus) -> f64 {
    let p = OperatorParams::fixed_mu(80.0, 0.3, true);
    let pose = tool.pose(0.5);
    let proj = tool.project(&pose, &x, None).unwrap();
    let res = alart_curnier(&x, &xr, &l, &proj, &p);
    assert_eq!(res.status, expect, "status at the base point");
    let h = 1e-6;
    let (mut worst, mut scale) = (0.0f64, 1e-12f64);
    for j in 0..6 {
        let ((xp, lp), (xm, lm)) = stencil(x, l, j, h);
        let (sp, rp) = residual(tool, &xp, &lp, &xr, &p);
        let (sm, rm) = residual(tool, &xm, &lm, &xr, &p);
        assert_eq!(
            (sp, sm),
            (expect, expect),
            "status constant over the stencil"
        );
        for i in 0..6 {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            let an = match (i < 3, j < 3) {
                (true, true) => res.equi_x[(i, j)],
                (true, false) => res.equi_lambda[(i, j - 3)],
                (false, true) => res.suppl_x[(i - 3, j)],
                (false, false) => res.suppl_lambda[(i - 3, j - 3)],
            };
            worst = worst.max((fd - an).abs());
            scale = scale.max(an.abs());
        }
    }
    worst / scale
}

/// Points and multipliers giving each status on a tool whose surface passes near `foot`
/// with outward normal `n` (at the pose of time 0.5).
fn check_all_statuses(name: &str, tool: &Tool) {
    let pose = tool.pose(0.5);
    let probe = Vec3::new(0.35, -0.15, 0.2);
    let p = tool.project(&pose, &probe, None).unwrap();
    let (foot, n) = (p.foot, p.normal);
    let t1 = n.cross(&Vec3::new(0.3, 0.9, 0.1)).normalize();
    let xr = foot + t1 * 0.01;
    let cases = [
        (ContactStatus::Gap, foot + n * 0.2, Vec3::zeros()),
        (
            ContactStatus::Stick,
            foot - n * 0.01 + t1 * 0.0105,
            -n * 10.0,
        ),
        (
            ContactStatus::Slip,
            foot - n * 0.02 + t1 * 0.3,
            -n * 3.0 + t1 * 0.5,
        ),
    ];
    for (status, x, l) in cases {
        let m = fd_mismatch(tool, x, l, xr, status);
        println!("{name:9} {status:?}: relative mismatch {m:.2e}");
        assert!(
            m < 1e-6,
            "{name} {status:?}: Jacobian differs from finite differences by {m:.2e}"
        );
    }
}

#[test]
fn jacobian_matches_finite_differences_on_a_plane() {
    let s = Plane::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.1, 0.2, 1.0)).unwrap();
    check_all_statuses("plane", &moved_tool(Arc::new(s)));
}

#[test]
fn jacobian_matches_finite_differences_on_a_cylinder() {
    let s = Cylinder::new(Vec3::new(0.0, 0.0, -2.0), Vec3::new(0.2, 1.0, 0.1), 2.0).unwrap();
    check_all_statuses("cylinder", &moved_tool(Arc::new(s)));
}

#[test]
fn jacobian_matches_finite_differences_on_a_sphere() {
    let s = Sphere::new(Vec3::new(0.1, 0.0, -1.5), 1.5).unwrap();
    check_all_statuses("sphere", &moved_tool(Arc::new(s)));
}

/// As [`check_all_statuses`], with every base point's foot at the surface point nearest to
/// `probe` (so that the stencil stays where the test puts it: inside a patch, near a seam):
/// the point moves along the normal only and the reference point carries the tangential
/// offset (the same `x - x_ref` as above).
fn check_statuses_at_foot(name: &str, tool: &Tool, probe: Vec3) {
    let pose = tool.pose(0.5);
    let p = tool.project(&pose, &probe, None).unwrap();
    let (foot, n) = (p.foot, p.normal);
    let t1 = n.cross(&Vec3::new(0.3, 0.9, 0.1)).normalize();
    let cases = [
        (ContactStatus::Gap, n * 0.2, Vec3::zeros(), Vec3::zeros()),
        (
            ContactStatus::Stick,
            -n * 0.01,
            -n * 0.01 + t1 * 0.0005,
            -n * 10.0,
        ),
        (
            ContactStatus::Slip,
            -n * 0.02,
            -n * 0.02 + t1 * 0.29,
            -n * 3.0 + t1 * 0.5,
        ),
    ];
    for (status, offset, x_minus_ref, l) in cases {
        let x = foot + offset;
        let m = fd_mismatch(tool, x, l, x - x_minus_ref, status);
        println!("{name:24} {status:?}: relative mismatch {m:.2e}");
        assert!(
            m < 1e-6,
            "{name} {status:?}: Jacobian differs from finite differences by {m:.2e}"
        );
    }
}

/// The same tool rotated by 40° about a skew axis over t in [0, 1] (20° at t = 0.5) on top
/// of its translation.
fn rotated(tool: &Tool) -> Tool {
    let mut t = tool.clone();
    t.schedule = t
        .schedule
        .clone()
        .with_rotation(
            Vec3::new(0.5, -0.3, 0.2),
            Vec3::new(0.3, 1.0, 0.4),
            vec![(0.0, 0.0), (1.0, 40.0)],
        )
        .unwrap();
    t
}

/// Patch tools: inside a torus patch of the square-cup punch's nose corner, 1e-4 from its
/// seams with the nose-radius cylinder and with the flat nose (where the curvature jumps,
/// so the stencil of 1e-6 must not cross), in the flat nose where two patches overlap,
/// and exactly on a seam of a cylinder of quarter patches (curvature continuous there);
/// each with the tool translated, and translated and rotated.
#[test]
fn jacobian_matches_finite_differences_on_patch_tools() {
    use tribo::geometry::builders::{punch_patches, Extent, PunchSpec};
    use tribo::geometry::{BezierPatch, PatchSurface};
    let spec = PunchSpec {
        side: 70.0,
        plan_corner_radius: 10.0,
        nose_radius: 8.0,
        wall_height: 20.0,
        level: 0.0,
    };
    let punch = PatchSurface::new(punch_patches(&spec, Extent::Full).unwrap()).unwrap();
    let punch = moved_tool(Arc::new(punch));
    // Nose corner: torus of tube-centre circle radius 2 around (25, 25), tube radius 8 at
    // height 8. A point at plan angle psi, tube angle phi (from the outward radial, -90°
    // is straight down) and distance 0.5 outside, in the tool's frame at t = 0.5.
    let corner = |psi: f64, phi: f64| {
        let (psi, phi) = (psi.to_radians(), phi.to_radians());
        let radial = Vec3::new(psi.cos(), psi.sin(), 0.0);
        let n = radial * phi.cos() + Vec3::z() * phi.sin();
        let local = Vec3::new(25.0, 25.0, 8.0) + radial * 2.0 + n * 8.5;
        punch.pose(0.5).to_global_point(&local)
    };
    let seam_angle = 1e-4f64.to_degrees() / 8.0; // 1e-4 of arc on the tube, in degrees
    let quarter_cylinder = (0..4)
        .map(|q| {
            let start = q as f64 * std::f64::consts::FRAC_PI_2;
            BezierPatch::quarter_cylinder(
                Vec3::new(0.0, -3.0, -2.0),
                Vec3::new(0.2, 1.0, 0.1),
                Vec3::x(),
                start,
                2.0,
                6.0,
            )
        })
        .collect::<tribo::Result<Vec<_>>>()
        .unwrap();
    let cylinder = moved_tool(Arc::new(PatchSurface::new(quarter_cylinder).unwrap()));
    // The quarter cylinder's seam at angle 90° from x around the axis, mid-length.
    let cylinder_seam = {
        let a = Vec3::new(0.2, 1.0, 0.1).normalize();
        let f1 = (Vec3::x() - a * a.x).normalize();
        let local = Vec3::new(0.0, -3.0, -2.0) + a * 3.0 + a.cross(&f1) * 2.5;
        cylinder.pose(0.5).to_global_point(&local)
    };
    let pose = punch.pose(0.5);
    let cases = [
        ("punch torus interior", &punch, corner(40.0, -50.0)),
        ("punch torus near wall", &punch, corner(40.0, -seam_angle)),
        (
            "punch torus near flat",
            &punch,
            corner(40.0, -90.0 + seam_angle),
        ),
        ("punch torus near side", &punch, corner(seam_angle, -40.0)),
        (
            "punch flat overlap",
            &punch,
            pose.to_global_point(&Vec3::new(10.0, 10.0, -0.5)),
        ),
        ("quarter cylinder seam", &cylinder, cylinder_seam),
    ];
    for (name, tool, probe) in cases {
        check_statuses_at_foot(name, tool, probe);
        let turned = rotated(tool);
        // The same material point of the tool, seen at the rotated pose.
        let local = tool.pose(0.5).to_local(&probe);
        let probe_turned = turned.pose(0.5).to_global_point(&local);
        check_statuses_at_foot(&format!("{name} (rotated)"), &turned, probe_turned);
    }
}

/// The state of the coarse benchmark cup's linear tail (docs/convergence-log.md, "The linear
/// tail of the coarse benchmark cup's first increment"): a node slipping on the flat holder
/// with its tangential trial force only 3 % outside the Coulomb cone (r = 5.75e4 N/mm,
/// mu = 0.162, sigma_n = -105.5 N, |sigma_t| = 17.6 N against mu |sigma_n| = 17.1 N).
/// There the Jacobian is exact (central differences), and along a Newton-sized multiplier
/// step across the slip direction (2.3 N, as measured there) the Taylor remainder is smooth
/// (it falls fourfold per halving of the step) and as large as the slip direction's own
/// curvature predicts, `mu |sigma_n| |d lambda_perp|^2 / (2 |sigma_t|^2)`: what slows
/// Newton there is that curvature, not a wrong or missing term.
#[test]
fn slip_just_outside_the_cone_has_an_exact_but_strongly_curved_jacobian() {
    let plane = Plane::new(Vec3::zeros(), Vec3::new(0.0, 0.0, -1.0)).unwrap();
    let tool = Tool::new("holder", Arc::new(plane));
    let pose = tool.pose(0.0);
    let (r, mu) = (5.75e4, 0.162);
    let p = OperatorParams::fixed_mu(r, mu, true);
    let n = Vec3::new(0.0, 0.0, -1.0);
    let x = Vec3::new(46.875, 56.25, 0.0);
    // sigma = lambda + r (d n + delta_t) with d = 0: the slip reference sets delta_t.
    let (sigma_n, sigma_t) = (-105.5, Vec3::new(17.6, 0.0, 0.0));
    let lambda = Vec3::new(-20.0, 3.0, 0.0) + n * sigma_n;
    let x_ref = x - (sigma_t - Vec3::new(-20.0, 3.0, 0.0)) / r;
    let eval = |x: &Vec3, l: &Vec3| {
        let proj = tool.project(&pose, x, None).unwrap();
        alart_curnier(x, &x_ref, l, &proj, &p)
    };
    let base = eval(&x, &lambda);
    assert_eq!(base.status, ContactStatus::Slip);

    // Central differences (h = 1e-7 mm in x, 1e-4 N in lambda: each well inside the
    // 3e-4 mm / 17.6 N scale of the slip direction; the h^2 term is below 1e-6 relative).
    let mut worst = 0.0f64;
    for j in 0..6 {
        let h = if j < 3 { 1e-7 } else { 1e-4 };
        let ((xp, lp), (xm, lm)) = stencil(x, lambda, j, h);
        let (a, b) = (eval(&xp, &lp), eval(&xm, &lm));
        assert_eq!(
            (a.status, b.status),
            (ContactStatus::Slip, ContactStatus::Slip)
        );
        for i in 0..3 {
            let fd = (a.f_equi[i] - b.f_equi[i]) / (2.0 * h);
            let an = if j < 3 {
                base.equi_x[(i, j)]
            } else {
                base.equi_lambda[(i, j - 3)]
            };
            let scale = if j < 3 { r } else { 1.0 };
            worst = worst.max((fd - an).abs() / scale);
        }
    }
    println!("relative mismatch to central differences {worst:.2e}");
    assert!(
        worst < 1e-6,
        "Jacobian differs from finite differences by {worst:.2e}"
    );

    // Taylor remainder of F_equi along a multiplier step across the slip direction.
    let step = Vec3::new(0.0, 2.3, 0.0);
    let remainder = |s: f64| {
        let moved = eval(&x, &(lambda + step * s));
        (moved.f_equi - base.f_equi - base.equi_lambda * step * s).norm()
    };
    let (r1, r2, r4) = (remainder(1.0), remainder(0.5), remainder(0.25));
    let predicted = mu * sigma_n.abs() * step.norm().powi(2) / (2.0 * sigma_t.norm().powi(2));
    println!("remainders {r1:.3e} {r2:.3e} {r4:.3e}, predicted {predicted:.3e}");
    // Smooth: the second-order term dominates (ratio 4 up to the third-order term, which
    // is |d lambda| / |sigma_t| = 13 % of it at the full step).
    for (big, small) in [(r1, r2), (r2, r4)] {
        assert!((3.5..4.5).contains(&(big / small)), "ratio {}", big / small);
    }
    // As large as the slip direction's curvature says (within its own third-order term).
    assert!(
        (0.8..1.2).contains(&(r1 / predicted)),
        "remainder {r1:.3e} against {predicted:.3e}"
    );
    // And large: a thousandth of the step's own force change would be quadratic Newton
    // with room to spare; here it is several percent.
    let linear = (base.equi_lambda * step).norm();
    assert!(
        r1 > 0.03 * linear,
        "remainder {r1:.3e}, linear part {linear:.3e}"
    );
}
