//! Issue 16, items 7 and 9, in the REPL: Ctrl-C during `sim.run()` returns to the prompt
//! with the state of the last converged increment, and the next `sim.step()` goes on from
//! there; a script that steps itself in a loop is loaded up to its first `sim.step()`
//! (stepping deferred). Driven through a pseudo-terminal by util-linux `script`, so that
//! Ctrl-C is the terminal's: the byte 0x03 typed while a line runs becomes SIGINT.

mod common;

use common::pty::Session;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_tribo");

/// A cylinder dragged over a block in 300 increments (about 3 s of CPU), stepping itself.
fn scene() -> String {
    common::pty::drag_scene(
        32,
        300,
        1000,
        "while !sim.finished() { sim.step(); }\nprint(\"the loop ran while loading\");",
    )
}

/// Rows of the REPL's history.csv (in its own folder below --out, issue 52).
fn history_rows(out: &Path) -> usize {
    std::fs::read_to_string(out.join("repl/history.csv"))
        .map(|t| t.lines().count().saturating_sub(1))
        .unwrap_or(0)
}

#[test]
fn ctrl_c_during_run_returns_to_the_prompt_and_stepping_goes_on() {
    let dir: PathBuf =
        std::env::temp_dir().join(format!("tribo-repl-interrupt-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("drag.rhai");
    std::fs::write(&script, scene()).unwrap();
    let out = dir.join("out");
    let mut s = Session::start(BIN, &script, &out, "dumb");

    // Loading stops at the loop's first sim.step(): nothing stepped.
    let at = s.expect(0, "up to its first sim.step() (line 11;");
    let at = s.expect(at, "tribo> ");
    assert!(!s
        .output
        .lock()
        .unwrap()
        .contains("the loop ran while loading"));
    assert_eq!(history_rows(&out), 0);

    s.send(b"sim.run()\r");
    let start = Instant::now();
    while history_rows(&out) < 20 {
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "sim.run() makes no progress"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    s.send(&[0x03]);
    let at = s.expect(
        at,
        "interrupted: back at the last converged increment (t = ",
    );
    let at = s.expect(at, "tribo> ");
    let converged = history_rows(&out);
    assert!(
        (20..300).contains(&converged),
        "{converged} increments before Ctrl-C"
    );

    // The simulation is where it was interrupted and steps on from there.
    s.send(b"sim.history().len()\r");
    let at = s.expect(at, &format!("\n{converged}\r"));
    s.send(b"sim.step().index\r");
    let at = s.expect(at, &format!("\n{}\r", converged + 1));
    s.send(b"(sim.time * 100.0).round().to_int()\r");
    // Increments of 0.01 in time: the next one ends at (converged + 1) / 100.
    let at = s.expect(at, &format!("\n{}\r", converged + 1));
    assert_eq!(history_rows(&out), converged + 1);
    let _ = at;
    s.quit();
    let _ = std::fs::remove_dir_all(&dir);
}
