//! Springback of an elastic-perfectly-plastic strip (issue 47, "enough points through the
//! thickness"): one solid-shell layer in plane strain bent to 2 and to 5 times its yield
//! curvature `κe`, then unbent until its moment vanishes; the released curvature against
//! the closed form of a rectangular section,
//!
//! ```text
//! M / Me = (3/2) (1 - (1/3) (κe/κ)²)   (κ >= κe),     Me = σy t² / 6,   κe = 2 σy / (E' t),
//! κ_res  = κ - M / (E' I),                            I = t³ / 12        (per unit width).
//! ```
//!
//! The closed form is for a one-dimensional elastic-perfectly-plastic law. A plane-strain
//! von Mises point with `ν > 0` is not one (its width stress moves from `ν σ` to `σ/2` as
//! it yields, so its bending stress rises by 2.6 % after first yield); Hill48 with
//! `H = 0` and `ν = 0` is: the width stress stays zero, the plastic flow is
//! `(1, 0, -1) ε̇p`, `φ = σxx`, `E' = E`. So the test measures the element and its thickness
//! rule, not the material.
//!
//! Set-up (as tests/solid_shell_bending.rs): a slice of length and width t/16; x- the
//! symmetry plane, y faces held (plane strain), one node of the base held in z; the x+
//! face turned about the centre of curvature by `κ L` (curvature control, default
//! settings otherwise: small strain). The curvature rises to `k κe` in 20 increments, then
//! falls to 0.3 κe below the closed-form released curvature in 20 more; the unloading is
//! elastic (its curvature change stays below `2 κe`, where reverse yielding would start),
//! so the moment is linear in `κ` there and the linear interpolation of its zero between
//! two increments is exact.
//!
//! Why curvature control: under an end moment (moment control) the loaded curvature is
//! `dκ/κ = (κ/κe)² dM/Me`, 25 times the moment's relative error at `5 κe`; every fixed
//! thickness rule of up to 12 points then misses the released curvature by 3 % to 86 %
//! (docs/solid-shell.md, "Springback").

use std::sync::Arc;

use tribo::element::solid_shell::{ACCURATE_THICKNESS_POINTS, DEFAULT_THICKNESS_POINTS};
use tribo::element::ElementKind;
use tribo::geometry::Vec3;
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};
use tribo::mesh::Mesh;
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

const T: f64 = 1.0;
const SLICE: f64 = T / 16.0;
const E: f64 = 210e3;
const SY: f64 = 250.0;
const STEPS: usize = 40;

fn kappa_e() -> f64 {
    2.0 * SY / (E * T)
}

/// Closed-form moment per unit width at `κ = k κe` and released curvature.
fn closed_form(k: f64) -> (f64, f64) {
    let me = SY * T * T / 6.0;
    let m = me * 1.5 * (1.0 - 1.0 / (3.0 * k * k));
    (m, k * kappa_e() - m / (E * T.powi(3) / 12.0))
}

/// Curvature at pseudo-time `time` in [0, 2] for the peak `k κe`.
fn curvature(k: f64, time: f64) -> f64 {
    let peak = k * kappa_e();
    let low = closed_form(k).1 - 0.3 * kappa_e();
    if time <= 1.0 {
        peak * time
    } else {
        peak + (low - peak) * (time - 1.0)
    }
}

