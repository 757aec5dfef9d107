//! What a script friction law is, for the checkpoint's fingerprint: the source text of the
//! function a script gives `tool.friction(...)`, so that a restart whose law has another
//! body is refused (issue 52; mu at zero work alone let such a change through).
//!
//! Rhai keeps no source text, and the name it gives a closure (`anon$` and a hash of its
//! syntax tree) hashes source positions too, so that an edit elsewhere in the file would
//! change it. The text is therefore taken from the script's source ([`super::HostOptions`]
//! keeps every compiled script's text by its source name): the argument list of the
//! `friction` call at the call's position, read to its matching `)` by a scanner that skips
//! string literals and comments, and for a law named by a function (`friction(my_law)`) that
//! function's definition as well. The values a closure captured (`let k = 0.1; |w, s, p| k`)
//! are added as Rhai prints them.
//!
//! The law's description is `script function <text> [source fnv1a <16 hex digits>]`: the text
//! on one line (runs of white space collapsed, so re-indenting is no change; a comment inside
//! the call is) shortened to [`SHOWN`] characters for messages, the hash over all of it
//! (FNV-1a, the checkpoint's hash). Where the text cannot be found (a line typed in the REPL,
//! a std-lib module), the function's Rhai name stands in for it.

use rhai::FnPtr;

/// Characters of a law's text shown in its description (the hash covers all of it).
pub const SHOWN: usize = 80;

/// The description of the script friction law `law` given by the `friction` call at
/// (`line`, `column`) (1-based, Rhai's positions) of `source`, if known.
pub fn describe(law: &FnPtr, source: Option<&str>, line: usize, column: usize) -> String {
    let mut text = source
        .and_then(|s| call_arguments(s, line, column, "friction"))
        .map_or_else(|| law.fn_name().to_string(), one_line);
    if !law.fn_name().starts_with("anon$") {
        if let Some(def) = source.and_then(|s| fn_definition(s, law.fn_name())) {
            text = format!("{text}; {}", one_line(def));
        }
    }
    let captured: Vec<String> = law.curry().iter().map(|v| v.to_string()).collect();
    if !captured.is_empty() {
        text = format!("{text}; captured {}", captured.join(", "));
    }
    let hash = crate::solver::simulation::checkpoint::fnv1a(text.bytes());
    let shown: String = text.chars().take(SHOWN).collect();
    let more = if shown.len() < text.len() { " ..." } else { "" };
    format!("script function {shown}{more} [source fnv1a {hash}]")
}

/// `text` on one line: runs of white space as one space.
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Byte offset of (`line`, `column`) in `source` (1-based; the column counts characters).
fn offset(source: &str, line: usize, column: usize) -> Option<usize> {
    let start: usize = source
        .split_inclusive('\n')
        .take(line.checked_sub(1)?)
        .map(str::len)
        .sum();
    let rest = source.get(start..)?;
    let within = rest
        .char_indices()
        .nth(column.saturating_sub(1))
        .map_or(rest.len(), |(i, _)| i);
    Some(start + within)
}

/// The text between the parentheses of the call of `name` at or after (`line`, `column`).
fn call_arguments<'a>(source: &'a str, line: usize, column: usize, name: &str) -> Option<&'a str> {
    let at = offset(source, line, column)?;
    let found = at + source.get(at..)?.find(name)?;
    let after = found + name.len();
    let open = after + source[after..].len() - source[after..].trim_start().len();
    if !source[open..].starts_with('(') {
        return None;
    }
    let close = matching(source, open)?;
    Some(source[open + 1..close].trim())
}

/// The definition `fn name(...) { ... }` in `source`, whole.
fn fn_definition<'a>(source: &'a str, name: &str) -> Option<&'a str> {
    let pattern = format!("fn {name}");
    let mut from = 0;
    while let Some(k) = source[from..].find(&pattern) {
        let start = from + k;
        let after = start + pattern.len();
        let rest = source[after..].trim_start();
        let word_before = source[..start]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_');
        if rest.starts_with('(') && !word_before {
            let open_paren = source.len() - rest.len();
            let close_paren = matching(source, open_paren)?;
            let brace = close_paren + 1 + source[close_paren + 1..].find('{')?;
            let end = matching(source, brace)?;
            return Some(&source[start..=end]);
        }
        from = after;
    }
    None
}

/// Index of the bracket closing the one at `open` (`(`, `[` or `{`), skipping string and
/// character literals and comments; `None` if the text ends first.
fn matching(source: &str, open: usize) -> Option<usize> {
    let bytes = source.as_bytes();
    let mut depth = 0usize;
    let mut i = open;
    while i < bytes.len() {
        match bytes[i] {
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => {
                depth = depth.checked_sub(1)?;
                if depth == 0 {
                    return Some(i);
                }
            }
            quote @ (b'"' | b'\'' | b'`') => i = literal_end(bytes, i, quote)?,
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i += source[i..].find('\n').unwrap_or(source.len() - i);
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                i += 2 + source[i + 2..].find("*/")? + 1;
            }
            _ => {}
        }
        i += 1;
    }
    None
}

/// Index of the quote closing the literal that opens at `start` (a backslash escapes the
/// next byte).
fn literal_end(bytes: &[u8], start: usize, quote: u8) -> Option<usize> {
    let mut i = start + 1;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 1,
            b if b == quote => return Some(i),
            _ => {}
        }
        i += 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_call_text_is_read_to_its_matching_parenthesis() {
        let src = "let t = tool(\"a\", p);\nt.friction(|w, s, p| {\n  // a ) in a comment\n  \
                   if w > 1.0 { 0.2 } else { 0.1 + \")\".len() * 0.0 }\n}); let z = (1);\n";
        let text = call_arguments(src, 2, 3, "friction").unwrap();
        assert!(
            text.starts_with("|w, s, p| {") && text.ends_with('}'),
            "{text}"
        );
        assert!(text.contains("\")\".len()"), "{text}");
    }

    #[test]
    fn a_named_law_brings_its_definition() {
        let src = "fn other(a) { a }\nfn law(w, s, p) { if w > 0.0 { 0.3 } else { 0.2 } }\n\
                   t.friction(law);\n";
        assert_eq!(
            fn_definition(src, "law").unwrap(),
            "fn law(w, s, p) { if w > 0.0 { 0.3 } else { 0.2 } }"
        );
        assert!(fn_definition(src, "aw").is_none());
        assert_eq!(call_arguments(src, 3, 1, "friction"), Some("law"));
    }

    #[test]
    fn positions_count_characters_and_missing_text_is_none() {
        let src = "é.friction(x)\n";
        assert_eq!(call_arguments(src, 1, 2, "friction"), Some("x"));
        assert_eq!(call_arguments(src, 3, 1, "friction"), None);
        assert_eq!(call_arguments("t.friction(|w| (w)", 1, 1, "friction"), None);
    }
}
