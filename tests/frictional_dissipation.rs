//! Issue 16, item 12: the frictional dissipation is the sum over contact nodes and
//! increments of lambda_t . delta_t, exactly zero for frictionless contact; the normal
//! contact force's work on a gap closing within an increment is no longer credited to the
//! tools (it was, and the friction term absorbed it), so the balance still closes.

mod common;

use tribo::contact::FrictionLaw;
use tribo::solver::Simulation;

/// The cylinder pressed 0.1 into the block and dragged 3 along it (common::cylinder_drag_model)
/// with Coulomb friction `mu`, on tight tolerances.
fn drag(mu: f64) -> Simulation {
    let mut model = common::cylinder_drag_model(8.0, 2.0, 16, 3.0);
    model.contacts[0].tool.friction = FrictionLaw::coulomb(mu).unwrap();
    model.settings.increments = 12;
    model.settings.force_rel_tol = 1e-12;
    model.settings.contact_tol = 1e-12;
    Simulation::new(model).unwrap()
}

#[test]
fn frictionless_contact_dissipates_exactly_nothing() {
    let mut sim = drag(0.0);
    let mut slipped = 0;
    while !sim.is_finished() {
        let r = sim.step().unwrap();
        slipped += r.slipping_nodes;
        // Every increment, pressing and sliding: exactly 0, not round-off.
        assert_eq!(r.energy.frictional_dissipation, vec![0.0], "t = {}", r.time);
    }
    assert!(slipped > 0, "the nodes under the cylinder slide");
    let e = sim.energy();
    // The gap closing within the first increments is no longer tool work: the tool's work
    // is what the elastic body stores, up to the trapezoidal rule's error on the body
    // (the run's own balance error).
    assert!(e.normal_contact_work > 0.0, "{e:?}");
    let gap = (e.tool_work - e.elastic_energy).abs() / e.elastic_energy;
    println!(
        "frictionless drag: tool work {}, elastic energy {}, normal contact work {}, balance error {:e}",
        e.tool_work, e.elastic_energy, e.normal_contact_work, e.relative_error
    );
    // Linear elasticity: the trapezoidal work of the body is its stored energy exactly, so
    // the two agree to round-off (measured 2e-14); before the fix the tool work was larger
    // by the normal contact work (3 % here), and the friction term held it.
    assert!(
        gap <= 1e-10,
        "tool work and elastic energy differ by {gap:e}"
    );
    assert!(e.relative_error.abs() <= 1e-10, "{e:?}");
}

/// A pure press (no drag, 4 increments): the tool's work equals the stored elastic energy
/// to round-off (measured 2e-14). Before the fix the tool work exceeded it by the normal
/// contact work, which the friction term then held.
#[test]
fn frictionless_press_tool_work_is_the_stored_energy() {
    let mut model = common::cylinder_drag_model(8.0, 2.0, 16, 0.0);
    model.contacts[0].tool.friction = FrictionLaw::coulomb(0.0).unwrap();
    model.settings.end_time = 1.0;
    model.settings.increments = 4;
    let mut sim = Simulation::new(model).unwrap();
    while !sim.is_finished() {
        sim.step().unwrap();
    }
    let e = sim.energy();
    assert_eq!(e.frictional_dissipation, vec![0.0]);
    assert!(
        e.normal_contact_work > 0.0,
        "the gap closes within the first increment"
    );
    let rel = (e.tool_work - e.elastic_energy).abs() / e.elastic_energy;
    println!(
        "press: tool work {} elastic {} rel {rel:e}, normal contact work {}",
        e.tool_work, e.elastic_energy, e.normal_contact_work
    );
    assert!(rel <= 1e-10, "{e:?}");
}

/// With friction, each increment's dissipation is the sum over the nodes of
/// lambda_t . delta_t. For a slipping node lambda_t is parallel to delta_t, so the product
/// is |lambda_t| times the growth of the node's accumulated slip; a sticking node has
/// delta_t = 0 to the contact tolerance.
#[test]
fn frictional_dissipation_is_the_sum_of_tangential_force_times_slip_increment() {
    let mut sim = drag(0.2);
    let mut slip_before: Vec<f64> = sim.contact_states(0).iter().map(|s| s.slip).collect();
    let mut dissipation_before = 0.0;
    let mut total = 0.0;
    while !sim.is_finished() {
        sim.step().unwrap();
        let states = sim.contact_states(0);
        let expected: f64 = states
            .iter()
            .zip(&slip_before)
            .map(|(s, before)| s.lambda_t_norm() * (s.slip - before))
            .sum();
        let now = sim.energy().frictional_dissipation[0];
        let increment = now - dissipation_before;
        // Relative round-off of the two products, plus an absolute floor for the pressing
        // increments, where sticking nodes move by round-off (1e-17 here).
        assert!(
            (increment - expected).abs() <= 1e-8 * expected.abs() + 1e-12,
            "t = {}: dissipation increment {increment}, sum |lambda_t| |delta_t| {expected}",
            sim.time()
        );
        total += expected;
        dissipation_before = now;
        slip_before = states.iter().map(|s| s.slip).collect();
    }
    assert!(total > 0.0, "the drag dissipates");
    // The nodes' frictional work is the same sum (clipped at zero per increment).
    let work: f64 = sim.contact_states(0).iter().map(|s| s.work).sum();
    assert!((work - total).abs() <= 1e-8 * total, "{work} vs {total}");
    assert!(sim.energy().relative_error.abs() <= 1e-3);
}
