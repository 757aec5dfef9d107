//! A run's output folder is its own (issue 52): a second `tribo run` into a folder that
//! holds an earlier run's results is refused naming the folder and `--overwrite`;
//! `--overwrite` removes only the files a run writes, so no stale frame is left beside the
//! new ones and the user's files stay; the REPL writes into OUT/repl and never mixes with a
//! run's results in OUT. (A restart into its own folder: tests/interrupt_restart.rs.)

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn script() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scripts/cylinder_drag.rhai")
}

/// `tribo run cylinder_drag.rhai` on a coarse mesh (about a second) with `extra` arguments.
fn run(out: &Path, increments: usize, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tribo"))
        .arg("run")
        .arg(script())
        .args(["--quiet", "--set", "cells=24", "--set"])
        .arg(format!("increments={increments}"))
        .args(extra)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

fn summary_increments(dir: &Path) -> u64 {
    let text = std::fs::read_to_string(dir.join("summary.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["increments"].as_u64().unwrap()
}

/// Data rows of history.csv (its first line is the header).
fn history_rows(dir: &Path) -> usize {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    text.lines().count() - 1
}

#[test]
fn a_used_folder_is_refused_then_overwritten_and_the_repl_keeps_its_own() {
    let base = common::TestDir::new(&format!("tribo-folders-{}", std::process::id()));
    let out = base.join("out");
    let first = run(&out, 12, &[]);
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    assert_eq!(summary_increments(&out), 12);
    // A user's note, and a frame no run of 6 increments writes (as a longer run would).
    std::fs::write(out.join("notes.txt"), "my notes").unwrap();
    let stale = out.join("frames/frame_0999.vtu");
    std::fs::copy(out.join("frames/frame_0001.vtu"), &stale).unwrap();
    let summary_before = std::fs::read(out.join("summary.json")).unwrap();

    // Refused, naming the folder and the option; nothing written.
    let second = run(&out, 6, &[]);
    let err = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&out.display().to_string()) && err.contains("--overwrite"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(out.join("summary.json")).unwrap(),
        summary_before
    );

    // --overwrite: the earlier run's files are gone, the user's note stays.
    let third = run(&out, 6, &["--overwrite"]);
    assert!(
        third.status.success(),
        "{}",
        String::from_utf8_lossy(&third.stderr)
    );
    assert!(
        !stale.exists(),
        "a stale frame was left beside the new ones"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "my notes"
    );
    assert_eq!(summary_increments(&out), 6);
    assert_eq!(history_rows(&out), 6);
    let pvd = std::fs::read_to_string(out.join("frames.pvd")).unwrap();
    let listed = pvd.matches("<DataSet").count();
    let on_disk = std::fs::read_dir(out.join("frames")).unwrap().count();
    assert_eq!(listed, on_disk, "every frame on disk is one the .pvd lists");

    // The REPL into the same --out: its own folder OUT/repl, the run's results untouched.
    let history_before = std::fs::read(out.join("history.csv")).unwrap();
    for _ in 0..2 {
        let mut repl = Command::new(env!("CARGO_BIN_EXE_tribo"))
            .arg("repl")
            .arg(script())
            .arg("--out")
            .arg(&out)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        use std::io::Write;
        let stdin = repl.stdin.as_mut().unwrap();
        stdin.write_all(b"sim.step();\n:quit\n").unwrap();
        let done = repl.wait_with_output().unwrap();
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
        // A second session starts afresh in the REPL's folder: one increment, not two.
        assert_eq!(history_rows(&out.join("repl")), 1);
    }
    assert_eq!(
        std::fs::read(out.join("history.csv")).unwrap(),
        history_before
    );
    assert_eq!(summary_increments(&out), 6);
}

/// `--overwrite` and `--restart` together would remove the checkpoint being restarted from.
#[test]
fn overwrite_and_restart_are_refused_together() {
    let base = common::TestDir::new(&format!("tribo-folders-r-{}", std::process::id()));
    let out = run(
        &base,
        2,
        &["--overwrite", "--restart", "checkpoints/final.json"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--overwrite") && err.contains("--restart"),
        "{err}"
    );
}

/// Without --out each variant of a script has its own folder: out/<script name> and
/// `_NAME-VALUE` per --set, so the README's three square-cup commands do not collide.
#[test]
fn the_default_folder_names_the_set_values() {
    let base = common::TestDir::new(&format!("tribo-folders-d-{}", std::process::id()));
    std::fs::create_dir_all(&*base).unwrap();
    for sets in [&[][..], &["--set", "mu=0.2"][..]] {
        let out = Command::new(env!("CARGO_BIN_EXE_tribo"))
            .arg("run")
            .arg(script())
            .args(["--quiet", "--set", "cells=24", "--set", "increments=2"])
            .args(sets)
            .current_dir(&*base)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    for folder in [
        "out/cylinder_drag_cells-24_increments-2",
        "out/cylinder_drag_cells-24_increments-2_mu-0.2",
    ] {
        assert_eq!(summary_increments(&base.join(folder)), 2, "{folder}");
    }
}
