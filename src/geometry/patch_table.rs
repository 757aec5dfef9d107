//! Patches from the user's own control-point tables: rows of points (and of weights), in a
//! script or in a JSON file. Every error names the patch and the entry at fault.
//!
//! JSON layout:
//!
//! ```json
//! { "patches": [ { "points": [[[x, y, z], ...], ...],      // rows along u, columns along v
//!                  "weights": [[w, ...], ...],              // optional, default all 1
//!                  "flip": false } ],                       // optional
//!   "outside": [x, y, z] }                                  // optional: a point outside the tool
//! ```

use super::bezier::BezierPatch;
use super::Vec3;
use crate::{Error, Result};
use serde_json::Value;

/// A patch from `points[i][j]` (`i` along `u`: degree = rows - 1, `j` along `v`) and
/// optional `weights[i][j]`; `name` ("patch 3") prefixes every error.
pub fn patch_from_rows(
    name: &str,
    points: &[Vec<Vec3>],
    weights: Option<&[Vec<f64>]>,
) -> Result<BezierPatch> {
    let rows = points.len();
    let cols = points.first().map_or(0, |r| r.len());
    if rows < 2 || cols < 2 {
        return Err(Error::input(
            &format!("{name} control net size"),
            format!("{rows} x {cols}"),
            "must be at least 2 x 2 (degree >= 1 in u and v)",
        ));
    }
    for (i, row) in points.iter().enumerate() {
        if row.len() != cols {
            return Err(Error::input(
                &format!("{name} points row {i} length"),
                row.len(),
                &format!("must equal row 0's length {cols}"),
            ));
        }
    }
    let weights: Vec<f64> = match weights {
        None => vec![1.0; rows * cols],
        Some(w) => {
            if w.len() != rows {
                return Err(Error::input(
                    &format!("{name} weights row count"),
                    w.len(),
                    &format!("must equal the points' row count {rows}"),
                ));
            }
            for (i, row) in w.iter().enumerate() {
                if row.len() != cols {
                    return Err(Error::input(
                        &format!("{name} weights row {i} length"),
                        row.len(),
                        &format!("must equal the points' row length {cols}"),
                    ));
                }
            }
            w.iter().flatten().copied().collect()
        }
    };
    let flat: Vec<Vec3> = points.iter().flatten().copied().collect();
    BezierPatch::new(rows - 1, cols - 1, flat, weights).map_err(|e| prefix(name, e))
}

/// `Error::Input(m)` -> `Error::Input("name: m")`.
pub(crate) fn prefix(name: &str, e: Error) -> Error {
    match e {
        Error::Input(m) => Error::Input(format!("{name}: {m}")),
        other => other,
    }
}

/// What a wrong JSON value is, for an error message: its kind, and the value itself only
/// for numbers and booleans. A table may come from a file, and error messages never echo a
/// file's text (issue 16).
pub(crate) fn kind(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(_) => "a string".into(),
        Value::Array(a) => format!("an array of {} entries", a.len()),
        Value::Object(_) => "an object".into(),
    }
}

pub(crate) fn number(v: &Value, what: &str) -> Result<f64> {
    v.as_f64()
        .ok_or_else(|| Error::input(what, kind(v), "must be a number"))
}

pub(crate) fn array<'a>(v: &'a Value, what: &str) -> Result<&'a Vec<Value>> {
    v.as_array()
        .ok_or_else(|| Error::input(what, kind(v), "must be an array"))
}

pub(crate) fn point(v: &Value, what: &str) -> Result<Vec3> {
    let a = array(v, what)?;
    if a.len() != 3 {
        return Err(Error::input(what, kind(v), "must be [x, y, z]"));
    }
    Ok(Vec3::new(
        number(&a[0], what)?,
        number(&a[1], what)?,
        number(&a[2], what)?,
    ))
}

/// A table of rows (`what[i][j]`), each entry read by `entry`; errors name the entry.
pub(crate) fn rows_of<T>(
    v: &Value,
    what: &str,
    entry: impl Fn(&Value, &str) -> Result<T>,
) -> Result<Vec<Vec<T>>> {
    array(v, what)?
        .iter()
        .enumerate()
        .map(|(i, row)| {
            array(row, &format!("{what}[{i}]"))?
                .iter()
                .enumerate()
                .map(|(j, x)| entry(x, &format!("{what}[{i}][{j}]")))
                .collect()
        })
        .collect()
}

