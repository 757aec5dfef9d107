//! The generalised Coulomb law: frictional work per node, mu(theta) from a Bernstein
//! polynomial, explicit and implicit updates against the frictional-work ODE, the
//! mesh-objective per-area work measure, and the energy balance.
//!
//! The set-up makes the ODE exact: a block whose nodes all follow a prescribed rigid
//! translation s(t) along x (y held), pressed on a rigid plane by a total force N. Every
//! bottom node then slips by exactly the increment of s and carries the constant normal
//! force N_node = N A_node / A, so its work obeys dPsi/ds = mu(Psi) N_node, and the only
//! error left is the time discretisation of the friction update.

mod common;

use tribo::contact::{BernsteinLaw, FrictionLaw, FrictionUpdate, WorkMeasure};
use tribo::geometry::{Plane, Vec3};
use tribo::mesh::Mesh;
use tribo::solver::{Model, Simulation};
use tribo::tool::{ScalarSchedule, Tool};

const N: f64 = 100.0;
const SLIDE: f64 = 10.0;
/// The paper's curve (mu_init = 0.16, mu_cut = 0.01), cut-off beyond the work reached here
/// so that theta stays inside (0, 1) and mu is smooth along the whole path.
const POINTS: [f64; 4] = [0.16, 0.16, 0.01, 0.01];
const WORK_CUT: f64 = 50.0;

fn sliding_column(
    cells: usize,
    slide_increments: usize,
    law: FrictionLaw,
    update: FrictionUpdate,
) -> Simulation {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 2.0, 1.0), [cells, cells, 1]).unwrap();
    let mut model = Model::new(mesh, common::elastic(10000.0, 0.0)).unwrap();
    let mut floor = Tool::new(
        "floor",
        std::sync::Arc::new(Plane::new(Vec3::zeros(), Vec3::z()).unwrap()),
    );
    floor.friction = law;
    model.add_tool(floor, "z-", None).unwrap();
    model
        .add_load(
            "z+",
            Vec3::new(0.0, 0.0, -N),
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 1.0)]).unwrap(),
        )
        .unwrap();
    let everything = model.mesh.select_nodes(|_| true);
    model.mesh.add_node_set("all", everything).unwrap();
    let slide = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 0.0), (2.0, SLIDE)]).unwrap();
    model.prescribe("all", "x", slide).unwrap();
    model
        .prescribe("all", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.end_time = 2.0;
    model.settings.increments = 2 * slide_increments;
    model.settings.force_rel_tol = 1e-13;
    model.settings.contact_tol = 1e-13;
    model.settings.contact.friction_update = update;
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    sim
}

fn paper_law(measure: WorkMeasure, cut: f64) -> FrictionLaw {
    FrictionLaw::Bernstein(BernsteinLaw::new(POINTS.to_vec(), cut, measure).unwrap())
}

/// Psi(s) of dPsi/ds = mu(Psi) n_node by RK4 with a step far below the test's (error
/// ~ h^4 ~ 1e-14 relative), sampled at `samples` + 1 equally spaced points (the study's
/// integrator, on the same law and slide as this test).
fn ode_reference(n_node: f64, samples: usize) -> Vec<f64> {
    assert_eq!(
        (POINTS, WORK_CUT, SLIDE),
        (
            tribo::study::scenes::ODE_POINTS,
            tribo::study::scenes::ODE_WORK_CUT,
            tribo::study::scenes::ODE_SLIDE
        )
    );
    tribo::study::scenes::ode_work(n_node, samples, 2000).unwrap()
}

/// (error in the final work, largest error of the friction force of an increment against
/// the exact force averaged over the increment) for one run.
fn errors(slide_increments: usize, update: FrictionUpdate) -> (f64, f64) {
    let sim = sliding_column(
        1,
        slide_increments,
        paper_law(WorkMeasure::PerNode, WORK_CUT),
        update,
    );
    let n_node = N / 4.0;
    let exact = ode_reference(n_node, slide_increments);
    let law = BernsteinLaw::new(POINTS.to_vec(), WORK_CUT, WorkMeasure::PerNode).unwrap();
    let work = sim.contact_states(0)[0].work;
    for s in sim.contact_states(0) {
        assert!(
            (s.work - work).abs() < 1e-9 * work,
            "the four nodes are alike"
        );
        assert!(
            (s.slip - SLIDE).abs() < 1e-9,
            "every node slid the full distance"
        );
    }
    let work_error = (work - exact[slide_increments]).abs() / exact[slide_increments];
    // Friction force of each slide increment (the reaction, 4 nodes) against the exact one.
    let slides: Vec<_> = sim
        .history
        .iter()
        .filter(|r| r.time > 1.0 + 1e-12)
        .collect();
    assert_eq!(slides.len(), slide_increments);
    let mut force_error: f64 = 0.0;
    for (i, r) in slides.iter().enumerate() {
        let exact_force = 0.5 * (law.mu(exact[i], 1.0) + law.mu(exact[i + 1], 1.0)) * N;
        force_error = force_error.max((r.tool_forces[0][0] - exact_force).abs() / (0.16 * N));
    }
    (work_error, force_error)
}

