//! Bad input through the command line: a clear message naming the fault and where it is,
//! a non-zero exit code, and never a panic.

use std::path::PathBuf;
use std::process::Command;

mod common;

fn run_script(name: &str, source: &str, extra: &[&str]) -> (i32, String) {
    common::run_script("cli", name, source, extra)
}

const SCENE: &str = r#"
let cells = 2;
let young = 1000.0;
let radius = 1.0;
let mesh = block([0, 0, 0], [1, 1, 1], [cells, 2, 2]);
let sim = simulation(mesh, linear_elastic(young, 0.3));
let roller = tool("roller", cylinder([0, 0, 2], [0, 1, 0], radius)).path([[0, 0, 0, 0], [1, 0, 0, -1]]);
sim.add_tool(roller, "z+");
"#;

#[test]
fn syntax_error_reports_file_line_and_column() {
    let (code, err) = run_script("syntax", "let a = 1;\nlet b = (a + ;\n", &[]);
    assert_ne!(code, 0);
    assert!(err.contains("syntax.rhai:2:"), "{err}");
}

#[test]
fn negative_young_modulus_is_named() {
    let (code, err) = run_script("young", SCENE, &["--set", "young=-5"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("Young's modulus") && err.contains("-5"),
        "{err}"
    );
    assert!(
        err.contains("young.rhai:6:"),
        "the script position is given: {err}"
    );
}

#[test]
fn zero_cell_count_is_named() {
    let (code, err) = run_script("cells", SCENE, &["--set", "cells=0"]);
    assert_ne!(code, 0);
    assert!(err.contains("cells[0] = 0"), "{err}");
}

#[test]
fn zero_cylinder_radius_is_named() {
    let (code, err) = run_script("radius", SCENE, &["--set", "radius=0"]);
    assert_ne!(code, 0);
    assert!(err.contains("radius") && err.contains("0"), "{err}");
}

#[test]
fn schedule_going_back_in_time_is_named() {
    let src = SCENE.replace(
        "[[0, 0, 0, 0], [1, 0, 0, -1]]",
        "[[0, 0, 0, 0], [1, 0, 0, -1], [0.5, 0, 0, -2]]",
    );
    let (code, err) = run_script("schedule", &src, &[]);
    assert_ne!(code, 0);
    assert!(err.contains("time[2]") && err.contains("0.5"), "{err}");
}

#[test]
fn unknown_override_is_refused() {
    let (code, err) = run_script("override", SCENE, &["--set", "celss=3"]);
    assert_ne!(code, 0);
    assert!(err.contains("celss"), "{err}");
}

#[test]
fn missing_script_is_an_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_tribo"))
        .args(["run", "/nonexistent/none.rhai", "--quiet"])
        .output()
        .unwrap();
    assert_ne!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("none.rhai"), "{err}");
}

#[test]
fn repl_loads_a_scene_and_steps_it() {
    use std::io::Write;
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scripts/cylinder_drag.rhai");
    let out = common::TestDir::new(&format!("tribo-repl-{}", std::process::id()));
    let mut child = Command::new(env!("CARGO_BIN_EXE_tribo"))
        .arg("repl")
        .arg(&script)
        .arg("--out")
        .arg(&*out)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"sim.step(); sim.step(); sim.step();\nsim.time\nsim.tool_force(\"roller\")[2] > 0.0\nsim.bogus()\n:quit\n")
        .unwrap();
    let output = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert!(stdout.contains("sim.run() deferred"), "{stdout}");
    assert!(
        stdout.contains("0.30000000000000004") || stdout.contains("0.3\n"),
        "{stdout}"
    );
    assert!(
        stdout.contains("true"),
        "the roller is pushed up after 3 increments: {stdout}"
    );
    assert!(
        stdout.contains("error: <repl>:1:5: Function not found: bogus"),
        "{stdout}"
    );
    // The REPL writes into its own folder below --out (issue 52).
    assert!(out.join("repl/frames/frame_0000.vtu").exists());
}

#[test]
fn set_accepts_strings_and_booleans() {
    let src = "let label = \"a\";\nlet flag = false;\nassert(label == \"hello\", \"string override\");\nassert(flag, \"bool override\");\n";
    let (code, err) = run_script(
        "overrides",
        src,
        &["--set", "label=hello", "--set", "flag=true"],
    );
    assert_eq!(code, 0, "{err}");
}

#[test]
fn endless_loop_stops_with_a_clear_message() {
    let (code, err) = run_script("endless", "let i = 0;\nloop { i += 1; }\n", &[]);
    assert_ne!(code, 0);
    assert!(
        err.contains("endless.rhai:2:") && err.to_lowercase().contains("too many operations"),
        "{err}"
    );
}

/// `tribo extrapolate`: a first-order sequence read from standard input gives its limit and
/// order (f = 5 - 2h on h = 1, 2, 4: R = 1/2, p = 1, f_ext = 5 exactly); a quantity with two
/// meshes is refused naming it.
#[test]
fn extrapolate_reads_a_sequence_and_names_a_bad_quantity() {
    use std::io::Write;
    let run = |input: &str| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tribo"))
            .args(["extrapolate", "-"])
            .stdin(std::process::Stdio::piped())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        child
            .stdin
            .take()
            .unwrap()
            .write_all(input.as_bytes())
            .unwrap();
        child.wait_with_output().unwrap()
    };
    let out = run(r#"{"quantities": {"DX 40": [[2, 1], [1, 3], [4, -3]]}}"#);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let dx = &doc["quantities"]["DX 40"];
    assert!((dx["value"].as_f64().unwrap() - 5.0).abs() < 1e-12, "{doc}");
    assert!(
        (dx["observed_order"].as_f64().unwrap() - 1.0).abs() < 1e-9,
        "{doc}"
    );
    assert_eq!(dx["asymptotic"], true);
    let bad = run(r#"{"quantities": {"DD 15": [[1, 2], [2, 3]]}}"#);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("\"DD 15\" has 2") && err.contains("standard input"),
        "{err}"
    );
}
