//! `mesh.map(f)`: a mesh carried through a map of its reference coordinates (curved
//! shells from a block). `f` takes `|x, y, z|` (like `mesh.select`) or `|p|` with
//! `p = [x, y, z]`, and returns `[x', y', z']`.

use rhai::{Array, Dynamic, Engine, EvalAltResult, FnPtr, NativeCallContext};

use crate::geometry::Vec3;
use crate::mesh::Mesh;
use crate::Error;

use super::convert::{fail, ScriptResult};

/// Calls `f` with three numbers, or with one array if it takes one parameter.
fn call(ctx: &NativeCallContext, f: &FnPtr, p: Vec3) -> ScriptResult<Dynamic> {
    match f.call_within_context::<Dynamic>(ctx, (p.x, p.y, p.z)) {
        Err(e) if matches!(*e, EvalAltResult::ErrorFunctionNotFound(..)) => {
            let arr: Array = vec![p.x.into(), p.y.into(), p.z.into()];
            f.call_within_context::<Dynamic>(ctx, (arr,))
        }
        other => other,
    }
}

fn point(v: Dynamic, from: Vec3) -> crate::Result<Vec3> {
    let bad = || {
        Error::Script(format!(
            "mesh.map: the function must return [x, y, z] (three numbers); for the node at \
             ({}, {}, {}) it returned {}",
            from.x,
            from.y,
            from.z,
            v.type_name()
        ))
    };
    let arr = v.clone().try_cast::<Array>().ok_or_else(bad)?;
    if arr.len() != 3 {
        return Err(bad());
    }
    let mut q = [0.0; 3];
    for (k, c) in arr.iter().enumerate() {
        q[k] = c
            .as_float()
            .or_else(|_| c.as_int().map(|i| i as f64))
            .map_err(|_| bad())?;
    }
    Ok(Vec3::new(q[0], q[1], q[2]))
}

pub(super) fn register(engine: &mut Engine) {
    engine.register_fn(
        "map",
        |ctx: NativeCallContext, m: &mut Mesh, f: FnPtr| -> ScriptResult<Mesh> {
            let mut script_error = None;
            let mapped = m.map(|p| match call(&ctx, &f, p) {
                Ok(v) => point(v, p),
                Err(e) => {
                    let msg = e.to_string();
                    script_error = Some(e);
                    Err(Error::Script(msg))
                }
            });
            match mapped {
                Ok(mesh) => Ok(mesh),
                Err(_) if script_error.is_some() => Err(script_error.unwrap()),
                Err(e) => fail(e),
            }
        },
    );
}
