//! The cylindrical cup script (`scripts/cylindrical_cup.rhai`, issue 17) run to 20 mm of
//! punch travel on its coarse default mesh (quarter O-grid blank, 4 core cells, 216
//! hexahedra, one layer; finite strain; the square cup's Newton budget: 100 iterations, 8
//! cutbacks), through the real command line. About 8 s of CPU per run.
//!
//! **Axisymmetry (isotropic material).** Issue 17 asks that the radial draw-in at 0 and 45
//! deg be equal to 1e-6. The tools are exact surfaces of revolution and the ring of the
//! O-grid is a polar grid on rays at equal angles, which a 45 deg turn maps onto itself; its
//! square core is not, so the discrete problem is not rotationally symmetric and the two
//! draw-ins differ by a discretisation error that grows with the core. Measured (isotropic,
//! 20 mm, 4 core cells, `tribo run scripts/cylindrical_cup.rhai --set core_size=A --set
//! round_radius=RT --set ring_cells=M`):
//!
//! | core half side A | round_radius RT | ring_cells M | d(0) | d(0) - d(45) |
//! | --- | --- | --- | --- | --- |
//! | 12 | 24 (transition under the nose) | 16 | 7.707 mm | -6.2e-3 mm |
//! | 12 | 18 | 16 | 7.498 mm | -9.5e-4 mm |
//! | 8 | 18 | 16 | 7.502 mm | -2.7e-4 mm |
//! | 4 | 10 | 20 | 7.501 mm | -6.1e-6 mm |
//! | 2 (default) | 5 | 22 | 7.605 mm | -4.9e-8 mm |
//!
//! With the core small and deep under the flat punch bottom (radius 20), the default mesh
//! meets the 1e-6 mm with a margin of 20, so this test asks exactly that. It also
//! checks what is exact: the mesh, the tools and the material are mirror-symmetric about
//! the diagonal, so d(0) = d(90) to Newton's tolerance (1e-9).
//!
//! **Ears (Hill48, r0 = r90 = 2, r45 = 1).** Delta r = (r0 + r90 - 2 r45)/2 = 1 > 0: the
//! flange draws in less at 0 and 90 deg than at 45 deg (ears at 0/90); measured -4.30 mm.
//! The test asks the ear amplitude (d(0) + d(90))/2 - d(45) to be below -1 mm: 10^6 times
//! the isotropic bound, and a quarter of the measured value.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// |d(0) - d(45)| allowed for the isotropic material on the default mesh [mm].
const ISOTROPIC_BOUND_MM: f64 = 1e-6;

fn run(name: &str, sets: &[&str]) -> Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out: PathBuf = std::env::temp_dir().join(format!(
        "tribo_cylindrical_cup_{name}_{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&out);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tribo"));
    cmd.current_dir(root)
        .args(["run", "scripts/cylindrical_cup.rhai", "--quiet", "--out"])
        .arg(&out)
        .args(["--set", "charts=false"]);
    for s in sets {
        cmd.args(["--set", s]);
    }
    assert!(
        cmd.status().expect("tribo runs").success(),
        "cylindrical cup {sets:?} failed"
    );
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let _ = std::fs::remove_dir_all(&out);
    serde_json::from_str(&text).expect("summary.json is JSON")
}

fn number(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("summary has no number '{key}': {v}"))
}

/// The run reached 20 mm, is in vertical equilibrium, dissipates by friction, drew the
/// flange in, and is mirror-symmetric about the diagonal; returns the final draw-in map.
fn common_checks(summary: &Value) -> &Value {
    assert_eq!(summary["status"], "finished", "{summary}");
    assert!((number(summary, "time") - 20.0).abs() < 1e-9);
    let checks = &summary["checks"];
    assert!(number(checks, "vertical_force_balance") < 1e-6, "{checks}");
    assert!(number(checks, "frictional_work_min") >= 0.0, "{checks}");
    let draw = &summary["final_draw_in"];
    let (d0, d90) = (number(draw, "d0"), number(draw, "d90"));
    assert!(d0 > 3.0, "the flange was not drawn in: {draw}");
    assert!(
        (d0 - d90).abs() < 1e-9 * d0.max(1.0),
        "diagonal mirror: {draw}"
    );
    // The rim profile runs from 0 to 90 deg, one entry per rim node on the bottom face.
    let profile = summary["rim_draw_in"].as_array().expect("rim_draw_in");
    assert_eq!(profile.len(), 9);
    assert!(number(&profile[0], "angle_deg").abs() < 1e-9);
    assert!((number(&profile[8], "angle_deg") - 90.0).abs() < 1e-9);
    draw
}

#[test]
fn isotropic_cup_is_axisymmetric_to_the_core_discretisation() {
    let summary = run("isotropic", &[]);
    let draw = common_checks(&summary);
    let gap = number(draw, "d0") - number(draw, "d45");
    assert!(
        gap.abs() < ISOTROPIC_BOUND_MM,
        "d(0) - d(45) = {gap} mm: {draw}"
    );
    // The force peak of a full cup of this steel: wall stress = F / (2 pi r_wall t) must
    // stay below the Swift flow stress at the strains reached (about 600 MPa).
    let peak = number(&summary, "punch_force_peak_n");
    let wall_stress = peak / (2.0 * std::f64::consts::PI * 25.5 * 1.0);
    assert!(
        wall_stress > 100.0 && wall_stress < 600.0,
        "{wall_stress} MPa"
    );
}

#[test]
fn hill48_cup_has_ears_at_0_and_90_degrees() {
    let summary = run("hill48", &["yield_kind=\"hill48\""]);
    let draw = common_checks(&summary);
    let ears = number(draw, "ears");
    assert!(
        ears < -1e6 * ISOTROPIC_BOUND_MM,
        "ear amplitude {ears} mm (isotropic bound {ISOTROPIC_BOUND_MM}): {draw}"
    );
}

/// The whole blank (its in-plane rigid motion held by the axis column and one rim node)
/// and the quarter model (symmetry planes `"x-"`, `"y-"`) are the same discrete problem
/// restricted by symmetry: the full cup's punch force and draw-in equal the quarter's to
/// Newton's tolerance. Measured at 3 mm: equal to 1e-15.
#[test]
fn whole_blank_equals_the_quarter_model() {
    let quarter = run("quarter_2mm", &["travel=2"]);
    let whole = run("whole_2mm", &["travel=2", "quarter=false"]);
    for s in [&quarter, &whole] {
        assert_eq!(s["status"], "finished", "{s}");
    }
    let (fq, fw) = (
        number(&quarter, "punch_force_peak_n"),
        number(&whole, "punch_force_peak_n"),
    );
    assert!(fq > 0.0 && (fq - fw).abs() < 1e-8 * fq, "{fq} vs {fw}");
    for key in ["d0", "d45", "d90"] {
        let (a, b) = (
            number(&quarter["final_draw_in"], key),
            number(&whole["final_draw_in"], key),
        );
        assert!((a - b).abs() < 1e-9, "{key}: {a} vs {b}");
    }
}