/// Bends and unbends to `k κe` with `points` thickness points; returns the moment per
/// unit width at the peak and the curvature at which the moment vanishes while unloading.
fn bend_and_release(k: f64, points: usize) -> (f64, f64) {
    let mut mesh = Mesh::block(
        Vec3::new(0.0, 0.0, -T / 2.0),
        Vec3::new(SLICE, SLICE, T),
        [1, 1, 1],
    )
    .unwrap();
    for (name, z) in [("end0", -T / 2.0), ("end1", T / 2.0)] {
        let set = mesh.select_nodes(|p| (p.x - SLICE).abs() < 1e-12 && (p.z - z).abs() < 1e-9);
        mesh.add_node_set(name, set).unwrap();
    }
    let base = mesh.select_nodes(|p| p.x.abs() < 1e-12 && (p.z + T / 2.0).abs() < 1e-9);
    mesh.add_node_set("base", base).unwrap();
    // Hill48 with H = 0 and ν = 0: one-dimensional EPP in plane strain (module docs).
    let material = ElastoPlastic::new(
        LinearElastic::new(E, 0.0).unwrap(),
        Hill48::new(1.0, 1.0, 0.0, 1.5, 1.5, 1.5).unwrap(),
        Hardening::linear(SY, 0.0).unwrap(),
    );
    let mut model = Model::new(mesh, Arc::new(material)).unwrap();
    let zero = ScalarSchedule::constant(0.0);
    model.prescribe("x-", "x", zero.clone()).unwrap();
    model.prescribe("y-", "y", zero.clone()).unwrap();
    model.prescribe("y+", "y", zero.clone()).unwrap();
    model.prescribe("base", "z", zero).unwrap();
    for (name, z) in [("end0", -T / 2.0), ("end1", T / 2.0)] {
        let table = (0..=STEPS)
            .map(|i| {
                let time = 2.0 * i as f64 / STEPS as f64;
                let kappa = curvature(k, time);
                // x' = (R - z) sin(κ L) with R = 1/κ, minus the reference x = L.
                let u = if kappa == 0.0 {
                    0.0
                } else {
                    (1.0 / kappa - z) * (kappa * SLICE).sin() - SLICE
                };
                (time, u)
            })
            .collect();
        model
            .prescribe(name, "x", ScalarSchedule::new(table).unwrap())
            .unwrap();
    }
    model.settings.element = ElementKind::SolidShell;
    model.settings.thickness_points = points;
    model.settings.end_time = 2.0;
    model.settings.increments = STEPS;
    model.settings.force_rel_tol = 1e-10;
    let end: Vec<usize> = model.nodes("x+").unwrap();
    let (bottom, top) = (
        model.nodes("end0").unwrap()[0],
        model.nodes("end1").unwrap()[0],
    );
    let mut sim = Simulation::new(model).unwrap();
    let (mut kappa, mut moment) = (vec![], vec![]);
    while !sim.is_finished() {
        sim.step().unwrap();
        let eval = sim.evaluate_at(sim.time(), sim.unknowns()).unwrap();
        let pos = |n: usize| sim.model.mesh.nodes[n] + sim.displacement(n);
        let centre = (pos(bottom) + pos(top)) * 0.5;
        let m: f64 = end
            .iter()
            .map(|&n| {
                let d = pos(n) - centre;
                d.z * eval.f_int[3 * n] - d.x * eval.f_int[3 * n + 2]
            })
            .sum();
        kappa.push(curvature(k, sim.time()));
        moment.push(-m / SLICE);
    }
    let peak = moment[STEPS / 2 - 1];
    for i in STEPS / 2..STEPS - 1 {
        let (m0, m1) = (moment[i], moment[i + 1]);
        if m0.signum() != m1.signum() {
            return (peak, kappa[i] + (kappa[i + 1] - kappa[i]) * m0 / (m0 - m1));
        }
    }
    panic!("the moment does not vanish while unloading: {moment:?}");
}

/// The released curvature at 2 and 5 κe within 1 % of the closed form with the 11-point
/// rule (the one documented for springback): the requirement of issue 47. NOT MET: the
/// element errs by more than its thickness rule does (the rule alone, integrating the
/// exact profile, is +0.80 % and -0.57 % with 11 points, docs/springback_rule.py), so the
/// test is ignored until the element is fixed; `cargo test --release --test
/// springback_strip -- --ignored --nocapture` prints the figures (docs/solid-shell.md,
/// "Springback").
#[test]
#[ignore = "issue 47: not met yet, the solid-shell's released curvature is off by more than 1 % (docs/solid-shell.md, Springback)"]
fn released_curvature_of_an_epp_strip_is_the_closed_form() {
    let mut worst: f64 = 0.0;
    for k in [2.0, 5.0] {
        let (m_exact, res_exact) = closed_form(k);
        for points in [DEFAULT_THICKNESS_POINTS, ACCURATE_THICKNESS_POINTS, 12] {
            let (m, res) = bend_and_release(k, points);
            let err = res / res_exact - 1.0;
            println!(
                "k = {k}: {points} points: moment {m:.4} vs {m_exact:.4} ({:+.3} %), released \
                 curvature {res:.6e} vs {res_exact:.6e} ({:+.3} %)",
                100.0 * (m / m_exact - 1.0),
                100.0 * err
            );
            if points == ACCURATE_THICKNESS_POINTS {
                worst = worst.max(err.abs());
            }
        }
    }
    assert!(
        worst < 0.01,
        "released curvature off by {:.2} %",
        100.0 * worst
    );
}
