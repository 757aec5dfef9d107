//! The formability outputs of one coarse square cup (scripts/square_cup.rhai, paper variant,
//! 10 x 10 cells of 7.5 mm, 10 mm of punch travel) on four sheet models: the solid-shell
//! on `block()`, the solid-shell on the Gmsh quarter blank (tests/data/mesh/quarter_blank.msh,
//! the same cells numbered by Gmsh, its columns found from the topology), and F-bar
//! hexahedra with one and with four layers.
//!
//! * The imported blank is the block's discrete problem renumbered, so its summary equals
//!   the block's to the Newton tolerance (1e-9 relative on forces; measured 1e-13) and names
//!   the same places.
//! * One and four F-bar layers are one element with two through-thickness discretisations:
//!   on this mesh the peak punch force differs by 0.8 % between them, and the largest
//!   thinning and smallest FLC margin must differ by no more than a few times that (2.5 %),
//!   at the same place of the blank.
//! * The solid-shell against F-bar is the elements' own difference, not the outputs': F-bar
//!   hexahedra nine thicknesses long lock in bending (docs/solid-shell.md), the sheet does
//!   not wrap the punch radius, and on this mesh the punch force is 50 % higher and the
//!   largest thinning 9.1 % against the solid-shell's 3.6 %. What both must agree on is the
//!   worst zone reached (the flange's wrinkling tendency) and the largest thinning lying on
//!   the punch's side of the die radius, inside the die opening.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn run(tag: &str, extra: &[&str]) -> Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("tribo_form_cup_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tribo"));
    cmd.current_dir(root)
        .args(["run", "scripts/square_cup.rhai", "--quiet", "--out"])
        .arg(&out)
        .args([
            "--set",
            "cells=10",
            "--set",
            "travel=10.0",
            "--set",
            "charts=false",
        ]);
    for s in extra {
        cmd.args(["--set", s]);
    }
    if extra.iter().any(|s| s.starts_with("blank_mesh")) {
        cmd.args(["--allow-read", "tests/data/mesh"]);
    }
    let status = cmd.status().expect("tribo runs");
    assert!(status.success(), "square cup ({tag}) failed");
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let _ = std::fs::remove_dir_all(&out);
    let summary: Value = serde_json::from_str(&text).expect("summary.json is JSON");
    assert_eq!(summary["status"], "finished", "{tag}");
    summary
}

fn number(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The in-plane reference position of a summary place (`max_thinning_at`, ...): the column
/// is the same whatever its node numbers or layers.
fn place(f: &Value, key: &str) -> [f64; 2] {
    let r = &f[key]["reference"];
    [number(&r[0]), number(&r[1])]
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs())
}

#[test]
fn four_sheet_models_of_one_coarse_cup() {
    let ss = run("ss", &["element=\"solid_shell\""]);
    let gmsh = run(
        "gmsh",
        &[
            "element=\"solid_shell\"",
            "blank_mesh=\"../tests/data/mesh/quarter_blank.msh\"",
        ],
    );
    let fbar1 = run("fbar1", &["element=\"hexahedron\""]);
    let fbar4 = run("fbar4", &["element=\"hexahedron\"", "layers=4"]);
    let (fs, fg, f1, f4) = (
        &ss["formability"],
        &gmsh["formability"],
        &fbar1["formability"],
        &fbar4["formability"],
    );
    let thinning = |f: &Value| number(&f["max_thinning_pct"]);
    let margin = |f: &Value| number(&f["min_flc_margin"]);
    let peak = |s: &Value| number(&s["punch_force_peak_n"]);

    // The imported blank: the same answer, the same places.
    assert!(thinning(fs) > 1.0, "the cup thins: {fs}");
    assert!(relative(thinning(fs), thinning(fg)) < 1e-9, "{fs}\n{fg}");
    assert!(relative(margin(fs), margin(fg)) < 1e-9, "{fs}\n{fg}");
    for key in ["max_thinning_at", "min_flc_margin_at"] {
        let (a, b) = (place(fs, key), place(fg, key));
        assert!(
            (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9,
            "{key}: {a:?} {b:?}"
        );
    }
    assert_eq!(fs["nodes_per_zone"], fg["nodes_per_zone"]);
    assert_eq!(fs["flc"], fg["flc"]);

    // One and four F-bar layers: within a few times their own force difference.
    let force_difference = relative(peak(&fbar1), peak(&fbar4));
    assert!(force_difference < 0.02, "{force_difference}");
    for (what, a, b) in [
        ("max thinning", thinning(f1), thinning(f4)),
        ("min FLC margin", margin(f1), margin(f4)),
    ] {
        assert!(
            relative(a, b) < 0.025,
            "{what}: {a} (1 layer) vs {b} (4 layers)"
        );
    }
    for key in ["max_thinning_at", "min_flc_margin_at"] {
        assert_eq!(place(f1, key), place(f4, key), "{key}");
    }

    // Every model: the worst zone, and the thinnest place inside the die opening (74 mm
    // square: half 37 mm; the node rows are 7.5 mm apart, the next one out at 37.5 mm).
    for f in [fs, fg, f1, f4] {
        assert_eq!(f["worst_zone"], fs["worst_zone"], "{f}");
        let p = place(f, "max_thinning_at");
        assert!(p[0] < 37.0 && p[1] < 37.0, "{p:?}");
    }
}
