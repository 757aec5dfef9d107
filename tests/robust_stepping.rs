//! Robust stepping (issue 6): checkpoint/restart reproduces the uninterrupted run, rollback
//! returns to a converged state, scripts cannot write outside their output folder and hit
//! clear limits.

mod common;

use common::TestDir;
use std::path::{Path, PathBuf};
use tribo::output::read_vtu_point_field;
use tribo::script::{self, HostOptions};
use tribo::solver::simulation::checkpoint::Checkpoint;
use tribo::solver::{Simulation, StepMode};

fn out_dir(name: &str) -> TestDir {
    TestDir::new(&format!("tribo-robust-{}-{name}", std::process::id()))
}

/// Output to `dir`, warnings not printed.
fn quiet_host(dir: &Path) -> HostOptions {
    HostOptions {
        out_dir: dir.to_path_buf(),
        warnings: false,
        ..HostOptions::default()
    }
}

fn robust_script(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/robust")
        .join(name)
}

fn adaptive_drag() -> tribo::solver::Model {
    let mut model = common::cylinder_drag_model(8.0, 2.0, 16, 3.0);
    model.settings.stepping.mode = StepMode::Adaptive;
    model.settings.stepping.max_slip_increment = 0.5;
    model.settings.increments = 4;
    model
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The checkpoint's JSON holds every f64 exactly, and the restarted run repeats the
/// uninterrupted one: same increments, same final displacements (the bound 1e-12 is the
/// issue's; the run being deterministic, the difference is expected to be exactly 0).
#[test]
fn restart_from_a_checkpoint_reproduces_the_uninterrupted_run() {
    let mut full = Simulation::new(adaptive_drag()).unwrap();
    full.run(|_, _| Ok(())).unwrap();
    let n_full = full.history.len();
    assert!(
        n_full >= 6,
        "adaptive drag takes several increments, got {n_full}"
    );

    let mut first = Simulation::new(adaptive_drag()).unwrap();
    for _ in 0..n_full / 2 {
        first.step().unwrap();
    }
    let json = Checkpoint::of(&first, vec![]).to_json().unwrap();
    drop(first);

    let mut resumed = Simulation::new(adaptive_drag()).unwrap();
    Checkpoint::from_json(&json, "memory")
        .unwrap()
        .restore(&mut resumed)
        .unwrap();
    // Exact round trip of the state through JSON.
    let again = Checkpoint::of(&resumed, vec![]).to_json().unwrap();
    assert_eq!(json, again, "the restored state writes the same checkpoint");
    resumed.run(|_, _| Ok(())).unwrap();

    let diff = max_difference(full.displacements(), resumed.displacements());
    println!(
        "increments {n_full} (restart after {}), max |u_full - u_restarted| = {diff:e}",
        n_full / 2
    );
    assert!(diff <= 1e-12, "restart differs by {diff}");
    assert_eq!(resumed.history.len(), n_full);
    let e_full = full.energy().frictional_dissipation[0];
    let e_rest = resumed.energy().frictional_dissipation[0];
    assert!((e_full - e_rest).abs() <= 1e-12 * e_full.abs().max(1.0));

    // A checkpoint of another model is refused with a message naming the difference.
    let refused = |model| {
        let mut sim = Simulation::new(model).unwrap();
        let ck = Checkpoint::from_json(&json, "memory").unwrap();
        ck.restore(&mut sim).unwrap_err().to_string()
    };
    let err = refused(common::cylinder_drag_model(8.0, 2.0, 8, 3.0));
    assert!(err.contains("does not belong to this model"), "{err}");
    // Same mesh, another tool path: the tool is elsewhere at the checkpoint's time.
    let mut moved = adaptive_drag();
    moved.contacts[0].tool.schedule = tribo::tool::schedule::Schedule::new(vec![
        (0.0, tribo::geometry::Vec3::zeros()),
        (3.0, tribo::geometry::Vec3::new(0.0, 0.0, -0.12)),
    ])
    .unwrap();
    let err = refused(moved);
    assert!(err.contains("the schedules changed"), "{err}");
    let err = Checkpoint::from_json("{\"x\": 1}", "bad.json")
        .unwrap_err()
        .to_string();
    assert!(err.contains("bad.json is not a tribo checkpoint"), "{err}");
}

fn last_frame(dir: &Path) -> PathBuf {
    let mut frames: Vec<PathBuf> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        // The blank's frames (frame_NNNN.vtu), not the tools' (frame_NNNN_<tool>.vtu).
        .filter(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            name.starts_with("frame_") && name.len() == "frame_0000.vtu".len()
        })
        .collect();
    frames.sort();
    frames.pop().unwrap()
}

