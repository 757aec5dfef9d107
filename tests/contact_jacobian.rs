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
        let (mut xp, mut xm, mut lp, mut lm) = (x, x, l, l);
        if j < 3 {
            xp[j] += h;
            xm[j] -= h;
        } else {
            lp[j - 3] += h;
            lm[j - 3] -= h;
        }
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
