//! Formability outputs (issue 48): through-thickness columns of imported blanks, and the
//! frame fields `thickness`, `thinning`, `major_strain`, `minor_strain`, `strain_ratio`,
//! `flc_margin`, `formability` under homogeneous stretching at finite strain.

use std::sync::Arc;

use tribo::element::{ElementKind, StrainTheory};
use tribo::geometry::Vec3;
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};
use tribo::mesh::gmsh::read_gmsh;
use tribo::mesh::Mesh;
use tribo::output::formability::{self, FormabilityOptions, Zone};
use tribo::output::{Configuration, Frame};
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

fn fixture(name: &str) -> Mesh {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/mesh")
        .join(name);
    read_gmsh(&std::fs::read(&path).unwrap(), name).unwrap()
}

/// The columns as lists of reference positions, sorted, so that two numberings compare.
fn column_positions(mesh: &Mesh) -> Vec<Vec<[f64; 3]>> {
    let mut cols: Vec<Vec<[f64; 3]>> = (mesh.columns().iter())
        .map(|c| c.iter().map(|&n| mesh.nodes[n].into()).collect())
        .collect();
    cols.sort_by(|a, b| a.partial_cmp(b).unwrap());
    cols
}

/// The Gmsh box (written by Gmsh, its own element numbering) has the block's columns: the
/// same nodes bottom to top (positions are exact in the file: multiples of 0.5).
#[test]
fn imported_gmsh_blank_has_the_blocks_columns() {
    let imported = fixture("block_4x2x2.msh");
    let block = Mesh::block(Vec3::zeros(), Vec3::new(4.0, 2.0, 1.0), [4, 2, 2]).unwrap();
    assert_eq!(imported.columns().len(), 15);
    assert_eq!(column_positions(&imported), column_positions(&block));
    tribo::element::solid_shell::check_columns(&imported).expect("elements stand in columns");
    let quarter = fixture("quarter_blank.msh");
    assert_eq!(quarter.columns().len(), 121);
    assert!(quarter.columns().iter().all(|c| c.len() == 2));
}

fn field<'a>(frame: &'a Frame, name: &str) -> &'a [f64] {
    &(frame.point_data.iter())
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("no field {name}"))
        .values
}

/// The NUMISHEET'93 quarter blank from Gmsh (one layer) stretched 10 % along x with the
/// solid-shell: it runs, and its frame carries thickness and the formability fields,
/// the thickness equal to the column length measured from the nodes.
#[test]
fn imported_one_layer_blank_runs_with_the_solid_shell() {
    let mesh = fixture("quarter_blank.msh");
    let material = ElastoPlastic::new(
        LinearElastic::new(210e3, 0.3).unwrap(),
        Hill48::von_mises(),
        Hardening::swift(565.0, 0.007, 0.26).unwrap(),
    );
    let mut model = Model::new(mesh, Arc::new(material)).unwrap();
    model.settings.element = ElementKind::SolidShell;
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.increments = 2;
    for (set, c) in [("x-", "x"), ("y-", "y")] {
        model
            .prescribe(set, c, ScalarSchedule::constant(0.0))
            .unwrap();
    }
    model
        .prescribe("origin", "z", ScalarSchedule::constant(0.0))
        .unwrap();
    let ramp = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 7.5)]).unwrap();
    model.prescribe("x+", "x", ramp).unwrap();
    let mut sim = Simulation::new(model).unwrap();
    while !sim.is_finished() {
        sim.step().unwrap();
    }
    let frame = tribo::output::frame(&sim, Configuration::Current);
    let thickness = field(&frame, "thickness");
    let mesh = &sim.model.mesh;
    let u = sim.displacements();
    for col in mesh.columns() {
        let at = |n: usize| mesh.nodes[n] + Vec3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2]);
        let t = (at(col[1]) - at(col[0])).norm();
        assert!((thickness[col[0]] - t).abs() < 1e-12 * t);
        assert!(t < 0.81, "the stretched sheet thins ({t})");
    }
    // A homogeneous uniaxial stretch: the imposed log strain at every node, to the
    // Newton tolerance's effect on the positions (1e-6 of the 7.5 travel, well above it).
    let major = field(&frame, "major_strain");
    assert!(
        major.iter().all(|&e| (e - 0.1_f64.ln_1p()).abs() < 1e-6),
        "{:?}",
        &major[..4]
    );
    for name in [
        "thinning",
        "minor_strain",
        "strain_ratio",
        "flc_margin",
        "formability",
    ] {
        field(&frame, name);
    }
}

