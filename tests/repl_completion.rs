//! Issue 18, the REPL that helps, typed into a pseudo-terminal as a person would (rustyline
//! in its editing mode, TERM=xterm): TAB completes methods from the engine's metadata, tool
//! names inside a string and `sim.settings` keys; a statement left open continues on the
//! next line; `:help NAME` shows the function's signature and its documented meaning;
//! `:foo` is an unknown command; `sim.step()` prints its one-line summary.

mod common;

use common::pty::Session;

const BIN: &str = env!("CARGO_BIN_EXE_tribo");

#[test]
fn completion_multi_line_input_and_help_in_a_terminal() {
    let dir = std::env::temp_dir().join(format!("tribo-repl-completion-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("drag.rhai");
    std::fs::write(&script, common::pty::drag_scene(16, 30, 0, "sim.run();")).unwrap();
    let mut s = Session::start(BIN, &script, &dir.join("out"), "xterm");
    let at = s.expect(0, "tribo> ");

    // A method completed from its prefix (only `tool_force` starts with `tool_fo` on a
    // Simulation), then the tool's name inside the string: without completion the line
    // would call unknown names and print an error instead.
    s.send(b"print(\"force components: \" + sim.tool_fo\t(\"ro\t\").len())\r");
    let at = s.expect(at, "force components: 3");

    // A settings key completed inside `sim.settings(#{ ... })`: an unknown key is refused.
    s.send(b"sim.settings(#{ max_sl\t: 0.2 }); print(\"settings accepted\")\r");
    let end = s.expect(at, "settings accepted");
    assert!(!s.text(at, end).contains("unknown setting"));
    let at = end;

    // Multi-line input: the open statement waits for its end on the next line.
    s.send(b"let answer = 40 +\r");
    let at = s.expect(at, "...> ");
    s.send(b"2;\r");
    let at = s.expect(at, "tribo> ");
    s.send(b"print(\"answer = \" + answer)\r");
    let at = s.expect(at, "answer = 42");

    // One function's help: the engine's signature and the reference's row.
    s.send(b":help tool_force\r");
    let at = s.expect(at, "tool_force(Simulation, string) -> array");
    let at = s.expect(
        at,
        "sim.tool_force(name): total force the body exerts on the tool",
    );

    s.send(b":foo\r");
    let at = s.expect(at, "unknown command ':foo'");

    // One step: its summary line, not the report map.
    s.send(b"sim.step()\r");
    let at = s.expect(
        at,
        "increment 1: t = 0.1 (dt 0.1), roller at [0.0, 0.0, -0.012]",
    );
    let end = s.expect(at, "active nodes");
    assert!(!s.text(at, end).contains("#{"), "the report map was echoed");
    s.quit();
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 52: TAB on a prefix that several names share inserted the first of them and cycled
/// through the others one TAB at a time (rustyline's default), so the choice was never
/// shown. Now the first TAB completes what they share and the second lists them all.
#[test]
fn a_second_tab_lists_every_candidate() {
    let dir = std::env::temp_dir().join(format!("tribo-repl-list-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("drag.rhai");
    std::fs::write(&script, common::pty::drag_scene(8, 30, 0, "sim.run();")).unwrap();
    let mut s = Session::start(BIN, &script, &dir.join("out"), "xterm");
    let at = s.expect(0, "tribo> ");
    // The Simulation methods starting with `tool_`: force, offset, position. Cycling showed
    // `tool_force`, then `tool_offset` in its place, never the third.
    s.send(b"print(\"n = \" + sim.tool_\t\t");
    for name in ["tool_force", "tool_offset", "tool_position"] {
        s.expect(at, name);
    }
    // The line is still the typed prefix: finishing it by hand runs.
    s.send(b"position(\"roller\").len())\r");
    s.expect(at, "n = 3");
    s.quit();
    let _ = std::fs::remove_dir_all(&dir);
}