/// The same through the command-line path: the script writes checkpoints every two
/// increments; `--restart` re-runs the script, loads one and continues to the end.
#[test]
fn scripted_restart_continues_from_a_written_checkpoint() {
    let script = robust_script("restart_drag.rhai");
    let full_dir = out_dir("restart-full");
    let host = quiet_host(&full_dir);
    script::run_file(&script, &[], &host).unwrap();
    let checkpoint = full_dir.join("checkpoints/checkpoint_0002.json");
    assert!(checkpoint.is_file(), "checkpoint written");

    let rest_dir = out_dir("restart-rest");
    let host = HostOptions {
        restart: Some(checkpoint),
        ..quiet_host(&rest_dir)
    };
    script::run_file(&script, &[], &host).unwrap();
    let u_full = read_vtu_point_field(&last_frame(&full_dir), "displacement").unwrap();
    let u_rest = read_vtu_point_field(&last_frame(&rest_dir), "displacement").unwrap();
    let diff = max_difference(&u_full, &u_rest);
    println!("scripted restart: max |u_full - u_restarted| = {diff:e}");
    assert!(diff <= 1e-12, "restart differs by {diff}");
    // history.csv of the restarted run holds every increment, the restored ones included.
    let rows = |d: &Path| {
        std::fs::read_to_string(d.join("history.csv"))
            .unwrap()
            .lines()
            .count()
    };
    assert_eq!(rows(&full_dir), rows(&rest_dir));
}

#[test]
fn rollback_returns_to_the_previous_converged_state() {
    let mut sim = Simulation::new(adaptive_drag()).unwrap();
    sim.step().unwrap();
    sim.step().unwrap();
    let u2 = sim.displacements().to_vec();
    let t2 = sim.time();
    sim.step().unwrap();
    assert!(max_difference(&u2, sim.displacements()) > 0.0);
    let t = sim.rollback(1).unwrap();
    assert_eq!(t, t2);
    assert_eq!(max_difference(&u2, sim.displacements()), 0.0);
    assert_eq!(sim.history.len(), 2);
    // Stepping on repeats the increment exactly.
    let r = sim.step().unwrap();
    assert_eq!(r.index, 3);
    let err = sim.rollback(10).unwrap_err().to_string();
    assert!(err.contains("rollback_depth"), "{err}");
}

/// Runs `source` as a script in a folder of its own; the folder (removed when the test
/// passes) and the run's output folder or its error.
fn run_inline(name: &str, source: &str) -> (TestDir, Result<PathBuf, String>) {
    let dir = out_dir(name);
    std::fs::create_dir_all(&*dir).unwrap();
    let path = dir.join(format!("{name}.rhai"));
    std::fs::write(&path, source).unwrap();
    let out = dir.join("out");
    let host = HostOptions {
        out_dir: out.clone(),
        ..HostOptions::default()
    };
    let result = script::run_file(&path, &[], &host)
        .map(|_| out)
        .map_err(|e| e.to_string());
    (dir, result)
}

#[test]
fn scripts_cannot_write_outside_their_output_folder() {
    let err = run_inline("abs", "write_text(\"/tmp/x\", \"hello\");")
        .1
        .unwrap_err();
    assert!(
        err.contains("\"/tmp/x\"") && err.contains("absolute paths are refused"),
        "{err}"
    );
    let err = run_inline("dotdot", "write_text(\"../x\", \"hello\");")
        .1
        .unwrap_err();
    assert!(err.contains("\"../x\"") && err.contains("'..'"), "{err}");
    let err = run_inline("nested", "write_text(\"notes/../../x\", \"hello\");")
        .1
        .unwrap_err();
    assert!(err.contains("'..'"), "{err}");
    // Checkpoints go through the same guard.
    let scene =
        "let sim = simulation(block([0,0,0],[1,1,1],[1,1,1]), linear_elastic(1000.0, 0.3));\n\
                 sim.fix(\"z-\", \"xyz\");\n";
    let err = run_inline("ck", &format!("{scene}sim.checkpoint(\"/tmp/x\");"))
        .1
        .unwrap_err();
    assert!(err.contains("absolute paths are refused"), "{err}");
    let err = run_inline("ck2", &format!("{scene}sim.checkpoint(\"../x\");"))
        .1
        .unwrap_err();
    assert!(err.contains("'..'"), "{err}");
    // A relative path lands below the output folder.
    let (_dir, out) = run_inline("ok", "write_text(\"notes/a.txt\", \"hello\");");
    let out = out.unwrap();
    assert_eq!(
        std::fs::read_to_string(out.join("notes/a.txt")).unwrap(),
        "hello"
    );
    assert!(!Path::new("/tmp/x").exists() || std::fs::read_to_string("/tmp/x").unwrap() != "hello");
}

