//! A tool made of exact rational Bezier patches behaves as the analytic surface it
//! represents: the cylinder drag (press, then slide across the patch seams) gives the same
//! solution with a cylinder of four quarter patches as with the analytic cylinder.

mod common;

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;
use tribo::contact::ContactStatus;
use tribo::geometry::{BezierPatch, PatchSurface, Vec3};
use tribo::solver::Simulation;

fn run(bezier: bool) -> Simulation {
    let mut model = common::cylinder_drag_model(16.0, 4.0, 32, 8.0);
    model.settings.increments = 12;
    model.settings.force_rel_tol = 1e-12;
    model.settings.contact_tol = 1e-12;
    if bezier {
        // Same axis as the analytic cylinder (x = 4, z = 4 + 5 + 0.02, along y), 3 long.
        let axis_point = Vec3::new(4.0, -1.0, 9.02);
        let patches = (0..4)
            .map(|q| {
                BezierPatch::quarter_cylinder(
                    axis_point,
                    Vec3::y(),
                    Vec3::x(),
                    q as f64 * FRAC_PI_2,
                    5.0,
                    3.0,
                )
                .unwrap()
            })
            .collect();
        model.contacts[0].tool.surface = Arc::new(PatchSurface::new(patches).unwrap());
    }
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    sim
}

#[test]
fn bezier_cylinder_gives_the_analytic_cylinders_solution() {
    let analytic = run(false);
    let bezier = run(true);
    let d = analytic
        .displacements()
        .iter()
        .zip(bezier.displacements())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let (fa, fb) = (analytic.tool_force(0), bezier.tool_force(0));
    let iters = |s: &Simulation| s.history.iter().map(|r| r.iterations).sum::<usize>();
    println!(
        "max displacement difference {d:.2e}; forces {fa:?} vs {fb:?}; iterations {} vs {}",
        iters(&analytic),
        iters(&bezier)
    );
    assert!(d < 1e-8, "displacements differ by {d}");
    assert!((fa - fb).norm() < 1e-8 * fa.norm());
}

/// The drag cylinder's lower half in 3° patches (arc length 0.26 mm; the contact zone,
/// about 2 mm wide, spans some 8 of them), the upper half in two quarter patches.
fn narrow_patch_cylinder() -> PatchSurface {
    let axis_point = Vec3::new(4.0, -1.0, 9.02);
    let patch = |start: f64, sweep: f64| {
        BezierPatch::cylinder_patch(axis_point, Vec3::y(), -Vec3::z(), start, sweep, 5.0, 3.0)
    };
    let step = 3f64.to_radians();
    let mut patches: Vec<BezierPatch> = (0..60)
        .map(|k| patch(-FRAC_PI_2 + k as f64 * step, step).unwrap())
        .collect();
    patches.push(patch(FRAC_PI_2, FRAC_PI_2).unwrap());
    patches.push(patch(PI, FRAC_PI_2).unwrap());
    PatchSurface::new(patches).unwrap()
}

/// Per increment, every contact node's status and (if in contact) the patch of its foot.
fn contact_histories(sim: &mut Simulation) -> Vec<Vec<(ContactStatus, Option<usize>)>> {
    let mut histories = vec![Vec::new(); sim.model.contacts[0].candidates.len()];
    sim.run(|s, _| {
        for (h, state) in histories.iter_mut().zip(s.contact_states(0)) {
            let patch = state
                .hint
                .filter(|_| state.status.is_active())
                .map(|p| p.patch);
            h.push((state.status, patch));
        }
        Ok(())
    })
    .unwrap();
    histories
}

