//! `:help` and `:help NAME`. One function's help is its signatures as the engine registered
//! them (parameter and return types, [`Catalogue`]) followed by the rows of the script API
//! reference (docs/script-api.md, compiled into the binary) that document it, so the REPL
//! says what the reference says.

use super::catalogue::Catalogue;

/// The script API reference, as shipped in the repository.
const REFERENCE: &str = include_str!("../../../docs/script-api.md");

pub const OVERVIEW: &str = "\
Rhai lines are evaluated in a persistent scope; a statement left open (`let x = 1 +`,
an unclosed bracket) continues on the next line. TAB completes functions, methods,
settings keys and tool names. Useful calls on a simulation `sim`:
  sim.step()                      one increment; prints a one-line summary (time, tool
                                  positions, iterations, last residuals, cutbacks, active
                                  nodes) and returns the report map (`let r = sim.step();`
                                  `r.residuals`, or `print(r)` for all of it)
  sim.run()                       run to the end time
  sim.run_step()                  run to the end of the current step (sim.steps([...]))
  sim.time                        current pseudo-time
  sim.tool_force(\"punch\")         total force on a tool [fx, fy, fz]
  sim.contact_nodes(\"punch\")      state of every candidate node of a tool
  sim.contact_node(\"punch\", 12)   one node's state: status, gap, lambda_n, lambda_t, work, mu
  sim.node_history(\"punch\", 12)   that node's work, mu and status over the increments
  sim.displacement(node)          a node's displacement
  sim.write_frame()               write a VTK frame now
  sim.history()                   one report per converged increment (r.time, r.iterations, ...)
  sim.rollback()                  undo the last converged increment (sim.rollback(n): n of them)
  sim.settings(#{...})            change stepping settings (step_control, dt_max, ...) and step on
  sim.checkpoint(\"name.json\")     save the committed state below the output folder
Numbers are shown to 6 significant digits (print(x) shows them in full).
Commands: :help, :help NAME (one function), :quit";

/// The help of one function, or a message naming the closest names when there is none.
pub fn function_help(catalogue: &Catalogue, name: &str) -> String {
    let signatures: Vec<&str> = catalogue
        .signatures(name)
        .map(|f| f.signature.as_str())
        .collect();
    if signatures.is_empty() {
        let mut near: Vec<&str> = catalogue
            .functions
            .iter()
            .map(|f| f.name.as_str())
            .filter(|n| n.contains(name) || name.contains(*n))
            .collect();
        near.dedup();
        return if near.is_empty() {
            format!("no function named '{name}' (TAB after `:help ` lists them)")
        } else {
            format!("no function named '{name}'; similar: {}", near.join(", "))
        };
    }
    let mut text = signatures.join("\n");
    let rows = reference_rows(name);
    if rows.is_empty() {
        text.push_str("\n  (not described in docs/script-api.md)");
    }
    for (call, meaning) in rows {
        let call = call.replace('`', "");
        let items = keyed_items(&meaning);
        if items.len() > 3 {
            // A list of keys (sim.settings): a table, one key per row, wrapped.
            text.push_str(&format!("\n  {call}:"));
            text.push_str(&table(&items));
        } else {
            let row = format!("  {call}: {}", meaning.replace('`', ""));
            text.push_str(&wrap(&row, 4));
        }
    }
    text
}

/// Width of the help's lines.
const WIDTH: usize = 100;

/// A meaning cell that lists keys (`key` (what), `key`: what; ...) split into (key, what),
/// at the commas and semicolons outside brackets that start a new `key`. A sentence after
/// the list is kept as a row with no key. Empty unless the cell starts with a key.
fn keyed_items(meaning: &str) -> Vec<(String, String)> {
    let mut items: Vec<(String, String)> = Vec::new();
    let mut current = String::new();
    let mut depth = 0i32;
    let chars: Vec<char> = meaning.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        depth += match c {
            '(' | '[' | '{' => 1,
            ')' | ']' | '}' => -1,
            _ => 0,
        };
        let next_key = chars.get(i + 1) == Some(&' ') && chars.get(i + 2) == Some(&'`');
        let sentence = c == '.'
            && chars.get(i + 1) == Some(&' ')
            && chars.get(i + 2).is_some_and(|c| c.is_uppercase());
        if depth == 0 && ((",;".contains(c) && next_key) || sentence) {
            if sentence {
                current.push('.');
            }
            items.push(split_key(&current));
            current.clear();
            i += 2;
            continue;
        }
        current.push(c);
        i += 1;
    }
    items.push(split_key(&current));
    if items.first().is_none_or(|(k, _)| k.is_empty()) {
        return Vec::new();
    }
    items
}

/// "`key` (what)" -> ("key", "(what)"); text without a leading key -> ("", text).
fn split_key(item: &str) -> (String, String) {
    let item = item.trim();
    match item.strip_prefix('`').and_then(|r| r.split_once('`')) {
        Some((key, rest)) => (
            key.to_string(),
            rest.trim_start_matches(':').trim().replace('`', ""),
        ),
        None => (String::new(), item.replace('`', "")),
    }
}

/// `text` as lines of at most [`WIDTH`] (a longer word alone on its line), each after the
/// first indented by `indent`; every line starts with a newline.
fn wrap(text: &str, indent: usize) -> String {
    let lead = text.len() - text.trim_start().len();
    let mut out = String::new();
    let mut line = " ".repeat(lead);
    for word in text.split_whitespace() {
        if !line.trim().is_empty() && line.len() + 1 + word.len() > WIDTH {
            out.push('\n');
            out.push_str(&line);
            line = " ".repeat(indent);
        }
        if !line.trim().is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    out.push('\n');
    out.push_str(&line);
    out
}

/// Rows `  key   what`, the meanings wrapped at [`WIDTH`] under their column.
fn table(items: &[(String, String)]) -> String {
    let column = items
        .iter()
        .map(|(k, _)| k.len())
        .max()
        .unwrap_or(0)
        .min(30)
        + 4;
    let mut text = String::new();
    for (key, what) in items {
        let mut line = format!("    {key:<w$}", w = column - 2);
        for word in what.split_whitespace() {
            if line.len() + 1 + word.len() > WIDTH && line.trim().len() > key.len() {
                text.push('\n');
                text.push_str(&line);
                line = " ".repeat(column + 2);
            }
            if !line.ends_with(' ') {
                line.push(' ');
            }
            line.push_str(word);
        }
        text.push('\n');
        text.push_str(&line);
    }
    text
}

/// The (call, meaning) rows of the reference's tables whose call column names `name` as a
/// function, method or property.
fn reference_rows(name: &str) -> Vec<(String, String)> {
    REFERENCE
        .lines()
        .filter(|l| l.starts_with("| `") || l.starts_with("| ..."))
        .filter_map(|l| {
            let cells = split_row(l);
            let (call, meaning) = (cells.first()?, cells.get(1)?);
            let documented = names_in(call).any(|n| n == name);
            documented.then(|| (call.replace("\\|", "|"), meaning.replace("\\|", "|")))
        })
        .collect()
}

/// Cells of a markdown table row (`\|` inside a cell is not a separator).
fn split_row(line: &str) -> Vec<String> {
    let body = line.trim().trim_start_matches('|').trim_end_matches('|');
    let mut cells = vec![String::new()];
    let mut chars = body.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '\\' && chars.peek() == Some(&'|') {
            cells.last_mut().expect("one cell").push_str("\\|");
            chars.next();
        } else if c == '|' {
            cells.push(String::new());
        } else {
            cells.last_mut().expect("one cell").push(c);
        }
    }
    cells.into_iter().map(|c| c.trim().to_string()).collect()
}

/// Identifiers called or read as properties in a call column: `sim.tool_force(name)` gives
/// `tool_force`; `mesh.n_nodes` gives `n_nodes`; `block(origin, ...)` gives `block`.
fn names_in(call: &str) -> impl Iterator<Item = &str> {
    let mut names = Vec::new();
    for span in call.split('`').skip(1).step_by(2) {
        let bytes = span.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            if bytes[i].is_ascii_alphabetic() || bytes[i] == b'_' {
                let start = i;
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                let after_dot = start > 0 && bytes[start - 1] == b'.';
                let called = bytes.get(i) == Some(&b'(');
                if called || after_dot {
                    names.push(&span[start..i]);
                }
            } else {
                i += 1;
            }
        }
    }
    names.into_iter()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::{engine, HostOptions};

    #[test]
    fn one_function_with_its_signature_and_reference_rows() {
        let catalogue = Catalogue::of(&engine(&HostOptions::default(), None));
        let h = function_help(&catalogue, "tool_force");
        assert!(
            h.starts_with("tool_force(Simulation, string) -> array\n"),
            "{h}"
        );
        assert!(
            h.contains("sim.tool_force(name): total force the body exerts on the tool"),
            "{h}"
        );
        let b = function_help(&catalogue, "bernstein");
        assert!(b.contains("work per unit area"), "{b}");
        let m = function_help(&catalogue, "n_nodes");
        assert!(m.contains("mesh.n_nodes"), "{m}");
        assert!(function_help(&catalogue, "tool_forse").starts_with("no function named"));
        assert!(function_help(&catalogue, "force").contains("tool_force"));
    }

    /// `:help settings` is a table: one key per row, every line within the width (a
    /// word longer than the line aside); it was one 3,000-character paragraph.
    #[test]
    fn help_on_settings_is_a_table_of_keys() {
        let catalogue = Catalogue::of(&engine(&HostOptions::default(), None));
        let h = function_help(&catalogue, "settings");
        let lines: Vec<&str> = h.lines().collect();
        let long: Vec<&&str> = lines
            .iter()
            .filter(|l| l.len() > WIDTH && l.trim().contains(' '))
            .collect();
        assert!(long.is_empty(), "lines over {WIDTH}: {long:?}");
        // The keys the reference's sim.settings rows list (others, such as output_interval,
        // are documented in rows of their own), one row each.
        let rows = lines
            .iter()
            .filter(|l| l.starts_with("    ") && !l.starts_with("     "));
        assert!(rows.count() >= 30, "{h}");
        for key in [
            "increments",
            "end_time",
            "kinematics",
            "linear_solver",
            "step_control",
            "dt_min",
            "anti_cycling",
            "checkpoint_every",
        ] {
            let row = format!("    {key} ");
            assert!(
                lines.iter().any(|l| l.starts_with(&row)),
                "no row for {key} in:\n{h}"
            );
        }
    }

    #[test]
    fn escaped_bars_stay_in_their_cell() {
        let cells = split_row("| `mesh.select(\"n\", \\|x, y, z\\| x < 1.0)` | defines a set |");
        assert_eq!(cells.len(), 2);
        assert_eq!(names_in(&cells[0]).collect::<Vec<_>>(), ["select"]);
    }
}

#[cfg(test)]
mod coverage {
    use super::*;
    use crate::script::{engine, HostOptions};

    /// Every function a script can call is described in docs/script-api.md (so `:help NAME`
    /// always has a meaning to show, and the reference is complete).
    #[test]
    fn every_registered_function_is_in_the_reference() {
        let catalogue = Catalogue::of(&engine(&HostOptions::default(), None));
        let mut missing: Vec<&str> = catalogue
            .functions
            .iter()
            .map(|f| f.name.as_str())
            .filter(|n| reference_rows(n).is_empty())
            .collect();
        missing.dedup();
        assert!(missing.is_empty(), "not in docs/script-api.md: {missing:?}");
    }
}
