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

#[cfg(test)]
mod tests {
    use crate::mesh::Mesh;
    use crate::script::{engine, HostOptions};

    fn eval(src: &str) -> Result<Mesh, String> {
        engine(&HostOptions::default(), None)
            .eval::<Mesh>(src)
            .map_err(|e| e.to_string())
    }

    /// Defaults follow the keys given (transition rows = core cells; circles from twice
    /// the core size); the quarter has the symmetry-plane sets; bad keys and values are
    /// named.
    #[test]
    fn round_blank_from_a_script() {
        let m = eval("round_blank(#{ radius: 50, thickness: 1.0, quarter: true, core_cells: 2, core_size: 5.0, ring_cells: 3 })")
            .unwrap();
        // Core 3 x 3 points, 5 rays x (2 transition + 3 ring) rows, 2 layers of points.
        assert_eq!(m.node_count(), (9 + 5 * 5) * 2);
        assert!(m.node_set("x-").is_ok() && m.node_set("rim").is_ok());
        let rim_at = m.node_set("rim").unwrap()[0];
        assert!((m.nodes[rim_at].x.hypot(m.nodes[rim_at].y) - 50.0).abs() < 1e-12);

        let e = eval("round_blank(#{ radius: 50.0 })").unwrap_err();
        assert!(e.contains("round_blank needs the key `thickness`"), "{e}");
        let e = eval("round_blank(#{ radius: 50.0, thickness: 1.0, cells: 3 })").unwrap_err();
        assert!(e.contains("unknown key `cells`"), "{e}");
        let e = eval("round_blank(#{ radius: 50.0, thickness: 1.0, layers: 0 })").unwrap_err();
        assert!(e.contains("round_blank.layers = 0 must be >= 1"), "{e}");
        let e =
            eval("round_blank(#{ radius: 50.0, thickness: 1.0, core_cells: 2.5 })").unwrap_err();
        assert!(e.contains("core_cells must be an integer"), "{e}");
        let e = eval("round_blank(#{ radius: 50.0, thickness: 1.0, quarter: 1 })").unwrap_err();
        assert!(e.contains("quarter must be true or false"), "{e}");
        let e =
            eval("round_blank(#{ radius: 50.0, thickness: 1.0, round_radius: 80.0 })").unwrap_err();
        assert!(
            e.contains("round_radius = 80 must be < the radius 50"),
            "{e}"
        );
    }
}