/// A block dragged 6 mm under a cylinder of 62 patches, 1 mm per increment: each contact
/// node's foot slides some 2 mm over the tool, 7 patch widths and as many seams. Every
/// increment converges quadratically (last observed order >= 1.8); while in contact,
/// each node's foot walks monotonically over the patches (no seam flip-flop); the status
/// of every node in every increment is the analytic cylinder's (the seams add no
/// stick/slip change), and so is the solution.
#[test]
fn large_slip_across_many_seams_converges_without_chattering() {
    let model = |bezier: bool| {
        let mut m = common::cylinder_drag_model(16.0, 4.0, 32, 6.0);
        // 3 press increments, then 6 drag increments of 1 mm (about 4 patch widths).
        m.settings.increments = 9;
        m.settings.max_cutbacks = 0;
        // From the committed state, and r as this test was written with (see
        // `former_default_r`), so that each increment has iterations to show a rate.
        m.settings.extrapolate = false;
        common::former_default_r(&mut m, 0, 0.3, 0.5, 0.5);
        m.settings.force_rel_tol = 1e-11;
        m.settings.contact_tol = 1e-11;
        if bezier {
            m.contacts[0].tool.surface = Arc::new(narrow_patch_cylinder());
        }
        m
    };
    let mut sim = Simulation::new(model(true)).unwrap();
    let histories = contact_histories(&mut sim);
    let mut analytic = Simulation::new(model(false)).unwrap();
    let exact = contact_histories(&mut analytic);
    // Noise floor of relative residuals as in cylinder_drag_newton.rs.
    let mut worst = f64::INFINITY;
    for r in &sim.history {
        let res: Vec<f64> = r.residuals.iter().map(|x| x.force_rel).collect();
        if let Some(&last) = common::convergence_orders(&res, 1e-15).last() {
            worst = worst.min(last);
        }
    }
    let slid = sim
        .contact_states(0)
        .iter()
        .map(|s| s.slip)
        .fold(0.0, f64::max);
    let patch_walks: Vec<Vec<usize>> = histories
        .iter()
        .map(|h| h.iter().filter_map(|e| e.1).collect())
        .collect();
    let non_monotone = patch_walks
        .iter()
        .filter(|w| {
            let up = w.windows(2).all(|p| p[1] >= p[0]);
            let down = w.windows(2).all(|p| p[1] <= p[0]);
            !(up || down)
        })
        .count();
    let crossed = patch_walks
        .iter()
        .map(|w| w.iter().max().unwrap_or(&0) - w.iter().min().unwrap_or(&0))
        .max()
        .unwrap_or(0);
    let statuses = |h: &[Vec<(ContactStatus, Option<usize>)>]| -> Vec<Vec<ContactStatus>> {
        h.iter().map(|n| n.iter().map(|e| e.0).collect()).collect()
    };
    let back_and_forth = statuses(&histories)
        .iter()
        .filter(|h| {
            let mut active: Vec<ContactStatus> =
                h.iter().copied().filter(|s| s.is_active()).collect();
            active.dedup();
            active.windows(3).any(|w| w[0] == w[2])
        })
        .count();
    println!(
        "worst last order {worst:.3}; largest slip {slid:.3} mm (3° patch = 0.262 mm); \
         most patches crossed by one node {crossed}; {non_monotone} non-monotone walks; \
         {back_and_forth} nodes with slip-stick-slip (same in the analytic run: {})",
        statuses(&histories) == statuses(&exact)
    );
    assert!(worst >= 1.8, "observed convergence order {worst} < 1.8");
    assert!(
        slid > 3.0 * 0.262,
        "slip {slid} spans more than 3 patch widths"
    );
    // Feet are sampled once per converged increment (a node touches for about 2 of them),
    // so this counts fewer seams than the slip (about 7 patch widths) crosses.
    assert!(crossed >= 3, "a node's foot crossed at least 3 seams");
    assert_eq!(non_monotone, 0, "a node's foot went back over a seam");
    assert!(
        statuses(&histories) == statuses(&exact),
        "the seams changed some node's stick/slip status"
    );
    let d = analytic
        .displacements()
        .iter()
        .zip(sim.displacements())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!("max displacement difference to the analytic cylinder {d:.2e}");
    assert!(d < 1e-8, "displacements differ by {d}");
}

/// A Bezier cylinder tool rotating about a skew axis (and translating): its projection at
/// any time equals that of the analytic cylinder placed by hand at the rotated position,
/// to round-off (1e-10 in foot, normal and gap over 2000 points at 4 times).
#[test]
fn rotated_bezier_tool_projects_like_the_rotated_analytic_cylinder() {
    use tribo::geometry::{Cylinder, RigidSurface};
    use tribo::tool::{schedule::Schedule, Pose, Tool};
    let (c, a, r) = (
        Vec3::new(1.0, -2.0, 0.5),
        Vec3::new(0.1, 1.0, 0.2).normalize(),
        2.0,
    );
    let patches = (0..4)
        .map(|q| {
            BezierPatch::quarter_cylinder(c - a * 5.0, a, Vec3::x(), q as f64 * FRAC_PI_2, r, 10.0)
                .unwrap()
        })
        .collect();
    let mut tool = Tool::new("roller", Arc::new(PatchSurface::new(patches).unwrap()));
    let (pivot, axis) = (Vec3::new(0.5, 0.5, -1.0), Vec3::new(1.0, 0.2, 0.3));
    tool.schedule = Schedule::new(vec![(0.0, Vec3::zeros()), (1.0, Vec3::new(0.4, 0.0, -0.3))])
        .unwrap()
        .with_rotation(pivot, axis, vec![(0.0, 0.0), (0.5, 30.0), (1.0, -75.0)])
        .unwrap();
    let mut seed = 77u64;
    let mut uniform = |lo: f64, hi: f64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    for (time, angle) in [(0.0, 0.0), (0.25, 15.0), (0.5, 30.0), (0.8, -33.0)] {
        let pose = tool.pose(time);
        let by_hand = Pose::about_axis(
            &pivot,
            &axis.normalize(),
            f64::to_radians(angle),
            &tool.schedule.translation(time),
        );
        assert!((pose.rotation - by_hand.rotation).norm() < 1e-14);
        let placed =
            Cylinder::new(by_hand.to_global_point(&c), by_hand.to_global_vector(&a), r).unwrap();
        let mut hint = None;
        for _ in 0..500 {
            // Within the patches' length (axial offset < 4 of 5), up to 3.5 off the axis.
            let v = Vec3::new(uniform(-1.0, 1.0), uniform(-1.0, 1.0), uniform(-1.0, 1.0)) * 3.5;
            let local = c + a * uniform(-4.0, 4.0) + (v - a * a.dot(&v));
            let x = by_hand.to_global_point(&local);
            let Some(exact) = placed.project(&x, None) else {
                continue;
            };
            let p = tool.project(&pose, &x, hint.as_ref()).unwrap();
            hint = Some(p.hint);
            assert!(
                (p.foot - exact.foot).norm() < 1e-10
                    && (p.normal - exact.normal).norm() < 1e-10
                    && (p.gap - exact.gap).abs() < 1e-10,
                "t = {time}, x = {x:?}: {p:?} vs {exact:?}"
            );
            assert!((p.normal_gradient - exact.normal_gradient).norm() < 1e-9);
        }
    }
}
