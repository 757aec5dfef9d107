//! Elastoplastic bending of a sheet to a radius of 10 thicknesses and its springback
//! (issue 15): one solid-shell layer with 5 thickness points against 8 F-bar hexahedra
//! through the thickness, finite strain, von Mises with Swift hardening.
//!
//! Set-up: a slice of a long strip in plane strain (thickness t = 1, slice length and
//! width t/16: the state is uniform along the strip, so one element along it suffices;
//! this short a slice keeps the parasitic shear of the fully integrated F-bar cells in
//! pure bending below 0.2 %). The x- face is the symmetry plane (u_x = 0); the x+ face is
//! turned about the centre of curvature by `φ = κ L`, prescribing `u_x` of its nodes
//! (`x' = (R - z) sin φ`) and leaving `u_z` free (no thickness or neutral-axis constraint
//! beyond plane sections). The curvature rises to `κ = 1/(10 t)` in 20 increments, then
//! falls by 5 % in 20 more (past the springback, short of reverse yielding); the bending moment of the x+ face's nodal forces about its
//! current mid-point gives the moment-curvature curve, and its zero on the way down the
//! springback curvature.

use std::sync::Arc;

use tribo::element::solid_shell::ACCURATE_THICKNESS_POINTS;
use tribo::element::{ElementKind, StrainTheory};
use tribo::geometry::Vec3;
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};
use tribo::mesh::Mesh;
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

const T: f64 = 1.0;
const SLICE: f64 = T / 16.0;
const KAPPA: f64 = 0.1 / T;
const STEPS: usize = 40;
/// Curvature from which the moment curves are compared to 1 % (see the test).
const TRANSITION: f64 = 0.02 / T;

/// Curvature at pseudo-time `time` in [0, 2].
fn curvature(time: f64) -> f64 {
    if time <= 1.0 {
        KAPPA * time
    } else {
        KAPPA * (1.0 - 0.05 * (time - 1.0))
    }
}

struct Curve {
    kappa: Vec<f64>,
    moment: Vec<f64>,
    iterations: Vec<usize>,
}

