//! The assembled Jacobian of the mixed (u, lambda) system equals central finite differences
//! of the assembled residual at a Newton iterate in the middle of a frictional drag over a
//! cylinder (elements, contact in stick and slip, curvature terms, multiplier rows).

mod common;

use tribo::geometry::Vec3;
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

/// Issue 47: a node that slipped and has not moved since sits on the Coulomb cone,
/// `|sigma_t| = mu |sigma_n|`, where the slip law's derivative across the slip direction
/// vanishes: `dF_suppl_y / dlambda_y = -(1 + mu sigma_n / |sigma_t|) / r = 0`. In plane
/// strain the multiplier's only other entry lies in the node's y equilibrium row, a
/// Dirichlet row, so its column was empty and the Jacobian singular (the U-channel's
/// release with Chaboche hardening stopped there). The component gets the equation
/// `lambda_y = 0` instead, which is the operator's own solution (`F_equi_y = 0`): the
/// empty-column rule of src/solver/assembly/unit_rows.rs.
#[test]
fn a_slipping_node_on_the_cone_in_plane_strain_leaves_no_empty_column() {
    use tribo::contact::ContactStatus;
    use tribo::solver::linear::{FaerLu, LinearSolver};
    // Pulled along x just past mu * 20 (by a relative 1e-15: outside the cone by round-off,
    // as a node that slipped last increment).
    let (x, n_u, candidates, e) = pressed_and_pulled(1.0 + 1e-15);
    assert!(
        e.nodal[0]
            .iter()
            .all(|(r, _)| r.status == ContactStatus::Slip),
        "every candidate slips"
    );
    let scale = e.jacobian.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let column_size = |j: usize| {
        let mut ej = vec![0.0; x.len()];
        ej[j] = 1.0;
        e.jacobian
            .mul_vec(&ej)
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    // Every column holds an entry of the matrix's own size (1e-10 of its largest: the
    // element stiffness is ~1e3, the multiplier rows ~1/r; the column found empty before
    // held at most 1e-15/r, round-off of the cone factor).
    for j in 0..x.len() {
        assert!(
            column_size(j) > 1e-10 * scale,
            "column {j} is empty ({:e} against {scale:e})",
            column_size(j)
        );
    }
    // The Newton step solves and keeps the y multipliers at zero.
    let mut dx: Vec<f64> = e.residual.iter().map(|v| -v).collect();
    FaerLu::default().solve(&e.jacobian, &mut dx).unwrap();
    assert!(dx.iter().all(|v| v.is_finite()));
    for k in 0..candidates {
        assert_eq!(x[n_u + 3 * k + 1] + dx[n_u + 3 * k + 1], 0.0);
    }
}

/// The counterpart: pulled to twice the cone, the slip law's own row determines the y
/// multiplier (`dF_suppl_y / dlambda_y = -(1 - mu |sigma_n| / |sigma_t|) / r = -1 / (2 r)`),
/// and the empty-column rule leaves it alone: the diagonal entry is the operator's, not the
/// unit row's 1.
#[test]
fn a_slipping_node_off_the_cone_keeps_its_own_multiplier_row() {
    let (_, n_u, candidates, e) = pressed_and_pulled(2.0);
    for k in 0..candidates {
        let l = n_u + 3 * k + 1;
        let (result, _) = &e.nodal[0][k];
        let diagonal = e.jacobian.values[e.jacobian.pattern.position(l, l).unwrap()];
        assert_eq!(diagonal, result.suppl_lambda[(1, 1)], "candidate {k}");
        // -1/(2r) to round-off, r being the pair's augmentation.
        assert!(diagonal < 0.0, "candidate {k}: {diagonal}");
        assert_eq!(e.residual[l], result.f_suppl[1], "candidate {k}");
    }
}

/// A 2 x 1 x 1 elastic block in plane strain (y fixed on both faces), clamped below, its top
/// face touching a holder plane (Coulomb 0.1); every candidate's multiplier pressed with 20
/// and pulled along x to `pull` times the cone, `mu * 20`. Returns the unknowns, the number
/// of displacement unknowns, the candidates and the evaluation there.
fn pressed_and_pulled(pull: f64) -> (Vec<f64>, usize, usize, tribo::solver::assembly::Evaluation) {
    use tribo::geometry::Plane;
    use tribo::tool::ScalarSchedule;
    let mesh =
        tribo::mesh::Mesh::block(Vec3::zeros(), Vec3::new(2.0, 1.0, 1.0), [2, 1, 1]).unwrap();
    let mut model = tribo::solver::Model::new(mesh, common::elastic(1000.0, 0.3)).unwrap();
    // A holder plane touching the top face (gap 0), its normal towards the block.
    let holder = Plane::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::z()).unwrap();
    let path = [(0.0, [0.0; 3]), (1.0, [0.0; 3])];
    let mu = 0.1;
    model
        .add_tool(common::tool("holder", holder, &path, mu), "z+", None)
        .unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    for face in ["y-", "y+"] {
        model
            .prescribe(face, "y", ScalarSchedule::constant(0.0))
            .unwrap();
    }
    model.settings.end_time = 1.0;
    let sim = Simulation::new(model).unwrap();
    let n_u = 3 * sim.model.mesh.nodes.len();
    let candidates = sim.model.contacts[0].candidates.len();
    let mut x = sim.unknowns().to_vec();
    assert_eq!(
        x.len(),
        n_u + 3 * candidates,
        "displacements, then multipliers"
    );
    let pressed = 20.0;
    for k in 0..candidates {
        x[n_u + 3 * k] = -mu * pressed * pull;
        x[n_u + 3 * k + 2] = pressed;
    }
    let e = sim.evaluate_at(0.5, &x).unwrap();
    (x, n_u, candidates, e)
}