/// The three stretches of the issue: x+ pulled to `l1`, y+ free (uniaxial), held (plane
/// strain) or pulled alike (equibiaxial); symmetry planes x-, y-, z-; the top free.
#[derive(Clone, Copy, Debug)]
enum Path {
    Uniaxial,
    PlaneStrain,
    Equibiaxial,
}

/// A 2 x 2 x 1 sheet (1 x 1 x 0.2) of `material` stretched along `path` to the log strain
/// `strain` in `increments` (finite strain, F-bar); the frames after each increment.
fn stretch(
    material: ElastoPlastic,
    path: Path,
    strain: f64,
    increments: usize,
) -> Vec<(Frame, Vec<f64>)> {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 0.2), [2, 2, 1]).unwrap();
    let mut model = Model::new(mesh, Arc::new(material)).unwrap();
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.increments = increments;
    model.settings.force_rel_tol = 1e-12;
    for (set, c) in [("x-", "x"), ("y-", "y"), ("z-", "z")] {
        model
            .prescribe(set, c, ScalarSchedule::constant(0.0))
            .unwrap();
    }
    let ramp = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, strain.exp_m1())]).unwrap();
    model.prescribe("x+", "x", ramp.clone()).unwrap();
    match path {
        Path::Uniaxial => {}
        Path::PlaneStrain => model
            .prescribe("y+", "y", ScalarSchedule::constant(0.0))
            .unwrap(),
        Path::Equibiaxial => model.prescribe("y+", "y", ramp).unwrap(),
    }
    let mut sim = Simulation::new(model).unwrap();
    let mut frames = Vec::new();
    while !sim.is_finished() {
        sim.step().unwrap();
        let frame = tribo::output::frame(&sim, Configuration::Current);
        frames.push((frame, sim.displacements().to_vec()));
    }
    frames
}

fn steel(r: Option<(f64, f64, f64)>) -> ElastoPlastic {
    let yield_function = match r {
        Some((r0, r45, r90)) => Hill48::from_lankford(r0, r45, r90).unwrap(),
        None => Hill48::von_mises(),
    };
    ElastoPlastic::new(
        LinearElastic::new(210e3, 0.3).unwrap(),
        yield_function,
        Hardening::swift(565.0, 0.007, 0.26).unwrap(),
    )
}

/// Homogeneous stretching at finite strain (log strain 0.3 along x), von Mises and Hill48:
/// at every node `major_strain`, `minor_strain` are the logarithms of the stretches (the
/// imposed one, and the free one measured from the nodes), `thinning` is
/// `100 (1 - t / t0)` of the thickness measured from the nodes, to 1e-8 (the
/// deformation is homogeneous, so the corner formula of the mid-surface is exact; what
/// remains is round-off of strains of 0.3 through logarithms, ~1e-15).
#[test]
fn homogeneous_stretching_gives_the_logs_of_the_stretches() {
    let (l1, t0) = (0.3_f64.exp(), 0.2);
    for r in [None, Some((0.7, 1.3, 2.1))] {
        for path in [Path::Uniaxial, Path::PlaneStrain, Path::Equibiaxial] {
            let frames = stretch(steel(r), path, 0.3, 6);
            let (frame, u) = frames.last().unwrap();
            // Node 8 is the corner (1, 1, 0) of the 3 x 3 x 2 nodes; node 17 above it.
            let l2 = 1.0 + u[3 * 8 + 1];
            let t = t0 + u[3 * 17 + 2] - u[3 * 8 + 2];
            let (e1, e2) = (l1.ln().max(l2.ln()), l1.ln().min(l2.ln()));
            match path {
                Path::Uniaxial => assert!(l2 < 1.0),
                Path::PlaneStrain => assert_eq!(l2, 1.0),
                Path::Equibiaxial => assert!((l2 - l1).abs() < 1e-12),
            }
            let (major, minor) = (field(frame, "major_strain"), field(frame, "minor_strain"));
            let thinning = field(frame, "thinning");
            let ratio = field(frame, "strain_ratio");
            for n in 0..major.len() {
                let at = format!("{r:?} {path:?} node {n}");
                assert!(
                    (major[n] - e1).abs() < 1e-8,
                    "{at}: major {} against {e1}",
                    major[n]
                );
                assert!(
                    (minor[n] - e2).abs() < 1e-8,
                    "{at}: minor {} against {e2}",
                    minor[n]
                );
                let want = 100.0 * (1.0 - t / t0);
                assert!(
                    (thinning[n] - want).abs() < 1e-8,
                    "{at}: thinning {} against {want}",
                    thinning[n]
                );
                assert!((ratio[n] - e2 / e1).abs() < 1e-8, "{at}");
            }
        }
    }
}

