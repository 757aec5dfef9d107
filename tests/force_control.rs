//! Force control of a tool (its position along an axis is an unknown fixed by a scheduled
//! force): the assembled Jacobian with the offset row and column against central finite
//! differences, a flat punch on an elastic block against the analytic compression, and the
//! observed Newton convergence order while a force-controlled roller is dragged.

mod common;

use tribo::geometry::{Plane, Vec3};
use tribo::solver::{Model, Simulation};
use tribo::tool::{ForceControl, ScalarSchedule, Tool};

/// The roller of `common::cylinder_drag_model`, pressed down by a force ramped to `FORCE`
/// over t in [0, 1] (it starts 0.02 above the block: the first iteration is the approach
/// step) and held while the schedule drags it along x.
const FORCE: f64 = 20.0;

fn force_controlled_drag(drag: f64, cells: usize, length: f64, depth: f64, force: f64) -> Model {
    let mut model = common::cylinder_drag_model(length, depth, cells, drag);
    let t = &mut model.contacts[0].tool;
    // Keep only the drag of the schedule; the vertical position is the unknown.
    t.schedule = tribo::tool::Schedule::new(vec![
        (0.0, Vec3::zeros()),
        (1.0, Vec3::zeros()),
        (3.0, Vec3::new(drag, 0.0, 0.0)),
    ])
    .unwrap();
    t.force_control = Some(
        ForceControl::new(
            Vec3::new(0.0, 0.0, -1.0),
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, force), (3.0, force)]).unwrap(),
        )
        .unwrap(),
    );
    model
}

#[test]
fn jacobian_with_offset_unknown_matches_finite_differences() {
    let mut model = force_controlled_drag(2.0, 16, 8.0, 2.0, FORCE);
    model.settings.increments = 12;
    let mut sim = Simulation::new(model).unwrap();
    for _ in 0..7 {
        sim.step().unwrap();
    }
    let s_dof = sim.unknowns().len() - 1;
    // First Newton iterate of the next increment: not converged, contact active, slipping.
    let t_new = sim.time() + 0.25;
    let x = common::first_newton_iterate(&sim, t_new);
    let e = sim.evaluate_at(t_new, &x).unwrap();
    assert!(
        e.nodal[0]
            .iter()
            .any(|(r, _)| r.status == tribo::contact::ContactStatus::Slip),
        "some node slips"
    );

    let scale = e.jacobian.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // h = 1e-7 on O(1) unknowns: truncation O(h^2 |R'''|) and round-off O(eps |R| / h) are
    // both below 1e-8 of the largest entry; a missing term is of the size of the entries.
    let errors = common::jacobian_column_errors(&sim, t_new, &x, 1e-7);
    let worst = errors.iter().fold(0.0f64, |m, v| m.max(*v));
    let worst_s_col = errors[s_dof];
    let mut ej = vec![0.0; x.len()];
    ej[s_dof] = 1.0;
    let s_col_size = e
        .jacobian
        .mul_vec(&ej)
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    println!(
        "largest entry {scale:.3e}; worst difference {worst:.3e}; offset column: largest entry {s_col_size:.3e}, worst difference {worst_s_col:.3e}"
    );
    assert!(s_col_size > 1e-3 * scale, "the offset column is populated");
    assert!(
        worst < 1e-6 * scale,
        "assembled Jacobian differs from finite differences by {worst:e}"
    );
}

/// Between the windows of its force control a tool is kinematic with its offset held
/// (`R_s = s - s_committed`, issue 47's steps): the roller pressed over t in (0, 1], then
/// dragged at the offset it reached. The assembled Jacobian, the held row included, against
/// central finite differences, and the offset stays put while the tool is dragged.
#[test]
fn held_offset_between_windows_matches_finite_differences() {
    let mut model = force_controlled_drag(2.0, 16, 8.0, 2.0, FORCE);
    model.settings.increments = 12;
    model.contacts[0]
        .tool
        .force_control
        .as_mut()
        .unwrap()
        .windows = vec![(0.0, 1.0)];
    let mut sim = Simulation::new(model).unwrap();
    for _ in 0..4 {
        sim.step().unwrap();
    }
    let pressed = sim.tool_offset(0);
    for _ in 0..3 {
        sim.step().unwrap();
    }
    // Held exactly: the row is linear, solved to round-off in one step.
    assert_eq!(
        sim.tool_offset(0),
        pressed,
        "the offset is held after t = 1"
    );
    let s_dof = sim.unknowns().len() - 1;
    let t_new = sim.time() + 0.25;
    let x = common::first_newton_iterate(&sim, t_new);
    let e = sim.evaluate_at(t_new, &x).unwrap();
    let scale = e.jacobian.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // Same step and bound as `jacobian_with_offset_unknown_matches_finite_differences`.
    let errors = common::jacobian_column_errors(&sim, t_new, &x, 1e-7);
    let worst = errors.iter().fold(0.0f64, |m, v| m.max(*v));
    println!(
        "largest entry {scale:.3e}; worst difference {worst:.3e}, offset column {:.3e}",
        errors[s_dof]
    );
    assert!(
        worst < 1e-6 * scale,
        "assembled Jacobian differs from finite differences by {worst:e}"
    );
    // The held row: d R_s / d s = 1 and R_s = s - s_committed.
    let mut es = vec![0.0; x.len()];
    es[s_dof] = 1.0;
    let column = e.jacobian.mul_vec(&es);
    assert!(
        (column[s_dof] - 1.0).abs() < 1e-12,
        "dR_s/ds = {}",
        column[s_dof]
    );
    assert!((e.residual[s_dof] - (x[s_dof] - pressed)).abs() < 1e-15);
}