#[test]
fn script_size_and_depth_limits_stop_with_a_clear_message() {
    let err = run_inline("string", "let s = \"x\"; loop { s += s; }")
        .1
        .unwrap_err();
    // Issue 52: the messages name the bound (and the option where there is one), not
    // only Rhai's "Length of string" / "Size of array".
    assert!(
        err.contains("a script string would be longer than 1 048 576 bytes"),
        "{err}"
    );
    let err = run_inline("array", "let a = [1]; loop { a += a; }")
        .1
        .unwrap_err();
    assert!(
        err.contains("a script array would hold more than 65 536 entries")
            && err.contains("--max-array-size"),
        "{err}"
    );
    let err = run_inline("depth", "fn f(n) { f(n + 1) }\nf(0);")
        .1
        .unwrap_err();
    assert!(
        err.to_lowercase().contains("stack overflow") || err.contains("call"),
        "{err}"
    );
}

/// Column `name` of a history.csv.
fn history_column(dir: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect()
}

/// A pin of radius 0.25 (half a cell) ploughs 6 mm through a plastic block with mu = 0.3.
/// With two fixed increments (press, then the whole drag) Newton does not converge within
/// the 10-iteration budget; adaptive steps with the same Newton settings complete, cutting
/// the increments where Newton struggles, and history.csv records the cutbacks.
#[test]
fn fast_drag_fails_with_fixed_steps_and_completes_with_adaptive_steps() {
    let script = robust_script("fast_drag.rhai");
    let common_sets = [
        "radius=0.25",
        "cells=24",
        "max_iterations=10",
        "max_cutbacks=0",
        // The stop is what this test is about: no last resorts at the smallest step.
        "last_resort=false",
    ];
    let sets = |mode: &str| {
        let mut v: Vec<_> = common_sets
            .iter()
            .map(|s| script::parse_override(s).unwrap())
            .collect();
        v.push(script::parse_override(&format!("step_control={mode}")).unwrap());
        v
    };
    let fixed_dir = out_dir("fast-fixed");
    let host = quiet_host(&fixed_dir);
    let err = script::run_file(&script, &sets("fixed"), &host)
        .unwrap_err()
        .to_string();
    println!("fixed steps: {err}");
    assert!(
        err.contains("Newton iterations without convergence"),
        "{err}"
    );
    assert!(
        err.contains("largest force residual at node(s)"),
        "names the nodes: {err}"
    );
    // The stop keeps what was written and saves the last converged state.
    assert!(fixed_dir.join("checkpoints/final.json").is_file());
    assert!(fixed_dir.join("frames/frame_0001.vtu").is_file());
    let summary = std::fs::read_to_string(fixed_dir.join("summary.json")).unwrap();
    assert!(summary.contains("\"stopped\""), "{summary}");

    let adaptive_dir = out_dir("fast-adaptive");
    let host = quiet_host(&adaptive_dir);
    script::run_file(&script, &sets("adaptive"), &host).unwrap();
    let time = history_column(&adaptive_dir, "time");
    let cutbacks = history_column(&adaptive_dir, "cutbacks");
    let total: f64 = cutbacks.iter().sum();
    println!(
        "adaptive steps: {} increments, {total} cutbacks, smallest dt {:e}",
        time.len(),
        history_column(&adaptive_dir, "dt")
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min)
    );
    assert_eq!(*time.last().unwrap(), 2.0, "lands exactly on the end time");
    assert!(
        time.contains(&1.0),
        "lands exactly on the schedule's breakpoint t = 1"
    );
    assert!(total >= 1.0, "cutbacks recorded in history.csv");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(adaptive_dir.join("summary.json")).unwrap())
            .unwrap();
    let reasons = summary["cutback_reasons"].as_array().unwrap();
    assert_eq!(
        reasons.len() as f64,
        total,
        "one reason per cutback: {reasons:?}"
    );
}