/// Hill48 uniaxial tension along the rolling direction in the plastic range: the change
/// of `minor_strain` over the change of the thickness strain `ln(1 - thinning/100)`
/// between two plastic states is r0. Tolerance 1 %: the ratio is r0 for the plastic
/// strains; the elastic strains change with the stress (Swift hardening from 0.15 to 0.3
/// raises it by ~90 MPa, an elastic strain change of ~4e-4) against plastic changes of
/// ~0.06 and ~0.09.
#[test]
fn hill48_uniaxial_width_to_thickness_strain_ratio_is_r() {
    let r0 = 0.7;
    let frames = stretch(steel(Some((r0, 1.3, 2.1))), Path::Uniaxial, 0.3, 6);
    let at = |k: usize| {
        let f = &frames[k].0;
        let thickness_strain = (1.0 - field(f, "thinning")[0] / 100.0).ln();
        (field(f, "minor_strain")[0], thickness_strain)
    };
    let ((w1, t1), (w2, t2)) = (at(2), at(5));
    let r = (w2 - w1) / (t2 - t1);
    assert!((r - r0).abs() < 0.01 * r0, "r = {r}, input {r0}");
}

/// The zones on a stretched sheet: the Keeler-Brazier curve of the Swift exponent (0.26)
/// and the 0.2 mm sheet sits at ln(1 + 0.26 (23.3 + 2.826) / 21) = 0.28 in plane strain, so
/// plane strain to 0.3 is beyond it: every node is in the crack zone with the margin of
/// the curve, while at 0.05 (the first increment) the sheet is safe or at risk.
#[test]
fn plane_strain_beyond_the_curve_is_a_crack() {
    let frames = stretch(steel(None), Path::PlaneStrain, 0.3, 6);
    let flc = formability::Flc::keeler_brazier(0.26, 0.2).unwrap();
    let (last, _) = frames.last().unwrap();
    let margin = field(last, "flc_margin");
    let zone = field(last, "formability");
    let major = field(last, "major_strain");
    for n in 0..margin.len() {
        assert!((margin[n] - flc.margin(major[n], 0.0)).abs() < 1e-12);
        assert!(margin[n] < 0.0);
        assert_eq!(zone[n], Zone::Crack.code() as f64);
    }
    let first = field(&frames[0].0, "formability");
    assert!(first
        .iter()
        .all(|&z| z == Zone::RiskOfCrack.code() as f64 || z == Zone::Safe.code() as f64));
    let _ = FormabilityOptions::default();
}

