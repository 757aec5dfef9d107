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
//! A face on an analytic surface (`PLANE`, `CYLINDRICAL_SURFACE`, `CONICAL_SURFACE`,
//! `SPHERICAL_SURFACE`, `TOROIDAL_SURFACE`, `SURFACE_OF_REVOLUTION`,
//! `SURFACE_OF_LINEAR_EXTRUSION`, `OFFSET_SURFACE` of one) is made the exact NURBS it is in
//! STEP's own parameters ([`super::step_analytic`]); its line, circle, ellipse and B-spline
//! pcurves are bounded by the edge's vertices (found on the pcurve by Gauss-Newton on the
//! surface from the 3-D curve's parameter), an edge with no pcurve on a plane is mapped
//! onto the plane exactly. Any other surface is refused naming it and the kinds read. The
//! edges of a loop are chained by continuity: each edge's options (its pcurves, both ways,
//! and on a periodic surface a turn either side) searched depth first for a closed chain,
//! so a loop needs only its pcurves, not the orientation flags. A face's outward normal is
//! its surface's `S_u x S_v` if its `same_sense` is true, the opposite otherwise (a face of
//! a closed shell or solid then points out of it, as OpenCascade writes them), reversed
//! again where its shell lists it through an `ORIENTED_FACE` with orientation `.F.`; the
//! names a face answers to (its own, its shell's, its solid's) are gathered by
//! [`super::step_topology`] for choosing faces by name.
//! Parts placed in an assembly (`CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` with an
//! `ITEM_DEFINED_TRANSFORMATION`) come out at their placed pose ([`super::step_assembly`]). Every error names the file, the line
//! and the instance (`#id`); the file's text is never echoed.

