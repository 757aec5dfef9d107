//! `round_blank(#{...})`: the O-grid round or quarter-round blank (`mesh/ogrid.rs`) for
//! scripts. Registered in one place.

use super::convert::*;
use crate::mesh::{Mesh, RoundBlank};
use rhai::{Engine, Map};

const KEYS: &[&str] = &[
    "radius",
    "thickness",
    "quarter",
    "core_cells",
    "core_size",
    "round_radius",
    "transition_cells",
    "ring_cells",
    "ring_ratio",
    "layers",
];

fn size(spec: &Map, key: &str, default: Option<f64>) -> ScriptResult<f64> {
    match (spec.get(key), default) {
        (Some(v), _) => number(v, &format!("round_blank.{key}")),
        (None, Some(d)) => Ok(d),
        (None, None) => runtime_error(format!("round_blank needs the key `{key}`")),
    }
}

fn count(spec: &Map, key: &str, default: usize) -> ScriptResult<usize> {
    let Some(v) = spec.get(key) else {
        return Ok(default);
    };
    match v.as_int() {
        Ok(n) if n >= 1 => Ok(n as usize),
        Ok(n) => runtime_error(format!("round_blank.{key} = {n} must be >= 1")),
        Err(t) => runtime_error(format!("round_blank.{key} must be an integer, got {t}")),
    }
}

/// The blank `spec` describes, with the defaults of [`RoundBlank::new`] for the keys it
/// leaves out (round_radius defaults to twice the core size, transition_cells to
/// core_cells, ring_cells to cells about as wide as the rim cells).
fn parse(spec: &Map) -> ScriptResult<RoundBlank> {
    if let Some(key) = spec.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return runtime_error(format!(
            "round_blank: unknown key `{key}` (keys: {})",
            KEYS.join(", ")
        ));
    }
    let mut b = RoundBlank::new(size(spec, "radius", None)?, size(spec, "thickness", None)?);
    b.quarter = match spec.get("quarter") {
        Some(v) => v
            .as_bool()
            .or_else(|_| runtime_error("round_blank.quarter must be true or false"))?,
        None => false,
    };
    b.core_cells = count(spec, "core_cells", b.core_cells)?;
    b.transition_cells = count(spec, "transition_cells", b.core_cells)?;
    b.core_size = size(spec, "core_size", Some(b.core_size))?;
    b.round_radius = size(spec, "round_radius", Some(2.0 * b.core_size))?;
    b.ring_ratio = size(spec, "ring_ratio", Some(1.0))?;
    b.layers = count(spec, "layers", 1)?;
    b.ring_cells = count(spec, "ring_cells", b.square_ring_cells())?;
    Ok(b)
}

pub fn register(engine: &mut Engine, limits: super::limits::Limits) {
    // round_blank(#{ radius, thickness, quarter, core_cells, core_size, round_radius,
    //                transition_cells, ring_cells, ring_ratio, layers })
    engine.register_fn("round_blank", move |spec: Map| -> ScriptResult<Mesh> {
        let blank = parse(&spec)?;
        if let Some(nodes) = blank.node_count() {
            limits.check_mesh(nodes as u64).or_else(runtime_error)?;
        }
        lift(Mesh::round_blank(&blank))
    });
}