/// High friction (mu = 0.5), oblique drag of a small ball, full Newton steps: a node at the
/// edge of the contact cycles between stick and slip. Without the treatment the plain
/// Newton (no status prediction) diverges; freezing the node's status converges in a few
/// iterations, the node is named in the report and history.csv. The frozen state is then
/// released and Newton finishes with the free law, so the accepted state satisfies it to
/// the Newton tolerances. Status prediction (the engine's default) gets through without
/// anti-cycling too.
#[test]
fn anti_cycling_makes_a_high_friction_drag_converge() {
    let script = robust_script("high_friction_drag.rhai");
    let run_predicted = |mode: &str, line_search: bool, rounds: usize| {
        let dir = out_dir(&format!("cycling-{mode}-{line_search}-{rounds}"));
        let host = HostOptions {
            out_dir: dir.to_path_buf(),
            ..HostOptions::default()
        };
        let sets = [
            script::parse_override(&format!("anti_cycling={mode}")).unwrap(),
            script::parse_override(&format!("line_search={line_search}")).unwrap(),
            script::parse_override(&format!("status_prediction={rounds}")).unwrap(),
            // Newton's own behaviour is compared: no last resorts before a stop.
            script::parse_override("last_resort=false").unwrap(),
        ];
        (script::run_file(&script, &sets, &host), dir)
    };
    let run_with = |mode: &str, line_search: bool| run_predicted(mode, line_search, 0);
    let run = |mode: &str| run_with(mode, false);
    let (off, _off_dir) = run("off");
    let err = off.unwrap_err().to_string();
    println!("without anti-cycling: {err}");
    assert!(err.contains("status cycling at"), "{err}");
    let (on, on_dir) = run("freeze");
    on.unwrap();
    let iterations = history_column(&on_dir, "newton_iterations");
    let cycling = history_column(&on_dir, "cycling_nodes");
    let frozen = history_column(&on_dir, "frozen_nodes");
    println!("with anti-cycling: Newton iterations per increment {iterations:?}, cycling nodes {cycling:?}, frozen {frozen:?}");
    assert_eq!(iterations.len(), 4);
    assert!(frozen.iter().sum::<f64>() >= 1.0, "a node was frozen");
    assert!(
        iterations.iter().all(|&i| i <= 12.0),
        "converges in a few iterations: {iterations:?}"
    );
    // The line search alone also gets through: it backtracks the cycling full steps.
    let (searched, searched_dir) = run_with("off", true);
    searched.unwrap();
    println!(
        "line search, no anti-cycling: iterations {:?}, backtracks {:?}",
        history_column(&searched_dir, "newton_iterations"),
        history_column(&searched_dir, "line_search_cuts")
    );
    // Status prediction alone, full steps: the cycling node is linearised on the status
    // the step carries it into.
    let (predicted, predicted_dir) = run_predicted("off", false, 8);
    predicted.unwrap();
    let iterations = history_column(&predicted_dir, "newton_iterations");
    println!("status prediction, no anti-cycling: iterations {iterations:?}");
    assert_eq!(iterations.len(), 4, "no cutback");
    assert!(
        iterations.iter().all(|&i| i <= 12.0),
        "converges in a few iterations: {iterations:?}"
    );
}

