//! `tribo extrapolate FILE.json`: Richardson extrapolation ([`super::richardson`]) of mesh
//! sequences computed elsewhere (by scripts, by another code), so that a report written in any
//! language gets the study's own observed order, asymptotic-range check and GCI band instead of
//! a copy of the formulas.
//!
//! Input (a file, or `-` for standard input):
//!
//! ```json
//! { "rule": { "min": 0.5, "max": 3.0, "assumed": 1.0 },
//!   "quantities": { "DX 40": [[0.75, 26.80], [1.5, 26.61], [3.0, 26.39]], ... } }
//! ```
//!
//! each quantity three `[h, value]` pairs in any order (sorted here, finest first); `rule` is
//! optional (default: the square-cup study's, [`DEFAULT_RULE`]). Output on standard output:
//! `{ "rule": ..., "quantities": { name: Extrapolation } }` with every field of
//! [`Extrapolation`]. A quantity that cannot be extrapolated (sizes not distinct, a value not
//! finite) is an error naming it. Cost: O(quantities), each a bisection of at most 60 steps.

use super::richardson::{extrapolate, Extrapolation, Level, OrderRule};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The rule of the square-cup study (`cup_reference`): an observed order in [0.5, 3] counts as
/// asymptotic; otherwise first order is assumed (the draw-in of a contact problem converges at
/// first order once the contact zone's edge is resolved by one cell at most).
pub const DEFAULT_RULE: OrderRule = OrderRule {
    min: 0.5,
    max: 3.0,
    assumed: 1.0,
};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Input {
    rule: Option<OrderRule>,
    quantities: BTreeMap<String, Vec<[f64; 2]>>,
}

/// The extrapolation of every quantity, with the rule used.
#[derive(Debug, Serialize)]
pub struct Output {
    pub rule: OrderRule,
    pub quantities: BTreeMap<String, Extrapolation>,
}

/// Parses the input document and extrapolates each quantity. `source` names the input in
/// errors (a path or "standard input").
pub fn run(text: &str, source: &str) -> Result<Output> {
    let input: Input = serde_json::from_str(text).map_err(|e| {
        Error::Input(format!(
            "{source}: not an extrapolation input ({e}); expected {{\"rule\": {{\"min\", \"max\", \"assumed\"}} (optional), \"quantities\": {{NAME: [[h, value], [h, value], [h, value]]}}}}"
        ))
    })?;
    let rule = input.rule.unwrap_or(DEFAULT_RULE);
    let mut quantities = BTreeMap::new();
    for (name, pairs) in input.quantities {
        let levels = levels_of(&pairs)
            .ok_or_else(|| Error::Input(format!("{source}: quantity \"{name}\" has {} [h, value] pairs; a Richardson extrapolation needs exactly three", pairs.len())))?;
        let e = extrapolate(levels, rule)
            .map_err(|why| Error::Input(format!("{source}: quantity \"{name}\": {why}")))?;
        quantities.insert(name, e);
    }
    Ok(Output { rule, quantities })
}

/// Three levels, finest first, or None for another count.
fn levels_of(pairs: &[[f64; 2]]) -> Option<[Level; 3]> {
    let mut levels: Vec<Level> = pairs.iter().map(|&[h, value]| Level { h, value }).collect();
    levels.sort_by(|a, b| a.h.total_cmp(&b.h));
    levels.try_into().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_order_sequence_in_any_order_gives_its_limit_and_order() {
        // f = 2 + 0.3 h^2 on h = 1, 2, 4: the limit 2 and order 2 exactly.
        let f = |h: f64| 2.0 + 0.3 * h * h;
        let text = format!(
            r#"{{"quantities": {{"q": [[4, {}], [1, {}], [2, {}]]}}}}"#,
            f(4.0),
            f(1.0),
            f(2.0)
        );
        let out = run(&text, "test").unwrap();
        let q = &out.quantities["q"];
        assert!((q.value - 2.0).abs() < 1e-12, "{q:?}");
        assert!((q.observed_order.unwrap() - 2.0).abs() < 1e-9);
        assert!(q.asymptotic);
        assert_eq!(out.rule, DEFAULT_RULE);
    }

    #[test]
    fn bad_inputs_name_the_quantity_or_the_shape() {
        let two = run(r#"{"quantities": {"DX 15": [[1, 2], [2, 3]]}}"#, "f.json").unwrap_err();
        assert!(two.to_string().contains("\"DX 15\" has 2"), "{two}");
        let same = run(
            r#"{"quantities": {"DD": [[1, 2], [1, 3], [2, 4]]}}"#,
            "f.json",
        )
        .unwrap_err()
        .to_string();
        assert!(
            same.contains("\"DD\"") && same.contains("strictly growing"),
            "{same}"
        );
        let shape = run(r#"{"levels": []}"#, "f.json").unwrap_err().to_string();
        assert!(
            shape.contains("f.json: not an extrapolation input"),
            "{shape}"
        );
    }
}