/// A frictionless plane punch at height `z`, facing down, pushed down by a force ramped
/// from 0 to `force` over t in [0, 1].
fn punch(z: f64, force: f64) -> Tool {
    let plane = Plane::new(Vec3::new(0.0, 0.0, z), Vec3::new(0.0, 0.0, -1.0)).unwrap();
    let mut punch = Tool::new("punch", std::sync::Arc::new(plane));
    punch.force_control = Some(
        ForceControl::new(
            Vec3::new(0.0, 0.0, -1.0),
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, force)]).unwrap(),
        )
        .unwrap(),
    );
    punch
}

/// A frictionless rigid plane pushed with force F onto a block H high with cross-section A,
/// on rollers (z fixed at the bottom, x and y fixed on the symmetry planes x = 0, y = 0):
/// uniaxial stress, u_z(top) = -F H / (E A). Laterally fixed (x and y fixed on all four
/// sides): uniaxial strain, with the constrained modulus E' = E (1 - nu) / ((1 + nu)(1 - 2 nu)).
/// Both fields are homogeneous, which trilinear hexahedra with B-bar reproduce exactly, so
/// the only error is the Newton tolerance. The punch starts `GAP` above the block: the
/// first iteration is the approach step.
fn flat_punch(laterally_fixed: bool) {
    const GAP: f64 = 0.01;
    let (young, poisson, force) = (1000.0, 0.3, 100.0);
    let size = Vec3::new(2.0, 2.0, 1.0);
    let mesh = tribo::mesh::Mesh::block(Vec3::zeros(), size, [2, 2, 2]).unwrap();
    let mut model = Model::new(mesh, common::elastic(young, poisson)).unwrap();
    let zero = ScalarSchedule::constant(0.0);
    model.prescribe("z-", "z", zero.clone()).unwrap();
    model.prescribe("x-", "x", zero.clone()).unwrap();
    model.prescribe("y-", "y", zero.clone()).unwrap();
    if laterally_fixed {
        model.prescribe("x+", "x", zero.clone()).unwrap();
        model.prescribe("y+", "y", zero).unwrap();
    }
    model
        .add_tool(punch(size.z + GAP, force), "z+", None)
        .unwrap();
    model.settings.increments = 4;
    let contact_tol = model.settings.contact_tol;
    let r_sum: f64 = model.contacts[0].r.iter().sum();
    let r_mean = r_sum / model.contacts[0].r.len() as f64;
    let modulus = if laterally_fixed {
        young * (1.0 - poisson) / ((1.0 + poisson) * (1.0 - 2.0 * poisson))
    } else {
        young
    };
    let mut sim = Simulation::new(model).unwrap();
    while !sim.is_finished() {
        let report = sim.step().unwrap();
        let f = force * report.time;
        let reaction = sim.tool_force(0).z; // = -a . (force on the tool), a = -z
                                            // The force row holds -a . sum lambda = F to r_mean * contact_tol; the reported
                                            // force sums F_equi = lambda + r F_suppl, each within r_k * contact_tol.
        let force_tol = (r_mean + r_sum) * contact_tol;
        assert!(
            (reaction - f).abs() <= force_tol,
            "t = {}: reaction {reaction} vs scheduled {f} (tolerance {force_tol:e})",
            report.time
        );
        let compression = sim.tool_offset(0) - GAP;
        let analytic = f * size.z / (modulus * size.x * size.y);
        // Newton stops with contact residuals below contact_tol (a length) and relative
        // force residuals below 1e-9: the compression is exact to about 1e-9 (absolute).
        println!(
            "t = {}: reaction {reaction:.12} (F = {f}), compression {compression:.12e}, analytic {analytic:.12e}",
            report.time
        );
        assert!(
            (compression - analytic).abs() <= 1e-8,
            "compression {compression} vs analytic {analytic}"
        );
        // The tool's work counts its offset: for a linear response the trapezoidal rule is
        // exact, so the balance closes to the solver tolerance.
        assert!(
            report.energy.relative_error.abs() < 1e-8,
            "energy balance error {}",
            report.energy.relative_error
        );
        assert_eq!(report.tool_offsets[0], sim.tool_offset(0));
        assert!((sim.tool_position(0).z + sim.tool_offset(0)).abs() < 1e-15);
    }
}