/// The REPL steps, rolls back to the previous converged increment, switches to adaptive
/// steps and steps on; history.csv follows the rollback.
#[test]
fn repl_rolls_back_and_changes_a_setting_before_stepping_on() {
    use std::io::Write;
    use std::process::{Command, Stdio};
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scripts/cylinder_drag.rhai");
    let out = out_dir("repl-rollback");
    let mut child = Command::new(env!("CARGO_BIN_EXE_tribo"))
        .arg("repl")
        .arg(&script)
        .arg("--out")
        .arg(&*out)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(
            b"sim.step(); sim.step(); sim.step();\n\
              sim.rollback()\n\
              sim.history().len()\n\
              sim.settings(#{ step_control: \"adaptive\", dt_max: 0.05 });\n\
              sim.step(); sim.time\n\
              sim.rollback(9)\n\
              :quit\n",
        )
        .unwrap();
    let output = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    let lines: Vec<&str> = stdout.lines().collect();
    println!("{stdout}");
    // Three nominal increments of 0.1, back to 0.2, then one adaptive step of 0.05.
    assert!(lines.iter().any(|l| l.trim() == "0.2"), "{stdout}");
    assert!(lines.iter().any(|l| l.trim() == "2"), "{stdout}");
    assert!(
        lines.iter().any(|l| l.trim().starts_with("0.25")),
        "{stdout}"
    );
    assert!(
        stdout.contains("cannot roll back 9 increment(s)"),
        "{stdout}"
    );
    // The REPL writes into its own folder below --out (issue 52).
    let history = std::fs::read_to_string(out.join("repl/history.csv")).unwrap();
    assert_eq!(
        history.lines().count(),
        1 + 3,
        "header + 2 kept + 1 new row"
    );
}

#[test]
fn restart_from_a_missing_or_foreign_checkpoint_is_a_clear_error() {
    use std::process::Command;
    let script = robust_script("restart_drag.rhai");
    let dir = out_dir("bad-restart");
    std::fs::create_dir_all(&*dir).unwrap();
    let run = |ck: &Path| {
        let out = Command::new(env!("CARGO_BIN_EXE_tribo"))
            .args(["run", "--quiet", "--restart"])
            .arg(ck)
            .arg("--out")
            .arg(dir.join("out"))
            .arg(&script)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(
            !out.status.success() && !stderr.contains("panicked"),
            "{stderr}"
        );
        stderr
    };
    let err = run(&dir.join("missing.json"));
    assert!(err.contains("missing.json"), "{err}");
    let foreign = dir.join("foreign.json");
    std::fs::write(&foreign, "{\"format\": \"something else\"}").unwrap();
    let err = run(&foreign);
    assert!(err.contains("is not a tribo checkpoint"), "{err}");
}

/// When the increment cannot be completed at the minimum step the run stops with the
/// reason and the nodes where the residual is largest; the committed state is untouched.
/// The failed attempts' work is in the run's phase times and evaluation counts (nothing was
/// accepted, so before they were counted these were zero).
#[test]
fn adaptive_stop_at_the_minimum_step_names_the_reason_and_keeps_the_state() {
    let mut model = adaptive_drag();
    // One plain Newton iteration cannot converge a contact increment; dt cannot be cut
    // below 0.4. (With status prediction one iteration does converge it at dt = 0.4: the
    // predicted statuses are this drag's.)
    model.settings.max_iterations = 1;
    model.settings.status_prediction = 0;
    model.settings.stepping.dt_min = Some(0.4);
    model.settings.stepping.last_resort = false;
    let mut sim = Simulation::new(model).unwrap();
    let err = sim.step().unwrap_err().to_string();
    println!("{err}");
    assert!(
        err.contains("cannot be completed at the minimum step") && err.contains("dt_min = 4"),
        "{err}"
    );
    assert!(err.contains("largest force residual at node(s)"), "{err}");
    assert_eq!(sim.time(), 0.0);
    assert!(sim.displacements().iter().all(|&u| u == 0.0));
    assert!(sim.history.is_empty());
    let spent = &sim.phase_times;
    assert!(
        spent.full_evaluations >= 2 && spent.elements > 0.0 && spent.factorization_and_solve > 0.0,
        "failed attempts not accounted: {spent:?}"
    );
}

