//! The NUMISHEET'93 square cup script (`scripts/square_cup.rhai`), run on a coarse mesh for
//! the first millimetres of punch travel in both process variants, through the real command
//! line. The script writes its own checks into summary.json; this test holds them to
//! bounds that follow from the discrete problem:
//!
//! - vertical force balance: the symmetry planes hold only x and y, so punch, blankholder and
//!   die forces cancel along z up to Newton's force tolerance (1e-9 relative): < 1e-6;
//! - quarter symmetry about the diagonal x = y: the mesh, the tools and the isotropic
//!   material are symmetric, so the converged displacements are, up to the same tolerance
//!   times the compliance: < 1e-6 of the largest displacement;
//! - frictional work >= 0 at every node (it only grows by lambda_t . delta_t >= 0), and mu
//!   within the law's control points: [0.01, 0.16] for the paper's Bernstein curve, 0.162 for
//!   the benchmark's Coulomb friction;
//! - the benchmark's blankholder, under force control, carries 4 x 4.9 kN on the full cup.

mod common;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn run_cup(variant: &str, out: &Path) -> Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let status = Command::new(env!("CARGO_BIN_EXE_tribo"))
        .current_dir(root)
        .args(["run", "scripts/square_cup.rhai", "--quiet", "--out"])
        .arg(out)
        .args(["--set", "cells=8", "--set", "travel=3.0"])
        .args(["--set", "element=\"hexahedron\"", "--set"])
        .arg(format!("variant=\"{variant}\""))
        .status()
        .expect("tribo runs");
    assert!(status.success(), "square cup ({variant}) failed");
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tribo_square_cup_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn number(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("summary has no number '{key}': {v}"))
}

fn common_checks(summary: &Value, mu_range: (f64, f64)) {
    assert_eq!(summary["status"], "finished", "{summary}");
    let checks = &summary["checks"];
    assert!(number(checks, "vertical_force_balance") < 1e-6, "{checks}");
    assert!(number(checks, "diagonal_asymmetry") < 1e-6, "{checks}");
    assert!(number(checks, "frictional_work_min") >= 0.0, "{checks}");
    assert!(
        number(checks, "frictional_work_max") > 0.0,
        "no sliding at all: {checks}"
    );
    assert!(number(checks, "mu_min") >= mu_range.0 - 1e-12, "{checks}");
    assert!(number(checks, "mu_max") <= mu_range.1 + 1e-12, "{checks}");
    assert!(number(summary, "punch_force_peak_n") > 0.0);
    assert!(summary["draw_in"].as_array().is_some());
}

