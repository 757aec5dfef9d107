//! Two runs into one output folder: the second is refused naming the first's process, and
//! the first's results equal those of the same run alone. A lock left by a killed run is
//! taken over with a warning.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tribo(out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_tribo"));
    c.arg("run")
        .arg(root().join("scripts/cylinder_drag.rhai"))
        .args([
            "--quiet",
            "--set",
            "cells=24",
            "--set",
            "increments=12",
            "--out",
        ])
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

fn wait_for(path: &Path) {
    let start = Instant::now();
    // The holder writes its pid right after taking the lock.
    while std::fs::read_to_string(path).map_or(true, |t| t.trim().is_empty()) {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "{} never appeared",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_second_run_into_a_busy_folder_is_refused() {
    let base = std::env::temp_dir().join(format!("tribo-lock-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    let (shared, alone) = (base.join("shared"), base.join("alone"));

    let first = tribo(&shared).spawn().unwrap();
    wait_for(&shared.join(".tribo.lock"));
    let second = tribo(&shared).output().unwrap();
    let err = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(1), "{err}");
    assert!(
        err.contains("is in use by another tribo run")
            && err.contains(&format!("process {}", first.id())),
        "{err}"
    );
    let first = first.wait_with_output().unwrap();
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    assert!(
        !shared.join(".tribo.lock").exists(),
        "lock released at the end"
    );

    let lone = tribo(&alone).output().unwrap();
    assert!(lone.status.success());
    for file in ["history.csv", "frames/frame_0012.vtu", "frames.pvd"] {
        let a = std::fs::read(shared.join(file)).unwrap();
        let b = std::fs::read(alone.join(file)).unwrap();
        assert!(a == b, "{file} differs from the lone run's");
    }

    // kill -9 leaves the lock file; the next run takes it over with a warning (and, the
    // killed run's results being in the folder, needs --overwrite to run there).
    let mut victim = tribo(&base.join("killed")).spawn().unwrap();
    wait_for(&base.join("killed/.tribo.lock"));
    victim.kill().unwrap();
    victim.wait().unwrap();
    assert!(base.join("killed/.tribo.lock").exists());
    let next = tribo(&base.join("killed"))
        .arg("--overwrite")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&next.stderr);
    assert!(next.status.success(), "{err}");
    assert!(
        err.contains("taking over the lock") && err.contains(&format!("process {}", victim.id())),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&base);
}
