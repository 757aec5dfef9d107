//! A rigid cylinder pressed into an elastic block and dragged across it with friction, the
//! slip being four times the contact width. The generalised Newton method with the
//! consistent Jacobian (curvature terms included) converges quadratically in the last
//! iterations of every increment; without the curvature terms it needs more iterations.
//! Each drag increment moves the cylinder by about one contact width (2 mm), so that every
//! increment changes the active set and Newton has several iterations to show its rate.

mod common;

use tribo::solver::{Model, Simulation};

const DRAG: f64 = 8.0;
/// Relative residuals below this are round-off. Values just above it may carry some noise,
/// which can only make an order estimate smaller: the assertion errs on the strict side.
const NOISE_FLOOR: f64 = 1e-15;

fn drag_model(curvature: bool) -> Model {
    let mut model = common::cylinder_drag_model(16.0, 4.0, 32, DRAG);
    model.settings.increments = 6;
    model.settings.max_iterations = 40;
    model.settings.max_cutbacks = 0;
    model.settings.force_rel_tol = 1e-11;
    model.settings.contact_tol = 1e-11;
    model.settings.contact.curvature = curvature;
    // r as this test was written with (see `former_default_r`): 0.5 x 1 x 0.5 cells.
    common::former_default_r(&mut model, 0, 0.3, 0.5, 0.5);
    model
}

#[test]
fn newton_converges_quadratically_while_dragging() {
    let mut sim = Simulation::new(drag_model(true)).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    let contact_width = {
        // Widest extent of the contact zone during the drag, from the committed states.
        let xs: Vec<f64> = sim
            .contact_states(0)
            .iter()
            .zip(&sim.model.contacts[0].candidates)
            .filter(|(s, _)| s.status.is_active())
            .map(|(_, &n)| sim.model.mesh.nodes[n].x)
            .collect();
        xs.iter().cloned().fold(f64::MIN, f64::max) - xs.iter().cloned().fold(f64::MAX, f64::min)
    };
    assert!(
        contact_width > 0.5,
        "the cylinder is in contact at the end (width {contact_width})"
    );
    assert!(
        DRAG >= 2.0 * contact_width,
        "slip {DRAG} is at least twice the contact width {contact_width}"
    );

    let mut worst: f64 = f64::INFINITY;
    println!("increment  iterations  last orders");
    for r in sim.history.iter().filter(|r| r.time > 1.0 + 1e-9) {
        let res: Vec<f64> = r.residuals.iter().map(|x| x.force_rel).collect();
        let orders = common::convergence_orders(&res, NOISE_FLOOR);
        println!(
            "{:9}  {:10}  {:?}  residuals {:?}",
            r.index, r.iterations, orders, res
        );
        if let Some(&last) = orders.last() {
            worst = worst.min(last);
        }
    }
    assert!(
        worst.is_finite(),
        "some increment measured a convergence order"
    );
    assert!(worst >= 1.8, "observed convergence order {worst} < 1.8");
}

#[test]
fn dropping_the_curvature_terms_costs_iterations() {
    let mut with = Simulation::new(drag_model(true)).unwrap();
    with.run(|_, _| Ok(())).unwrap();
    let mut without = Simulation::new(drag_model(false)).unwrap();
    without.run(|_, _| Ok(())).unwrap();
    let count = |s: &Simulation| s.history.iter().map(|r| r.iterations).sum::<usize>();
    println!(
        "Newton iterations over the drag: curvature terms on {}, off {}",
        count(&with),
        count(&without)
    );
    assert!(count(&without) > count(&with));
    // Both reach the same converged state.
    let d = with
        .displacements()
        .iter()
        .zip(without.displacements())
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        d < 1e-8,
        "the two runs converge to the same displacements (max difference {d})"
    );
}
