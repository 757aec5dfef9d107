//! Meshes from files and structured meshes beyond `block()`, for scripts: Gmsh MSH 4.1,
//! CalculiX/Abaqus decks (every read through the run's read policy), and the names of a
//! mesh's sets. Registered in one place.

use super::convert::*;
use crate::mesh::gmsh::read_gmsh;
use crate::mesh::inp::read_inp;
use crate::mesh::Mesh;
use crate::paths::ReadPolicy;
use rhai::{Array, Dynamic, Engine};
use std::path::Path;
use std::rc::Rc;

pub fn register(engine: &mut Engine, policy: Rc<ReadPolicy>, limits: super::limits::Limits) {
    register_files(engine, policy, limits.clone());
    register_structured(engine, limits);
    register_set_names(engine);
    register_round_tools(engine);
}

/// `spec.key` as a number, or `default` when absent (`None`: the key is required).
fn field(spec: &rhai::Map, key: &str, default: Option<f64>, what: &str) -> ScriptResult<f64> {
    match (spec.get(key), default) {
        (Some(v), _) => number(v, &format!("{what}.{key}")),
        (None, Some(d)) => Ok(d),
        (None, None) => runtime_error(format!("{what} needs the key `{key}`")),
    }
}

fn revolved(
    spec: &rhai::Map,
    what: &str,
    keys: &[&str],
    profile: impl Fn(&[f64]) -> crate::Result<Vec<crate::geometry::revolution::Segment>>,
) -> ScriptResult<super::api_scene::ScriptSurface> {
    use crate::geometry::revolution::{revolve, Revolution};
    for key in spec.keys() {
        if !keys.contains(&key.as_str()) && key != "level" && key != "quarter" {
            return runtime_error(format!(
                "{what}: unknown key `{key}` (keys: {}, level, quarter)",
                keys.join(", ")
            ));
        }
    }
    let values = keys
        .iter()
        .map(|k| field(spec, k, None, what))
        .collect::<ScriptResult<Vec<f64>>>()?;
    let mut args = values;
    args.push(field(spec, "level", Some(0.0), what)?);
    let quarter = match spec.get("quarter") {
        Some(v) => v
            .as_bool()
            .or_else(|_| runtime_error(format!("{what}.quarter must be true or false")))?,
        None => false,
    };
    let extent = if quarter {
        Revolution::Quarter
    } else {
        Revolution::Full
    };
    let patches = lift(revolve(&lift(profile(&args))?, extent))?;
    Ok(super::api_scene::ScriptSurface(std::sync::Arc::new(lift(
        crate::geometry::PatchSurface::new(patches),
    )?)))
}

fn register_round_tools(engine: &mut Engine) {
    use crate::geometry::revolution::{round_die, round_holder, round_punch};
    // round_punch(#{ radius, nose_radius, wall_height, level: 0, quarter: false })
    engine.register_fn("round_punch", |spec: rhai::Map| {
        revolved(
            &spec,
            "round_punch",
            &["radius", "nose_radius", "wall_height"],
            |a| round_punch(a[0], a[1], a[2], a[3]),
        )
    });
    // round_die(#{ opening_radius, entry_radius, flat_extent, wall_depth, level, quarter })
    engine.register_fn("round_die", |spec: rhai::Map| {
        revolved(
            &spec,
            "round_die",
            &[
                "opening_radius",
                "entry_radius",
                "flat_extent",
                "wall_depth",
            ],
            |a| round_die(a[0], a[1], a[2], a[3], a[4]),
        )
    });
    // round_holder(#{ inner_radius, outer_radius, level, quarter })
    engine.register_fn("round_holder", |spec: rhai::Map| {
        revolved(
            &spec,
            "round_holder",
            &["inner_radius", "outer_radius"],
            |a| round_holder(a[0], a[1], a[2]),
        )
    });
}

fn numbers(a: &Array, what: &str) -> ScriptResult<Vec<f64>> {
    a.iter()
        .enumerate()
        .map(|(i, v)| number(v, &format!("{what}[{i}]")))
        .collect()
}

fn to_array(x: &[f64]) -> Array {
    x.iter().map(|&v| Dynamic::from(v)).collect()
}

