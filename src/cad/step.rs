//! STEP (ISO 10303-21 exchange structure, AP203/AP214 geometry) reader for the faces of a
//! tool.
//!
//! Read: every `ADVANCED_FACE` (file order of instance ids) whose surface is a
//! `B_SPLINE_SURFACE_WITH_KNOTS`, rational or not (the complex instance
//! `(B_SPLINE_SURFACE(..) B_SPLINE_SURFACE_WITH_KNOTS(..) RATIONAL_B_SPLINE_SURFACE(..) ..)`);
//! its bounds `FACE_OUTER_BOUND` / `FACE_BOUND` -> `EDGE_LOOP` -> `ORIENTED_EDGE` ->
//! `EDGE_CURVE` -> `SURFACE_CURVE` / `SEAM_CURVE`, of which the `PCURVE` on the face's
//! surface gives the trimming curve in the parameter plane (a `B_SPLINE_CURVE_WITH_KNOTS`,
//! rational or not, or a `POLYLINE`); the face's `same_sense` (a face of a solid points out
//! of it); and the length unit (`SI_UNIT` with its prefix, or a `CONVERSION_BASED_UNIT`
//! named inch or foot). Faces come out in mm.
//!
//! A face on another surface (`PLANE`, `CYLINDRICAL_SURFACE`, `TOROIDAL_SURFACE`, ...) is
//! refused naming it: export B-splines (OpenCascade: `BRepBuilderAPI_NurbsConvert`). The
//! edges of a loop are chained by continuity (each one turned so that it starts where the
//! previous ended), so a loop needs only its pcurves, not the orientation flags.
//! Parts placed in an assembly (`CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` with an
//! `ITEM_DEFINED_TRANSFORMATION`) come out at their placed pose ([`super::step_assembly`]). Every error names the file, the line
//! and the instance (`#id`); the file's text is never echoed.

use super::Face;
use crate::geometry::nurbs::{check_knots, curve_segments, NurbsSurface};
use crate::geometry::trim::{TrimRegion, TrimSegment};
use crate::geometry::Vec3;
use crate::{Error, Result};
use std::collections::BTreeMap;

/// A parameter of an instance.
#[derive(Debug, Clone)]
pub(super) enum Value {
    Number(f64),
    Text(String),
    Enum(String),
    Ref(usize),
    List(Vec<Value>),
    /// `TYPE(value)`, e.g. `LENGTH_MEASURE(1.E-07)`.
    Typed(Box<Value>),
    /// `$` or `*`.
    Unset,
}

/// An instance: one or more `TYPE(params)` parts (several for a complex instance).
#[derive(Debug)]
pub(super) struct Instance {
    pub(super) parts: Vec<(String, Vec<Value>)>,
    pub(super) line: usize,
}

pub(super) struct Step<'a> {
    pub(super) source: &'a str,
    pub(super) instances: BTreeMap<usize, Instance>,
    pub(super) to_mm: f64,
}

struct Lexer<'a> {
    bytes: &'a [u8],
    at: usize,
    line: usize,
    source: &'a str,
}

