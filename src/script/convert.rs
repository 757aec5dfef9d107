//! Conversions between Rhai values and engine types, and error mapping.

use crate::geometry::Vec3;
use rhai::{Array, Dynamic, EvalAltResult, Position};

pub type ScriptResult<T> = Result<T, Box<EvalAltResult>>;

/// Maps a library error into a Rhai runtime error (Rhai adds the call position).
pub fn fail<T>(err: crate::Error) -> ScriptResult<T> {
    Err(Box::new(EvalAltResult::ErrorRuntime(
        err.to_string().into(),
        Position::NONE,
    )))
}

pub fn lift<T>(r: crate::Result<T>) -> ScriptResult<T> {
    r.or_else(fail)
}

pub fn runtime_error<T>(msg: impl Into<String>) -> ScriptResult<T> {
    fail(crate::Error::Input(msg.into()))
}

/// A number from an integer or a float.
pub fn number(v: &Dynamic, what: &str) -> ScriptResult<f64> {
    if let Some(f) = v.clone().try_cast::<f64>() {
        Ok(f)
    } else if let Some(i) = v.clone().try_cast::<i64>() {
        Ok(i as f64)
    } else {
        runtime_error(format!("{what} must be a number, got {}", v.type_name()))
    }
}

/// A 3-vector from an array of three numbers.
pub fn vec3(a: &Array, what: &str) -> ScriptResult<Vec3> {
    if a.len() != 3 {
        return runtime_error(format!("{what} must have 3 components, got {}", a.len()));
    }
    Ok(Vec3::new(
        number(&a[0], what)?,
        number(&a[1], what)?,
        number(&a[2], what)?,
    ))
}

pub fn array3(v: &Vec3) -> Array {
    vec![Dynamic::from(v.x), Dynamic::from(v.y), Dynamic::from(v.z)]
}

/// Three non-negative integers (cell counts).
pub fn counts3(a: &Array, what: &str) -> ScriptResult<[usize; 3]> {
    if a.len() != 3 {
        return runtime_error(format!("{what} must have 3 entries, got {}", a.len()));
    }
    let mut out = [0; 3];
    for (i, v) in a.iter().enumerate() {
        let n = v
            .as_int()
            .map_err(|t| format!("{what}[{i}] must be an integer, got {t}"))
            .or_else(runtime_error)?;
        if n < 0 {
            return runtime_error(format!("{what}[{i}] = {n} must be >= 0"));
        }
        out[i] = n as usize;
    }
    Ok(out)
}
