//! What the engine says about its own functions: names, parameter types and return types
//! from Rhai's metadata (`Engine::gen_fn_signatures`), so that completion and `:help` list
//! exactly what a script can call, with nothing kept by hand beside the registrations.

use rhai::Engine;

/// One registered function (or property getter), parsed from its signature.
#[derive(Clone, Debug, PartialEq)]
pub struct Function {
    /// Name as called from a script (`tool_force`; a getter's property name, `time`).
    pub name: String,
    /// Parameter types, as the engine names them (`Simulation`, `&str`, `Array`, ...).
    pub params: Vec<String>,
    /// Whether this is a property getter (`sim.time`), not a call.
    pub property: bool,
    /// Return type (empty for none).
    pub returns: String,
    /// The signature for a reader: `tool_force(Simulation, string) -> array`.
    pub signature: String,
}

/// Every function the engine has registered outside Rhai's standard packages.
#[derive(Clone, Debug, Default)]
pub struct Catalogue {
    pub functions: Vec<Function>,
}

impl Catalogue {
    pub fn of(engine: &Engine) -> Catalogue {
        let mut functions: Vec<Function> = engine
            .gen_fn_signatures(false)
            .iter()
            .filter_map(|s| parse(s, &|t: &str| display_type(engine, t)))
            .collect();
        functions.sort_by(|a, b| a.name.cmp(&b.name).then(a.signature.cmp(&b.signature)));
        functions.dedup_by(|a, b| a.signature == b.signature);
        Catalogue { functions }
    }

    /// Names callable on a value of type `receiver` (`sim.` + TAB): functions whose first
    /// parameter has that type and its properties; any type (`None`): every function with
    /// a parameter.
    pub fn methods<'a>(&'a self, receiver: Option<&'a str>) -> impl Iterator<Item = &'a str> {
        self.functions
            .iter()
            .filter(move |f| match (receiver, f.params.first()) {
                (_, None) => false,
                (None, Some(_)) => true,
                (Some(t), Some(p)) => p == t,
            })
            .map(|f| f.name.as_str())
    }

    /// Names callable as free functions (`block(`, `tool(`).
    pub fn free_functions(&self) -> impl Iterator<Item = &str> {
        self.functions
            .iter()
            .filter(|f| !f.property)
            .map(|f| f.name.as_str())
    }

    /// Every signature of `name`.
    pub fn signatures<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Function> {
        self.functions.iter().filter(move |f| f.name == name)
    }
}

/// A type as Rhai names it to a script writer: registered types by their script names,
/// `Result<T, _>` as `T`, Rust's paths dropped (`alloc::vec::Vec<Dynamic>` is an `array`).
fn display_type(engine: &Engine, rust: &str) -> String {
    let t = rust
        .trim()
        .trim_start_matches("&mut ")
        .trim_start_matches('&')
        .trim();
    let t = engine.map_type_name(t);
    if let Some(inner) = t
        .strip_prefix("core::result::Result<")
        .or_else(|| t.strip_prefix("Result<"))
    {
        let ok = split_top_level(inner.strip_suffix('>').unwrap_or(inner));
        return display_type(engine, ok.first().map_or("", String::as_str));
    }
    match t {
        "()" => String::new(),
        "str"
        | "String"
        | "alloc::string::String"
        | "rhai::ImmutableString"
        | "ImmutableString"
        | "string" => "string".into(),
        "i64" | "int" => "int".into(),
        "f64" | "float" => "float".into(),
        _ if t.contains("Vec<") || t == "Array" => "array".into(),
        _ if t.contains("BTreeMap<") || t == "Map" => "map".into(),
        _ if t.contains("::") => {
            let head = t.split('<').next().unwrap_or(t);
            head.rsplit("::").next().unwrap_or(head).to_string()
        }
        _ => t.to_string(),
    }
}

