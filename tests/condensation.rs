//! Eliminating the contact multipliers node by node gives the same Newton step as solving
//! the mixed (u, lambda) system, in every contact status, and so the same simulation.

mod common;

use tribo::solver::Simulation;

fn drag(eliminate: bool) -> Simulation {
    let mut model = common::cylinder_drag_model(16.0, 4.0, 32, 8.0);
    model.settings.increments = 12;
    // Free the y faces: contact nodes with a prescribed component keep their multipliers.
    model.dirichlet.retain(|d| !d.label.starts_with('y'));
    model.settings.eliminate_multipliers = eliminate;
    Simulation::new(model).unwrap()
}

#[test]
fn condensed_newton_step_equals_the_mixed_one() {
    let mut sim = drag(true);
    assert!(sim.eliminated_multipliers() > 0);
    for _ in 0..6 {
        sim.step().unwrap();
    }
    // A Newton iterate of the next increment, statuses mixed (gap, stick and slip).
    let t_new = sim.time() + 0.25;
    let x = sim.unknowns().to_vec();
    let e = sim.evaluate_at(t_new, &x).unwrap();
    let (_, _, scale, diff) = common::full_and_condensed_steps(&sim, &e);
    println!("largest step entry {scale:.3e}, difference {diff:.3e}");
    assert!(diff < 1e-10 * scale, "condensed step differs by {diff:e}");
}

/// The slot plan places every contribution where a search in the pattern would: the reduced
/// matrix and right-hand side are bitwise those of the search-based construction (same
/// contributions, summed in the same order).
#[test]
fn slot_plan_builds_the_reduced_system_of_the_search() {
    let mut sim = drag(true);
    for _ in 0..6 {
        sim.step().unwrap();
    }
    let t_new = sim.time() + 0.25;
    let x = sim.unknowns().to_vec();
    let e = sim.evaluate_at(t_new, &x).unwrap();
    let condenser = sim.condenser().expect("multipliers are eliminated");
    let (a, rhs) = condenser.reduced_system(&e.jacobian, &e.residual);
    let (a_ref, rhs_ref) = condenser.reduced_system_by_search(&e.jacobian, &e.residual);
    assert!(a.values.iter().any(|v| *v != 0.0));
    assert_eq!(a.pattern, a_ref.pattern);
    for (k, (v, w)) in a.values.iter().zip(&a_ref.values).enumerate() {
        assert_eq!(v.to_bits(), w.to_bits(), "value {k}: {v} vs {w}");
    }
    for (k, (v, w)) in rhs.iter().zip(&rhs_ref).enumerate() {
        assert_eq!(v.to_bits(), w.to_bits(), "right-hand side {k}: {v} vs {w}");
    }
}

#[test]
fn condensed_and_mixed_runs_agree() {
    let mut a = drag(true);
    let mut b = drag(false);
    a.run(|_, _| Ok(())).unwrap();
    b.run(|_, _| Ok(())).unwrap();
    let d = a
        .unknowns()
        .iter()
        .zip(b.unknowns())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let iters = |s: &Simulation| s.history.iter().map(|r| r.iterations).sum::<usize>();
    println!(
        "max difference {d:.2e}; iterations {} and {}",
        iters(&a),
        iters(&b)
    );
    assert!(d < 1e-9, "runs differ by {d}");
    assert_eq!(iters(&a), iters(&b));
}