fn register_structured(engine: &mut Engine, limits: super::limits::Limits) {
    // block_lines(xs, ys, zs): the structured block on explicit node coordinates.
    engine.register_fn(
        "block_lines",
        move |x: Array, y: Array, z: Array| -> ScriptResult<Mesh> {
            let nodes = (x.len() as u64)
                .saturating_mul(y.len() as u64)
                .saturating_mul(z.len() as u64);
            limits.check_mesh(nodes).or_else(runtime_error)?;
            lift(Mesh::block_lines(
                &numbers(&x, "block_lines x")?,
                &numbers(&y, "block_lines y")?,
                &numbers(&z, "block_lines z")?,
            ))
        },
    );
    // graded_line([c0, c1], h, ratio, [e0, e1]): uniform cells h on the core, geometric
    // growth by ratio outward to the extent.
    engine.register_fn(
        "graded_line",
        |core: Array, size: Dynamic, ratio: Dynamic, extent: Array| -> ScriptResult<Array> {
            let pair = |a: &Array, what: &str| -> ScriptResult<[f64; 2]> {
                match numbers(a, what)?.as_slice() {
                    [lo, hi] => Ok([*lo, *hi]),
                    _ => runtime_error(format!("{what} must be [start, end]")),
                }
            };
            Ok(to_array(&lift(crate::mesh::core_and_growth(
                pair(&core, "graded_line core")?,
                number(&size, "graded_line cell size")?,
                number(&ratio, "graded_line ratio")?,
                pair(&extent, "graded_line extent")?,
            ))?))
        },
    );
    // a.merge(b [, tolerance]): the meshes as one, nodes of b within the tolerance (default
    // 1e-9 times the larger bounding-box diagonal) of nodes of a merged into them.
    engine.register_fn("merge", |a: &mut Mesh, b: Mesh| -> ScriptResult<Mesh> {
        let diag = |m: &Mesh| m.bounding_box().map_or(1.0, |(lo, hi)| (hi - lo).norm());
        lift(a.merged(&b, 1e-9 * diag(a).max(diag(&b))))
    });
    engine.register_fn(
        "merge",
        |a: &mut Mesh, b: Mesh, tolerance: Dynamic| -> ScriptResult<Mesh> {
            lift(a.merged(&b, number(&tolerance, "merge tolerance")?))
        },
    );
}

/// The path a script gave, relative to the script's folder when it is relative.
fn shown(policy: &ReadPolicy, path: &Path) -> String {
    path.strip_prefix(policy.base())
        .unwrap_or(path)
        .display()
        .to_string()
}

fn checked(mesh: Mesh, limits: &super::limits::Limits) -> ScriptResult<Mesh> {
    limits
        .check_mesh(mesh.node_count() as u64)
        .or_else(runtime_error)?;
    Ok(mesh)
}

fn register_files(engine: &mut Engine, policy: Rc<ReadPolicy>, limits: super::limits::Limits) {
    // mesh_from_gmsh(path): a Gmsh MSH 4.1 or 2.2 file (ASCII or binary), physical groups as sets.
    let (p, l) = (policy.clone(), limits.clone());
    engine.register_fn("mesh_from_gmsh", move |path: &str| -> ScriptResult<Mesh> {
        let (_, bytes) = lift(p.read_bytes(path, "Gmsh mesh"))?;
        checked(lift(read_gmsh(&bytes, path))?, &l)
    });
    // mesh_from_inp(path): the mesh of a CalculiX/Abaqus deck; *INCLUDE files are read
    // relative to the including file, through the same policy.
    engine.register_fn("mesh_from_inp", move |path: &str| -> ScriptResult<Mesh> {
        let (_, text) = lift(policy.read_to_string(path, "CalculiX/Abaqus deck"))?;
        let base = policy.base().to_path_buf();
        let mut include = |given: &str, from: &str| {
            let from_dir = base.join(from);
            let dir = from_dir.parent().unwrap_or(&base);
            let wanted = dir.join(given);
            let (resolved, text) =
                policy.read_to_string(&wanted.display().to_string(), "included file")?;
            Ok((shown(&policy, &resolved), text))
        };
        checked(lift(read_inp(&text, path, &mut include))?, &limits)
    });
}

fn register_set_names(engine: &mut Engine) {
    engine.register_get("node_sets", |m: &mut Mesh| strings(m.node_set_names()));
    engine.register_get("element_sets", |m: &mut Mesh| {
        strings(m.element_set_names())
    });
    engine.register_get("face_sets", |m: &mut Mesh| strings(m.face_set_names()));
    engine.register_fn(
        "element_set",
        |m: &mut Mesh, name: &str| -> ScriptResult<Array> {
            Ok(lift(m.element_set(name))?
                .iter()
                .map(|&e| Dynamic::from(e as i64))
                .collect())
        },
    );
    // face_set(name): each face as its 4 node indices, counter-clockwise seen from outside.
    engine.register_fn(
        "face_set",
        |m: &mut Mesh, name: &str| -> ScriptResult<Array> {
            Ok(lift(m.face_set(name))?
                .iter()
                .map(|q| {
                    Dynamic::from(
                        q.iter()
                            .map(|&n| Dynamic::from(n as i64))
                            .collect::<Array>(),
                    )
                })
                .collect())
        },
    );
    // Element connectivity, for comparing meshes: mesh.element(e) -> 8 node indices.
    engine.register_fn("element", |m: &mut Mesh, e: i64| -> ScriptResult<Array> {
        match m.hexes.get(e as usize) {
            Some(h) if e >= 0 => Ok(h.iter().map(|&n| Dynamic::from(n as i64)).collect()),
            _ => runtime_error(format!(
                "element {e} is out of range (mesh has {} elements)",
                m.hexes.len()
            )),
        }
    });
}
