//! Eliminating the contact multipliers node by node gives the same Newton step as solving
//! the mixed (u, lambda) system, in every contact status, and so the same simulation.

mod common;

use tribo::contact::ContactStatus;
use tribo::solver::linear::{FaerLu, SymmetricLu};
use tribo::solver::LinearSolverKind;
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
/// contributions, summed in the same order). The plan skips the contributions of zero
/// coefficients, which the search adds: only the sign of an entry that is exactly zero may
/// differ (`+0 + -0 = +0`). A reduced system built after another one replays only the
/// segments whose inputs changed and keeps the rest: the same holds after a change of one
/// node's rows (a status prediction re-solve), after the next Newton iterate (most segments
/// dirty: the whole matrix replayed), after no change at all and after a change of the
/// right-hand side only.
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
    let mut one_node = e.jacobian.clone();
    // The equilibrium row of the middle contact candidate (a row with a multiplier
    // column), its entries scaled.
    let n_u = sim.displacements().len();
    let candidates: Vec<usize> = (0..n_u / 3)
        .filter(|&n| {
            (n_u..e.jacobian.pattern.n).any(|c| e.jacobian.pattern.position(3 * n, c).is_some())
        })
        .collect();
    let node = candidates[candidates.len() / 2];
    for c in 0..one_node.pattern.n {
        if let Some(k) = one_node.pattern.position(3 * node, c) {
            one_node.values[k] *= 1.25;
        }
    }
    let mut x2 = x.clone();
    x2.iter_mut()
        .enumerate()
        .for_each(|(i, v)| *v += 1e-4 * (i as f64).sin());
    let e2 = sim.evaluate_at(t_new, &x2).unwrap();
    let mut previous: Option<Vec<f64>> = None;
    for (what, j, residual) in [
        ("first", &e.jacobian, &e.residual),
        ("one node's rows", &one_node, &e.residual),
        ("the next iterate", &e2.jacobian, &e2.residual),
        ("no change", &e2.jacobian, &e2.residual),
        // Only the right-hand side changes: every kept row's, clean segments included.
        ("another residual", &e2.jacobian, &e.residual),
    ] {
        let (a, rhs) = condenser.reduced_system(j, residual).unwrap();
        let (a_ref, rhs_ref) = condenser.reduced_system_by_search(j, residual).unwrap();
        assert!(a.values.iter().any(|v| *v != 0.0));
        assert_eq!(a.pattern, a_ref.pattern);
        for (k, (v, w)) in a.values.iter().zip(&a_ref.values).enumerate() {
            if *v != 0.0 || *w != 0.0 {
                assert_eq!(v.to_bits(), w.to_bits(), "{what}: value {k}: {v} vs {w}");
            }
        }
        for (k, (v, w)) in rhs.iter().zip(&rhs_ref).enumerate() {
            assert_eq!(v.to_bits(), w.to_bits(), "{what}: right-hand side {k}");
        }
        if let Some(p) = &previous {
            let changed = p.iter().zip(&a.values).filter(|(u, v)| u != v).count();
            println!(
                "{what}: {changed} of {} reduced entries changed",
                a.values.len()
            );
            match what {
                "no change" | "another residual" => assert_eq!(changed, 0),
                _ => assert!(changed > 0, "{what}"),
            }
        }
        previous = Some(a.values.clone());
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

/// The plane-strain drag (y faces fixed: the roller's nodes have a prescribed component and
/// keep their multipliers, which the factorization without pivoting eliminates after their
/// node's displacements: the mixed system) and the free drag (multipliers condensed).
fn drag_with(free_y: bool, solver: LinearSolverKind) -> Simulation {
    let mut model = common::cylinder_drag_model(16.0, 4.0, 32, 8.0);
    model.settings.increments = 12;
    if free_y {
        model.dirichlet.retain(|d| !d.label.starts_with('y'));
    }
    model.settings.linear_solver = solver;
    Simulation::new(model).unwrap()
}

/// The same Newton steps from the LU without pivoting on the symmetric structure as from
/// faer's pivoting LU, on the reduced system with kept multipliers (gap, stick and slip
/// statuses, pressing then dragging), without the pivoting fallback.
#[test]
fn symmetric_lu_steps_equal_the_pivoting_lu_steps() {
    for free_y in [false, true] {
        let mut sim = drag_with(free_y, LinearSolverKind::SymmetricLu);
        for steps in [2, 4] {
            for _ in 0..steps {
                sim.step().unwrap();
            }
            let t_new = sim.time() + 0.25;
            let mut x = sim.unknowns().to_vec();
            for _ in 0..3 {
                let e = sim.evaluate_at(t_new, &x).unwrap();
                let old = sim.newton_step(&e, &mut FaerLu::default()).unwrap();
                let mut symmetric = SymmetricLu::default();
                let new = sim.newton_step(&e, &mut symmetric).unwrap();
                assert_eq!(symmetric.fallback_count, 0);
                let scale = old.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let diff = old
                    .iter()
                    .zip(&new)
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                println!("free y {free_y}, t {t_new}: step {scale:.3e}, difference {diff:.3e}");
                // Two factorizations of one system: round-off times the condition number.
                assert!(diff < 1e-10 * scale, "steps differ by {diff:e}");
                for (xi, d) in x.iter_mut().zip(&new) {
                    *xi += d;
                }
            }
        }
    }
}

/// Whole runs with either solver: the same iterations, the same converged unknowns up to
/// Newton's tolerance.
#[test]
fn symmetric_lu_and_pivoting_lu_runs_agree() {
    runs_agree(
        drag_with(false, LinearSolverKind::SymmetricLu),
        drag_with(false, LinearSolverKind::Lu),
    );
}

/// Runs both simulations to the end: the same iterations in every increment, the same
/// converged unknowns to 1e-9 of the largest (Newton's tolerance).
fn runs_agree(mut a: Simulation, mut b: Simulation) {
    a.run(|_, _| Ok(())).unwrap();
    b.run(|_, _| Ok(())).unwrap();
    let scale = b.unknowns().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let d = a
        .unknowns()
        .iter()
        .zip(b.unknowns())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let iters = |s: &Simulation| s.history.iter().map(|r| r.iterations).collect::<Vec<_>>();
    println!(
        "max difference {d:.2e} of {scale:.2e}; iterations {:?}",
        iters(&a)
    );
    assert_eq!(iters(&a), iters(&b));
    assert!(d < 1e-9 * scale, "runs differ by {d}");
}

/// The free drag with a second roller on the same face, 6 ahead of the first: every top
/// node is a candidate of both tools (two pairs, like the cup's top face under punch and
/// holder), and all their multipliers are eliminated.
fn two_roller_drag(eliminate: bool) -> Simulation {
    use tribo::geometry::{Cylinder, Vec3};
    let mut model = common::cylinder_drag_model(16.0, 4.0, 32, 3.0);
    model.settings.increments = 12;
    model.dirichlet.retain(|d| !d.label.starts_with('y'));
    let axis = Vec3::new(10.0, 0.0, 4.0 + 5.0 + 0.02);
    let cyl = Cylinder::new(axis, Vec3::y(), 5.0).unwrap();
    let path = [
        (0.0, [0.0; 3]),
        (1.0, [0.0, 0.0, -0.12]),
        (3.0, [3.0, 0.0, -0.12]),
    ];
    model
        .add_tool(common::tool("second roller", cyl, &path, 0.3), "z+", None)
        .unwrap();
    model.settings.eliminate_multipliers = eliminate;
    Simulation::new(model).unwrap()
}

/// Nodes with two pairs: the local elimination (one pair active, the other in gap, or both
/// in gap) gives the mixed system's Newton step, in every iterate of pressing and dragging.
#[test]
fn two_pair_nodes_condense_to_the_mixed_step() {
    let mut sim = two_roller_drag(true);
    let n_lambda = sim.unknowns().len() - 3 * (33 * 2 * 9);
    assert_eq!(
        sim.eliminated_multipliers(),
        n_lambda,
        "displacement-only system"
    );
    let mut worst = 0.0f64;
    let mut active_per_tool = [0usize; 2];
    for steps in [2, 3, 3] {
        for _ in 0..steps {
            sim.step().unwrap();
        }
        let t_new = sim.time() + 0.25;
        let mut x = sim.unknowns().to_vec();
        for _ in 0..3 {
            let e = sim.evaluate_at(t_new, &x).unwrap();
            for (count, tool) in active_per_tool.iter_mut().zip(&e.nodal) {
                *count += tool
                    .iter()
                    .filter(|(n, _)| n.status != ContactStatus::Gap)
                    .count();
            }
            let (_, condensed, scale, diff) = common::full_and_condensed_steps(&sim, &e);
            println!("t {t_new}: step {scale:.3e}, difference {diff:.3e}");
            // One system, two eliminations: round-off times the condition number.
            assert!(diff < 1e-10 * scale, "condensed step differs by {diff:e}");
            worst = worst.max(diff / scale);
            for (xi, d) in x.iter_mut().zip(&condensed) {
                *xi += d;
            }
        }
    }
    // Each roller's pair is the active one at some nodes (and in gap at the others).
    assert!(
        active_per_tool.iter().all(|&c| c > 0),
        "{active_per_tool:?}"
    );
    let condenser = sim.condenser().unwrap();
    assert_eq!(
        condenser.fallback_count(),
        0,
        "no node had two active pairs"
    );
    println!("worst relative difference {worst:.2e}");
}

/// Whole runs with two rollers: the same iterations, the same converged unknowns up to
/// Newton's tolerance, with and without the elimination.
#[test]
fn two_pair_condensed_and_mixed_runs_agree() {
    runs_agree(two_roller_drag(true), two_roller_drag(false));
}

/// A node with both pairs active (here: both sliding without friction, normals z and x)
/// has no local elimination: that call solves the mixed system instead, with the same
/// step.
#[test]
fn two_active_pairs_fall_back_to_the_mixed_solve() {
    let mut sim = two_roller_drag(true);
    sim.step().unwrap();
    sim.step().unwrap();
    let x = sim.unknowns().to_vec();
    let mut e = sim.evaluate_at(sim.time() + 0.25, &x).unwrap();
    let (model, n_u) = (&sim.model, 3 * sim.model.mesh.nodes.len());
    let k = model.contacts[0].candidates.len() / 2;
    let node = model.contacts[0].candidates[k];
    assert_eq!(model.contacts[1].candidates[k], node);
    let j = &mut e.jacobian;
    for (c, normal) in [(0, 2), (1, 0)] {
        let l = n_u + 3 * c * model.contacts[0].candidates.len() + 3 * k;
        let r = model.contacts[c].r[k];
        for a in 0..3 {
            for b in 0..3 {
                let nn = if a == normal && b == normal { 1.0 } else { 0.0 };
                let mut set = |row: usize, col: usize, v: f64| {
                    let p = j.pattern.position(row, col).expect("pair block entry");
                    j.values[p] = v;
                };
                set(3 * node + a, l + b, nn);
                set(l + a, l + b, (nn - f64::from(u8::from(a == b))) / r);
                set(l + a, 3 * node + b, nn);
            }
        }
    }
    let before = sim.condenser().unwrap().fallback_count();
    let (_, _, scale, diff) = common::full_and_condensed_steps(&sim, &e);
    assert_eq!(sim.condenser().unwrap().fallback_count(), before + 1);
    println!("step {scale:.3e}, difference {diff:.3e}");
    assert!(diff < 1e-10 * scale, "steps differ by {diff:e}");
}
