//! The assembled Jacobian of the mixed (u, lambda) system equals central finite differences
//! of the assembled residual at a Newton iterate in the middle of a frictional drag over a
//! cylinder (elements, contact in stick and slip, curvature terms, multiplier rows).

mod common;

use tribo::solver::Simulation;

#[test]
fn assembled_jacobian_matches_finite_differences() {
    check(common::cylinder_drag_model(8.0, 2.0, 16, 4.0));
}

/// With the implicit friction update mu depends on the increment's own frictional work,
/// lambda_t . delta_t: its gradient enters the slip rows (the softening Bernstein law,
/// cut-off work chosen so that theta is mid-range).
#[test]
fn assembled_jacobian_with_implicit_friction_matches_finite_differences() {
    use tribo::contact::{BernsteinLaw, FrictionLaw, FrictionUpdate, WorkMeasure};
    let mut model = common::cylinder_drag_model(8.0, 2.0, 16, 4.0);
    let law =
        BernsteinLaw::new(vec![0.3, 0.2, 0.05, 0.1, 0.02], 20.0, WorkMeasure::PerArea).unwrap();
    model.contacts[0].tool.friction = FrictionLaw::Bernstein(law);
    model.settings.contact.friction_update = FrictionUpdate::Implicit;
    let sim = check(model);
    let evolving = sim
        .contact_states(0)
        .iter()
        .filter(|s| {
            s.status == tribo::contact::ContactStatus::Slip && s.theta > 0.0 && s.theta < 1.0
        })
        .count();
    assert!(
        evolving > 0,
        "some slipping node has 0 < theta < 1, so that d mu / d work is exercised"
    );
}

fn check(mut model: tribo::solver::Model) -> Simulation {
    model.settings.increments = 12;
    let mut sim = Simulation::new(model).unwrap();
    for _ in 0..7 {
        sim.step().unwrap();
    }
    // First Newton iterate of the next increment: not converged, contact active.
    let t_new = sim.time() + 0.25;
    let x = common::first_newton_iterate(&sim, t_new);
    let e = sim.evaluate_at(t_new, &x).unwrap();
    let statuses: Vec<_> = e.nodal[0].iter().map(|(r, _)| r.status).collect();
    assert!(
        statuses.contains(&tribo::contact::ContactStatus::Slip),
        "some node slips"
    );

    let scale = e.jacobian.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = common::jacobian_column_errors(&sim, t_new, &x, 1e-7)
        .into_iter()
        .fold(0.0f64, f64::max);
    println!(
        "largest Jacobian entry {scale:.3e}, worst difference to finite differences {worst:.3e}"
    );
    assert!(
        worst < 1e-6 * scale,
        "assembled Jacobian differs from finite differences by {worst:e}"
    );
    sim
}