/// Patches (and the optional outside point) from the JSON text of a patch table; `source`
/// (the file name) prefixes every error.
pub fn patches_from_json(source: &str, text: &str) -> Result<(Vec<BezierPatch>, Option<Vec3>)> {
    let fail = |e: Error| prefix(source, e);
    let root: Value = serde_json::from_str(text)
        .map_err(|e| Error::Input(format!("{source}: not valid JSON: {e}")))?;
    let list = root
        .get("patches")
        .ok_or_else(|| Error::Input(format!("{source}: no \"patches\" array")))?;
    let list = array(list, "patches").map_err(fail)?;
    let mut patches = Vec::new();
    for (k, entry) in list.iter().enumerate() {
        let name = format!("patches[{k}]");
        let rows = entry
            .get("points")
            .ok_or_else(|| Error::Input(format!("{source}: {name} has no \"points\"")))?;
        let points = rows_of(rows, &format!("{name}.points"), point).map_err(fail)?;
        let weights = match entry.get("weights") {
            None => None,
            Some(w) => Some(rows_of(w, &format!("{name}.weights"), number).map_err(fail)?),
        };
        let mut patch = patch_from_rows(&name, &points, weights.as_deref()).map_err(fail)?;
        match entry.get("flip") {
            None => {}
            Some(Value::Bool(true)) => patch = patch.flipped(),
            Some(Value::Bool(false)) => {}
            Some(other) => {
                return Err(fail(Error::input(
                    &format!("{name}.flip"),
                    kind(other),
                    "must be true or false",
                )))
            }
        }
        patches.push(patch);
    }
    let outside = match root.get("outside") {
        None => None,
        Some(v) => Some(point(v, "outside").map_err(fail)?),
    };
    Ok((patches, outside))
}

/// [`patches_from_json`] of a file.
pub fn load_patches_json(path: &std::path::Path) -> Result<(Vec<BezierPatch>, Option<Vec3>)> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    patches_from_json(&path.display().to_string(), &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"{ "patches": [
        { "points": [[[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]]] },
        { "points": [[[1,0,0],[1,1,0]],[[2,0,0.5],[2,1,0.5]],[[3,0,0],[3,1,0]]],
          "weights": [[1,1],[0.5,0.5],[1,1]], "flip": false } ],
      "outside": [0.5, 0.5, 1] }"#;

    #[test]
    fn json_table_gives_the_patches() {
        let (patches, outside) = patches_from_json("t.json", GOOD).unwrap();
        assert_eq!(patches.len(), 2);
        assert_eq!(patches[1].degrees(), (2, 1));
        assert_eq!(patches[1].weights()[2], 0.5);
        assert_eq!(outside, Some(Vec3::new(0.5, 0.5, 1.0)));
    }

    #[test]
    fn errors_name_the_patch_and_the_entry() {
        let msg = |text: &str| patches_from_json("t.json", text).unwrap_err().to_string();
        let bad_point = GOOD.replace("[2,1,0.5]", "[2,\"a\",0.5]");
        let e = msg(&bad_point);
        assert!(
            e.contains("t.json: patches[1].points[1][1] = a string must be a number"),
            "{e}"
        );
        let secret = GOOD.replace("[2,1,0.5]", "[2,\"root:x:0:0\",0.5]");
        let e = msg(&secret);
        assert!(!e.contains("root:x"), "a file's text is never echoed: {e}");
        let ragged = GOOD.replace("[[1,0,0],[1,1,0]]]", "[[1,0,0]]]");
        let e = msg(&ragged);
        assert!(
            e.contains("t.json: patches[0] points row 1 length = 1 must equal row 0's length 2"),
            "{e}"
        );
        let bad_w = GOOD.replace("[0.5,0.5]", "[0.5,-0.5]");
        let e = msg(&bad_w);
        assert!(
            e.contains("t.json: patches[1]: bezier patch weight [1][1] = -0.5 must be > 0"),
            "{e}"
        );
        let e = msg(&GOOD.replace("\"flip\": false", "\"flip\": 1"));
        assert!(
            e.contains("patches[1].flip = 1 must be true or false"),
            "{e}"
        );
        let e = msg("{ \"patches\": [ {} ] }");
        assert!(e.contains("t.json: patches[0] has no \"points\""), "{e}");
        let e = msg("{ nope");
        assert!(e.contains("t.json: not valid JSON"), "{e}");
    }
}
