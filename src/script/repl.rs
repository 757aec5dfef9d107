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
//! the line (rustyline's behaviour) and Ctrl-D leaves.

use super::{compile, describe_error, engine, HostOptions, DEFERRED};
use crate::Result;
use rhai::{Dynamic, EvalAltResult, Scope};
use rustyline::error::ReadlineError;
use std::path::Path;

const HELP: &str = "\
Rhai lines are evaluated in a persistent scope. Useful calls on a simulation `sim`:
  sim.step()                      one increment; prints iterations and residuals
  sim.run()                       run to the end time
  sim.time                        current pseudo-time
  sim.tool_force(\"punch\")         total force on a tool [fx, fy, fz]
  sim.contact_nodes(\"punch\")      state of every candidate node of a tool
  sim.contact_node(\"punch\", 12)   one node's state: status, gap, lambda_n, lambda_t, work, mu
  sim.node_history(\"punch\", 12)   that node's work, mu and status over the increments
  sim.displacement(node)          a node's displacement
  sim.write_frame()               write a VTK frame now
  sim.history()                   one map per converged increment
  sim.rollback()                  undo the last converged increment (sim.rollback(n): n of them)
  sim.settings(#{...})            change stepping settings (step_control, dt_max, ...) and step on
  sim.checkpoint(\"name.json\")     save the committed state below the output folder
Commands: :help, :quit";

/// Runs the REPL; returns when the person quits (Ctrl-D or :quit).
pub fn run(script: Option<&Path>, host: &HostOptions) -> Result<()> {
    let engine = engine(host, script.and_then(|p| p.parent()));
    let mut scope = Scope::new();
    if let Some(path) = script {
        let ast = compile(&engine, path)?;
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
                describe_error(&path.display().to_string(), &e)
            ),
        }
    }
    println!("tribo repl: type :help for help, :quit to leave");
    let mut editor = rustyline::DefaultEditor::new()
        .map_err(|e| crate::Error::Input(format!("cannot start the line editor: {e}")))?;
    loop {
        match editor.readline("tribo> ") {
            Ok(line) => {
                let line = line.trim();
                if line.is_empty() {
                    continue;
                }
                let _ = editor.add_history_entry(line);
                match line {
                    ":quit" | ":q" | "exit" => break,
                    ":help" | ":h" => {
                        println!("{HELP}");
                        println!(
                            "std-lib modules (import \"NAME\" as m;): {}",
                            super::stdlib::module_names().join(", ")
                        );
                        continue;
                    }
                    _ => {}
                }
                // A signal that arrived while the prompt waited (kill -INT) is not meant for
                // this line.
                host.interrupt.clear();
                let result = engine.eval_with_scope::<Dynamic>(&mut scope, line);
                let text = outcome_line(&result, host);
                if !text.is_empty() {
                    println!("{text}");
                }
            }
            Err(ReadlineError::Interrupted) => continue,
            Err(ReadlineError::Eof) => break,
            Err(e) => return Err(crate::Error::Input(format!("line editor: {e}"))),
        }
    }
    Ok(())
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
        Ok(v) => v.to_string(),
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
        Err(e) => format!("error: {}", describe_error("<repl>", e)),
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