/// Through the script layer: a sheet pulled in plane strain with an FLC table and a
/// thinning limit from the settings; summary.json's `formability` names the largest
/// thinning and smallest margin where the frame has them, counts every node in one zone,
/// and reports the table; the FLD and thinning map are written under 200 kB.
#[test]
fn summary_and_charts_of_a_scripted_stretch() {
    let dir = std::env::temp_dir().join(format!("tribo-formability-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("stretch.rhai");
    std::fs::write(
        &script,
        r#"
let mesh = block([0.0, 0.0, 0.0], [10.0, 10.0, 1.0], [4, 4, 1]);
let sim = simulation(mesh, elastoplastic(210000.0, 0.3, von_mises(), swift(565.0, 0.007, 0.26)));
sim.fix("x-", "x");
sim.fix("y-", "y");
sim.fix("y+", "y");
sim.fix("z-", "z");
sim.prescribe("x+", "x", [[0.0, 0.0], [1.0, 2.0]]);
sim.settings(#{ end_time: 1.0, increments: 4, kinematics: "finite",
                flc: [[-0.2, 0.35], [0.0, 0.15], [0.2, 0.3]], thinning_limit: 10.0 });
sim.run();
sim.chart_fld("fld.svg");
sim.chart_field("thinning.svg", "z+", "thinning");
"#,
    )
    .unwrap();
    let host = tribo::script::HostOptions {
        out_dir: dir.join("out"),
        ..tribo::script::HostOptions::default()
    };
    tribo::script::run_file(&script, &[], &host).unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
            .unwrap();
    let f = &summary["formability"];
    // Plane strain to ln(1.2) = 0.18 > 0.15: every column beyond the table's curve.
    assert_eq!(f["worst_zone"], "crack", "{f}");
    assert_eq!(f["nodes_per_zone"]["crack"], 50, "{f}");
    let total: u64 = (f["nodes_per_zone"].as_object().unwrap().values())
        .map(|v| v.as_u64().unwrap())
        .sum();
    assert_eq!(total, 50);
    assert_eq!(f["flc"]["kind"], "table");
    let margin = f["min_flc_margin"].as_f64().unwrap();
    assert!((margin - (0.15 - 1.2_f64.ln())).abs() < 1e-6, "{margin}");
    let thinning = f["max_thinning_pct"].as_f64().unwrap();
    assert!(thinning > 10.0 && thinning < 20.0, "{thinning}");
    assert!(f["max_thinning_at"]["node"].is_u64());
    for chart in ["fld.svg", "fld.csv", "thinning.svg", "thinning.csv"] {
        let size = std::fs::metadata(dir.join("out").join(chart))
            .unwrap()
            .len();
        assert!(size > 0 && size < 200_000, "{chart}: {size} bytes");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Keeler-Brazier reads the thickness in mm (module doc of output::formability): a sheet
/// modelled in metres with `units: #{ length: "m" }` gets the curve of its thickness in mm,
/// the same curve as the same sheet in mm; a unit it cannot convert gives no curve, and
/// summary.json says why.
#[test]
fn keeler_brazier_reads_the_thickness_in_the_scripts_length_unit() {
    let dir = std::env::temp_dir().join(format!("tribo-flc-units-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = |tag: &str, scale: f64, unit: &str| -> serde_json::Value {
        let script = dir.join(format!("{tag}.rhai"));
        let units = if unit.is_empty() {
            String::new()
        } else {
            format!("units: #{{ length: \"{unit}\" }},")
        };
        std::fs::write(
            &script,
            format!(
                r#"
let s = {scale:?};
let mesh = block([0.0, 0.0, 0.0], [10.0 * s, 10.0 * s, 0.8 * s], [2, 2, 1]);
let sim = simulation(mesh, elastoplastic(210000.0, 0.3, von_mises(), swift(565.0, 0.007, 0.26)));
sim.fix("x-", "x");
sim.fix("y-", "y");
sim.fix("z-", "z");
sim.prescribe("x+", "x", [[0.0, 0.0], [1.0, 0.5 * s]]);
sim.settings(#{{ end_time: 1.0, increments: 1, kinematics: "finite", {units} }});
sim.run();
"#
            ),
        )
        .unwrap();
        let out = dir.join(tag);
        let host = tribo::script::HostOptions {
            out_dir: out.clone(),
            ..tribo::script::HostOptions::default()
        };
        tribo::script::run_file(&script, &[], &host).unwrap();
        let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()["formability"]["flc"].clone()
    };
    let mm = run("mm", 1.0, "");
    let metres = run("m", 1e-3, "m");
    assert_eq!(mm["kind"], "Keeler-Brazier (NADDRG)", "{mm}");
    let t = |f: &serde_json::Value| f["thickness_mm"].as_f64().unwrap();
    assert!((t(&mm) - 0.8).abs() < 1e-12, "{mm}");
    assert!((t(&metres) - 0.8).abs() < 1e-12, "{metres}");
    let flc0 = |f: &serde_json::Value| f["flc0_true"].as_f64().unwrap();
    assert!((flc0(&mm) - flc0(&metres)).abs() < 1e-12);
    let unknown = run("furlong", 1.0, "furlong");
    assert_eq!(unknown["kind"], "none", "{unknown}");
    let reason = unknown["reason"].as_str().unwrap();
    assert!(
        reason.contains("'furlong'") && reason.contains("flc"),
        "{reason}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
