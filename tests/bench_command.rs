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
        stdout.contains("case drag (cells=8)") && stdout.contains("base/this"),
        "{stdout}"
    );
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let results = results.as_array().unwrap();
    assert_eq!(results.len(), 1);
    let mut counts = Vec::new();
    for key in ["this", "baseline"] {
        let m = &results[0][key];
        let out_dir = m["out_dir"].as_str().unwrap();
        let summary: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(std::path::Path::new(out_dir).join("summary.json")).unwrap(),
        )
        .unwrap();
        for field in [
            "newton_iterations",
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