fn observed_orders(update: FrictionUpdate) -> (Vec<f64>, Vec<f64>) {
    let runs: Vec<(f64, f64)> = [10, 20, 40]
        .into_iter()
        .map(|n| errors(n, update))
        .collect();
    println!("{update:?}: slide increments 10, 20, 40 -> (work error, force error) {runs:?}");
    let order = |a: f64, b: f64| (a / b).log2();
    let work = vec![order(runs[0].0, runs[1].0), order(runs[1].0, runs[2].0)];
    let force = vec![order(runs[0].1, runs[1].1), order(runs[1].1, runs[2].1)];
    println!("{update:?}: observed orders: work {work:.3?}, force {force:.3?}");
    (work, force)
}

#[test]
fn explicit_update_converges_at_first_order() {
    let (work, force) = observed_orders(FrictionUpdate::Explicit);
    for p in work.iter().chain(&force) {
        assert!(
            (0.8..=1.2).contains(p),
            "explicit update order {p} outside [0.8, 1.2]"
        );
    }
}

#[test]
fn implicit_update_converges_at_second_order() {
    let (work, force) = observed_orders(FrictionUpdate::Implicit);
    for p in work.iter().chain(&force) {
        assert!(*p >= 1.8, "implicit update order {p} < 1.8");
    }
}

#[test]
fn per_area_work_gives_a_mesh_independent_friction_field() {
    // Work per unit area (cut-off 50 N/mm over a 2 x 2 mm face): every node obeys the same
    // ODE whatever its tributary area.
    // Both meshes, 2x2 and 4x4 cells, 10 slide increments, explicit update.
    let pair = |measure| {
        let run = |cells| {
            sliding_column(
                cells,
                10,
                paper_law(measure, WORK_CUT),
                FrictionUpdate::Explicit,
            )
        };
        (run(2), run(4))
    };
    let (coarse, fine) = pair(WorkMeasure::PerArea);
    let mus: Vec<f64> = coarse
        .contact_states(0)
        .iter()
        .chain(fine.contact_states(0))
        .map(|s| s.mu)
        .collect();
    let (lo, hi) = mus
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &m| (a.min(m), b.max(m)));
    println!("per-area work: mu in [{lo:.9}, {hi:.9}] over both meshes");
    assert!(
        hi - lo < 1e-6,
        "per-area mu field differs between meshes by {}",
        hi - lo
    );
    assert!(lo < 0.15, "friction has evolved (mu = {lo})");

    // Nodal work (the paper's): the field depends on each node's area, hence on the mesh.
    let (coarse, fine) = pair(WorkMeasure::PerNode);
    let corner = |sim: &Simulation| sim.contact_states(0)[0].mu;
    let centre = |sim: &Simulation| {
        let k = sim.model.contacts[0]
            .candidates
            .iter()
            .position(|&n| (sim.model.mesh.nodes[n] - Vec3::new(1.0, 1.0, 0.0)).norm() < 1e-12)
            .unwrap();
        sim.contact_states(0)[k].mu
    };
    println!(
        "nodal work: corner mu {:.4} (2x2) {:.4} (4x4); centre mu {:.4} (2x2) {:.4} (4x4)",
        corner(&coarse),
        corner(&fine),
        centre(&coarse),
        centre(&fine)
    );
    assert!((corner(&coarse) - corner(&fine)).abs() > 1e-3);
    assert!((centre(&coarse) - centre(&fine)).abs() > 1e-3);
}

#[test]
fn energy_balance_holds_on_the_dragged_elastic_block() {
    // An elastic block (not the rigid column) dragged by its top face, friction softening.
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(10.0, 10.0, 2.0), [4, 4, 2]).unwrap();
    let mut model = Model::new(mesh, common::elastic(1000.0, 0.3)).unwrap();
    let mut floor = Tool::new(
        "floor",
        std::sync::Arc::new(Plane::new(Vec3::zeros(), Vec3::z()).unwrap()),
    );
    floor.friction = paper_law(WorkMeasure::PerNode, 20.0);
    model.add_tool(floor, "z-", None).unwrap();
    model
        .add_load(
            "z+",
            Vec3::new(0.0, 0.0, -N),
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 1.0)]).unwrap(),
        )
        .unwrap();
    model
        .prescribe(
            "z+",
            "x",
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 0.0), (2.0, 5.0)]).unwrap(),
        )
        .unwrap();
    model
        .prescribe("z+", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.end_time = 2.0;
    model.settings.increments = 40;
    model.settings.force_rel_tol = 1e-12;
    model.settings.contact_tol = 1e-12;
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    let e = sim.energy();
    println!("{e:#?}");
    let dissipated: f64 = e.frictional_dissipation.iter().sum();
    assert!(
        dissipated > 0.5 * 0.01 * N * 5.0,
        "friction dissipated energy ({dissipated})"
    );
    for s in sim.contact_states(0) {
        assert!(s.work >= 0.0 && (0.01..=0.16).contains(&s.mu));
    }
    // Every work term uses the trapezoidal rule, which is exact for a linear elastic body:
    // what is left is the Newton tolerance (1e-12), far inside the 1e-3 asked.
    let worst = sim
        .history
        .iter()
        .map(|r| r.energy.relative_error.abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "energy balance error {worst:e}");
}
