//! Tools from CAD files for scripts: `tool_from_iges(path, options)`,
//! `tool_from_step(path, options)` and `tool_from_nurbs_json(path, options)`. Files are read through the read policy.

use super::api_scene::ScriptSurface;
use super::convert::*;
use crate::cad::ImportOptions;
use crate::cad::{iges::faces_from_iges, nurbs_json::faces_from_json, step::faces_from_step};
use crate::cad::{tool_surface, Face};
use rhai::{Array, Engine, Map};
use std::rc::Rc;
use std::sync::Arc;

/// `#{ faces: [0, 3], names: ["top"], facing: [0, 0, 1], facing_angle: 30, flip: false,
/// translate: [0, 0, 0.81] }`, every key optional.
fn options(map: &Map, function: &str) -> ScriptResult<ImportOptions> {
    let mut out = ImportOptions::default();
    let mut facing: Option<crate::geometry::Vec3> = None;
    let mut facing_angle: Option<f64> = None;
    for (key, value) in map {
        match key.as_str() {
            "faces" => {
                let list = value
                    .clone()
                    .try_cast::<Array>()
                    .ok_or_else(|| {
                        format!("{function} option faces must be an array of face indices")
                    })
                    .or_else(runtime_error)?;
                let mut faces = Vec::with_capacity(list.len());
                for (k, f) in list.iter().enumerate() {
                    match f.as_int() {
                        Ok(i) if i >= 0 => faces.push(i as usize),
                        _ => {
                            return runtime_error(format!(
                                "{function} option faces[{k}] must be an integer >= 0"
                            ))
                        }
                    }
                }
                out.faces = Some(faces);
            }
            "names" => out.names = Some(names(value, function)?),
            "facing" => {
                let a = value
                    .clone()
                    .try_cast::<Array>()
                    .ok_or_else(|| {
                        format!("{function} option facing must be a direction [x, y, z]")
                    })
                    .or_else(runtime_error)?;
                facing = Some(vec3(&a, &format!("{function} option facing"))?);
            }
            "facing_angle" => {
                facing_angle = Some(number(value, &format!("{function} option facing_angle"))?)
            }
            "flip" => {
                out.flip = value.as_bool().or_else(|_| {
                    runtime_error(format!("{function} option flip must be true or false"))
                })?
            }
            "translate" => {
                let a = value
                    .clone()
                    .try_cast::<Array>()
                    .ok_or_else(|| format!("{function} option translate must be [x, y, z]"))
                    .or_else(runtime_error)?;
                out.translate = vec3(&a, &format!("{function} option translate"))?;
            }
            other => {
                return runtime_error(format!(
                    "{function} option '{other}' is unknown; expected faces, names, facing, \
                     facing_angle, flip, translate"
                ))
            }
        }
    }
    out.facing = match (facing, facing_angle) {
        // Default 90 degrees: n . d > 0, the faces seen from the side d points to.
        (Some(d), angle) => Some(lift(crate::cad::Facing::new(
            d,
            angle.unwrap_or(90.0),
            &format!("{function} option facing"),
        ))?),
        (None, Some(_)) => {
            return runtime_error(format!(
                "{function} option facing_angle needs the option facing (a direction)"
            ))
        }
        (None, None) => None,
    };
    Ok(out)
}

/// A name or an array of names.
fn names(value: &rhai::Dynamic, function: &str) -> ScriptResult<Vec<String>> {
    if value.is_string() {
        return Ok(vec![value.to_string()]);
    }
    let bad = || format!("{function} option names must be a string or an array of strings");
    let list = value
        .clone()
        .try_cast::<Array>()
        .ok_or_else(bad)
        .or_else(runtime_error)?;
    list.iter()
        .map(|n| {
            if n.is_string() {
                Ok(n.to_string())
            } else {
                runtime_error(bad())
            }
        })
        .collect()
}

type Reader = fn(&str, &str) -> crate::Result<Vec<Face>>;

fn load(
    policy: &crate::paths::ReadPolicy,
    path: &str,
    what: &str,
    read: Reader,
    options: &ImportOptions,
) -> ScriptResult<ScriptSurface> {
    let (_, text) = lift(policy.read_to_string(path, what))?;
    let faces = lift(read(path, &text))?;
    Ok(ScriptSurface(Arc::new(lift(tool_surface(
        path, faces, options,
    ))?)))
}

pub fn register(engine: &mut Engine, policy: Rc<crate::paths::ReadPolicy>) {
    for (function, what, read) in [
        ("tool_from_iges", "IGES file", faces_from_iges as Reader),
        ("tool_from_step", "STEP file", faces_from_step as Reader),
        (
            "tool_from_nurbs_json",
            "NURBS JSON table",
            faces_from_json as Reader,
        ),
    ] {
        let p = policy.clone();
        engine.register_fn(function, move |path: &str| -> ScriptResult<ScriptSurface> {
            load(&p, path, what, read, &ImportOptions::default())
        });
        let p = policy.clone();
        engine.register_fn(
            function,
            move |path: &str, map: Map| -> ScriptResult<ScriptSurface> {
                load(&p, path, what, read, &options(&map, function)?)
            },
        );
    }
}
