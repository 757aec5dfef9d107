//! Interactive stepping: `tribo repl [SCRIPT]`.
//!
//! Lines are evaluated in one persistent scope. A script given on the command line is run
//! first with stepping deferred, so its scene can be stepped by hand: `sim.run()` returns
//! at once and the script goes on, a `sim.step()` ends the loading there (a script that
//! steps itself in a loop is loaded up to that loop).
//!
//! Ctrl-C while a line runs (`sim.run()`, `sim.step()`) abandons the increment under way
//! and returns to the prompt; the simulation keeps the state of its last converged
//! increment and the next `sim.step()` goes on from there. At the prompt, Ctrl-C clears
//! the line (and an open statement) and Ctrl-D leaves.
//!
//! A line that leaves a statement open (Rhai reaches the end of the text still expecting
//! more) is kept and the next line is appended to it, under the prompt `  ...> `; this is
//! done here rather than in rustyline's validator so that it works the same when the input
//! is not a terminal. TAB completion ([`complete`]) and `:help NAME` ([`help`]) take their
//! names from the engine's registrations ([`catalogue`]); values are shown by [`display`].
//! TAB completes what the candidates share and a second TAB lists every candidate.

mod catalogue;
mod complete;
mod display;
mod help;

use super::{compile_source, describe_error, engine, remember_source, HostOptions, DEFERRED};
use crate::Result;
use rhai::{Dynamic, Engine, EvalAltResult, ParseErrorType, Scope};
use rustyline::error::ReadlineError;
use std::path::Path;

const PROMPT: &str = "tribo> ";
/// Prompt of a line continuing an open statement.
const CONTINUE: &str = "  ...> ";

/// Runs the REPL; returns when the person quits (Ctrl-D or :quit).
pub fn run(script: Option<&Path>, host: &HostOptions) -> Result<()> {
    let engine = engine(host, script.and_then(|p| p.parent()));
    let mut scope = Scope::new();
    if let Some(path) = script {
        let (ast, source) = compile_source(&engine, path)?;
        remember_source(host, path, source);
        host.defer_run.set(true);
        let loaded = engine.run_ast_with_scope(&mut scope, &ast);
        host.defer_run.set(false);
        match loaded {
            Ok(()) => println!(
                "loaded {} ({} variables in scope)",
                path.display(),
                scope.len()
            ),
            Err(e) if is_deferred(&e) => println!(
                "loaded {} up to its first sim.step() (line {}; {} variables in scope): step with sim.step() or sim.run()",
                path.display(),
                e.position().line().unwrap_or(0),
                scope.len()
            ),
            Err(e) => println!(
                "error while loading: {}",
                describe_error(&path.display().to_string(), &e, &host.limits)
            ),
        }
    }
    println!("tribo repl: type :help for help, :quit to leave");
    let mut editor: rustyline::Editor<complete::ReplHelper, rustyline::history::DefaultHistory> =
        rustyline::Editor::with_config(editor_config())
            .map_err(|e| crate::Error::Input(format!("cannot start the line editor: {e}")))?;
    let catalogue = catalogue::Catalogue::of(&engine);
    editor.set_helper(Some(complete::ReplHelper {
        catalogue: catalogue.clone(),
        session: Default::default(),
    }));
    let mut pending = String::new();
    loop {
        if let Some(h) = editor.helper() {
            *h.session.borrow_mut() = session(&engine, &scope, host);
        }
        let prompt = if pending.is_empty() { PROMPT } else { CONTINUE };
        let line = match editor.readline(prompt) {
            Ok(line) => line,
            Err(ReadlineError::Interrupted) => {
                pending.clear();
                continue;
            }
            Err(ReadlineError::Eof) => break,
            Err(e) => return Err(crate::Error::Input(format!("line editor: {e}"))),
        };
        if pending.is_empty() {
            let trimmed = line.trim();
            if trimmed.is_empty() {
                continue;
            }
            let _ = editor.add_history_entry(trimmed);
            if let Some(command) = trimmed.strip_prefix(':') {
                match command_line(command, &catalogue) {
                    Some(text) => println!("{text}"),
                    None => break,
                }
                continue;
            }
        } else {
            let _ = editor.add_history_entry(line.trim());
            pending.push('\n');
        }
        pending.push_str(&line);
        if is_incomplete(&engine, &pending) {
            continue;
        }
        let code = std::mem::take(&mut pending);
        // A signal that arrived while the prompt waited (kill -INT) is not meant for
        // this line.
        host.interrupt.clear();
        let result = engine.eval_with_scope::<Dynamic>(&mut scope, &code);
        let text = outcome_line(&result, host);
        if !text.is_empty() {
            println!("{text}");
        }
    }
    Ok(())
}

/// The line editor's settings: TAB completes the part all candidates share and a second
/// TAB lists them all (as bash does), rather than rustyline's default of inserting the first
/// candidate and cycling through the others one TAB at a time, which hid the choice.
fn editor_config() -> rustyline::Config {
    rustyline::Config::builder()
        .completion_type(rustyline::CompletionType::List)
        .build()
}