fn bend(kind: ElementKind, layers: usize, elastic: bool, points: usize) -> Curve {
    let mut mesh = Mesh::block(
        Vec3::new(0.0, 0.0, -T / 2.0),
        Vec3::new(SLICE, SLICE, T),
        [1, 1, layers],
    )
    .unwrap();
    let levels: Vec<f64> = (0..=layers)
        .map(|k| -T / 2.0 + T * k as f64 / layers as f64)
        .collect();
    for (k, z) in levels.iter().enumerate() {
        let set = mesh.select_nodes(|p| (p.x - SLICE).abs() < 1e-12 && (p.z - z).abs() < 1e-9);
        mesh.add_node_set(&format!("end{k}"), set).unwrap();
    }
    let base = mesh.select_nodes(|p| p.x.abs() < 1e-12 && (p.z + T / 2.0).abs() < 1e-9);
    mesh.add_node_set("base", base).unwrap();
    let material = ElastoPlastic::new(
        LinearElastic::new(210e3, 0.3).unwrap(),
        Hill48::from_lankford(1.0, 1.0, 1.0).unwrap(),
        Hardening::swift(500.0, 0.01, 0.22).unwrap(),
    );
    let mut model = if elastic {
        Model::new(mesh, Arc::new(LinearElastic::new(210e3, 0.3).unwrap())).unwrap()
    } else {
        Model::new(mesh, Arc::new(material)).unwrap()
    };
    model
        .prescribe("x-", "x", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe("y-", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe("y+", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe("base", "z", ScalarSchedule::constant(0.0))
        .unwrap();
    for (k, z) in levels.iter().enumerate() {
        let table = (0..=STEPS)
            .map(|i| {
                let time = 2.0 * i as f64 / STEPS as f64;
                let kappa = curvature(time);
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
            .prescribe(&format!("end{k}"), "x", ScalarSchedule::new(table).unwrap())
            .unwrap();
    }
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.element = kind;
    model.settings.thickness_points = points;
    model.settings.end_time = 2.0;
    model.settings.increments = STEPS;
    model.settings.max_cutbacks = 0;
    model.settings.force_rel_tol = 1e-10;
    let end: Vec<usize> = model.nodes("x+").unwrap();
    let (bottom, top) = (
        model.nodes("end0").unwrap()[0],
        model.nodes(&format!("end{layers}")).unwrap()[0],
    );
    let mut sim = Simulation::new(model).unwrap();
    let mut curve = Curve {
        kappa: vec![],
        moment: vec![],
        iterations: vec![],
    };
    while !sim.is_finished() {
        let report = sim.step().unwrap();
        curve.iterations.push(report.iterations);
        let eval = sim.evaluate_at(sim.time(), sim.unknowns()).unwrap();
        let pos = |n: usize| sim.model.mesh.nodes[n] + sim.displacement(n);
        let centre = (pos(bottom) + pos(top)) * 0.5;
        let moment: f64 = end
            .iter()
            .map(|&n| {
                let d = pos(n) - centre;
                let f = Vec3::new(
                    eval.f_int[3 * n],
                    eval.f_int[3 * n + 1],
                    eval.f_int[3 * n + 2],
                );
                d.z * f.x - d.x * f.z
            })
            .sum();
        curve.kappa.push(curvature(sim.time()));
        curve.moment.push(moment / SLICE);
    }
    curve
}

/// The curvature at which the moment returns to zero on the way down (linear
/// interpolation between the increments around the sign change: the unloading is elastic).
fn springback(c: &Curve) -> f64 {
    for i in STEPS / 2..c.moment.len() - 1 {
        let (m0, m1) = (c.moment[i], c.moment[i + 1]);
        if m0.signum() != m1.signum() {
            return c.kappa[i] + (c.kappa[i + 1] - c.kappa[i]) * m0 / (m0 - m1);
        }
    }
    panic!(
        "the moment does not change sign while unloading: {:?}",
        c.moment
    );
}

/// Moment per unit width within 1 % at every loading increment from `κ = 1/(50 t)` on,
/// within 1 % of the peak moment while unloading (it passes through zero there), and the
/// springback curvature within 2 %; Newton converges (at most 8 iterations per increment
/// for the solid-shell). Below `1/(50 t)` the section is in its elastic-plastic transition:
/// the elastic core's edges `±ε_y/κ` (kinks of the stress profile) fall between the 5
/// Simpson points, and the two curves differ by 4.3 % at `1/(200 t)` and 1.2 % at
/// `1/(100 t)` (printed; neither is converged there: the crude closed form lies between).
#[test]
fn one_solid_shell_layer_bends_and_springs_back_like_eight_fbar_layers() {
    let shell = bend(ElementKind::SolidShell, 1, false, 5);
    let fbar = bend(ElementKind::Hexahedron, 8, false, 5);
    let peak = shell.moment.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst: f64 = 0.0;
    for i in 0..STEPS {
        let (a, b) = (shell.moment[i], fbar.moment[i]);
        println!(
            "κ {:.4}: M solid-shell {a:.4}, F-bar {b:.4}, difference {:+.3} %, iterations {} / {}",
            shell.kappa[i],
            100.0 * (a / b - 1.0),
            shell.iterations[i],
            fbar.iterations[i]
        );
        if i < STEPS / 2 {
            if shell.kappa[i] >= TRANSITION {
                worst = worst.max((a / b - 1.0).abs());
            }
        } else {
            worst = worst.max((a - b).abs() / peak);
        }
    }
    let (ks, kf) = (springback(&shell), springback(&fbar));
    println!(
        "worst moment difference {:.3} %; springback curvature solid-shell {ks:.5}, F-bar {kf:.5} \
         ({:+.3} %)",
        100.0 * worst,
        100.0 * (ks / kf - 1.0),
    );
    assert!(worst < 0.01, "moment difference {worst}");
    assert!((ks / kf - 1.0).abs() < 0.02, "springback {ks} vs {kf}");
    assert!(
        shell.iterations.iter().all(|&n| n <= 8),
        "{:?}",
        shell.iterations
    );
}

/// Elastic check of the set-up and of the element: with a Hencky-elastic material the
/// solid-shell's moment per unit width is the plane-strain `E κ t³ / (12 (1 - ν²))` to
/// 1e-4 at `κ = 1/(200 t)` (geometric and Hencky nonlinearity ~1e-5 there); the 8 F-bar
/// layers are 0.7 % softer (F-bar's centre volume change in each layer drops part of the
/// bending energy).
#[test]
fn elastic_bending_moment_is_plate_theory() {
    let shell = bend(ElementKind::SolidShell, 1, true, 5);
    let fbar = bend(ElementKind::Hexahedron, 8, true, 5);
    let exact = 210e3 / (1.0 - 0.09) * shell.kappa[0] * T.powi(3) / 12.0;
    println!(
        "elastic: solid-shell {:.6}, F-bar {:.6}, plate theory {exact:.6}",
        -shell.moment[0], -fbar.moment[0]
    );
    assert!((-shell.moment[0] / exact - 1.0).abs() < 1e-4);
}

/// The 11-point thickness rule follows the elastic-plastic transition: with
/// `ACCURATE_THICKNESS_POINTS` (11) one layer's moment is within 1.5 % of the 8 F-bar layers'
/// at every loading increment, from the first (`R = 200 t`, where 5 points are 4.3 % off)
/// on, and within 1 % from `R = 50 t` on. Why 1.5 % in the transition: the 11-point rule is
/// within 1.1 % of the analytic moment-curvature there and the F-bar reference within
/// 0.23 % (docs/solid_shell_transition.py), so their difference may reach ~1.3 %.
#[test]
fn eleven_point_thickness_rule_follows_the_elastic_plastic_transition() {
    let shell = bend(ElementKind::SolidShell, 1, false, ACCURATE_THICKNESS_POINTS);
    let fbar = bend(ElementKind::Hexahedron, 8, false, 5);
    let five = bend(ElementKind::SolidShell, 1, false, 5);
    let mut worst_transition: f64 = 0.0;
    let mut worst_plastic: f64 = 0.0;
    for i in 0..STEPS / 2 {
        let d = shell.moment[i] / fbar.moment[i] - 1.0;
        println!(
            "κ {:.4}: {ACCURATE_THICKNESS_POINTS} points {:+.3} %, 5 points {:+.3} % against 8 F-bar layers",
            shell.kappa[i],
            100.0 * d,
            100.0 * (five.moment[i] / fbar.moment[i] - 1.0)
        );
        if shell.kappa[i] >= TRANSITION {
            worst_plastic = worst_plastic.max(d.abs());
        } else {
            worst_transition = worst_transition.max(d.abs());
        }
    }
    assert!(worst_transition < 0.015, "transition {worst_transition}");
    assert!(worst_plastic < 0.01, "plastic {worst_plastic}");
    // The 5-point default does not (the reason to offer 11).
    assert!((five.moment[0] / fbar.moment[0] - 1.0).abs() > 0.02);
}
