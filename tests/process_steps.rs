//! Issue 47, steps: a process in named steps (tests/scripts/clamp_draw_steps.rhai: closing
//! with a force-controlled holder and a stationary punch, drawing, unclamping with the
//! holder force ramped off, release with the holder switched to displacement control and
//! the tools retracted). A run restarted from a checkpoint inside a step, or at a step's
//! end, equals the uninterrupted run bit for bit (history.csv and the state of the last
//! checkpoint); summary.json says what each step did; bad steps are refused with
//! messages naming the step and the value.

mod common;

use common::TestDir;
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_tribo");
const SCRIPT: &str = "tests/scripts/clamp_draw_steps.rhai";

/// `tribo run` of the scene with a checkpoint after every increment.
fn run(out: &Path, restart: Option<&Path>) {
    let mut cmd = Command::new(BIN);
    cmd.args(["run", SCRIPT, "--quiet", "--set", "checkpoint_every=1"])
        .arg("--out")
        .arg(out)
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    if let Some(ck) = restart {
        cmd.arg("--restart").arg(ck);
    }
    let o = cmd.output().expect("tribo runs");
    assert!(
        o.status.success(),
        "tribo failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn restart_inside_a_step_and_at_its_end_equals_the_whole_run() {
    let tag = std::process::id();
    let full = TestDir::new(&format!("tribo-steps-full-{tag}"));
    run(&full, None);
    let summary = json(&full.join("summary.json"));
    let steps = summary["steps"].as_array().expect("summary.json has steps");
    let names: Vec<&str> = steps.iter().map(|s| s["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["closing", "drawing", "unclamping", "release"]);
    // Every step reached its end in at least its planned increments (a cutback adds one;
    // measured: 4, 8, 5 and 7, one cutback in the unclamping, two in the release).
    for s in steps {
        assert!(
            s["increments"].as_u64() >= s["planned_increments"].as_u64(),
            "{s}"
        );
    }
    assert!(steps.iter().all(|s| s["completed"] == true));
    let last = summary["increments"].as_u64().unwrap();
    // Checkpoint 6 is inside the drawing step, 4 the end of closing, 21 inside the release
    // after its cut-back parts (checkpoints are written at the end of nominal increments).
    for at in [6, 4, 21] {
        let out = TestDir::new(&format!("tribo-steps-restart{at}-{tag}"));
        let ck = full.join(format!("checkpoints/checkpoint_{at:04}.json"));
        run(&out, Some(&ck));
        assert_eq!(
            std::fs::read(full.join("history.csv")).unwrap(),
            std::fs::read(out.join("history.csv")).unwrap(),
            "history.csv after a restart from increment {at}"
        );
        let end = format!("checkpoints/checkpoint_{last:04}.json");
        // The state bit for bit (JSON numbers are written round-trip exact).
        assert_eq!(
            json(&full.join(&end))["state"],
            json(&out.join(&end))["state"],
            "final state after a restart from increment {at}"
        );
        let _ = std::fs::remove_dir_all(&out);
    }
    let _ = std::fs::remove_dir_all(&full);
}

/// Runs `source` as a script in a fresh folder and returns its error message.
fn script_error(name: &str, steps: &str) -> String {
    let dir = TestDir::new(&format!("tribo-steps-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let source = format!(
        r#"let mesh = block([0, 0, 0], [4.0, 1.0, 1.0], [2, 1, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.fix("z-", "z");
sim.add_tool(tool("punch", plane([0, 0, 1.1], [0, 0, -1])), "z+");
sim.steps({steps});
sim.run();
"#
    );
    let path = dir.join("steps.rhai");
    std::fs::write(&path, source).unwrap();
    let host = tribo::script::HostOptions {
        out_dir: dir.join("out"),
        ..Default::default()
    };
    let err = tribo::script::run_file(&path, &[], &host)
        .expect_err("the script is refused")
        .to_string();
    let _ = std::fs::remove_dir_all(&dir);
    err
}

#[test]
fn bad_steps_are_refused_naming_the_step_and_the_value() {
    let cases = [
        (
            "unknown_tool",
            r#"[#{ name: "draw", duration: 1.0, tools: #{ punh: #{ move: [0, 0, -1] } } }]"#,
            "step 0 ('draw'): no tool named 'punh' (the tools added so far: punch)",
        ),
        (
            "duration",
            r#"[#{ name: "a", duration: 1.0 }, #{ name: "b", duration: -2.0 }]"#,
            "step 1 ('b'): duration = -2 must be > 0",
        ),
        (
            "same_name",
            r#"[#{ name: "a", duration: 1.0 }, #{ name: "a", duration: 1.0 }]"#,
            "step 1 ('a') name = a is used by an earlier step",
        ),
        (
            "no_axis",
            r#"[#{ name: "close", duration: 1.0, tools: #{ punch: #{ force: 5.0 } } }]"#,
            "step 0 ('close'), tool 'punch': force control needs an axis",
        ),
        (
            "unknown_key",
            r#"[#{ name: "close", duration: 1.0, tools: #{ punch: #{ mvoe: [0, 0, 1] } } }]"#,
            "step 0 ('close'), tool 'punch': unknown key 'mvoe'",
        ),
        (
            "force_fraction",
            r#"[#{ name: "close", duration: 2.0, tools: #{ punch: #{ axis: [0, 0, -1], force: [[0, 0], [2, 5]] } } }]"#,
            "force times are fractions of the step, in [0, 1]",
        ),
    ];
    for (name, steps, expected) in cases {
        let err = script_error(name, steps);
        assert!(err.contains(expected), "{name}: {err}");
        assert!(
            err.contains("steps.rhai:5:"),
            "{name}: the error names the line: {err}"
        );
    }
}