/// The iterations of attempts not kept are reported with the increment they preceded:
/// with a budget of one Newton iteration the drag's first attempts fail after exactly one
/// step, each once with status prediction and once in its plain retry (at most one
/// iteration too), until a halved increment converges in one; so an increment's
/// `discarded_iterations` is twice its cutbacks, and the run's Newton steps (phase
/// counts) are its iterations plus the discarded ones. Under fixed stepping the report
/// `step` returns covers the nominal increment's parts, and so do both counts; each history
/// row, its own part.
#[test]
fn the_iterations_of_discarded_attempts_are_reported() {
    for mode in [StepMode::Adaptive, StepMode::Fixed] {
        let mut model = adaptive_drag();
        model.settings.stepping.mode = mode;
        model.settings.max_iterations = 1;
        model.settings.max_cutbacks = 8;
        model.settings.stepping.last_resort = false;
        // r at the membrane stiffness (the default before it became a tenth), under which a
        // halved increment converges in one iteration: at the default the one-iteration
        // attempts went on failing (38 cutbacks to dt_min at increment 15, measured).
        model.settings.contact.r_fraction = 1.0;
        let mut sim = Simulation::new(model).unwrap();
        let mut cutbacks = 0;
        while !sim.is_finished() && sim.history.len() < 12 {
            let report = sim.step().unwrap();
            assert_eq!(
                report.discarded_iterations,
                2 * report.cutbacks,
                "{mode:?}, increment {}: {} cutbacks ({:?})",
                report.index,
                report.cutbacks,
                report.cutback_reasons
            );
            cutbacks += report.cutbacks;
        }
        assert!(
            cutbacks > 0,
            "{mode:?}: no attempt failed: the test checks nothing"
        );
        for row in &sim.history {
            assert_eq!(
                row.discarded_iterations,
                2 * row.cutbacks,
                "{mode:?}: row {}",
                row.index
            );
        }
        let iterations: usize = sim.history.iter().map(|r| r.iterations).sum();
        let discarded: usize = sim.history.iter().map(|r| r.discarded_iterations).sum();
        assert_eq!(discarded, 2 * cutbacks, "{mode:?}");
        assert_eq!(
            sim.phase_times.newton_steps,
            iterations + discarded,
            "{mode:?}"
        );
    }
}

/// Fixed stepping: each history row counts the cutbacks made before it was reached, since
/// the last converged part, so a row's dt is the previous part's (or the nominal increment's)
/// or the rest of the nominal increment (tried whole where a part fails after a converged
/// one), halved at most that many times; the rows of a nominal increment land on its end,
/// and history.csv's column sums to the failed attempts.
#[test]
fn fixed_step_cutbacks_are_counted_once() {
    let script = robust_script("fast_drag.rhai");
    let sets: Vec<_> = [
        "radius=0.25",
        "cells=24",
        "max_iterations=10",
        "max_cutbacks=6",
        "step_control=\"fixed\"",
    ]
    .iter()
    .map(|s| script::parse_override(s).unwrap())
    .collect();
    let dir = out_dir("fixed-cutbacks");
    script::run_file(&script, &sets, &quiet_host(&dir)).unwrap();
    let time = history_column(&dir, "time");
    let dt = history_column(&dir, "dt");
    let cutbacks = history_column(&dir, "cutbacks");
    // Two nominal increments of 1 (end time 2).
    let (mut nominal_end, mut start, mut part) = (1.0, 0.0, 1.0);
    for k in 0..time.len() {
        let rest = nominal_end - start;
        let halved = |base: f64| {
            (0..=cutbacks[k] as i32).any(|m| (dt[k] - base / 2f64.powi(m)).abs() <= 1e-12)
        };
        assert!(
            halved(part) || halved(rest),
            "row {k}: dt {} is neither the last part {part} nor the rest {rest} halved at most {} times",
            dt[k],
            cutbacks[k]
        );
        assert!(
            time[k] <= nominal_end + 1e-12,
            "row {k} overshoots {nominal_end}"
        );
        start = time[k];
        part = dt[k];
        if (time[k] - nominal_end).abs() <= 1e-12 {
            nominal_end += 1.0;
            part = 1.0;
        }
    }
    assert_eq!(*time.last().unwrap(), 2.0);
    let total: f64 = cutbacks.iter().sum();
    println!("fixed drag: {} rows, {total} cutbacks", time.len());
    assert!(
        total >= 1.0,
        "the fast drag needs cutbacks in two fixed steps"
    );
    // summary.json gives each cutback its reason, under the row that followed it.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let reasons = summary["cutback_reasons"].as_array().unwrap();
    assert_eq!(reasons.len() as f64, total);
    for (k, &c) in cutbacks.iter().enumerate() {
        let here: Vec<&str> = reasons
            .iter()
            .filter(|r| r["increment"].as_u64() == Some(k as u64 + 1))
            .map(|r| r["reason"].as_str().unwrap())
            .collect();
        assert_eq!(here.len() as f64, c, "row {k}: {here:?}");
        for why in here {
            println!("row {k}: cut back at {why}");
            assert!(why.starts_with("t = ") && why.contains("(dt = "), "{why}");
            assert!(
                why.contains("Newton") || why.contains("iterations"),
                "names the failure: {why}"
            );
        }
    }
}
