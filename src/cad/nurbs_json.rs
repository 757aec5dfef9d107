//! Faces from a JSON NURBS table (mm). Every error names the face and the entry at fault,
//! never echoing the file's text.
//!
//! ```json
//! { "faces": [
//!     { "degree": [2, 1],                                  // p along u, q along v
//!       "knots": [[0, 0, 0, 1, 1, 1], [0, 0, 1, 1]],       // U (n + p + 1), V (m + q + 1)
//!       "points": [[[x, y, z], ...], ...],                 // n rows along u, m columns along v
//!       "weights": [[w, ...], ...],                        // optional, default all 1
//!       "range": [[u0, u1], [v0, v1]],                     // optional, default the knot domain
//!       "trim": [ [ curve, ... ], ... ] } ] }              // optional loops (outer, holes)
//! ```
//!
//! A trimming `curve` is a NURBS curve in the face's `(u, v)` plane:
//! `{ "degree": 1, "knots": [0, 0, 1, 1], "points": [[u, v], [u, v]], "weights": [1, 1] }`
//! (weights optional); each loop's curves join end to start and the last returns to the
//! first. A point of the surface belongs to the face when it is inside an odd number of
//! loops (so holes are loops inside the outer one, in any direction).

use super::Face;
use crate::geometry::nurbs::{check_knots, curve_segments, NurbsSurface};
use crate::geometry::patch_table::{array, kind, number, point, prefix, rows_of};
use crate::geometry::trim::{TrimRegion, TrimSegment};
use crate::{Error, Result};
use serde_json::Value;

fn field<'a>(v: &'a Value, key: &str, name: &str) -> Result<&'a Value> {
    v.get(key)
        .ok_or_else(|| Error::Input(format!("{name} has no \"{key}\"")))
}

fn numbers(v: &Value, what: &str) -> Result<Vec<f64>> {
    array(v, what)?
        .iter()
        .enumerate()
        .map(|(i, x)| number(x, &format!("{what}[{i}]")))
        .collect()
}

fn degree(v: &Value, what: &str) -> Result<usize> {
    v.as_u64()
        .filter(|&d| (1..=64).contains(&d))
        .map(|d| d as usize)
        .ok_or_else(|| Error::input(what, kind(v), "must be an integer in 1..=64"))
}

/// One trimming curve's Bézier segments.
fn curve(v: &Value, name: &str) -> Result<Vec<TrimSegment>> {
    let p = degree(field(v, "degree", name)?, &format!("{name}.degree"))?;
    let knots = numbers(field(v, "knots", name)?, &format!("{name}.knots"))?;
    let points = array(field(v, "points", name)?, &format!("{name}.points"))?;
    let mut uv = Vec::with_capacity(2 * points.len());
    for (i, q) in points.iter().enumerate() {
        let what = format!("{name}.points[{i}]");
        let a = array(q, &what)?;
        if a.len() != 2 {
            return Err(Error::input(&what, kind(q), "must be [u, v]"));
        }
        uv.push(number(&a[0], &what)?);
        uv.push(number(&a[1], &what)?);
    }
    let n = points.len();
    let weights = match v.get("weights") {
        None => vec![1.0; n],
        Some(w) => numbers(w, &format!("{name}.weights"))?,
    };
    if weights.len() != n {
        return Err(Error::input(
            &format!("{name}.weights count"),
            weights.len(),
            &format!("must equal the point count {n}"),
        ));
    }
    if let Some(i) = weights.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(Error::input(
            &format!("{name}.weights[{i}]"),
            weights[i],
            "must be finite and > 0",
        ));
    }
    check_knots(name, p, n, &knots)?;
    let range = [knots[p], knots[n]];
    Ok(curve_segments(p, &knots, &uv, &weights, 2, range)
        .into_iter()
        .map(|(h, _)| TrimSegment::new(h.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()))
        .collect())
}

fn face(v: &Value, name: &str) -> Result<Face> {
    let d = array(field(v, "degree", name)?, &format!("{name}.degree"))?;
    if d.len() != 2 {
        return Err(Error::input(
            &format!("{name}.degree"),
            kind(&v["degree"]),
            "must be [p, q]",
        ));
    }
    let degrees = [
        degree(&d[0], &format!("{name}.degree[0]"))?,
        degree(&d[1], &format!("{name}.degree[1]"))?,
    ];
    let k = array(field(v, "knots", name)?, &format!("{name}.knots"))?;
    if k.len() != 2 {
        return Err(Error::input(
            &format!("{name}.knots"),
            kind(&v["knots"]),
            "must be [U, V]",
        ));
    }
    let knots = [
        numbers(&k[0], &format!("{name}.knots[0]"))?,
        numbers(&k[1], &format!("{name}.knots[1]"))?,
    ];
    let points = rows_of(field(v, "points", name)?, &format!("{name}.points"), point)?;
    let weights = match v.get("weights") {
        None => None,
        Some(w) => Some(rows_of(w, &format!("{name}.weights"), number)?),
    };
    let mut surface =
        NurbsSurface::new(degrees, knots, points, weights).map_err(|e| prefix(name, e))?;
    if let Some(r) = v.get("range") {
        let r = array(r, &format!("{name}.range"))?;
        if r.len() != 2 {
            return Err(Error::input(
                &format!("{name}.range"),
                kind(&v["range"]),
                "must be [[u0, u1], [v0, v1]]",
            ));
        }
        let u = numbers(&r[0], &format!("{name}.range[0]"))?;
        let w = numbers(&r[1], &format!("{name}.range[1]"))?;
        if u.len() != 2 || w.len() != 2 {
            return Err(Error::Input(format!(
                "{name}.range must be [[u0, u1], [v0, v1]]"
            )));
        }
        surface = surface
            .restricted([u[0], u[1]], [w[0], w[1]])
            .map_err(|e| prefix(name, e))?;
    }
    let trim = match v.get("trim") {
        None => None,
        Some(t) => {
            let loops = array(t, &format!("{name}.trim"))?
                .iter()
                .enumerate()
                .map(|(l, curves)| {
                    let mut segments = Vec::new();
                    for (c, cv) in array(curves, &format!("{name}.trim[{l}]"))?
                        .iter()
                        .enumerate()
                    {
                        segments.extend(curve(cv, &format!("{name}.trim[{l}][{c}]"))?);
                    }
                    Ok(segments)
                })
                .collect::<Result<Vec<_>>>()?;
            Some(TrimRegion::new(loops).map_err(|e| prefix(&format!("{name}.trim"), e))?)
        }
    };
    Ok(Face {
        surface,
        trim,
        origin: name.to_string(),
        flip: false,
        arcs: [None, None],
        names: Vec::new(),
    })
}