use super::step_analytic::Analytic;
use super::step_curves::{Curve, Frame};
use super::Face;
use crate::geometry::analytic_nurbs::NurbsCurve;
use crate::geometry::nurbs::NurbsSurface;
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

    pub(super) fn kind(&self, id: usize) -> String {
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

    pub(super) fn boolean(&self, id: usize, v: Option<&Value>, what: &str) -> Result<bool> {
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
    pub(super) fn knots(
        &self,
        id: usize,
        mults: Option<&Value>,
        values: Option<&Value>,
    ) -> Result<Vec<f64>> {
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

    pub(super) fn degree(&self, id: usize, v: Option<&Value>) -> Result<usize> {
        let d = self.number(id, v, "degree")?;
        if !(1.0..=64.0).contains(&d) || d.fract() != 0.0 {
            return Err(self.fail(id, format!("degree {d} is not an integer in 1..64")));
        }
        Ok(d as usize)
    }

    /// A B-spline surface instance as a NURBS surface in mm.
    pub(super) fn surface(&self, id: usize, face: usize) -> Result<NurbsSurface> {
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
                    "its surface #{id} is a {}, which is not read (read: {})",
                    self.kind(id),
                    super::step_analytic::READ
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
        if self.part(id, "B_SPLINE_CURVE_WITH_KNOTS").is_none() {
            return Err(self.fail(
                id,
                format!(
                    "a {} as a parameter-space trimming curve is not read (read: B-spline curves, \
                 polylines, and lines, circles, ellipses bounded by the edge's vertices)",
                    self.kind(id)
                ),
            ));
        }
        Ok(segments_2d(&self.spline_curve(id)?))
    }

    /// The trimming segments on `surface` of an edge: one chain per pcurve of the edge on
    /// that surface (a seam has two). A B-spline or polyline pcurve is taken whole; a line,
    /// circle or ellipse pcurve runs over the edge's parameter range on its 3-D curve
    /// ([`Step::edge_range`]), the pcurve sharing the 3-D curve's parameter (OpenCascade's
    /// same-parameter edges), which is checked on the analytic surface. An edge with no
    /// pcurve on a plane is mapped onto the plane exactly.
    fn edge_pcurves(
        &self,
        edge: usize,
        surface: usize,
        analytic: Option<&Analytic>,
    ) -> Result<Vec<Vec<TrimSegment>>> {
        let e = self.part(edge, "EDGE_CURVE").ok_or_else(|| {
            self.fail(
                edge,
                "an oriented edge whose edge is not an EDGE_CURVE".into(),
            )
        })?;
        let geometry = self.reference(edge, e.get(3), "edge geometry")?;
        self.instance(geometry, edge, "edge geometry")?;
        let g = self
            .part(geometry, "SURFACE_CURVE")
            .or_else(|| self.part(geometry, "SEAM_CURVE"));
        let (curve_id, associated) = match g {
            Some(g) => (
                self.reference(geometry, g.get(1), "3-D curve")?,
                self.list(geometry, g.get(2), "associated geometry")?,
            ),
            None => (geometry, &[][..]),
        };
        let mut pcurves = Vec::new();
        for a in associated {
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
            pcurves.push(self.reference(rep, items.first(), "curve")?);
        }
        if pcurves.is_empty() {
            return match analytic {
                Some(Analytic::Plane(frame)) => {
                    let curve = self.curve(curve_id, geometry)?;
                    let range = self.edge_range(edge, &curve)?;
                    let c = curve
                        .nurbs(range)
                        .map_err(|x| self.fail(curve_id, super::strip(x)))?;
                    Ok(vec![on_plane(&c, frame)])
                }
                _ => Err(self.fail(
                    geometry,
                    format!(
                        "no PCURVE on the face's surface #{surface} (an edge without \
                             one is read on planes only)"
                    ),
                )),
            };
        }
        let mut out = Vec::new();
        for pc in pcurves {
            // On a B-spline surface, B-spline and polyline pcurves are whole (as written
            // for B-spline faces); on an analytic one every pcurve is bounded by the edge.
            let bounded = ["LINE", "CIRCLE", "ELLIPSE"]
                .iter()
                .any(|k| self.part(pc, k).is_some())
                || (analytic.is_some() && self.part(pc, "B_SPLINE_CURVE_WITH_KNOTS").is_some());
            if !bounded {
                out.push(self.param_curve(pc)?);
                continue;
            }
            let curve = self.curve(curve_id, geometry)?;
            let range = self.edge_range(edge, &curve)?;
            let plane = self.curve(pc, geometry)?;
            let ranges = self.same_parameter_range(pc, &plane, &curve, range, analytic)?;
            let mut segments = Vec::new();
            for range in &ranges {
                let c = plane
                    .nurbs(*range)
                    .map_err(|x| self.fail(pc, super::strip(x)))?;
                segments.extend(segments_2d(&c));
            }
            let range = ranges[0];
            out.push(segments.clone());
            if curve.periodic() && self.part(pc, "LINE").is_some() {
                // A turn of the 3-D curve's parameter moves along the line by a period of
                // the surface: which one the loop needs, its chaining decides.
                let turn = plane.point(range[0] + std::f64::consts::TAU) - plane.point(range[0]);
                for k in [-1.0, 1.0] {
                    out.push(
                        segments
                            .iter()
                            .map(|s| s.shifted(k * turn.x, k * turn.y))
                            .collect(),
                    );
                }
            }
        }
        Ok(out)
    }

    /// The parameter range of an edge on its 3-D curve: from the vertex it starts at to
    /// the one it ends at, swapped if the edge runs against the curve (`same_sense` false);
    /// on a circle or ellipse the increasing sweep between them (a whole turn if they
    /// coincide), starting in `[0, 2 pi)`.
    fn edge_range(&self, edge: usize, curve: &Curve) -> Result<[f64; 2]> {
        let e = self.part(edge, "EDGE_CURVE").unwrap_or(&[]);
        let vertex = |k: usize| -> Result<Vec3> {
            let v = self.reference(edge, e.get(k), "vertex")?;
            let p = self
                .part(v, "VERTEX_POINT")
                .ok_or_else(|| self.fail(edge, format!("its vertex #{v} is not a VERTEX_POINT")))?;
            self.vec3(self.reference(v, p.get(1), "vertex geometry")?, v)
        };
        let (start, end) = (vertex(1)?, vertex(2)?);
        let (a, b) = if self.boolean(edge, e.get(4), "same_sense")? {
            (start, end)
        } else {
            (end, start)
        };
        let (t0, t1) = (curve.parameter(a), curve.parameter(b));
        if curve.periodic() {
            let mut sweep = (t1 - t0).rem_euclid(std::f64::consts::TAU);
            if sweep < 1e-12 || (a - b).norm() < 1e-9 * (1.0 + a.norm()) {
                sweep = std::f64::consts::TAU;
            }
            return Ok([t0, t0 + sweep]);
        }
        if (t1 - t0).abs() < 1e-300 {
            return Err(self.fail(edge, "an edge of zero length on its curve".into()));
        }
        Ok([t0.min(t1), t0.max(t1)])
    }

    /// The edge's range on its pcurve. The 3-D range first (OpenCascade's edges share
    /// the parameter), each end then moved to where the pcurve's point on the analytic
    /// surface is the 3-D curve's end point, by Gauss-Newton on `|S(p(t)) - C(t_end)|^2`
    /// (derivative by central differences): a writer may reparametrise the surface but
    /// not its lines (OpenCascade's cones). Errs naming the pcurve if an end is not
    /// reached to `1e-6` of the size (the file's digits) or the middle of the pcurve's
    /// range is off the 3-D curve.
    fn same_parameter_range(
        &self,
        pc: usize,
        plane: &Curve,
        curve: &Curve,
        range: [f64; 2],
        analytic: Option<&Analytic>,
    ) -> Result<Vec<[f64; 2]>> {
        let Some(s) = analytic else {
            return Ok(vec![range]);
        };
        let on = |t: f64| {
            let uv = plane.point(t);
            s.point(uv.x, uv.y)
        };
        let fail = || {
            self.fail(
                pc,
                "this pcurve does not run along its edge's 3-D curve on the face's surface".into(),
            )
        };
        // The pcurve's parameter where its point on the surface is `want`, from `guess`.
        // A B-spline pcurve (maybe closed, maybe in its own parameter) starts from the
        // nearest of 512 samples of its range, the others from the 3-D parameter.
        let spline = match plane {
            Curve::Spline(c) => Some(c.range),
            _ => None,
        };
        let solve = |guess: f64, want: Vec3| -> Result<f64> {
            let guess = match spline {
                Some([lo, hi]) => (0..=512)
                    .map(|k| lo + (hi - lo) * k as f64 / 512.0)
                    .min_by(|x, y| (on(*x) - want).norm().total_cmp(&(on(*y) - want).norm()))
                    .unwrap_or(guess),
                None => guess,
            };
            let (mut t, h) = (guess, 1e-6 * (1.0 + guess.abs()));
            for _ in 0..50 {
                let tangent = (on(t + h) - on(t - h)) / (2.0 * h);
                let step = (on(t) - want).dot(&tangent) / tangent.norm_squared().max(1e-300);
                t -= step;
                if step.abs() <= 1e-15 * (1.0 + t.abs()) {
                    break;
                }
            }
            if let Some([lo, hi]) = spline {
                t = t.clamp(lo, hi);
            }
            if (on(t) - want).norm() <= 1e-6 * (1.0 + want.norm()) {
                Ok(t)
            } else {
                Err(fail())
            }
        };
        let [a, b] = range;
        let (ta, tb) = (solve(a, curve.point(a))?, solve(b, curve.point(b))?);
        if let Some([lo, hi]) = spline {
            // Between the ends, or, on a closed spline, round through its own ends.
            let (t0, t1) = (ta.min(tb), ta.max(tb));
            let tm = solve(0.5 * (t0 + t1), curve.point(0.5 * (a + b)))?;
            return Ok(if tm >= t0 && tm <= t1 {
                vec![[t0, t1]]
            } else {
                [[t1, hi], [lo, t0]]
                    .into_iter()
                    .filter(|r| r[1] > r[0])
                    .collect()
            });
        }
        if !plane.periodic() {
            return Ok(vec![[ta.min(tb), ta.max(tb)]]);
        }
        // A circle or ellipse of the parameter plane runs counter-clockwise, which may be
        // against the edge: take the arc between the ends that holds the edge's middle.
        let tau = std::f64::consts::TAU;
        let closed = (b - a - tau).abs() < 1e-9 * (1.0 + b.abs());
        let sweep = (tb - ta).rem_euclid(tau);
        if closed || sweep < 1e-12 {
            return Ok(vec![[ta, ta + tau]]);
        }
        let tm = solve(0.5 * (ta + tb), curve.point(0.5 * (a + b)))?;
        let out = if (tm - ta).rem_euclid(tau) < sweep {
            [ta, ta + sweep]
        } else {
            [tb, tb + (ta - tb).rem_euclid(tau)]
        };
        Ok(vec![out])
    }

    /// A loop's segments, edges chained by continuity.
    fn boundary(
        &self,
        bound: usize,
        surface: usize,
        analytic: Option<&Analytic>,
    ) -> Result<Vec<TrimSegment>> {
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
            for c in self.edge_pcurves(edge, surface, analytic)? {
                let reversed: Vec<TrimSegment> = c.iter().rev().map(|s| s.reversed()).collect();
                options.push(c);
                options.push(reversed);
            }
            edges.push(options);
        }
        Ok(chain(&edges))
    }

    /// The trimming loops of face `id` on `surface` (vertex loops bound nothing).
    fn loops(
        &self,
        id: usize,
        surface: usize,
        analytic: Option<&Analytic>,
    ) -> Result<Vec<Vec<TrimSegment>>> {
        let p = self.part(id, "ADVANCED_FACE").unwrap_or(&[]);
        let mut loops = Vec::new();
        for b in self.list(id, p.get(1), "bounds")? {
            let b = self.reference(id, Some(b), "bound")?;
            let segments = self.boundary(b, surface, analytic)?;
            if !segments.is_empty() {
                loops.push(segments);
            }
        }
        Ok(loops)
    }

    fn faces(&self) -> Result<Vec<Face>> {
        let placements = self.face_placements()?;
        let contexts = self.face_contexts()?;
        let mut faces = Vec::new();
        for (&id, inst) in &self.instances {
            let Some((_, p)) = inst.parts.iter().find(|(n, _)| n == "ADVANCED_FACE") else {
                continue;
            };
            let surface_id = self.reference(id, p.get(2), "face geometry")?;
            let analytic = self.analytic(surface_id, id)?;
            let same_sense = self.boolean(id, p.get(3), "same_sense")?;
            let (analytic, loops) = match self.loops(id, surface_id, analytic.as_ref()) {
                Ok(loops) => (analytic, loops),
                // A cone whose pcurves run by OpenCascade's slant length.
                Err(e) => match analytic.as_ref().and_then(Analytic::slanted) {
                    Some(slanted) => match self.loops(id, surface_id, Some(&slanted)) {
                        Ok(loops) => (Some(slanted), loops),
                        Err(_) => return Err(e),
                    },
                    None => return Err(e),
                },
            };
            let (surface, arcs) = match &analytic {
                None => (self.surface(surface_id, id)?, [None, None]),
                Some(a) => self.analytic_face(a, id, &loops)?,
            };
            let trim = if loops.is_empty() {
                None
            } else {
                Some(TrimRegion::new(loops).map_err(|e| self.fail(id, super::strip(e)))?)
            };
            let identity = [(crate::geometry::Mat3::identity(), Vec3::zeros())];
            let poses = placements.get(&id).map_or(&identity[..], |p| &p[..]);
            let context = contexts.get(&id).cloned().unwrap_or_default();
            for (r, t) in poses {
                faces.push(Face {
                    surface: surface.clone().transformed(r, &(t * self.to_mm)),
                    trim: trim.clone(),
                    origin: format!("#{id} (ADVANCED_FACE) at line {}", inst.line),
                    // n = s o (S_u x S_v) (step_topology.rs): flipped when exactly one of
                    // same_sense and the shell's orientation is false.
                    flip: !same_sense != context.reversed,
                    arcs,
                    names: context.names.clone(),
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

impl Step<'_> {
    /// The exact NURBS of an analytic face over the box of its loops, in mm, with its arc
    /// half angles (see [`super::step_analytic`]).
    fn analytic_face(
        &self,
        a: &Analytic,
        face: usize,
        loops: &[Vec<TrimSegment>],
    ) -> Result<(NurbsSurface, [Option<f64>; 2])> {
        let (s, arcs) = super::step_analytic::face_surface(a, loops)
            .map_err(|e| self.fail(face, super::strip(e)))?;
        let scale = crate::geometry::Mat3::identity() * self.to_mm;
        Ok((s.transformed(&scale, &Vec3::zeros()), arcs))
    }
}

/// The loop of one option per edge (each option an edge's segments one way, on one
/// turn of a periodic surface): a depth-first search for options that meet end to start
/// within `1e-9` of the loop's size and close the loop; a loop of one option per edge
/// has at most 6 options an edge and continuity prunes all but one or two, so the search
/// is short (capped at 10^5 steps). Without such a chain, the greedy one (each option
/// the nearest to the previous end), whose gap the trim region then reports.
pub(super) fn chain(edges: &[Vec<Vec<TrimSegment>>]) -> Vec<TrimSegment> {
    let gap = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let size = edges
        .iter()
        .flatten()
        .flatten()
        .flat_map(|s| [s.start(), s.end()])
        .fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
    let tol = 1e-9 * (1.0 + size);
    let mut picks = vec![0usize; edges.len()];
    let mut steps = 0usize;
    fn search(
        edges: &[Vec<Vec<TrimSegment>>],
        k: usize,
        picks: &mut Vec<usize>,
        steps: &mut usize,
        ok: &dyn Fn([f64; 2], [f64; 2]) -> bool,
    ) -> bool {
        if k == edges.len() {
            let first = edges[0][picks[0]][0].start();
            let last = edges[k - 1][picks[k - 1]].last().unwrap().end();
            return ok(last, first);
        }
        for (i, option) in edges[k].iter().enumerate() {
            *steps += 1;
            if *steps > 100_000 {
                return false;
            }
            if k > 0
                && !ok(
                    edges[k - 1][picks[k - 1]].last().unwrap().end(),
                    option[0].start(),
                )
            {
                continue;
            }
            picks[k] = i;
            if search(edges, k + 1, picks, steps, ok) {
                return true;
            }
        }
        false
    }
    let ok = |a: [f64; 2], b: [f64; 2]| gap(a, b) <= tol;
    if edges.is_empty() || search(edges, 0, &mut picks, &mut steps, &ok) {
        return picks
            .iter()
            .enumerate()
            .flat_map(|(k, &i)| edges[k][i].iter().cloned())
            .collect();
    }
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
    out
}

/// A curve of the parameter plane (its `z` is 0) as trimming segments.
fn segments_2d(c: &NurbsCurve) -> Vec<TrimSegment> {
    c.segments()
        .into_iter()
        .map(|h| TrimSegment::new(h.iter().map(|q| [q[0], q[1], q[3]]).collect()))
        .collect()
}

/// A space curve lying on a plane as trimming segments in the plane's `(u, v)`: the map
/// `x -> ((x - c) . x_axis, (x - c) . y_axis)` is affine, so it acts exactly on the
/// homogeneous control points.
pub(super) fn on_plane(c: &NurbsCurve, f: &Frame) -> Vec<TrimSegment> {
    c.segments()
        .into_iter()
        .map(|h| {
            let pts = h
                .iter()
                .map(|q| {
                    let d = Vec3::new(q[0], q[1], q[2]) - f.origin * q[3];
                    [d.dot(&f.x), d.dot(&f.y), q[3]]
                })
                .collect();
            TrimSegment::new(pts)
        })
        .collect()
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