/// What a `:command` prints; `None` for `:quit`.
fn command_line(command: &str, catalogue: &catalogue::Catalogue) -> Option<String> {
    let (name, arg) = command
        .trim()
        .split_once(char::is_whitespace)
        .map_or((command.trim(), ""), |(n, a)| (n, a.trim()));
    Some(match (name, arg) {
        ("quit" | "q", _) => return None,
        ("help" | "h", "") => format!(
            "{}\nstd-lib modules (import \"NAME\" as m;): {}",
            help::OVERVIEW,
            super::stdlib::module_names().join(", ")
        ),
        ("help" | "h", function) => help::function_help(catalogue, function),
        _ => format!(
            "unknown command ':{name}' (commands: {})",
            complete::COMMANDS.join(", ")
        ),
    })
}

/// Whether `code` is a statement left open: Rhai reached the end of the text while still
/// expecting more (`let x = 1 +`, an unclosed `(`, `[` or `{`). Any other syntax error is
/// reported at once.
fn is_incomplete(engine: &Engine, code: &str) -> bool {
    match engine.compile(code) {
        Ok(_) => false,
        Err(e) => match e.err_type() {
            ParseErrorType::UnexpectedEOF => true,
            ParseErrorType::MissingToken(..) => {
                // Missing a closing token at the very end of the text.
                let lines = code.lines().count().max(1);
                let line = e.position().line().unwrap_or(0);
                line >= lines || e.position().is_none()
            }
            _ => false,
        },
    }
}

/// The session's variables with their types and the tools built so far (for completion).
fn session(engine: &Engine, scope: &Scope, host: &HostOptions) -> complete::Session {
    complete::Session {
        variables: scope
            .iter_raw()
            .map(|(name, _, v)| {
                (
                    name.to_string(),
                    engine.map_type_name(v.type_name()).to_string(),
                )
            })
            .collect(),
        tools: host.simulations.tool_names(),
    }
}

/// What the REPL prints after evaluating a line. After Ctrl-C (the host's interrupt flag)
/// the flag is withdrawn, so that the next line steps again, and the message gives the
/// time of the state kept.
pub fn outcome_line(
    result: &std::result::Result<Dynamic, Box<EvalAltResult>>,
    host: &HostOptions,
) -> String {
    match result {
        Ok(v) if v.is_unit() => String::new(),
        Ok(v) => {
            // An increment report: sim.step()'s map, or a record of sim.history().
            let report = (v.read_lock::<rhai::Map>().map(|m| m.clone()))
                .or_else(|| (v.read_lock::<super::record::Record>()).map(|r| r.map().clone()))
                .filter(display::is_report);
            match report {
                Some(m) => display::report_line(&m, &host.simulations.tool_positions()),
                None => display::value(v),
            }
        }
        Err(_) if host.interrupt.is_raised() => {
            host.interrupt.clear();
            let times: Vec<String> = host
                .simulations
                .times()
                .iter()
                .map(|t| t.to_string())
                .collect();
            format!(
                "interrupted: back at the last converged increment (t = {}); sim.step() goes on from there",
                times.join(", ")
            )
        }
        Err(e) => format!(
            "error: {}",
            super::explain_late_sets(host, describe_error("<repl>", e, &host.limits))
        ),
    }
}

/// Whether loading stopped at the script's first `sim.step()` (see `DEFERRED`).
fn is_deferred(e: &EvalAltResult) -> bool {
    match e {
        EvalAltResult::ErrorTerminated(v, _) => {
            v.clone().into_string().is_ok_and(|s| s == DEFERRED)
        }
        EvalAltResult::ErrorInFunctionCall(_, _, inner, _) => is_deferred(inner),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_statements_continue_and_errors_do_not() {
        let engine = engine(&HostOptions::default(), None);
        for open in [
            "let x = 1 +",
            "let a = [1, 2,",
            "if true {",
            "fn f(x) {\n  x +",
            "print(\"a\"",
        ] {
            assert!(is_incomplete(&engine, open), "{open:?} should continue");
        }
        for done in [
            "let x = 1 + 2;",
            "if true { 1 }",
            "let x = 1 +\n2;",
            "let x = ;",
            "1 +* 2",
        ] {
            assert!(
                !is_incomplete(&engine, done),
                "{done:?} should be evaluated"
            );
        }
    }

    #[test]
    fn commands() {
        let c = catalogue::Catalogue::of(&engine(&HostOptions::default(), None));
        assert_eq!(command_line("quit", &c), None);
        assert!(command_line("foo", &c)
            .unwrap()
            .starts_with("unknown command ':foo'"));
        assert!(command_line("help", &c).unwrap().contains(":help NAME"));
        assert!(command_line("help step", &c)
            .unwrap()
            .starts_with("step(Simulation) -> map"));
    }
}