impl Lexer<'_> {
    fn fail(&self, m: &str) -> Error {
        Error::Input(format!("{}:{}: {m}", self.source, self.line))
    }

    /// Skips blanks and comments `/* */`, counting lines.
    fn skip(&mut self) {
        while self.at < self.bytes.len() {
            match self.bytes[self.at] {
                b'\n' => {
                    self.line += 1;
                    self.at += 1
                }
                b' ' | b'\t' | b'\r' => self.at += 1,
                b'/' if self.bytes.get(self.at + 1) == Some(&b'*') => {
                    self.at += 2;
                    while self.at < self.bytes.len()
                        && !(self.bytes[self.at] == b'*'
                            && self.bytes.get(self.at + 1) == Some(&b'/'))
                    {
                        if self.bytes[self.at] == b'\n' {
                            self.line += 1;
                        }
                        self.at += 1;
                    }
                    self.at += 2;
                }
                _ => break,
            }
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip();
        self.bytes.get(self.at).copied()
    }

    fn expect(&mut self, c: u8) -> Result<()> {
        if self.peek() == Some(c) {
            self.at += 1;
            Ok(())
        } else {
            Err(self.fail(&format!(
                "expected '{}' here: the file is damaged or truncated",
                c as char
            )))
        }
    }

    fn word(&mut self) -> String {
        self.skip();
        let start = self.at;
        while self.at < self.bytes.len()
            && (self.bytes[self.at].is_ascii_alphanumeric() || self.bytes[self.at] == b'_')
        {
            self.at += 1;
        }
        String::from_utf8_lossy(&self.bytes[start..self.at]).to_ascii_uppercase()
    }

    fn value(&mut self, depth: usize) -> Result<Value> {
        if depth > 64 {
            return Err(self.fail("lists nested too deeply"));
        }
        match self.peek() {
            Some(b'(') => {
                self.at += 1;
                let mut items = Vec::new();
                if self.peek() == Some(b')') {
                    self.at += 1;
                    return Ok(Value::List(items));
                }
                loop {
                    items.push(self.value(depth + 1)?);
                    match self.peek() {
                        Some(b',') => self.at += 1,
                        Some(b')') => {
                            self.at += 1;
                            return Ok(Value::List(items));
                        }
                        _ => {
                            return Err(
                                self.fail("expected ',' or ')' in a list: damaged or truncated")
                            )
                        }
                    }
                }
            }
            Some(b'\'') => {
                self.at += 1;
                let mut text = Vec::new();
                loop {
                    match self.bytes.get(self.at) {
                        None => return Err(self.fail("a string is not closed: truncated")),
                        Some(b'\'') if self.bytes.get(self.at + 1) == Some(&b'\'') => {
                            text.push(b'\'');
                            self.at += 2;
                        }
                        Some(b'\'') => {
                            self.at += 1;
                            break;
                        }
                        Some(&c) => {
                            if c == b'\n' {
                                self.line += 1;
                            }
                            text.push(c);
                            self.at += 1;
                        }
                    }
                }
                Ok(Value::Text(String::from_utf8_lossy(&text).into_owned()))
            }
            Some(b'.') => {
                self.at += 1;
                let w = self.word();
                self.expect(b'.')?;
                Ok(Value::Enum(w))
            }
            Some(b'#') => {
                self.at += 1;
                let start = self.at;
                while self.at < self.bytes.len() && self.bytes[self.at].is_ascii_digit() {
                    self.at += 1;
                }
                std::str::from_utf8(&self.bytes[start..self.at])
                    .ok()
                    .and_then(|s| s.parse().ok())
                    .map(Value::Ref)
                    .ok_or_else(|| self.fail("'#' not followed by an instance number"))
            }
            Some(b'$') | Some(b'*') => {
                self.at += 1;
                Ok(Value::Unset)
            }
            Some(c) if c == b'-' || c == b'+' || c.is_ascii_digit() => {
                let start = self.at;
                while self.at < self.bytes.len()
                    && matches!(
                        self.bytes[self.at],
                        b'0'..=b'9' | b'.' | b'E' | b'e' | b'+' | b'-'
                    )
                {
                    self.at += 1;
                }
                let s = std::str::from_utf8(&self.bytes[start..self.at]).unwrap_or("");
                s.parse::<f64>()
                    .map(Value::Number)
                    .map_err(|_| self.fail("a malformed number"))
            }
            Some(c) if c.is_ascii_alphabetic() => {
                self.word();
                self.expect(b'(')?;
                self.at -= 1;
                let inner = self.value(depth + 1)?;
                let single = match inner {
                    Value::List(mut v) if v.len() == 1 => v.pop().unwrap(),
                    other => other,
                };
                Ok(Value::Typed(Box::new(single)))
            }
            _ => {
                Err(self.fail("an unexpected character in a parameter list: damaged or truncated"))
            }
        }
    }

    /// `TYPE(params)` parts up to the closing `;` of an instance.
    fn parts(&mut self) -> Result<Vec<(String, Vec<Value>)>> {
        let mut parts = Vec::new();
        let complex = self.peek() == Some(b'(');
        if complex {
            self.at += 1;
        }
        loop {
            let name = self.word();
            if name.is_empty() {
                return Err(self.fail("an instance without an entity name"));
            }
            let Value::List(params) = self.value(0)? else {
                return Err(self.fail("an entity without its parameter list"));
            };
            parts.push((name, params));
            if !complex || self.peek() == Some(b')') {
                break;
            }
        }
        if complex {
            self.expect(b')')?;
        }
        self.expect(b';')?;
        Ok(parts)
    }
}