#[test]
fn flat_punch_uniaxial_stress_matches_analytic_compression() {
    flat_punch(false);
}

#[test]
fn flat_punch_uniaxial_strain_matches_analytic_compression() {
    flat_punch(true);
}

/// The block stands on a frictionless rigid floor (a second tool) instead of a support:
/// the floor's multipliers are condensed out, the punch's stay with the offset unknown.
/// Same iterates with and without the condensation, and the uniaxial-stress compression.
#[test]
fn condensed_floor_and_force_controlled_punch() {
    let run = |eliminate: bool| {
        let (young, force) = (1000.0, 100.0);
        let mesh =
            tribo::mesh::Mesh::block(Vec3::zeros(), Vec3::new(2.0, 2.0, 1.0), [2, 2, 2]).unwrap();
        let mut model = Model::new(mesh, common::elastic(young, 0.3)).unwrap();
        let zero = ScalarSchedule::constant(0.0);
        model.prescribe("x-", "x", zero.clone()).unwrap();
        model.prescribe("y-", "y", zero).unwrap();
        let floor = Plane::new(Vec3::zeros(), Vec3::z()).unwrap();
        model
            .add_tool(Tool::new("floor", std::sync::Arc::new(floor)), "z-", None)
            .unwrap();
        model.add_tool(punch(1.0, force), "z+", None).unwrap();
        model.settings.increments = 2;
        model.settings.eliminate_multipliers = eliminate;
        let mut sim = Simulation::new(model).unwrap();
        sim.run(|_, _| Ok(())).unwrap();
        let analytic = force * 1.0 / (young * 4.0);
        // Newton tolerances 1e-9 (see flat_punch).
        assert!(
            (sim.tool_offset(1) - analytic).abs() < 1e-8,
            "{}",
            sim.tool_offset(1)
        );
        (sim.eliminated_multipliers(), sim.tool_offset(1))
    };
    let (eliminated, s_condensed) = run(true);
    let (none, s_full) = run(false);
    assert!(eliminated > 0 && none == 0);
    // Same Newton iterates up to the round-off of two different factorizations.
    assert!(
        (s_condensed - s_full).abs() < 1e-12,
        "{s_condensed} vs {s_full}"
    );
}

/// The multipliers of a force-controlled tool are condensed out like the others (the
/// force row receives dl = rhs1 - K_a du): the condensed Newton step, offset included,
/// equals the mixed one at a mid-drag iterate with gap, stick and slip nodes.
#[test]
fn condensed_step_with_force_control_equals_the_mixed_one() {
    let mut model = force_controlled_drag(8.0, 32, 16.0, 4.0, FORCE);
    model.settings.increments = 12;
    // Free the y faces, so that the roller's nodes have no prescribed component.
    model.dirichlet.retain(|d| !d.label.starts_with('y'));
    let mut sim = Simulation::new(model).unwrap();
    let candidates = sim.model.contacts[0].candidates.len();
    assert!(
        sim.eliminated_multipliers() > 3 * candidates / 2,
        "most of the roller's multipliers are eliminated"
    );
    // The first two Newton iterates while pressing (t = 0.75: stick under the roller) and
    // while dragging (t = 1.75: slip).
    let mut seen = Vec::new();
    for steps in [2, 4] {
        for _ in 0..steps {
            sim.step().unwrap();
        }
        let t_new = sim.time() + 0.25;
        let mut x = sim.unknowns().to_vec();
        for iterate in 0..2 {
            let e = sim.evaluate_at(t_new, &x).unwrap();
            seen.extend(e.nodal[0].iter().map(|(r, _)| r.status));
            let (full, condensed, scale, diff) = common::full_and_condensed_steps(&sim, &e);
            let n = full.len();
            println!(
                "t = {t_new}, iterate {iterate}: largest step entry {scale:.3e}, difference {diff:.3e}; offset step {:.6e} vs {:.6e}",
                full[n - 1],
                condensed[n - 1]
            );
            // Two factorizations of equivalent systems: round-off times the condition
            // number.
            assert!(diff < 1e-10 * scale, "condensed step differs by {diff:e}");
            if iterate == 0 {
                assert!(full[n - 1].abs() > 1e-6, "the offset moves in this step");
            }
            for (xi, d) in x.iter_mut().zip(&condensed) {
                *xi += d;
            }
        }
    }
    use tribo::contact::ContactStatus::*;
    for s in [Gap, Stick, Slip] {
        assert!(seen.contains(&s), "{s:?} present");
    }
}

