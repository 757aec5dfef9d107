//! The solid-shell's face and mid-surface values in the VTK frames (issue 15;
//! `src/output/shell_layers.rs`): written, read back, and compared with the element's own
//! integration-point values at the first, middle and last thickness levels.

use std::sync::Arc;

use tribo::element::{ElementKind, StrainTheory};
use tribo::geometry::Vec3;
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic, PointState};
use tribo::mesh::Mesh;
use tribo::output::{frame, read_vtu, write_vtu, Configuration, Field};
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

const T: f64 = 1.0;
const LENGTH: f64 = 0.25;
/// Bending radius at the end: 20 thicknesses (surface strain 2.5 %, yield strain ~0.1 %).
const KAPPA: f64 = 0.05 / T;

fn steel() -> ElastoPlastic {
    ElastoPlastic::new(
        LinearElastic::new(210e3, 0.3).unwrap(),
        Hill48::from_lankford(1.0, 1.0, 1.0).unwrap(),
        Hardening::swift(500.0, 0.01, 0.22).unwrap(),
    )
}

/// A plane-strain strip of 2 x 1 x 1 solid-shells bent plastically to `R = 20 t` (end face
/// turned about the centre of curvature, as in tests/solid_shell_bending.rs), finite strain.
fn bent_strip(points: usize) -> Simulation {
    let mut mesh = Mesh::block(
        Vec3::new(0.0, 0.0, -T / 2.0),
        Vec3::new(LENGTH, LENGTH / 2.0, T),
        [2, 1, 1],
    )
    .unwrap();
    for (k, z) in [-T / 2.0, T / 2.0].iter().enumerate() {
        let set = mesh.select_nodes(|p| (p.x - LENGTH).abs() < 1e-12 && (p.z - z).abs() < 1e-9);
        mesh.add_node_set(&format!("end{k}"), set).unwrap();
    }
    let base = mesh.select_nodes(|p| p.x.abs() < 1e-12 && (p.z + T / 2.0).abs() < 1e-9);
    mesh.add_node_set("base", base).unwrap();
    let mut model = Model::new(mesh, Arc::new(steel())).unwrap();
    for (set, c) in [("x-", "x"), ("y-", "y"), ("y+", "y"), ("base", "z")] {
        model
            .prescribe(set, c, ScalarSchedule::constant(0.0))
            .unwrap();
    }
    for (k, z) in [-T / 2.0, T / 2.0].iter().enumerate() {
        let u = (1.0 / KAPPA - z) * (KAPPA * LENGTH).sin() - LENGTH;
        let ramp = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, u)]).unwrap();
        model.prescribe(&format!("end{k}"), "x", ramp).unwrap();
    }
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.element = ElementKind::SolidShell;
    model.settings.thickness_points = points;
    model.settings.increments = 5;
    model.settings.force_rel_tol = 1e-10;
    let mut sim = Simulation::new(model).unwrap();
    while !sim.is_finished() {
        sim.step().unwrap();
    }
    sim
}

fn field<'a>(fields: &'a [Field], name: &str) -> &'a Field {
    fields
        .iter()
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("no cell field {name}"))
}