/// Reads the faces of a STEP file's text; `source` (the file name) starts every message.
pub fn faces_from_step(source: &str, text: &str) -> Result<Vec<Face>> {
    let step = Step::parse(source, text)?;
    step.faces()
}

fn prefix_factor(p: &Value) -> Option<f64> {
    Some(match p {
        Value::Unset => 1.0,
        Value::Enum(e) => match e.as_str() {
            "MILLI" => 1e-3,
            "CENTI" => 1e-2,
            "DECI" => 1e-1,
            "MICRO" => 1e-6,
            "NANO" => 1e-9,
            "KILO" => 1e3,
            _ => return None,
        },
        _ => return None,
    })
}

impl<'a> Step<'a> {
    fn parse(source: &'a str, text: &'a str) -> Result<Step<'a>> {
        let data = text.find("DATA;").ok_or_else(|| {
            Error::Input(format!(
                "{source}:1: no DATA section: not a STEP file (ISO 10303-21)"
            ))
        })?;
        if !text[..data].contains("ISO-10303-21") {
            return Err(Error::Input(format!(
                "{source}:1: not a STEP file (no ISO-10303-21 header)"
            )));
        }
        let mut lex = Lexer {
            bytes: text.as_bytes(),
            at: data + 5,
            line: text[..data].matches('\n').count() + 1,
            source,
        };
        let mut instances = BTreeMap::new();
        loop {
            match lex.peek() {
                None => {
                    return Err(lex.fail("the DATA section has no ENDSEC: the file is truncated"))
                }
                Some(b'#') => {
                    lex.at += 1;
                    let line = lex.line;
                    let start = lex.at;
                    while lex.at < lex.bytes.len() && lex.bytes[lex.at].is_ascii_digit() {
                        lex.at += 1;
                    }
                    let id: usize = text[start..lex.at]
                        .parse()
                        .map_err(|_| lex.fail("'#' not followed by an instance number"))?;
                    lex.expect(b'=')?;
                    let parts = lex.parts()?;
                    if instances.insert(id, Instance { parts, line }).is_some() {
                        return Err(Error::Input(format!(
                            "{source}:{line}: instance #{id} is defined twice"
                        )));
                    }
                }
                Some(_) => {
                    let w = lex.word();
                    if w == "ENDSEC" {
                        break;
                    }
                    return Err(lex.fail("expected an instance '#n = ...' or ENDSEC"));
                }
            }
        }
        let mut step = Step {
            source,
            instances,
            to_mm: 1.0,
        };
        step.to_mm = step.length_unit()?;
        Ok(step)
    }

    pub(super) fn fail(&self, id: usize, m: String) -> Error {
        let (line, kind) = self
            .instances
            .get(&id)
            .map_or((0, String::new()), |i| (i.line, i.parts[0].0.clone()));
        Error::Input(format!("{}:{line}: #{id} ({kind}): {m}", self.source))
    }

    /// Millimetres per length unit of the file (the first `LENGTH_UNIT`).
    fn length_unit(&self) -> Result<f64> {
        for (&id, inst) in &self.instances {
            if !inst.parts.iter().any(|(n, _)| n == "LENGTH_UNIT") {
                continue;
            }
            if let Some((_, p)) = inst.parts.iter().find(|(n, _)| n == "SI_UNIT") {
                return p
                    .first()
                    .and_then(prefix_factor)
                    .map(|f| f * 1000.0)
                    .ok_or_else(|| {
                        self.fail(id, "an SI length unit prefix that is not read".into())
                    });
            }
            if let Some((_, p)) = inst
                .parts
                .iter()
                .find(|(n, _)| n == "CONVERSION_BASED_UNIT")
            {
                if let Some(Value::Text(name)) = p.first() {
                    match name.to_ascii_uppercase().as_str() {
                        "INCH" => return Ok(25.4),
                        "FOOT" => return Ok(304.8),
                        _ => {}
                    }
                }
            }
            return Err(self.fail(
                id,
                "a length unit that is not read (read: SI units, inch, foot)".into(),
            ));
        }
        Ok(1.0)
    }

    pub(super) fn instance(&self, id: usize, from: usize, what: &str) -> Result<&Instance> {
        self.instances
            .get(&id)
            .ok_or_else(|| self.fail(from, format!("its {what} #{id} is not defined in the file")))
    }

    /// Parameters of part `name` of instance `id`.
    pub(super) fn part(&self, id: usize, name: &str) -> Option<&[Value]> {
        self.instances
            .get(&id)?
            .parts
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, p)| p.as_slice())
    }

    fn kind(&self, id: usize) -> String {
        self.instances.get(&id).map_or(String::new(), |i| {
            i.parts
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(" ")
        })
    }

    pub(super) fn reference(&self, id: usize, v: Option<&Value>, what: &str) -> Result<usize> {
        match v {
            Some(Value::Ref(r)) => Ok(*r),
            _ => Err(self.fail(id, format!("its {what} is not an instance reference"))),
        }
    }

    pub(super) fn number(&self, id: usize, v: Option<&Value>, what: &str) -> Result<f64> {
        match v {
            Some(Value::Number(x)) if x.is_finite() => Ok(*x),
            Some(Value::Typed(inner)) => self.number(id, Some(inner), what),
            _ => Err(self.fail(id, format!("its {what} is not a number"))),
        }
    }

    pub(super) fn list<'v>(
        &self,
        id: usize,
        v: Option<&'v Value>,
        what: &str,
    ) -> Result<&'v [Value]> {
        match v {
            Some(Value::List(l)) => Ok(l),
            _ => Err(self.fail(id, format!("its {what} is not a list"))),
        }
    }

    fn boolean(&self, id: usize, v: Option<&Value>, what: &str) -> Result<bool> {
        match v {
            Some(Value::Enum(e)) if e == "T" => Ok(true),
            Some(Value::Enum(e)) if e == "F" => Ok(false),
            _ => Err(self.fail(id, format!("its {what} is not .T. or .F."))),
        }
    }

    /// Coordinates of a `CARTESIAN_POINT` (2 or 3 of them).
    pub(super) fn point(&self, id: usize, from: usize) -> Result<Vec<f64>> {
        let p = self.part(id, "CARTESIAN_POINT").ok_or_else(|| {
            self.fail(
                from,
                format!("its control point #{id} is not a CARTESIAN_POINT"),
            )
        })?;
        let c = self.list(id, p.get(1), "coordinates")?;
        c.iter()
            .map(|x| self.number(id, Some(x), "coordinate"))
            .collect()
    }

    /// Knots expanded from `(multiplicities)` and `(values)`.
    fn knots(&self, id: usize, mults: Option<&Value>, values: Option<&Value>) -> Result<Vec<f64>> {
        let m = self.list(id, mults, "knot multiplicities")?;
        let k = self.list(id, values, "knot values")?;
        if m.len() != k.len() {
            return Err(self.fail(
                id,
                format!("{} knot multiplicities for {} knots", m.len(), k.len()),
            ));
        }
        let mut out = Vec::new();
        for (mv, kv) in m.iter().zip(k) {
            let times = self.number(id, Some(mv), "knot multiplicity")?;
            if !(1.0..=64.0).contains(&times) || times.fract() != 0.0 {
                return Err(self.fail(
                    id,
                    format!("knot multiplicity {times} is not an integer in 1..64"),
                ));
            }
            let x = self.number(id, Some(kv), "knot")?;
            out.extend(std::iter::repeat_n(x, times as usize));
        }
        Ok(out)
    }

    fn degree(&self, id: usize, v: Option<&Value>) -> Result<usize> {
        let d = self.number(id, v, "degree")?;
        if !(1.0..=64.0).contains(&d) || d.fract() != 0.0 {
            return Err(self.fail(id, format!("degree {d} is not an integer in 1..64")));
        }
        Ok(d as usize)
    }

    /// A B-spline surface instance as a NURBS surface in mm.
    fn surface(&self, id: usize, face: usize) -> Result<NurbsSurface> {
        // Simple instance: name, du, dv, points, form, closed u, closed v, self-intersect,
        // u mults, v mults, u knots, v knots, spec. Complex: the same split in parts.
        let (head, knots, weights) = if let Some(p) = self
            .part(id, "B_SPLINE_SURFACE_WITH_KNOTS")
            .filter(|p| p.len() == 13)
        {
            (&p[1..4], &p[8..12], None)
        } else if let (Some(b), Some(k)) = (
            self.part(id, "B_SPLINE_SURFACE"),
            self.part(id, "B_SPLINE_SURFACE_WITH_KNOTS"),
        ) {
            if b.len() < 3 || k.len() < 4 {
                return Err(self.fail(id, "too few parameters for a B-spline surface".into()));
            }
            (
                &b[0..3],
                &k[0..4],
                self.part(id, "RATIONAL_B_SPLINE_SURFACE"),
            )
        } else {
            return Err(self.fail(
                face,
                format!(
                    "its surface #{id} is a {}, which is not read; export the faces as \
                     B-spline surfaces (OpenCascade: BRepBuilderAPI_NurbsConvert before writing)",
                    self.kind(id)
                ),
            ));
        };
        let degree = [
            self.degree(id, head.first())?,
            self.degree(id, head.get(1))?,
        ];
        let rows = self.list(id, head.get(2), "control points")?;
        let mut points = Vec::with_capacity(rows.len());
        for row in rows {
            let row = self.list(id, Some(row), "control point row")?;
            let mut r = Vec::with_capacity(row.len());
            for p in row {
                let c = self.point(self.reference(id, Some(p), "control point")?, id)?;
                if c.len() != 3 {
                    return Err(self.fail(id, "a control point without 3 coordinates".into()));
                }
                r.push(Vec3::new(c[0], c[1], c[2]) * self.to_mm);
            }
            points.push(r);
        }
        let ku = self.knots(id, knots.first(), knots.get(2))?;
        let kv = self.knots(id, knots.get(1), knots.get(3))?;
        let weights = match weights {
            None => None,
            Some(w) => {
                let rows = self.list(id, w.first(), "weights")?;
                Some(
                    rows.iter()
                        .map(|r| {
                            self.list(id, Some(r), "weight row")?
                                .iter()
                                .map(|x| self.number(id, Some(x), "weight"))
                                .collect::<Result<Vec<f64>>>()
                        })
                        .collect::<Result<Vec<_>>>()?,
                )
            }
        };
        NurbsSurface::new(degree, [ku, kv], points, weights)
            .map_err(|e| self.fail(id, super::strip(e)))
    }

    /// A 2-D curve of a pcurve's definitional representation, as trimming segments.
    fn param_curve(&self, id: usize) -> Result<Vec<TrimSegment>> {
        if let Some(p) = self.part(id, "POLYLINE") {
            let pts = self.list(id, p.get(1), "points")?;
            let xy: Vec<Vec<f64>> = pts
                .iter()
                .map(|q| self.point(self.reference(id, Some(q), "point")?, id))
                .collect::<Result<_>>()?;
            return Ok(xy
                .windows(2)
                .map(|w| TrimSegment::line([w[0][0], w[0][1]], [w[1][0], w[1][1]]))
                .collect());
        }
        let (head, knots, weights) = if let Some(p) = self
            .part(id, "B_SPLINE_CURVE_WITH_KNOTS")
            .filter(|p| p.len() == 9)
        {
            (&p[1..3], &p[6..8], None)
        } else if let (Some(b), Some(k)) = (
            self.part(id, "B_SPLINE_CURVE"),
            self.part(id, "B_SPLINE_CURVE_WITH_KNOTS"),
        ) {
            if b.len() < 2 || k.len() < 2 {
                return Err(self.fail(id, "too few parameters for a B-spline curve".into()));
            }
            (&b[0..2], &k[0..2], self.part(id, "RATIONAL_B_SPLINE_CURVE"))
        } else {
            return Err(self.fail(id, format!(
                "a {} as a parameter-space trimming curve is not read (read: B-spline curves, polylines)",
                self.kind(id)
            )));
        };
        let p = self.degree(id, head.first())?;
        let mut uv = Vec::new();
        for q in self.list(id, head.get(1), "control points")? {
            let c = self.point(self.reference(id, Some(q), "control point")?, id)?;
            if c.len() < 2 {
                return Err(self.fail(id, "a parameter-space point without 2 coordinates".into()));
            }
            uv.extend([c[0], c[1]]);
        }
        let n = uv.len() / 2;
        let knots = self.knots(id, knots.first(), knots.get(1))?;
        let w = match weights {
            None => vec![1.0; n],
            Some(w) => self
                .list(id, w.first(), "weights")?
                .iter()
                .map(|x| self.number(id, Some(x), "weight"))
                .collect::<Result<_>>()?,
        };
        if w.len() != n || w.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
            return Err(self.fail(
                id,
                format!(
                    "{} weights for {n} control points, all must be > 0",
                    w.len()
                ),
            ));
        }
        check_knots("curve", p, n, &knots).map_err(|e| self.fail(id, super::strip(e)))?;
        Ok(curve_segments(p, &knots, &uv, &w, 2, [knots[p], knots[n]])
            .into_iter()
            .map(|(h, _)| TrimSegment::new(h.chunks(3).map(|c| [c[0], c[1], c[2]]).collect()))
            .collect())
    }

    /// The pcurves on `surface` of an edge's curve, each as trimming segments.
    fn edge_pcurves(&self, edge: usize, surface: usize) -> Result<Vec<Vec<TrimSegment>>> {
        let e = self.part(edge, "EDGE_CURVE").ok_or_else(|| {
            self.fail(
                edge,
                "an oriented edge whose edge is not an EDGE_CURVE".into(),
            )
        })?;
        let geometry = self.reference(edge, e.get(3), "edge geometry")?;
        let g = self
            .part(geometry, "SURFACE_CURVE")
            .or_else(|| self.part(geometry, "SEAM_CURVE"))
            .ok_or_else(|| {
                self.fail(geometry, "an edge curve without parameter-space curves (a SURFACE_CURVE with PCURVEs) is not read".into())
            })?;
        let mut out = Vec::new();
        for a in self.list(geometry, g.get(2), "associated geometry")? {
            let pc = self.reference(geometry, Some(a), "associated geometry")?;
            let Some(p) = self.part(pc, "PCURVE") else {
                continue;
            };
            if self.reference(pc, p.get(1), "basis surface")? != surface {
                continue;
            }
            let rep = self.reference(pc, p.get(2), "definitional representation")?;
            let r = self
                .part(rep, "DEFINITIONAL_REPRESENTATION")
                .ok_or_else(|| {
                    self.fail(
                        pc,
                        "its reference is not a DEFINITIONAL_REPRESENTATION".into(),
                    )
                })?;
            let items = self.list(rep, r.get(1), "items")?;
            let curve = self.reference(rep, items.first(), "curve")?;
            out.push(self.param_curve(curve)?);
        }
        if out.is_empty() {
            return Err(self.fail(
                geometry,
                format!("no PCURVE on the face's surface #{surface}"),
            ));
        }
        Ok(out)
    }

    /// A loop's segments, edges chained by continuity.
    fn boundary(&self, bound: usize, surface: usize) -> Result<Vec<TrimSegment>> {
        let b = self
            .part(bound, "FACE_OUTER_BOUND")
            .or_else(|| self.part(bound, "FACE_BOUND"))
            .ok_or_else(|| self.fail(bound, "a face bound that is not a FACE_BOUND".into()))?;
        let lp = self.reference(bound, b.get(1), "loop")?;
        let Some(l) = self.part(lp, "EDGE_LOOP") else {
            return Ok(Vec::new()); // a vertex loop (a pole) bounds nothing
        };
        let mut edges = Vec::new();
        for oe in self.list(lp, l.get(1), "edge list")? {
            let oe = self.reference(lp, Some(oe), "oriented edge")?;
            let o = self.part(oe, "ORIENTED_EDGE").ok_or_else(|| {
                self.fail(oe, "an edge loop entry that is not an ORIENTED_EDGE".into())
            })?;
            let edge = self.reference(oe, o.get(3), "edge element")?;
            // Every pcurve on this surface, both ways (a seam edge has two).
            let mut options = Vec::new();
            for c in self.edge_pcurves(edge, surface)? {
                let reversed: Vec<TrimSegment> = c.iter().rev().map(|s| s.reversed()).collect();
                options.push(c);
                options.push(reversed);
            }
            edges.push(options);
        }
        let gap = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
        let mut out: Vec<TrimSegment> = Vec::new();
        for k in 0..edges.len() {
            // The option starting where the chain ends; the first edge's, the one ending
            // nearest to an end of the next edge.
            let score = |option: &Vec<TrimSegment>| match out.last() {
                Some(last) => gap(last.end(), option[0].start()),
                None => edges[(k + 1) % edges.len()]
                    .iter()
                    .map(|next| gap(option.last().unwrap().end(), next[0].start()))
                    .fold(f64::INFINITY, f64::min),
            };
            let best = edges[k]
                .iter()
                .min_by(|a, b| score(a).total_cmp(&score(b)))
                .unwrap();
            out.extend(best.iter().cloned());
        }
        Ok(out)
    }

    fn faces(&self) -> Result<Vec<Face>> {
        let placements = self.face_placements()?;
        let mut faces = Vec::new();
        for (&id, inst) in &self.instances {
            let Some((_, p)) = inst.parts.iter().find(|(n, _)| n == "ADVANCED_FACE") else {
                continue;
            };
            let surface_id = self.reference(id, p.get(2), "face geometry")?;
            self.instance(surface_id, id, "surface")?;
            let surface = self.surface(surface_id, id)?;
            let same_sense = self.boolean(id, p.get(3), "same_sense")?;
            let mut loops = Vec::new();
            for b in self.list(id, p.get(1), "bounds")? {
                let b = self.reference(id, Some(b), "bound")?;
                let segments = self.boundary(b, surface_id)?;
                if !segments.is_empty() {
                    loops.push(segments);
                }
            }
            let trim = if loops.is_empty() {
                None
            } else {
                Some(TrimRegion::new(loops).map_err(|e| self.fail(id, super::strip(e)))?)
            };
            let identity = [(crate::geometry::Mat3::identity(), Vec3::zeros())];
            let poses = placements.get(&id).map_or(&identity[..], |p| &p[..]);
            for (r, t) in poses {
                faces.push(Face {
                    surface: surface.clone().transformed(r, &(t * self.to_mm)),
                    trim: trim.clone(),
                    origin: format!("#{id} (ADVANCED_FACE) at line {}", inst.line),
                    flip: !same_sense,
                    arcs: [None, None],
                });
            }
        }
        if faces.is_empty() {
            return Err(Error::Input(format!(
                "{}: no ADVANCED_FACE in the file",
                self.source
            )));
        }
        Ok(faces)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn complex_instances_strings_and_units_parse() {
        let text = "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.CENTI.,.METRE.) );\n#2 = PRODUCT('it''s',(#1),$);\n/* note */ #3 = MEASURE(LENGTH_MEASURE(1.E-07),#1);\nENDSEC;\nEND-ISO-10303-21;\n";
        let s = Step::parse("t.step", text).unwrap();
        assert_eq!(s.to_mm, 10.0);
        assert_eq!(s.instances[&1].parts.len(), 3);
        assert!(matches!(&s.instances[&2].parts[0].1[0], Value::Text(t) if t == "it's"));
        assert_eq!(s.instances[&3].line, 7);
        let e = Step::parse(
            "t.step",
            &text.replace(
                "#3 = MEASURE(LENGTH_MEASURE(1.E-07),#1);\nENDSEC;\nEND-ISO-10303-21;\n",
                "#3 = MEASURE(LENGTH_",
            ),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("t.step:7:"), "{e}");
    }
}