#[test]
fn tool_moving_away_from_everything_is_reported() {
    let mesh =
        tribo::mesh::Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
    let mut model = Model::new(mesh, common::elastic(1000.0, 0.3)).unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    let plane = Plane::new(Vec3::new(0.0, 0.0, 1.5), Vec3::new(0.0, 0.0, -1.0)).unwrap();
    let mut punch = Tool::new("punch", std::sync::Arc::new(plane));
    // Axis pointing up, away from the block: nothing lies ahead.
    punch.force_control =
        Some(ForceControl::new(Vec3::z(), ScalarSchedule::constant(10.0)).unwrap());
    model.add_tool(punch, "z+", None).unwrap();
    model.settings.max_cutbacks = 0;
    let err = Simulation::new(model)
        .unwrap()
        .step()
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("force-controlled tool 'punch' touches no node"),
        "{err}"
    );
}

#[test]
fn force_control_under_penalty_is_refused() {
    let mut model = force_controlled_drag(1.0, 8, 8.0, 2.0, FORCE);
    model.settings.contact.enforcement = tribo::contact::Enforcement::Penalty;
    let err = Simulation::new(model).err().expect("refused").to_string();
    assert!(err.contains("'roller' is force-controlled"), "{err}");
}

/// Newton with the offset unknown keeps its quadratic rate during the drag (the
/// kinematic counterpart is tests/cylinder_drag_newton.rs). The press force (indentation
/// about 0.18 under a radius 5) is chosen so that the drag increments need four Newton
/// iterations: with three, the last residual is already round-off and no order can be
/// read.
#[test]
fn newton_converges_quadratically_with_force_control() {
    const PRESS: f64 = 120.0;
    let mut model = force_controlled_drag(8.0, 32, 16.0, 4.0, PRESS);
    model.settings.increments = 3;
    model.settings.max_iterations = 40;
    // The press from rest starts from a zero force residual (only the force row is off):
    // Newton's divergence guard must not read the first iterations as growth.
    model.settings.max_cutbacks = 0;
    model.settings.force_rel_tol = 1e-11;
    model.settings.contact_tol = 1e-11;
    // From the committed state and with r as this test was written with (see
    // `former_default_r`; 0.5 x 1 x 0.5 cells): else too few iterations to read an order.
    model.settings.extrapolate = false;
    common::former_default_r(&mut model, 0, 0.3, 0.5, 0.5);
    // The order read here is the tangent's (the force row's columns): plain Newton steps.
    // With status prediction (the default) the drag increments run 4.17, 0.36, 0.044,
    // 1.3e-5, 9e-12 and 4.08, 0.35, 0.062, 3.4e-5, 7.3e-11, 2e-14: the constant of the
    // last steps grows (a re-solve at a node on its status boundary changes the step by
    // the difference of the two branches' linearisations), and the three-point estimate
    // reads 1.74 in both.
    model.settings.status_prediction = 0;
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    let mut worst = f64::INFINITY;
    for r in sim.history.iter().filter(|r| r.time > 1.0 + 1e-9) {
        let res: Vec<f64> = r.residuals.iter().map(|x| x.force_rel).collect();
        // Converged relative residuals of this problem land at 4e-14 to 6e-13 (printed
        // here and in cylinder_drag_newton.rs): below 1e-12 the residual is round-off.
        let orders = common::convergence_orders(&res, 1e-12);
        println!(
            "increment {} ({} iterations, offset {:.6}, force {:.9}): orders {orders:?} residuals {res:?} contact {:?}",
            r.index, r.iterations, r.tool_offsets[0], r.tool_forces[0][2], r.residuals.iter().map(|x| x.contact).collect::<Vec<_>>()
        );
        if let Some(&last) = orders.last() {
            worst = worst.min(last);
        }
        assert!((r.tool_forces[0][2] - PRESS).abs() < 1e-6 * PRESS);
    }
    assert!(worst.is_finite(), "some increment measured an order");
    assert!(worst >= 1.8, "observed convergence order {worst} < 1.8");
}
