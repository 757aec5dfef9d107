//! `tribo bench`: argument errors are clear messages (no panic, non-zero exit), and the
//! numbers it reports are those of the runs it made (no timing is asserted).

use std::process::Command;

fn bench(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_tribo"))
        .arg("bench")
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).to_string(),
        stderr,
    )
}

/// The summary.json of a measurement's run.
fn summary_of(m: &serde_json::Value) -> serde_json::Value {
    let out_dir = std::path::Path::new(m["out_dir"].as_str().unwrap());
    serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn argument_errors_name_the_fault() {
    for (args, needle) in [
        (vec!["--case", "kettle"], "kettle"),
        (vec!["--case", "drag", "--cells", "0"], "--cells"),
        (vec!["--case", "cup", "--travel=-3"], "--travel"),
        (vec!["--case", "cup", "--layers", "99"], "--layers"),
        (
            vec!["--case", "drag", "--baseline", "/no/such/tribo"],
            "/no/such/tribo",
        ),
    ] {
        let (code, _, stderr) = bench(&args);
        assert_ne!(code, 0, "{args:?} must fail");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
    let (code, _, stderr) = bench(&["--cells", "abc"]);
    assert_ne!(code, 0);
    assert!(stderr.contains("abc"), "{stderr}");
}

/// The drag case against this same binary as baseline: every count in the table and the
/// JSON is the run's own summary's, and the two runs (same binary, deterministic solver)
/// agree on every count.
#[test]
fn reported_counts_are_the_runs_own() {
    let dir = std::env::temp_dir().join(format!("tribo-bench-test-{}", std::process::id()));
    let json = dir.join("bench.json");
    let (code, stdout, stderr) = bench(&[
        "--case",
        "drag",
        "--cells",
        "8",
        "--baseline",
        env!("CARGO_BIN_EXE_tribo"),
        "--json",
        json.to_str().unwrap(),
        "--work-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("case drag (cells=8;") && stdout.contains("base/this"),
        "{stdout}"
    );
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let results = results.as_array().unwrap();
    assert_eq!(results.len(), 1);
    let mut counts = Vec::new();
    for key in ["this", "baseline"] {
        let m = &results[0][key];
        let summary = summary_of(m);
        for field in [
            "newton_iterations",
            "discarded_iterations",
            "line_search_cuts",
            "increments",
            "nodes",
        ] {
            assert_eq!(m[field], summary[field], "{key}: {field}");
        }
        assert_eq!(m["phase_times_s"], summary["phase_times_s"], "{key}");
        let (it, cuts) = (
            m["newton_iterations"].as_f64().unwrap(),
            m["line_search_cuts"].as_f64().unwrap(),
        );
        assert!(it > 0.0);
        assert_eq!(
            m["trials_per_iteration"].as_f64().unwrap(),
            (it + cuts) / it
        );
        assert_eq!(
            m["displacement_unknowns"].as_u64().unwrap(),
            3 * m["nodes"].as_u64().unwrap()
        );
        // 8 x 1 x 2 cells: 9 x 2 x 3 nodes.
        assert_eq!(m["nodes"].as_u64().unwrap(), 54);
        assert!(
            stdout.contains(&format!(" {} ", m["newton_iterations"])),
            "{stdout}"
        );
        counts.push((it, cuts, m["increments"].clone()));
    }
    assert_eq!(counts[0], counts[1]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A baseline built in another checkout runs that checkout's own script, with only the
/// overrides that script declares: here a baseline tree (`TREE/target/release/tribo`, a
/// link to this binary) whose drag script has no `cells` (its mesh is fixed at 8 cells).
/// The run succeeds, the baseline's mesh is its script's (54 nodes, not the 13 x 2 x 4 of
/// `--cells 12`), the table names the override left out, and the evaluation counts are the
/// runs' own.
#[test]
fn baseline_runs_its_own_script_with_the_settings_it_declares() {
    let dir = std::env::temp_dir().join(format!("tribo-bench-own-{}", std::process::id()));
    let tree = dir.join("tree");
    std::fs::create_dir_all(tree.join("target/release")).unwrap();
    std::fs::create_dir_all(tree.join("scripts")).unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let drag = std::fs::read_to_string(root.join("scripts/cylinder_drag.rhai")).unwrap();
    assert!(drag.contains("let cells = 32;"));
    let old = drag
        .replace("let cells = 32;", "let n_cells = 8;")
        .replace("[cells, 1, cells / 4]", "[n_cells, 1, n_cells / 4]");
    std::fs::write(tree.join("scripts/cylinder_drag.rhai"), old).unwrap();
    let baseline = tree.join("target/release/tribo");
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_tribo"), &baseline).unwrap();
    let json = dir.join("bench.json");
    let (code, stdout, stderr) = bench(&[
        "--case",
        "drag",
        "--cells",
        "12",
        "--baseline",
        baseline.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--work-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("left out, not declared by that script: cells=12"),
        "{stdout}"
    );
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let (this, base) = (&results[0]["this"], &results[0]["baseline"]);
    assert_eq!(this["nodes"].as_u64().unwrap(), 13 * 2 * 4);
    assert_eq!(base["nodes"].as_u64().unwrap(), 54);
    assert_eq!(base["sets_left_out"][0], "cells=12");
    assert!(base["script"]
        .as_str()
        .unwrap()
        .ends_with("tree/scripts/cylinder_drag.rhai"));
    assert_eq!(this["threads"].as_u64(), Some(1), "pinned to one processor");
    for m in [this, base] {
        let summary = summary_of(m);
        let it = summary["newton_iterations"].as_f64().unwrap();
        let full = summary["evaluations"]["full"].as_f64().unwrap();
        // At least one full evaluation per Newton iteration (each step solves with one).
        assert!(full >= it, "{summary}");
        assert_eq!(
            m["full_evaluations_per_iteration"].as_f64().unwrap(),
            full / it
        );
        assert_eq!(
            m["residual_evaluations_per_iteration"].as_f64().unwrap(),
            summary["evaluations"]["residual_only"].as_f64().unwrap() / it
        );
        let completions = summary["evaluations"]["jacobian_completions"]
            .as_f64()
            .unwrap();
        assert_eq!(
            m["completions_per_iteration"].as_f64().unwrap(),
            completions / it
        );
        // The table's evaluations cell carries all three counts.
        let cell = format!(
            "{:.2}+{:.2}+{:.2}",
            full / it,
            summary["evaluations"]["residual_only"].as_f64().unwrap() / it,
            completions / it
        );
        assert!(stdout.contains(&cell), "{cell} not in {stdout}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