/// Parses `name(_: A, _: B) -> R`, naming types with `types`; operators and internal
/// functions (`+`, `index$get$`, setters) are left out. A getter `get$time(_: Simulation)
/// -> f64` becomes the property `time`.
fn parse(signature: &str, types: &dyn Fn(&str) -> String) -> Option<Function> {
    let open = signature.find('(')?;
    let raw_name = &signature[..open];
    let (name, property) = match raw_name.strip_prefix("get$") {
        Some(p) => (p, true),
        None => (raw_name, false),
    };
    let identifier = name
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_alphanumeric() || c == '_');
    if !identifier {
        return None;
    }
    let mut depth = 0usize;
    let mut close = None;
    for (i, c) in signature[open..].char_indices() {
        match c {
            '(' | '<' | '[' => depth += 1,
            ')' | '>' | ']' => {
                depth = depth.saturating_sub(1);
                if depth == 0 && c == ')' {
                    close = Some(open + i);
                    break;
                }
            }
            _ => {}
        }
    }
    let close = close?;
    let params: Vec<String> = split_top_level(&signature[open + 1..close])
        .into_iter()
        .filter(|p| !p.is_empty())
        .map(|p| types(p.split_once(':').map_or(p.as_str(), |(_, t)| t)))
        .collect();
    let returns = signature[close + 1..]
        .trim()
        .strip_prefix("->")
        .map_or(String::new(), types);
    let mut text = format!("{name}({})", params.join(", "));
    if property {
        text = format!("{}.{name}", params.first().map_or("_", String::as_str));
    }
    if !returns.is_empty() {
        text.push_str(&format!(" -> {returns}"));
    }
    Some(Function {
        name: name.to_string(),
        params,
        property,
        returns,
        signature: text,
    })
}

/// Splits at the commas that are not inside brackets.
fn split_top_level(text: &str) -> Vec<String> {
    let (mut parts, mut current, mut depth) = (Vec::new(), String::new(), 0usize);
    for c in text.chars() {
        match c {
            '(' | '<' | '[' => depth += 1,
            ')' | '>' | ']' => depth = depth.saturating_sub(1),
            ',' if depth == 0 => {
                parts.push(current.trim().to_string());
                current.clear();
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    parts.push(current.trim().to_string());
    parts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::{engine, HostOptions};

    #[test]
    fn parses_calls_and_getters_and_skips_operators() {
        let engine = Engine::new();
        let types = |t: &str| display_type(&engine, t);
        let f = parse(
            "tool_force(_: &mut Simulation, _: string) -> core::result::Result<alloc::vec::Vec<rhai::types::dynamic::Dynamic>,alloc::boxed::Box<rhai::types::error::EvalAltResult>>",
            &types,
        )
        .unwrap();
        assert_eq!(f.name, "tool_force");
        assert_eq!(f.params, ["Simulation", "string"]);
        assert!(!f.property);
        assert_eq!(f.signature, "tool_force(Simulation, string) -> array");
        let g = parse("get$time(_: &mut Simulation) -> f64", &types).unwrap();
        assert_eq!((g.name.as_str(), g.property), ("time", true));
        assert_eq!(g.params, ["Simulation"]);
        assert_eq!(g.signature, "Simulation.time -> float");
        assert!(parse("+(_: Vec3, _: Vec3) -> Vec3", &types).is_none());
        assert!(parse("set$x(_: A, _: f64)", &types).is_none());
        let h = parse(
            "f(_: alloc::collections::btree::map::BTreeMap<smartstring::SmartString, rhai::Dynamic>, _: i64) -> ()",
            &types,
        )
        .unwrap();
        assert_eq!(h.params, ["map", "int"]);
        assert_eq!(h.signature, "f(map, int)");
    }

    #[test]
    fn the_engine_lists_the_simulation_api() {
        let engine = engine(&HostOptions::default(), None);
        let c = Catalogue::of(&engine);
        let sim_methods: Vec<&str> = c.methods(Some("Simulation")).collect();
        for m in ["step", "run", "tool_force", "rollback", "settings", "time"] {
            assert!(sim_methods.contains(&m), "{m} missing from {sim_methods:?}");
        }
        assert!(!sim_methods.contains(&"block"));
        let free: Vec<&str> = c.free_functions().collect();
        for f in [
            "block",
            "simulation",
            "tool",
            "cylinder",
            "coulomb",
            "bernstein",
        ] {
            assert!(free.contains(&f), "{f} missing");
        }
        assert!(c.signatures("tool_force").any(|f| f.params.len() == 2));
    }
}
