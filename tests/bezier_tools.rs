//! A tool made of exact rational Bezier patches behaves as the analytic surface it
//! represents: the cylinder drag (press, then slide across the patch seams) gives the same
//! solution with a cylinder of four quarter patches as with the analytic cylinder.

mod common;

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;
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
