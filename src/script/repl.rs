//! Interactive stepping: `tribo repl [SCRIPT]`.
//!
//! Lines are evaluated in one persistent scope. A script given on the command line is run
//! first with `sim.run()` deferred, so its scene can be stepped by hand.

use super::{compile, describe_error, engine, HostOptions};
use crate::Result;
use rhai::{Dynamic, Scope};
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
                match engine.eval_with_scope::<Dynamic>(&mut scope, line) {
                    Ok(v) if v.is_unit() => {}
                    Ok(v) => println!("{v}"),
                    Err(e) => println!("error: {}", describe_error("<repl>", &e)),
                }
            }
            Err(ReadlineError::Interrupted) => continue,
            Err(ReadlineError::Eof) => break,
            Err(e) => return Err(crate::Error::Input(format!("line editor: {e}"))),
        }
    }
    Ok(())
}