/// The faces of a JSON NURBS table's text; `source` (the file name) prefixes every error.
pub fn faces_from_json(source: &str, text: &str) -> Result<Vec<Face>> {
    let fail = |e: Error| prefix(source, e);
    let root: Value = serde_json::from_str(text)
        .map_err(|e| Error::Input(format!("{source}: not valid JSON: {e}")))?;
    let list = root
        .get("faces")
        .ok_or_else(|| Error::Input(format!("{source}: no \"faces\" array")))?;
    array(list, "faces")
        .map_err(fail)?
        .iter()
        .enumerate()
        .map(|(k, f)| face(f, &format!("faces[{k}]")).map_err(fail))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cad::{tool_surface, ImportOptions};
    use crate::geometry::{RigidSurface, Vec3};

    /// A 4 x 2 square plate as one degree-(1, 1) face with two u spans, with a round hole
    /// of radius 0.5 around (1, 1) (four rational quadratic quarter arcs).
    const PLATE: &str = r#"{ "faces": [ {
        "degree": [1, 1],
        "knots": [[0, 0, 2, 4, 4], [0, 0, 2, 2]],
        "points": [[[0,0,0],[0,2,0]], [[2,0,0],[2,2,0]], [[4,0,0],[4,2,0]]],
        "trim": [
          [ { "degree": 1, "knots": [0,0,1,2,3,4,4],
              "points": [[0,0],[4,0],[4,2],[0,2],[0,0]] } ],
          [ { "degree": 2, "knots": [0,0,0,1,1,2,2,3,3,4,4,4],
              "points": [[1.5,1],[1.5,1.5],[1,1.5],[0.5,1.5],[0.5,1],[0.5,0.5],[1,0.5],[1.5,0.5],[1.5,1]],
              "weights": [1,0.7071067811865476,1,0.7071067811865476,1,0.7071067811865476,1,0.7071067811865476,1] } ] ]
    } ] }"#;

    #[test]
    fn a_plate_with_a_hole_gives_no_foot_in_the_hole() {
        let faces = faces_from_json("plate.json", PLATE).unwrap();
        let surface = tool_surface("plate.json", faces, &ImportOptions::default()).unwrap();
        assert_eq!(surface.patches().len(), 2);
        // Above the plate away from the hole: the foot is straight below.
        let p = surface.project(&Vec3::new(3.0, 1.5, 0.7), None).unwrap();
        assert!((p.foot - Vec3::new(3.0, 1.5, 0.0)).norm() < 1e-14);
        assert!((p.gap - 0.7).abs() < 1e-14);
        // Above the hole: the plane below is not part of the face, so no foot lies there.
        let x = Vec3::new(1.1, 0.9, 0.3);
        if let Some(p) = surface.project(&x, None) {
            let in_hole = (p.foot.x - 1.0).hypot(p.foot.y - 1.0) < 0.5 - 1e-9;
            assert!(!in_hole, "foot {:?} in the hole", p.foot);
        }
        let untrimmed = PLATE
            .split("\"trim\"")
            .next()
            .unwrap()
            .trim_end()
            .trim_end_matches(',');
        let untrimmed = format!("{untrimmed} }} ] }}");
        let faces = faces_from_json("plate.json", &untrimmed).unwrap();
        let whole = tool_surface("plate.json", faces, &ImportOptions::default()).unwrap();
        let p = whole.project(&x, None).unwrap();
        assert!((p.foot - Vec3::new(1.1, 0.9, 0.0)).norm() < 1e-14);
    }

    #[test]
    fn errors_name_the_face_and_entry() {
        let msg = |t: &str| faces_from_json("t.json", t).unwrap_err().to_string();
        let e = msg(&PLATE.replace("[[0, 0, 2, 4, 4]", "[[0, 0, 2, 4]"));
        assert!(
            e.contains(
                "t.json: faces[0]: nurbs u knot count = 4 must be control points + degree + 1 = 5"
            ),
            "{e}"
        );
        let e = msg(&PLATE.replace("[0.5,0.5],[1,0.5]", "[0.5,0.5],[1,\"x\"]"));
        assert!(
            e.contains("t.json: faces[0].trim[1][0].points[6] = a string must be a number"),
            "{e}"
        );
        let e = msg(&PLATE.replace("[4,2],[0,2],[0,0]]", "[4,2],[0,2],[0,0.5]]"));
        assert!(
            e.contains("t.json: faces[0].trim: trimming loop 0 segment 3: gap to the next segment"),
            "{e}"
        );
        let e = msg("{ \"faces\": [ { \"degree\": [1, 0] } ] }");
        assert!(
            e.contains("faces[0].degree[1] = 0 must be an integer in 1..=64"),
            "{e}"
        );
    }
}
