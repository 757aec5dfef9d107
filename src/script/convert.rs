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
    let v = Vec3::new(
        number(&a[0], what)?,
        number(&a[1], what)?,
        number(&a[2], what)?,
    );
    // A NaN point would match node 0 in every nearest-node search and move a tool nowhere.
    if !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()) {
        return runtime_error(format!(
            "{what} must be finite, got [{}, {}, {}]",
            v.x, v.y, v.z
        ));
    }
    Ok(v)
}

/// A script array of strings.
pub fn strings<'a>(it: impl IntoIterator<Item = &'a str>) -> Array {
    it.into_iter()
        .map(|s| Dynamic::from(s.to_string()))
        .collect()
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

/// What a script value is turned into JSON for; the two differ in what they do with a
/// number JSON cannot hold and in how their errors read.
#[derive(Clone, Copy)]
pub enum JsonUse {
    /// A run's summary: NaN and infinities become null, as in the engine's own summary.
    Summary,
    /// A checkpoint (`sim.keep`): [`from_json`] must give the same value back, so only
    /// finite numbers (a NaN would come back as unit).
    Checkpoint,
}

/// A Rhai value as JSON: unit, booleans, integers, floats, strings, arrays and maps of
/// them. `at` names the place in the value for errors.
pub fn to_json(v: &Dynamic, at: &str, purpose: JsonUse) -> ScriptResult<serde_json::Value> {
    use serde_json::Value;
    if v.is_unit() {
        Ok(Value::Null)
    } else if let Ok(b) = v.as_bool() {
        Ok(Value::Bool(b))
    } else if let Ok(i) = v.as_int() {
        Ok(Value::from(i))
    } else if let Ok(f) = v.as_float() {
        match (serde_json::Number::from_f64(f), purpose) {
            (Some(n), _) => Ok(Value::Number(n)),
            (None, JsonUse::Summary) => Ok(Value::Null),
            (None, JsonUse::Checkpoint) => runtime_error(format!(
                "sim.keep: {at} = {f} cannot be kept in a checkpoint (only finite numbers)"
            )),
        }
    } else if v.is_string() || v.is_char() {
        Ok(Value::String(v.to_string()))
    } else if let Some(a) = v.clone().try_cast::<Array>() {
        a.iter()
            .enumerate()
            .map(|(i, x)| to_json(x, &format!("{at}[{i}]"), purpose))
            .collect::<ScriptResult<Vec<_>>>()
            .map(Value::Array)
    } else if let Some(m) = (v.clone().try_cast::<rhai::Map>()).or_else(|| {
        // A record of sim.history() / sim.node_history() is written as its map.
        (v.read_lock::<super::record::Record>()).map(|r| r.map().clone())
    }) {
        let mut out = serde_json::Map::new();
        for (k, x) in &m {
            out.insert(k.to_string(), to_json(x, &format!("{at}.{k}"), purpose)?);
        }
        Ok(Value::Object(out))
    } else {
        let use_these = "(use numbers, strings, booleans, arrays, maps)";
        runtime_error(match purpose {
            JsonUse::Summary => format!(
                "summary value {at} is a {} which has no JSON form {use_these}",
                v.type_name()
            ),
            JsonUse::Checkpoint => format!(
                "sim.keep: {at} is a {} which a checkpoint cannot hold {use_these}",
                v.type_name()
            ),
        })
    }
}

/// The Rhai value of JSON written by [`to_json`] for a checkpoint: a number written with a fraction
/// or exponent is a float, one without an integer (serde_json writes every f64 with one).
pub fn from_json(v: &serde_json::Value) -> Dynamic {
    use serde_json::Value;
    match v {
        Value::Null => Dynamic::UNIT,
        Value::Bool(b) => Dynamic::from(*b),
        Value::Number(n) => match n.as_i64() {
            Some(i) => Dynamic::from(i),
            None => Dynamic::from(n.as_f64().unwrap_or(f64::NAN)),
        },
        Value::String(s) => Dynamic::from(s.clone()),
        Value::Array(a) => Dynamic::from(a.iter().map(from_json).collect::<Array>()),
        Value::Object(m) => Dynamic::from(
            m.iter()
                .map(|(k, x)| (k.as_str().into(), from_json(x)))
                .collect::<rhai::Map>(),
        ),
    }
}
