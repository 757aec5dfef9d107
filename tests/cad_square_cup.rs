//! The square cup (scripts/square_cup.rhai, coarse mesh) with the punch and die read from
//! the OpenCascade STEP exports (tests/data/cad) gives the built-in scene's answers: the
//! tools agree to 1e-11 mm (tests/cad_import.rs), so draw-in and punch force agree to the
//! Newton tolerance (1e-9 relative on forces); 1e-6 leaves room for different iterates.
//! The same cup on the Gmsh quarter blank gives the block() answers, and so does the cup
//! built wholly from imported geometry (STEP punch and die on the Gmsh blank).

use serde_json::Value;
use std::path::Path;
use std::process::Command;

fn run(tag: &str, extra: &[&str]) -> Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("tribo_cad_cup_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let status = Command::new(env!("CARGO_BIN_EXE_tribo"))
        .current_dir(root)
        .args(["run", "scripts/square_cup.rhai", "--quiet", "--out"])
        .arg(&out)
        .args(["--set", "travel=6.0", "--set", "charts=false"])
        .args(["--set", "element=\"hexahedron\""])
        .args(extra)
        .status()
        .expect("tribo runs");
    assert!(status.success(), "square cup ({tag}) failed");
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    let _ = std::fs::remove_dir_all(&out);
    serde_json::from_str(&text).expect("summary.json is JSON")
}

/// Asserts that two cup summaries have the same punch force peak and final draw-ins
/// (`dx`, `dy`, `dd`) to `rel` relative; the draw-ins of `a` must exceed `min_draw_in`
/// and its peak 1000 N, so that a run that did not draw cannot pass.
fn assert_same_cup(a: &Value, b: &Value, rel: f64, min_draw_in: f64) {
    let peak = |s: &Value| s["punch_force_peak_n"].as_f64().unwrap();
    let (pa, pb) = (peak(a), peak(b));
    assert!(pa > 1000.0, "{pa}");
    assert!((pa - pb).abs() <= rel * pa, "punch force peak {pa} vs {pb}");
    for key in ["dx", "dy", "dd"] {
        let d = |s: &Value| s["final_draw_in"][key].as_f64().unwrap();
        let (da, db) = (d(a), d(b));
        assert!(da > min_draw_in, "{key}: {da}");
        assert!((da - db).abs() <= rel * da, "draw-in {key}: {da} vs {db}");
    }
}

#[test]
fn cad_tools_give_the_built_in_draw_in_and_punch_force() {
    let builtin = run("builtin", &["--set", "cells=8"]);
    let cad = run(
        "step",
        &[
            "--set",
            "cells=8",
            "--set",
            "cad_tools=\"../tests/data/cad\"",
            "--allow-read",
            "tests/data/cad",
        ],
    );
    for s in [&builtin, &cad] {
        assert_eq!(s["status"], "finished", "{s}");
    }
    assert_same_cup(&builtin, &cad, 1e-6, 0.0);
}

/// The cup on the Gmsh quarter blank (tests/data/mesh/quarter_blank.msh: 75 x 75 x 0.81,
/// 10 x 10 x 1 hexahedra, written by Gmsh from tests/data/mesh/make_gmsh_fixtures.py) and on
/// `block()` with the same cells: the same discrete problem with the nodes numbered
/// otherwise, so the same iterations, and forces and draw-ins equal up to the round-off of
/// a different summation order (measured 1.2e-13 relative on the peak, 1.5e-14 on the
/// draw-in); 1e-9 is the Newton tolerance on forces.
#[test]
fn gmsh_blank_gives_the_block_draw_in_and_punch_force() {
    let cells = ["--set", "cells=10"];
    let block = run("block10", &cells);
    let gmsh = run(
        "gmsh10",
        &[
            cells[0],
            cells[1],
            "--set",
            "blank_mesh=\"../tests/data/mesh/quarter_blank.msh\"",
            "--allow-read",
            "tests/data/mesh",
        ],
    );
    for key in [
        "status",
        "nodes",
        "elements",
        "increments",
        "newton_iterations",
    ] {
        assert_eq!(block[key], gmsh[key], "{key}");
    }
    assert_eq!(block["nodes"], 2 * 11 * 11);
    assert_same_cup(&block, &gmsh, 1e-9, 0.1);
}

/// The cup built wholly from imported geometry: the STEP punch and die of
/// `cad_tools_give_the_built_in_draw_in_and_punch_force` on the Gmsh blank of
/// `gmsh_blank_gives_the_block_draw_in_and_punch_force`, against the built-in tools on
/// `block()` with the same cells. Both sources of difference are bounded above (tools to
/// 1e-11 mm, node numbering to round-off), so 1e-6 relative, as for the STEP tools alone.
#[test]
fn step_tools_on_the_gmsh_blank_give_the_built_in_cup() {
    let cells = ["--set", "cells=10"];
    let builtin = run("builtin10", &cells);
    let imported = run(
        "step_gmsh10",
        &[
            cells[0],
            cells[1],
            "--set",
            "blank_mesh=\"../tests/data/mesh/quarter_blank.msh\"",
            "--set",
            "cad_tools=\"../tests/data/cad\"",
            "--allow-read",
            "tests/data",
        ],
    );
    for s in [&builtin, &imported] {
        assert_eq!(s["status"], "finished", "{s}");
    }
    assert_eq!(builtin["nodes"], imported["nodes"]);
    assert_same_cup(&builtin, &imported, 1e-6, 0.1);
}