#[test]
fn paper_variant_first_millimetres() {
    let out = out_dir("paper");
    let summary = run_cup("paper", &out);
    common_checks(&summary, (0.01, 0.16));
    // The Bernstein curve has started to soften where the sheet slides hardest.
    assert!(number(&summary["checks"], "mu_min") < 0.16);
    for chart in ["punch_force.svg", "punch_force.csv"] {
        assert!(out.join(chart).is_file(), "{chart} missing");
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn benchmark_variant_holds_the_blankholder_force() {
    let out = out_dir("benchmark");
    let summary = run_cup("benchmark", &out);
    common_checks(&summary, (0.162, 0.162));
    let holder = &summary["tools"]["blankholder"]["final_force"][2];
    let f = holder.as_f64().expect("blankholder force");
    assert!(
        (f - 4900.0).abs() < 1e-6 * 4900.0,
        "quarter holder force {f}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// The script's default element (docs/solid-shell.md, "Default"): a one-layer block blank
/// is meshed with solid-shells, a blank of more layers with F-bar hexahedra; an explicit
/// `element` wins. Read back from summary.json, which names the element the run used, on
/// 4 x 4 cells to 1 mm (the element is chosen before the first increment).
#[test]
fn the_default_element_of_a_one_layer_cup_is_the_solid_shell() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (sets, expect) in [
        (vec![], "solid_shell"),
        (vec!["layers=2"], "hexahedron"),
        (vec!["element=\"hexahedron\""], "hexahedron"),
    ] {
        let out = out_dir(&format!(
            "default_element_{}",
            sets.len() * 10 + expect.len()
        ));
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tribo"));
        cmd.current_dir(root)
            .args(["run", "scripts/square_cup.rhai", "--quiet", "--out"])
            .arg(&out)
            .args([
                "--set",
                "cells=4",
                "--set",
                "travel=1.0",
                "--set",
                "charts=false",
            ]);
        for s in &sets {
            cmd.args(["--set", s]);
        }
        assert!(cmd.status().expect("tribo runs").success(), "{sets:?}");
        let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
        let summary: Value = serde_json::from_str(&text).expect("JSON");
        assert_eq!(summary["element"], expect, "{sets:?}");
        assert_eq!(summary["status"], "finished", "{sets:?}");
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// The benchmark's mild steel (`material="steel"`, Hill48 with its r-values, rolling
/// direction x), 8 x 8 x 1 to 3 mm: the same checks, with mu the steel's 0.144 and the
/// 0.78 mm sheet. Symmetry about the diagonal is no check here: r0 = 1.79 and r90 = 2.27
/// differ, so the mirror x <-> y is another material; the script says so
/// (`diagonal_symmetric_material: false`) and the asymmetry is far above the isotropic
/// run's round-off (> 1e-4 of the largest displacement; measured 3.4e-3 at 3 mm, the isotropic
/// steel 7e-16). The
/// von Mises steel on the same mesh is symmetric again (< 1e-6).
#[test]
fn benchmark_cup_of_the_mild_steel_runs_to_its_checks() {
    let base = [
        "cells=8",
        "travel=3.0",
        "charts=false",
        "variant=\"benchmark\"",
        "material=\"steel\"",
    ];
    let out = out_dir("steel_hill48");
    let sets: Vec<&str> = base
        .iter()
        .copied()
        .chain(["yield_kind=\"hill48\""])
        .collect();
    let summary = run_cup_with(&out, &sets);
    let checks = &summary["checks"];
    assert_eq!(summary["status"], "finished", "{summary}");
    assert!(number(checks, "vertical_force_balance") < 1e-6, "{checks}");
    assert_eq!(checks["diagonal_symmetric_material"], false, "{checks}");
    assert!(number(checks, "diagonal_asymmetry") > 1e-4, "{checks}");
    assert!(number(checks, "frictional_work_min") >= 0.0, "{checks}");
    assert!(number(checks, "frictional_work_max") > 0.0, "{checks}");
    assert_eq!(number(checks, "mu_min"), 0.144, "{checks}");
    assert_eq!(number(checks, "mu_max"), 0.144, "{checks}");
    let holder = summary["tools"]["blankholder"]["final_force"][2]
        .as_f64()
        .expect("blankholder force");
    assert!(
        (holder - 4900.0).abs() < 1e-6 * 4900.0,
        "quarter holder force {holder}"
    );
    // The blank is the steel's 0.78 mm: the punch-side contact points sit at z = 0.78.
    let at = &summary["frictional_work_peaks"]["punch"]["at"][2];
    assert!(
        (at.as_f64().expect("peak position") - 0.78).abs() < 1e-12,
        "{at}"
    );
    let _ = std::fs::remove_dir_all(&out);

    let out = out_dir("steel_von_mises");
    let sets: Vec<&str> = base
        .iter()
        .copied()
        .chain(["yield_kind=\"isotropic\""])
        .collect();
    let summary = run_cup_with(&out, &sets);
    let checks = &summary["checks"];
    assert_eq!(checks["diagonal_symmetric_material"], true, "{checks}");
    assert!(number(checks, "diagonal_asymmetry") < 1e-6, "{checks}");
    let _ = std::fs::remove_dir_all(&out);
}

fn run_cup_with(out: &Path, sets: &[&str]) -> Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_tribo"));
    cmd.current_dir(root)
        .args(["run", "scripts/square_cup.rhai", "--quiet", "--out"])
        .arg(out);
    // F-bar hexahedra unless the test names the element (the script's default for one layer
    // is the solid-shell; test below).
    if !sets.iter().any(|s| s.starts_with("element=")) {
        cmd.args(["--set", "element=\"hexahedron\""]);
    }
    for s in sets {
        cmd.args(["--set", s]);
    }
    assert!(
        cmd.status().expect("tribo runs").success(),
        "square cup {sets:?} failed"
    );
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

/// Issue 14 on the coarse cup (paper variant, 8 x 8 x 1, 15 mm in 0.5 mm increments), with
/// the engine's default r, predictor and anti-cycling (the script sets none of them):
/// - median Newton iterations per increment <= 6, none above 25, at most 2 cutbacks, and
///   at least 80 % full Newton steps (lower bound: one backtrack shortens one step);
/// - Newton stays Newton: the observed order of the last three force residuals above
///   round-off (1e-10 relative) is >= 1.8 in every increment from the 7th on. Measured
///   with the default r a tenth of the membrane stiffness: the first six increments (the
///   first contact of the flat blank and the holder coming on) end with orders 1.0, 1.86,
///   2.0, 1.55, 1.9, 1.22 (with r at the membrane stiffness: -18.8, 1.91, 1.92, 1.55, 1.94,
///   1.79), because a status still changes in their last iterations; that is recorded
///   here, not hidden; median 4 iterations, at most 10, 95.6 % full steps;
/// - the converged answer does not depend on r (the augmented Lagrangian's solution does
///   not): the script's former hand-picked r = E t on every node (ten times the default
///   now) gives the same draw-in and punch force peak within 1e-6 relative (the Newton
///   tolerance is 1e-9).
#[test]
fn defaults_converge_in_few_iterations_and_keep_the_answer() {
    let common = ["cells=8", "travel=15.0", "charts=false"];
    let out = out_dir("defaults");
    let summary = run_cup_with(&out, &common);
    common_checks(&summary, (0.01, 0.16));
    let newton = &summary["newton"];
    println!("{newton}");
    assert!(number(newton, "median_iterations") <= 6.0, "{newton}");
    assert!(number(newton, "max_iterations") <= 25.0, "{newton}");
    assert!(number(&summary, "cutbacks") <= 2.0, "{summary}");
    assert!(number(newton, "full_step_fraction_min") >= 0.8, "{newton}");
    let orders: Vec<f64> = newton["last_orders"]
        .as_array()
        .expect("orders")
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(
        orders.len() >= 25,
        "an order in most increments: {orders:?}"
    );
    for (i, p) in orders.iter().enumerate().skip(6) {
        assert!(*p >= 1.8, "increment {}: observed order {p}", i + 1);
    }

    let hand = out_dir("hand_picked_r");
    // E t of the script's aluminium sheet: 71 GPa x 0.81 mm, the former hand-picked value.
    let e_t = format!("r_contact={}", 71000.0 * 0.81);
    let reference = run_cup_with(&hand, &[common[0], common[1], common[2], &e_t]);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * b.abs();
    let (p, q) = (
        number(&summary, "punch_force_peak_n"),
        number(&reference, "punch_force_peak_n"),
    );
    assert!(close(p, q), "punch force peak {p} against {q}");
    for key in ["dx", "dy", "dd"] {
        let a = number(&summary["draw_in"][0], key);
        let b = number(&reference["draw_in"][0], key);
        assert!(close(a, b), "draw-in {key}: {a} against {b}");
    }
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&hand);
}

/// Per increment: Newton iterations, and the tools' forces (x, y, z of punch, blankholder,
/// die) from history.csv.
fn history(out: &Path) -> Vec<(usize, Vec<f64>)> {
    let names: Vec<String> = std::iter::once("newton_iterations".to_string())
        .chain(
            ["punch", "blankholder", "die"]
                .iter()
                .flat_map(|t| ["x", "y", "z"].map(|c| format!("{t}_force_{c}"))),
        )
        .collect();
    history_columns(out, &names)
        .into_iter()
        .map(|row| (row[0] as usize, row[1..].to_vec()))
        .collect()
}

/// Per increment, the values of the named columns of history.csv, in the order named.
fn history_columns(out: &Path, names: &[impl AsRef<str>]) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(out.join("history.csv")).expect("history.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    // Column names carry their unit after a space: "punch_force_x [N]".
    let columns: Vec<usize> = names
        .iter()
        .map(|name| {
            let name = name.as_ref();
            (header.iter())
                .position(|h| h.split(" [").next() == Some(name))
                .expect(name)
        })
        .collect();
    lines
        .map(|line| {
            let v: Vec<&str> = line.split(',').collect();
            columns.iter().map(|&k| v[k].parse().unwrap()).collect()
        })
        .collect()
}

/// The comparisons of two linear algebras below assert the same Newton iterations, so they
/// turn status prediction off: a re-solved step follows the statuses predicted at the
/// step's end, and a node predicted within round-off of its boundary can go either way in
/// two factorizations, which changes the path (not the answer) in the first increment.
const PLAIN_NEWTON: &str = "status_prediction: 0,";

/// The default factorization (LU without pivoting on the symmetric structure) and faer's
/// pivoting LU run the same cup (Newton steps not re-solved, [`PLAIN_NEWTON`]): the same
/// Newton iterations in every increment, forces and draw-in equal to 1e-7 of their size.
/// Why 1e-7: the two factorizations differ by round-off only, but each increment's answer
/// is fixed only to the Newton tolerance (a force residual of 1e-9 of the reference
/// force), and the multipliers amplify that by the system's conditioning: measured on the
/// benchmark variant, 1.0e-8 of the largest
/// force in increment 1 (first contact of the flat blank, the last residual just under the
/// tolerance), 1.1e-9 in increment 2, below 3e-11 after. On the displacement-only system
/// (both pairs of the top-face nodes eliminated) 5.1e-9, 3.0e-10, then below 1.3e-11; the
/// paper variant below 3e-11 throughout, draw-in 1.5e-11. The bound stays at 1e-7: the
/// increment-1 figure is where the last Newton residual happens to land under the
/// tolerance, which any round-off change moves by an order of magnitude.
#[test]
fn both_linear_solvers_give_the_same_cup() {
    for variant in ["paper", "benchmark"] {
        let (out_a, out_b) = (
            out_dir(&format!("{variant}_sym")),
            out_dir(&format!("{variant}_lu")),
        );
        let a = run_cup_settings(variant, "symmetric_lu", PLAIN_NEWTON, &out_a);
        let b = run_cup_settings(variant, "lu", PLAIN_NEWTON, &out_b);
        let (ha, hb) = (history(&out_a), history(&out_b));
        assert_eq!(ha.len(), hb.len());
        let scale = hb
            .iter()
            .flat_map(|(_, f)| f)
            .fold(0.0f64, |m, v| m.max(v.abs()));
        for ((ia, fa), (ib, fb)) in ha.iter().zip(&hb) {
            assert_eq!(ia, ib, "{variant}: Newton iterations differ");
            for (x, y) in fa.iter().zip(fb) {
                assert!((x - y).abs() < 1e-7 * scale, "{variant}: force {x} vs {y}");
            }
        }
        let (da, db) = (&a["final_draw_in"], &b["final_draw_in"]);
        let size = ["dx", "dy", "dd"]
            .iter()
            .fold(0.0f64, |m, k| m.max(number(db, k).abs()));
        assert!(size > 0.0, "{db}");
        for k in ["dx", "dy", "dd"] {
            let (x, y) = (number(da, k), number(db, k));
            assert!(
                (x - y).abs() < 1e-7 * size,
                "{variant}: draw-in {k} {x} vs {y}"
            );
        }
        let _ = std::fs::remove_dir_all(&out_a);
        let _ = std::fs::remove_dir_all(&out_b);
    }
}

/// Runs the cup script (8 x 8 x 1, 3 mm) with the factorization `linear_solver` and the
/// settings `extra` added to its own (a copy of the script, next to the output).
fn run_cup_settings(variant: &str, linear_solver: &str, extra: &str, out: &Path) -> Value {
    let sets = [
        "cells=8".to_string(),
        "travel=3.0".to_string(),
        format!("variant=\"{variant}\""),
        format!("linear_solver=\"{linear_solver}\""),
    ];
    let marker = "linear_solver: linear_solver,";
    common::run_edited_script("square_cup.rhai", marker, &format!(" {extra}"), &sets, out)
}

/// Runs the cup with the multipliers eliminated or not, Newton steps not re-solved on
/// predicted statuses (see [`PLAIN_NEWTON`]).
fn run_cup_eliminate(variant: &str, eliminate: bool, out: &Path) -> Value {
    run_cup_settings(
        variant,
        "symmetric_lu",
        &format!("eliminate_multipliers: {eliminate}, {PLAIN_NEWTON}"),
        out,
    )
}

/// The square cup's coarse mesh (8 x 8 x 1, 3 mm, both process variants) solved through
/// the condensed, displacement-only system (the default: every multiplier eliminated node
/// by node except at the symmetry planes, including the top-face nodes that both punch and
/// blankholder may touch) and through the mixed (u, lambda) system
/// (`eliminate_multipliers: false`): the same Newton iterations, the same forces and
/// draw-in. One linear system, two eliminations: each Newton step agrees to round-off
/// times the conditioning (1e-12 of the step on the two-roller drag, tests/condensation.rs).
///
/// Bound 1e-9 of the largest force and draw-in (measured at 8 x 8 x 1: 5.7e-14 and 1.5e-14
/// on the paper variant, 4.4e-12 and 4.6e-15 on the benchmark variant): both runs take the
/// same iterations, so the converged states differ only by the accumulated round-off of
/// the steps, far below Newton's force tolerance (1e-9 of the reference force), which is
/// what a wrong right-hand side in the reduction would show; a wrong reduced Jacobian
/// would change the iteration counts, asserted equal.
#[test]
fn condensed_and_mixed_cups_agree() {
    for variant in ["paper", "benchmark"] {
        let (out_a, out_b) = (
            out_dir(&format!("{variant}_condensed")),
            out_dir(&format!("{variant}_mixed")),
        );
        let a = run_cup_eliminate(variant, true, &out_a);
        let b = run_cup_eliminate(variant, false, &out_b);
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
        assert!(
            worst_force < CONDENSED_BOUND,
            "{variant}: forces differ by {worst_force:e}"
        );
        assert!(
            worst_draw_in < CONDENSED_BOUND,
            "{variant}: draw-in differs by {worst_draw_in:e}"
        );
        let _ = std::fs::remove_dir_all(&out_a);
        let _ = std::fs::remove_dir_all(&out_b);
    }
}

/// See [`condensed_and_mixed_cups_agree`].
const CONDENSED_BOUND: f64 = 1e-9;

/// The script's default step follows the mesh: 0.5 mm of travel per increment on 25 x 25
/// and coarser meshes (3 mm cells and up), a sixth of the in-plane cell on finer ones
/// (docs/convergence-log.md, "Time step and mesh"). 30 x 30 cells are 2.5 mm, so 0.5 mm of
/// travel takes two increments of 0.25 mm; 8 x 8 cells keep 0.5 mm.
#[test]
fn the_default_step_follows_the_cell() {
    for (cells, travel, expected) in [(30, 0.5, [0.25, 0.25]), (8, 1.0, [0.5, 0.5])] {
        let out = out_dir(&format!("step_{cells}"));
        let summary = run_cup_with(
            &out,
            &[
                "charts=false",
                &format!("cells={cells}"),
                &format!("travel={travel:?}"),
            ],
        );
        let steps: Vec<f64> = history_columns(&out, &["dt"])
            .into_iter()
            .map(|row| row[0])
            .collect();
        assert_eq!(steps, expected, "{cells} cells");
        // Nominal increments, not the halves of a cut-back one.
        assert_eq!(number(&summary, "cutbacks"), 0.0, "{cells} cells");
        let _ = std::fs::remove_dir_all(&out);
    }
}

/// The solid-shell paper cup (25 x 25 x 1) under the engine's Newton budget (30 iterations,
/// 4 halvings) through its hardest spot, where the flange between die and holder barely
/// touches either (the holder force falls to its minimum, about 0.8 kN, near 7.3-7.8 mm).
///
/// With the default r (a tenth of the membrane stiffness under each node) the run goes
/// through it in its 16 increments of 0.5 mm with no cutback (measured). With r at the
/// membrane stiffness itself (`r_fraction: 1.0`, the default before), a part of the
/// increment ending there fails even at a sixteenth of the step, and two things get over it,
/// depending on round-off (which statuses a failed attempt ends in): the rest of the
/// increment tried whole and halved afresh (`step_fixed`; parts then not all halves of 0.5
/// mm), or the last resorts at the smallest part and then on the rest whole (module
/// `stepping`; an increment with `last_resort` in its report). Before either, that run
/// stopped at 7.78 mm; with the elements' memory kept across increments, at 7.28 mm until
/// the last resorts went on to the rest whole. Either way both runs reach 8 mm, and every
/// increment converged to the run's tolerances.
#[test]
fn the_solid_shell_paper_cup_steps_over_its_flange_lift_off() {
    let out = out_dir("solid_shell_lift_off");
    let summary = run_cup_with(&out, &["charts=false", "element=solid_shell", "travel=8.0"]);
    let rows = history_columns(&out, &["time", "dt"]);
    assert_eq!(rows.last().expect("increments")[0], 8.0, "{summary}");
    assert_eq!(number(&summary, "cutbacks"), 0.0, "default r: {rows:?}");
    let _ = std::fs::remove_dir_all(&out);

    let former = common::TestDir::new(&format!(
        "tribo_square_cup_solid_shell_lift_off_former_r_{}",
        std::process::id()
    ));
    let sets = [
        "element=\"solid_shell\"".to_string(),
        "travel=8.0".to_string(),
    ];
    let summary = common::run_edited_script(
        "square_cup.rhai",
        "checkpoint_every: checkpoint_every",
        ", r_fraction: 1.0",
        &sets,
        &former,
    );
    let rows = history_columns(&former, &["time", "dt"]);
    assert_eq!(rows.last().expect("increments")[0], 8.0, "{summary}");
    let halves = |dt: f64| (0..12).any(|k| (dt - 0.5 / f64::from(1 << k)).abs() < 1e-12);
    let parts = rows.iter().filter(|r| !halves(r[1])).count();
    let resorts = number(&summary, "last_resort_increments");
    assert!(
        parts > 0 || resorts > 0.0,
        "neither the rest whole nor a last resort stepped over it: {rows:?}"
    );
    assert!(
        number(&summary, "cutbacks") >= 1.0,
        "the hard spot was met: {summary}"
    );
}
