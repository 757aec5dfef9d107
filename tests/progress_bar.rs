//! Issue 18: a run's progress bar on a terminal. Warnings printed during `sim.run()` stand on
//! their own lines (the bar is cleared, the warning printed, the bar drawn again under it),
//! not appended to the bar's line, and the bar shows an estimate of the time left.

mod common;

use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_tribo");

/// Adaptive steps with a slip limit no increment can meet at the minimum step: every
/// increment of the drag is accepted with the warning "... exceeds its limit ... at the
/// minimum step".
#[test]
fn warnings_do_not_repeat_the_progress_line_and_the_bar_has_an_eta() {
    let dir = std::env::temp_dir().join(format!("tribo-progress-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("drag.rhai");
    let tail = "sim.settings(#{ step_control: \"adaptive\", max_slip_increment: 1e-4, \
                dt_min: 0.1, dt_initial: 0.1 });\nsim.run();";
    std::fs::write(&script, common::pty::drag_scene(16, 30, 0, tail)).unwrap();
    let command = format!(
        "{BIN} run {} --out {}",
        script.display(),
        dir.join("out").display()
    );
    let out = Command::new("script")
        .args(["-q", "-e", "-c", &command, "/dev/null"])
        .env("TERM", "xterm")
        .output()
        .expect("util-linux `script` runs tribo in a pseudo-terminal");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "the run finishes:\n{text}");
    let warnings: Vec<usize> = text
        .match_indices("warning: increment")
        .map(|(i, _)| i)
        .collect();
    assert!(warnings.len() >= 5, "every increment warns:\n{text}");
    assert!(
        text.contains("of the time"),
        "the bar is drawn on a terminal:\n{text}"
    );
    assert!(text.contains("ETA"), "the bar shows the time left:\n{text}");
    for &at in &warnings {
        // What the terminal shows on the warning's line before it: the text after the last
        // line feed or carriage return (the bar is cleared by "\r" + erase-line).
        let line_start = text[..at].rfind(['\n', '\r']).map_or(0, |i| i + 1);
        let before = &text[line_start..at];
        assert!(
            !before.contains("of the time"),
            "a warning appended to the progress bar's line: {before:?}"
        );
    }
}
