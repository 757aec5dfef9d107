//! Tab completion in the REPL. Names come from the engine and the session, never from a
//! list kept here: functions and methods from the engine's metadata ([`Catalogue`]), the
//! variables of the REPL's scope with their types, the keys `sim.settings` accepts
//! ([`crate::script::SETTING_KEYS`]) and the tools of the simulations the session built.
//!
//! What is offered depends on where the cursor is:
//! - inside a string literal: tool names (`sim.tool_force("ro` -> `roller`);
//! - after `value.`: the methods and properties of the value's type (every method when the
//!   value is not a variable);
//! - inside `settings(#{ ... }` at a key's place: setting keys;
//! - after `:help `: function names; after `:`: the REPL's commands;
//! - elsewhere: free functions and variables.

use super::catalogue::Catalogue;
use rustyline::completion::Completer;
use rustyline::highlight::Highlighter;
use rustyline::hint::Hinter;
use rustyline::validate::Validator;
use rustyline::Helper;
use std::cell::RefCell;

/// What the session holds, refreshed after every evaluated line.
#[derive(Clone, Debug, Default)]
pub struct Session {
    /// Variables in scope with the engine's name of their type.
    pub variables: Vec<(String, String)>,
    /// Tools of every simulation built so far.
    pub tools: Vec<String>,
}

/// The REPL's rustyline helper: completion only (no hints, highlighting or validation;
/// multi-line input is handled by the REPL loop so that it works on any terminal).
pub struct ReplHelper {
    pub catalogue: Catalogue,
    pub session: RefCell<Session>,
}

/// The REPL's own commands (completed after `:`).
pub const COMMANDS: &[&str] = &[":help", ":quit"];

impl ReplHelper {
    /// Start of the word being completed and the candidates, sorted, without duplicates.
    pub fn candidates(&self, line: &str, pos: usize) -> (usize, Vec<String>) {
        let before = &line[..pos];
        let session = self.session.borrow();
        let (start, found): (usize, Vec<&str>) = if let Some(q) = open_string(before) {
            (q + 1, session.tools.iter().map(String::as_str).collect())
        } else {
            let start = before
                .char_indices()
                .rev()
                .take_while(|(_, c)| c.is_alphanumeric() || *c == '_')
                .last()
                .map_or(pos, |(i, _)| i);
            let head = before[..start].trim_end();
            let found: Vec<&str> = if head == ":help" || head == ":h" {
                self.catalogue
                    .functions
                    .iter()
                    .map(|f| f.name.as_str())
                    .collect()
            } else if before[..start].ends_with(':') && head == ":" {
                return (
                    start - 1,
                    COMMANDS
                        .iter()
                        .filter(|c| c.starts_with(&before[start - 1..]))
                        .map(|c| c.to_string())
                        .collect(),
                );
            } else if let Some(receiver) = before[..start].strip_suffix('.') {
                let var = receiver
                    .rsplit(|c: char| !(c.is_alphanumeric() || c == '_'))
                    .next()
                    .unwrap_or("");
                let typ = session
                    .variables
                    .iter()
                    .find(|(n, _)| n == var)
                    .map(|(_, t)| t.as_str());
                self.catalogue.methods(typ).collect()
            } else if in_settings_key(&before[..start]) {
                crate::script::SETTING_KEYS.to_vec()
            } else {
                self.catalogue
                    .free_functions()
                    .chain(session.variables.iter().map(|(n, _)| n.as_str()))
                    .collect()
            };
            (start, found)
        };
        let prefix = &before[start..];
        let mut out: Vec<String> = found
            .into_iter()
            .filter(|n| n.starts_with(prefix))
            .map(str::to_string)
            .collect();
        out.sort();
        out.dedup();
        (start, out)
    }
}

/// Byte index of the opening quote when `text` ends inside a string literal.
fn open_string(text: &str) -> Option<usize> {
    let mut open = None;
    let mut escaped = false;
    for (i, c) in text.char_indices() {
        match (c, open) {
            ('\\', Some(_)) if !escaped => {
                escaped = true;
                continue;
            }
            ('"', None) => open = Some(i),
            ('"', Some(_)) if !escaped => open = None,
            _ => {}
        }
        escaped = false;
    }
    open
}

/// Whether the text ends at a key's place inside `settings(#{ ... }`: after `#{` or a `,`
/// with no `}` closing the map.
fn in_settings_key(text: &str) -> bool {
    let Some(at) = text.rfind("settings(#{") else {
        return false;
    };
    let inside = &text[at + "settings(#{".len()..];
    if inside.contains('}') {
        return false;
    }
    let last = inside.trim_end();
    last.is_empty() || last.ends_with(',')
}

impl Completer for ReplHelper {
    type Candidate = String;

    fn complete(
        &self,
        line: &str,
        pos: usize,
        _ctx: &rustyline::Context<'_>,
    ) -> rustyline::Result<(usize, Vec<String>)> {
        Ok(self.candidates(line, pos))
    }
}

impl Hinter for ReplHelper {
    type Hint = String;
}
impl Highlighter for ReplHelper {}
impl Validator for ReplHelper {}
impl Helper for ReplHelper {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::{engine, HostOptions};

    fn helper() -> ReplHelper {
        let engine = engine(&HostOptions::default(), None);
        ReplHelper {
            catalogue: Catalogue::of(&engine),
            session: RefCell::new(Session {
                variables: vec![
                    ("sim".into(), "Simulation".into()),
                    ("mesh".into(), "Mesh".into()),
                ],
                tools: vec!["roller".into(), "punch".into()],
            }),
        }
    }

    fn complete(line: &str) -> (usize, Vec<String>) {
        helper().candidates(line, line.len())
    }

    #[test]
    fn methods_of_the_variable_type() {
        assert_eq!(complete("sim.tool_f"), (4, vec!["tool_force".to_string()]));
        let (_, all) = complete("sim.");
        assert!(all.contains(&"step".to_string()) && all.contains(&"time".to_string()));
        assert!(
            !all.contains(&"n_nodes".to_string()),
            "a mesh property offered on sim"
        );
        assert_eq!(complete("mesh.n_n").1, ["n_nodes"]);
    }

    #[test]
    fn free_functions_variables_settings_tools_and_commands() {
        let (start, c) = complete("let m = bloc");
        assert_eq!(
            (start, c),
            (8, vec!["block".to_string(), "block_lines".to_string()])
        );
        assert_eq!(complete("si").1, ["sig", "sim", "simulation"]);
        assert_eq!(
            complete("sim.settings(#{ step_control: \"adaptive\", max_sl").1,
            ["max_slip_increment"]
        );
        assert_eq!(complete("sim.settings(#{ end_").1, ["end_time"]);
        assert_eq!(
            complete("sim.tool_force(\"ro"),
            (16, vec!["roller".to_string()])
        );
        assert_eq!(complete(":he"), (0, vec![":help".to_string()]));
        assert_eq!(complete(":help tool_p").1, ["tool_position"]);
        // A value after a key is not a key.
        assert!(!complete("sim.settings(#{ end_time: inc")
            .1
            .contains(&"increments".to_string()));
    }
}
