//! The square cup's coarse mesh (8 x 8 x 1, 3 mm, both process variants) solved through
//! the condensed, displacement-only system (the default: every multiplier eliminated node
//! by node except at the symmetry planes, including the top-face nodes that both punch and
//! blankholder may touch) and through the mixed (u, lambda) system
//! (`eliminate_multipliers: false`): the same Newton iterations, the same forces and
//! draw-in. One linear system, two eliminations: each Newton step agrees to round-off
//! times the conditioning (1e-12 of the step on the two-roller drag, tests/condensation.rs).
//!
//! Bound 1e-9 of the largest force and draw-in (measured at 8 x 8 x 1: 5.7e-14 and 1.5e-14
//! on the paper variant, 4.4e-12 and 4.6e-15 on the benchmark variant): both runs take the
//! same iterations, so the converged states differ only by the accumulated round-off of
//! the steps, far below Newton's force tolerance (1e-9 of the reference force), which is
//! what a wrong right-hand side in the reduction would show; a wrong reduced Jacobian
//! would change the iteration counts, asserted equal.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs the cup script, with the multipliers eliminated or not (a copy of the script with
/// that setting added, next to the output).
fn run(variant: &str, eliminate: bool, out: &Path) -> Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(root.join("scripts/square_cup.rhai")).unwrap();
    let marker = "linear_solver: linear_solver,";
    assert!(source.contains(marker), "the cup script sets its linear solver");
    let source = source.replace(
        marker,
        &format!("{marker} eliminate_multipliers: {eliminate},"),
    );
    let _ = std::fs::remove_dir_all(out);
    let folder = out.with_extension("script");
    std::fs::create_dir_all(&folder).unwrap();
    let script = folder.join("square_cup.rhai");
    std::fs::write(&script, source).unwrap();
    let status = Command::new(env!("CARGO_BIN_EXE_tribo"))
        .arg("run")
        .arg(&script)
        .args(["--quiet", "--out"])
        .arg(out)
        .args(["--set", "cells=8", "--set", "travel=3.0", "--set"])
        .arg(format!("variant=\"{variant}\""))
        .status()
        .expect("tribo runs");
    assert!(status.success(), "square cup ({variant}, eliminate {eliminate}) failed");
    let _ = std::fs::remove_dir_all(&folder);
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

fn out_dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("tribo_condensed_cup_{name}_{}", std::process::id()))
}

/// Per increment: Newton iterations, and the tools' forces (x, y, z of punch, blankholder,
/// die) from history.csv.
fn history(out: &Path) -> Vec<(usize, Vec<f64>)> {
    let text = std::fs::read_to_string(out.join("history.csv")).expect("history.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let iterations = column("newton_iterations");
    let forces: Vec<usize> = ["punch", "blankholder", "die"]
        .iter()
        .flat_map(|t| ["x", "y", "z"].map(|c| column(&format!("{t}_force_{c}"))))
        .collect();
    lines
        .map(|line| {
            let v: Vec<&str> = line.split(',').collect();
            let f = forces.iter().map(|&k| v[k].parse().unwrap()).collect();
            (v[iterations].parse().unwrap(), f)
        })
        .collect()
}

#[test]
fn condensed_and_mixed_cups_agree() {
    for variant in ["paper", "benchmark"] {
        let (out_a, out_b) = (
            out_dir(&format!("{variant}_condensed")),
            out_dir(&format!("{variant}_mixed")),
        );
        let a = run(variant, true, &out_a);
        let b = run(variant, false, &out_b);
        let (ha, hb) = (history(&out_a), history(&out_b));
        assert_eq!(ha.len(), hb.len());
        let scale = hb
            .iter()
            .flat_map(|(_, f)| f)
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let mut worst_force = 0.0f64;
        for ((ia, fa), (ib, fb)) in ha.iter().zip(&hb) {
            assert_eq!(ia, ib, "{variant}: Newton iterations differ");
            for (x, y) in fa.iter().zip(fb) {
                worst_force = worst_force.max((x - y).abs() / scale);
            }
        }
        let (da, db) = (&a["final_draw_in"], &b["final_draw_in"]);
        let size = ["dx", "dy", "dd"]
            .iter()
            .fold(0.0f64, |m, k| m.max(db[k].as_f64().unwrap().abs()));
        assert!(size > 0.0, "{db}");
        let worst_draw_in = ["dx", "dy", "dd"]
            .iter()
            .map(|k| (da[k].as_f64().unwrap() - db[k].as_f64().unwrap()).abs() / size)
            .fold(0.0f64, f64::max);
        println!("{variant}: forces differ by {worst_force:.1e}, draw-in by {worst_draw_in:.1e}");
        // BOUND: see the module doc.
        assert!(worst_force < BOUND, "{variant}: forces differ by {worst_force:e}");
        assert!(worst_draw_in < BOUND, "{variant}: draw-in differs by {worst_draw_in:e}");
        let _ = std::fs::remove_dir_all(&out_a);
        let _ = std::fs::remove_dir_all(&out_b);
    }
}

const BOUND: f64 = 1e-9;
