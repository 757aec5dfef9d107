//! Issue 16, item 8: every stop of a run records summary.json with its reason and
//! checkpoints/final.json with the last converged state: a script friction law returning
//! NaN mid-run, a non-converging increment, a script error after some increments, a frame
//! that cannot be written. A write that fails at the stop is named in the summary and the
//! other files are still written. And (item 11) `--restart` with a script that starts no
//! simulation is refused instead of ignored.

mod common;

use common::TestDir;
use std::path::{Path, PathBuf};
use tribo::script::{self, HostOptions};
use tribo::solver::simulation::checkpoint::Checkpoint;

fn out_dir(name: &str) -> TestDir {
    let d = TestDir::new(&format!("tribo-stop-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&*d).unwrap();
    d
}

/// A block pressed on a plane by 100 N, then dragged (slipping from t = 1.5), with a
/// script friction law; `law` is the law's body, `run` how the script steps.
fn scene(law: &str, run: &str) -> String {
    format!(
        r#"
let mesh = block([0, 0, 0], [10, 10, 2], [3, 3, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.add_tool(tool("floor", plane([0, 0, 0], [0, 0, 1])).friction(|work, slip, pressure| {law}), "z-");
sim.load("z+", [0.0, 0.0, -100.0], [[0.0, 0.0], [1.0, 1.0]]);
sim.prescribe("z+", "x", [[0.0, 0.0], [1.0, 0.0], [2.0, 0.5]]);
sim.fix("z+", "y");
sim.settings(#{{ end_time: 2.0, increments: 4, max_cutbacks: 0, force_tolerance: 1e-12, contact_tolerance: 1e-12, last_resort: false }});
{run}
"#
    )
}

struct Stopped {
    error: String,
    summary: serde_json::Value,
    dir: PathBuf,
    /// The run's folder (`dir` is its `out`), removed when the test passes.
    _root: TestDir,
}

fn run_until_stop(name: &str, script_text: &str, prepare: impl FnOnce(&Path)) -> Stopped {
    let dir = out_dir(name);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    prepare(&out);
    let path = dir.join(format!("{name}.rhai"));
    std::fs::write(&path, script_text).unwrap();
    let host = HostOptions {
        out_dir: out.clone(),
        warnings: false,
        script_print: false,
        ..HostOptions::default()
    };
    let error = script::run_file(&path, &[], &host)
        .expect_err("the run stops")
        .to_string();
    let text = std::fs::read_to_string(out.join("summary.json"))
        .unwrap_or_else(|e| panic!("{name}: no summary.json ({e}); the run said: {error}"));
    Stopped {
        error,
        summary: serde_json::from_str(&text).unwrap(),
        dir: out,
        _root: dir,
    }
}

/// The final checkpoint exists, is a valid checkpoint of `increments` converged
/// increments, and history.csv has exactly those rows.
fn assert_final_state(s: &Stopped, increments: usize) {
    let file = s.dir.join("checkpoints/final.json");
    let text = std::fs::read_to_string(&file).expect("checkpoints/final.json");
    let ck = Checkpoint::from_json(&text, "final.json").unwrap();
    assert_eq!(ck.history.len(), increments, "{}", s.error);
    assert_eq!(ck.state.history_len, increments);
    assert!(ck.state.x.iter().all(|v| v.is_finite()));
    assert_eq!(s.summary["increments"], increments);
    assert_eq!(
        s.summary["final_checkpoint"].as_str().unwrap(),
        file.display().to_string()
    );
    let rows = std::fs::read_to_string(s.dir.join("history.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    assert_eq!(rows, increments, "history.csv rows");
}

#[test]
fn a_friction_law_returning_nan_mid_run_stops_with_summary_and_final_checkpoint() {
    // mu is fine while sticking; once a node has slipped 0.01 mm the law returns NaN.
    let s = run_until_stop(
        "nan_law",
        &scene(
            "if slip > 0.01 { (-1.0).sqrt() } else { 0.25 }",
            "sim.run();",
        ),
        |_| {},
    );
    assert_eq!(s.summary["status"], "stopped");
    let reason = s.summary["error"].as_str().unwrap();
    assert!(reason.contains("NaN"), "{reason}");
    assert!(reason.contains("friction coefficient"), "{reason}");
    assert!(
        reason.contains("nan_law.rhai:"),
        "the reason says where: {reason}"
    );
    // Increments 1, 2 press, 3 slips: its law call fails after it converged.
    assert_final_state(&s, 3);
}

#[test]
fn a_non_converging_increment_stops_with_summary_and_final_checkpoint() {
    let s = run_until_stop(
        "no_convergence",
        &scene(
            "0.25",
            "sim.step(); sim.step(); sim.settings(#{ max_iterations: 1 }); sim.step();",
        ),
        |_| {},
    );
    assert_eq!(s.summary["status"], "stopped");
    let reason = s.summary["error"].as_str().unwrap();
    assert!(reason.contains("no convergence"), "{reason}");
    assert!(reason.contains("increment 3"), "{reason}");
    assert!(
        s.error.contains("last converged state (t = 1) saved in"),
        "{}",
        s.error
    );
    assert_final_state(&s, 2);
}

/// Where the last resorts fail too (tolerances below round-off: nothing converges), the
/// run stops after them, and its reason names every attempt at the smallest part.
#[test]
fn a_stop_after_the_last_resorts_names_every_attempt() {
    let s = run_until_stop(
        "last_resorts",
        &scene(
            "0.25",
            "sim.step(); sim.step(); sim.settings(#{ last_resort: true, force_tolerance: 1e-30, force_abs_tolerance: 1e-300, contact_tolerance: 1e-300 }); sim.step();",
        ),
        |_| {},
    );
    assert_eq!(s.summary["status"], "stopped");
    let reason = s.summary["error"].as_str().unwrap();
    assert!(reason.contains("increment 3"), "{reason}");
    for attempt in [
        "Newton: t = ",
        "plain Newton with a longer budget: t = ",
        "pseudo-transient continuation: 80 Newton iterations without convergence",
    ] {
        assert!(reason.contains(attempt), "{attempt} in {reason}");
    }
    assert_final_state(&s, 2);
}

/// `last_resort: false` turns the last resorts off everywhere, also where fixed stepping
/// has halved the increment (the resorts would otherwise go on to the rest of it whole).
#[test]
fn without_last_resorts_a_halved_increment_stops_with_newton_alone() {
    let s = run_until_stop(
        "no_last_resorts",
        &scene(
            "0.25",
            "sim.step(); sim.step(); sim.settings(#{ max_iterations: 1, max_cutbacks: 2, last_resort: false }); sim.step();",
        ),
        |_| {},
    );
    let reason = s.summary["error"].as_str().unwrap();
    assert!(reason.contains("increment 3"), "{reason}");
    assert!(reason.contains("after 2 cutbacks"), "{reason}");
    assert!(
        !reason.contains("plain Newton with a longer budget")
            && !reason.contains("pseudo-transient continuation"),
        "no last resort was tried: {reason}"
    );
    assert_final_state(&s, 2);
}

#[test]
fn a_script_error_after_some_increments_stops_with_summary_and_final_checkpoint() {
    let s = run_until_stop(
        "script_error",
        &scene(
            "0.25",
            "sim.step(); sim.step();\nthrow \"the post-processing failed\";",
        ),
        |_| {},
    );
    assert_eq!(s.summary["status"], "stopped");
    let reason = s.summary["error"].as_str().unwrap();
    assert!(reason.contains("the post-processing failed"), "{reason}");
    assert!(
        reason.contains("script_error.rhai:10:"),
        "file and line: {reason}"
    );
    assert_final_state(&s, 2);
}

#[test]
fn a_frame_that_cannot_be_written_stops_with_summary_and_final_checkpoint() {
    // Frame 0 is written at the start, frame k after increment k: frame 2 is in the way.
    let s = run_until_stop("frame", &scene("0.25", "sim.run();"), |out| {
        std::fs::create_dir_all(out.join("frames/frame_0002.vtu/blocked")).unwrap();
    });
    assert_eq!(s.summary["status"], "stopped");
    let reason = s.summary["error"].as_str().unwrap();
    assert!(
        reason.contains("frame_0002.vtu"),
        "names the file: {reason}"
    );
    assert_final_state(&s, 2);
    assert!(
        s.dir.join("frames/frame_0001.vtu").is_file(),
        "earlier frames kept"
    );
}

#[test]
fn a_failing_write_at_the_stop_is_named_and_the_other_files_are_written() {
    let s = run_until_stop(
        "final_blocked",
        &scene("0.25", "sim.step();\nthrow \"stop here\";"),
        |out| {
            std::fs::create_dir_all(out.join("checkpoints/final.json/blocked")).unwrap();
        },
    );
    assert_eq!(s.summary["status"], "stopped");
    assert!(s.summary["final_checkpoint"].is_null());
    let failures = s.summary["write_failures"].as_array().unwrap();
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert!(
        failures[0].as_str().unwrap().contains("final.json"),
        "{failures:?}"
    );
    assert_eq!(s.summary["increments"], 1);
    assert!(s.dir.join("history.csv").is_file());
}

#[test]
fn restart_with_a_script_that_starts_no_simulation_is_refused() {
    let dir = out_dir("no_sim");
    let path = dir.join("no_sim.rhai");
    std::fs::write(&path, "let x = 1 + 1;\n").unwrap();
    let host = HostOptions {
        out_dir: dir.join("out"),
        restart: Some(dir.join("some_checkpoint.json")),
        ..HostOptions::default()
    };
    let err = script::run_file(&path, &[], &host).unwrap_err().to_string();
    assert!(err.contains("some_checkpoint.json"), "{err}");
    assert!(err.contains("started no simulation"), "{err}");
}