/// The written frame, read back from its file.
fn written(sim: &Simulation, tag: &str) -> Vec<Field> {
    let dir = std::env::temp_dir().join(format!("tribo-shell-output-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("frame.vtu");
    write_vtu(&path, &frame(sim, Configuration::Current)).unwrap();
    let back = read_vtu(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    back.cell_data
}

/// Mean over the in-plane points of element `e` at the thickness levels `levels`.
fn level_mean(
    sim: &Simulation,
    e: usize,
    levels: &[usize],
    value: impl Fn(&PointState) -> f64,
) -> f64 {
    let n = sim.model.settings.thickness_points;
    let pts: Vec<&PointState> = levels
        .iter()
        .flat_map(|&k| &sim.points()[4 * (n * e + k)..4 * (n * e + k + 1)])
        .collect();
    pts.iter().map(|p| value(p)).sum::<f64>() / pts.len() as f64
}

/// With 5 points (Newton-Cotes, levels at ζ = -1, -½, 0, ½, 1) the bottom, mid and top
/// fields are the in-plane means of levels 0, 2 and 4 of each element (to 1e-12 relative:
/// the same sums in another order; the file holds Float64 bit for bit); they are at
/// ζ = -1, 0, 1. The physics: the faces are plastic with opposite axial stresses, the
/// mid-surface elastic (its axial stress under 5 % of the faces').
#[test]
fn face_and_mid_values_are_the_first_middle_and_last_levels() {
    let sim = bent_strip(5);
    let cells = written(&sim, "five");
    for (face, level, zeta) in [("bottom", 0, -1.0), ("mid", 2, 0.0), ("top", 4, 1.0)] {
        let stress = field(&cells, &format!("shell_{face}_stress"));
        assert_eq!(stress.components, 6);
        assert_eq!(stress.component_names, ["xx", "yy", "zz", "xy", "yz", "xz"]);
        let plastic = field(&cells, &format!("shell_{face}_equivalent_plastic_strain"));
        let at = field(&cells, &format!("shell_{face}_zeta"));
        for e in 0..2 {
            assert_eq!(at.values[e], zeta);
            let scale = level_mean(&sim, e, &[level], |p| p.stress.norm());
            for i in 0..6 {
                let want = level_mean(&sim, e, &[level], |p| p.stress[i]);
                let got = stress.values[6 * e + i];
                assert!(
                    (got - want).abs() <= 1e-12 * scale,
                    "{face} {e} {i}: {got} vs {want}"
                );
            }
            let want = level_mean(&sim, e, &[level], |p| p.eq_plastic_strain);
            assert!((plastic.values[e] - want).abs() <= 1e-15, "{face} {e}");
        }
    }
    let sxx = |face: &str, e: usize| field(&cells, &format!("shell_{face}_stress")).values[6 * e];
    let eqp = |face: &str, e: usize| {
        field(&cells, &format!("shell_{face}_equivalent_plastic_strain")).values[e]
    };
    for e in 0..2 {
        println!(
            "element {e}: sxx bottom {:.2} mid {:.3} top {:.2} MPa; eq. plastic strain {:.5} {:.5} {:.5}",
            sxx("bottom", e),
            sxx("mid", e),
            sxx("top", e),
            eqp("bottom", e),
            eqp("mid", e),
            eqp("top", e)
        );
        assert!(sxx("bottom", e) > 100.0 && sxx("top", e) < -100.0);
        assert!(sxx("mid", e).abs() < 0.05 * sxx("bottom", e));
        assert!(eqp("bottom", e) > 0.01 && eqp("top", e) > 0.01);
        assert_eq!(eqp("mid", e), 0.0);
        // A plastic face is on the yield surface: its von Mises stress is the Swift flow
        // stress of its plastic strain (to 1 %: the Cauchy against the log-strain
        // conjugate stress, det F - 1 ~ 1e-3, and the spread of the 4 in-plane points).
        for face in ["bottom", "top"] {
            let mises = field(&cells, &format!("shell_{face}_von_mises")).values[e];
            let flow = 500.0 * (0.01 + eqp(face, e)).powf(0.22);
            assert!(
                (mises / flow - 1.0).abs() < 0.01,
                "{face}: {mises} vs {flow}"
            );
        }
    }
}

/// With 4 (Gauss) points none is on a face: bottom and top are the outermost levels as they
/// are, mid the mean of levels 1 and 2, and the ζ fields say so.
#[test]
fn even_rule_writes_the_outermost_and_the_two_middle_levels() {
    let sim = bent_strip(4);
    let cells = written(&sim, "four");
    let outer = 0.861_136_311_594_052_6;
    for (face, levels, zeta) in [
        ("bottom", vec![0], -outer),
        ("mid", vec![1, 2], 0.0),
        ("top", vec![3], outer),
    ] {
        let at = field(&cells, &format!("shell_{face}_zeta")).values[0];
        assert!((at - zeta).abs() < 1e-14, "{face}: {at}");
        let stress = field(&cells, &format!("shell_{face}_stress"));
        for e in 0..2 {
            let want = level_mean(&sim, e, &levels, |p| p.stress[0]);
            assert!((stress.values[6 * e] - want).abs() <= 1e-12 * want.abs().max(1.0));
        }
    }
}

/// A plate stretched in plane by 10 % (uniaxial, free to thin), Hill48-plastic: every
/// level's thickness strain `N · ε · N` equals `ln(t / t0)` of the written element thickness
/// (a homogeneous state: exact but for the Newton tolerance), and `t` is the nodes'.
#[test]
fn thickness_strain_at_the_levels_matches_the_element_thickness() {
    let t0 = 0.8;
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 1.0, t0), [2, 1, 1]).unwrap();
    let mut model = Model::new(mesh, Arc::new(steel())).unwrap();
    for (set, c) in [("x-", "x"), ("y-", "y"), ("z-", "z")] {
        model
            .prescribe(set, c, ScalarSchedule::constant(0.0))
            .unwrap();
    }
    model
        .prescribe(
            "x+",
            "x",
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 0.2)]).unwrap(),
        )
        .unwrap();
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.element = ElementKind::SolidShell;
    model.settings.increments = 4;
    model.settings.force_rel_tol = 1e-11;
    let mut sim = Simulation::new(model).unwrap();
    while !sim.is_finished() {
        sim.step().unwrap();
    }
    let cells = written(&sim, "stretch");
    let top_node = sim.model.nodes("z+").unwrap()[0];
    let t_nodes = t0 + sim.displacement(top_node).z;
    for e in 0..2 {
        let t = field(&cells, "shell_thickness").values[e];
        assert!((t - t_nodes).abs() < 1e-12, "{t} vs {t_nodes}");
        assert!(t < 0.97 * t0, "the plate thins: {t}");
        for face in ["bottom", "mid", "top"] {
            let strain = field(&cells, &format!("shell_{face}_thickness_strain")).values[e];
            assert!(
                (strain - (t / t0).ln()).abs() < 1e-8,
                "{face} {e}: {strain} vs {}",
                (t / t0).ln()
            );
        }
    }
}

/// A hexahedron model writes no shell fields: only the hexahedron's own four.
#[test]
fn hexahedron_models_write_no_shell_fields() {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 0.1), [1, 1, 1]).unwrap();
    let model = Model::new(mesh, Arc::new(LinearElastic::new(1.0, 0.0).unwrap())).unwrap();
    let sim = Simulation::new(model).unwrap();
    let f = frame(&sim, Configuration::Reference);
    let names: Vec<&str> = f.cell_data.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "stress",
            "von_mises",
            "equivalent_stress",
            "equivalent_plastic_strain"
        ]
    );
}
