//! Newton with the solid-shell's early-stopped local solves: iterates may use them
//! (`LocalSolve::Approximate`, the enhanced parameters solved from a prediction to 1e-4 of
//! the strain scale), converged states may not. Every element of each converged increment
//! of a plastic sheet pressed and dragged by a roller is evaluated again without a memory
//! (the tight local solve, from the converged parameters, against the same committed
//! states): its stresses and force equal the converged ones to round-off, so the converged
//! state is the exact discrete problem's, not the early stop's.
//!
//! What the elements remember at a converged state starts the next increment's local
//! solves, and a checkpoint keeps it: a restarted run repeats the uninterrupted one bit
//! for bit.

mod common;

use std::sync::Arc;
use tribo::element::ElementKind;
use tribo::geometry::{Cylinder, Vec3};
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};
use tribo::mesh::Mesh;
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

/// A plastic solid-shell sheet (20 x 8 x 1) pressed and dragged by a roller in 8
/// increments.
fn roller_model() -> Model {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(10.0, 4.0, 1.0), [20, 8, 1]).unwrap();
    let material = ElastoPlastic::new(
        LinearElastic::new(70e3, 0.33).unwrap(),
        Hill48::from_lankford(0.7, 1.3, 2.1).unwrap(),
        Hardening::swift(500.0, 0.01, 0.22).unwrap(),
    );
    let mut model = Model::new(mesh, Arc::new(material)).unwrap();
    let roller = Cylinder::new(Vec3::new(5.0, 0.0, 6.0 + 1e-3), Vec3::y(), 5.0).unwrap();
    let path = [
        (0.0, [0.0; 3]),
        (1.0, [0.0, 0.0, -0.3]),
        (2.0, [2.0, 0.0, -0.3]),
    ];
    model
        .add_tool(common::tool("roller", roller, &path, 0.2), "z+", None)
        .unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.element = ElementKind::SolidShell;
    model.settings.end_time = 2.0;
    model.settings.increments = 8;
    model
}

#[test]
fn converged_states_are_those_of_the_tight_local_solve() {
    let mut sim = Simulation::new(roller_model()).unwrap();
    let element = sim.model.element().unwrap();
    let per = element.point_count();
    let (mut worst, mut checked): (f64, usize) = (0.0, 0);
    while !sim.is_finished() {
        let before = sim.points().to_vec();
        let committed = sim.history.len();
        sim.step().unwrap();
        // A step that committed several increments (cut back) has no `before` here.
        if sim.history.len() != committed + 1 {
            continue;
        }
        checked += 1;
        let (mesh, u) = (&sim.model.mesh, sim.displacements());
        let converged = sim.points();
        let scale = converged
            .iter()
            .flat_map(|p| p.stress.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        for (e, hex) in mesh.hexes.iter().enumerate() {
            let x: Vec<Vec3> = hex.iter().map(|&n| mesh.nodes[n]).collect();
            let ue: Vec<Vec3> = hex
                .iter()
                .map(|&n| Vec3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2]))
                .collect();
            let points = e * per..(e + 1) * per;
            let mut trial = converged[points.clone()].to_vec();
            let mut force = vec![0.0; 24];
            element
                .evaluate_into(
                    &x,
                    &ue,
                    &before[points.clone()],
                    &mut trial,
                    sim.model.material.as_ref(),
                    &mut force,
                    None,
                )
                .unwrap();
            for (a, b) in trial.iter().zip(&converged[points]) {
                for (p, q) in a.stress.iter().zip(b.stress.iter()) {
                    worst = worst.max((p - q).abs() / scale);
                }
            }
        }
    }
    let plastic = sim.points().iter().any(|p| p.eq_plastic_strain > 1e-3);
    assert!(
        plastic,
        "the sheet must flow plastically for the test to mean anything"
    );
    let approximate = sim.phase_times.approximate_evaluations;
    println!(
        "iterates with early-stopped local solves: {approximate}; {checked} increments; \
         converged stresses against a tight local solve: {worst:.1e} of the largest"
    );
    assert!(approximate > 0, "no iterate stopped a local solve early");
    assert!(checked >= 6, "{checked} increments checked");
    // Round-off: the measured early-stopped iterates' stresses are off by 5e-11 to 1e-10
    // (tests/solid_shell_element.rs), 1e-12 tells them apart.
    assert!(worst < 1e-12, "{worst:e}");
}

/// The committed element memory is part of the checkpoint: a run restarted from one after 3
/// increments ends bit for bit where the uninterrupted run does. Restarted without it (the
/// field removed, as in a checkpoint of an older version), the next increment's first
/// local solves start cold: the same converged answer to the Newton tolerance, other bits,
/// which shows the memory is what the checkpoint restores.
#[test]
fn a_restart_repeats_the_run_with_the_elements_memory() {
    use tribo::solver::simulation::checkpoint::Checkpoint;
    let finish = |mut sim: Simulation| -> Vec<f64> {
        while !sim.is_finished() {
            sim.step().unwrap();
        }
        sim.displacements().to_vec()
    };
    let uninterrupted = finish(Simulation::new(roller_model()).unwrap());
    let mut first = Simulation::new(roller_model()).unwrap();
    for _ in 0..3 {
        first.step().unwrap();
    }
    let json: serde_json::Value =
        serde_json::from_str(&Checkpoint::of(&first, vec![0.0]).to_json().unwrap()).unwrap();
    let memory = json["state"]["element_memory"].as_array().unwrap();
    let remembered = first.model.element().unwrap().memory_len() * first.model.mesh.hexes.len();
    assert_eq!(memory.len(), remembered);
    assert!(
        memory.iter().all(|v| v.is_f64()),
        "every element remembers a linearisation"
    );
    let restarted = |json: &serde_json::Value| -> Vec<f64> {
        let mut sim = Simulation::new(roller_model()).unwrap();
        Checkpoint::from_json(&json.to_string(), "restart.json")
            .unwrap()
            .restore(&mut sim)
            .unwrap();
        finish(sim)
    };
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&restarted(&json)), bits(&uninterrupted));
    let mut cold = json.clone();
    cold["state"]
        .as_object_mut()
        .unwrap()
        .remove("element_memory");
    let cold = restarted(&cold);
    assert_ne!(bits(&cold), bits(&uninterrupted));
    let scale = uninterrupted.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let off = cold
        .iter()
        .zip(&uninterrupted)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // Two Newton paths converged to the same 1e-9 relative force residual.
    assert!(off < 1e-6 * scale, "{off:e} of {scale:e}");
}
