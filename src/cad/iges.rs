//! IGES 5.3 reader (fixed 80-column ASCII form) for the faces of a tool.
//!
//! Read: the global section's delimiters, model scale and units (faces come out in mm);
//! the directory entries; and the parameter data of the entities a face needs:
//!
//! - 128 rational B-spline surface (its parameter range `U0..U1 x V0..V1` kept),
//! - 144 trimmed surface: a 128 with an outer loop (or the whole range) and holes, each a
//!   142 curve on surface whose parameter-space curve is read,
//! - parameter-space curves: 126 rational B-spline curve, 110 line, 100 circular arc,
//!   102 composite curve of those,
//! - 124 transformation matrix on a surface or face (applied exactly to control points).
//!
//! - analytic surfaces a CAD exporter writes (in [`super::iges_analytic`]): 108 plane
//!   and 190 plane surface (trimmed by its model-space curves), 120 surface of revolution
//!   and 122 tabulated cylinder, made exact NURBS;
//! - BRep (in [`super::iges_brep`]): 186 manifold solids, 514 shells, 510 faces on 190,
//!   192, 194, 196, 198 or 128 surfaces, bounded by 508 loops of 504 edges.
//!
//! Faces are the BRep faces (shell by shell, then the 510s no shell lists), then the 144
//! entities, and the 128, 120, 122 and bounded 108 entities no 144, 142 or 510 refers to,
//! in directory order. Other surfaces (114, 118, 140, 143, and 192-198 outside a 510) are
//! refused naming the entity: export B-splines instead (OpenCascade:
//! `BRepBuilderAPI_NurbsConvert`). Other entities (annotations, groups, model-space
//! curves) are ignored. Every error names the file and the line (`file:line`),
//! and for an entity its type and directory line; the file's text is never echoed.

use super::Face;
use crate::geometry::nurbs::{check_knots, curve_segments, NurbsSurface};
use crate::geometry::trim::{TrimRegion, TrimSegment};
use crate::geometry::{Mat3, Vec3};
use crate::{Error, Result};
use std::collections::HashSet;

/// One directory entry (two D lines).
#[derive(Debug, Clone)]
pub(super) struct Entry {
    pub(super) kind: i64,
    /// First P line of the parameter data (1-based sequence number).
    data: usize,
    /// Directory line of a 124 transformation, or 0.
    matrix: usize,
    data_lines: usize,
    pub(super) form: i64,
    /// Physical line of the first D line, for messages.
    pub(super) file_line: usize,
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Number(f64),
    Text,
    Empty,
}

/// The parsed sections of a file.
pub(super) struct Iges<'a> {
    pub(super) source: &'a str,
    entries: Vec<Entry>,
    /// P lines: (physical line, data columns 1-64).
    data: Vec<(usize, &'a str)>,
    delimiter: char,
    record: char,
    /// Multiplies model coordinates to give millimetres.
    pub(super) to_mm: f64,
}

fn name(kind: i64) -> &'static str {
    match kind {
        100 => "circular arc",
        102 => "composite curve",
        104 => "conic arc",
        106 => "copious data",
        108 => "plane",
        110 => "line",
        112 => "parametric spline curve",
        114 => "parametric spline surface",
        116 => "point",
        118 => "ruled surface",
        120 => "surface of revolution",
        122 => "tabulated cylinder",
        123 => "direction",
        124 => "transformation matrix",
        126 => "rational B-spline curve",
        128 => "rational B-spline surface",
        140 => "offset surface",
        142 => "curve on a parametric surface",
        143 => "bounded surface",
        144 => "trimmed surface",
        186 => "manifold solid B-rep object",
        190 => "plane surface",
        192 => "right circular cylindrical surface",
        194 => "right circular conical surface",
        196 => "spherical surface",
        198 => "toroidal surface",
        502 => "vertex list",
        504 => "edge list",
        508 => "loop",
        510 => "face",
        514 => "shell",
        _ => "entity",
    }
}

/// Surfaces a CAD exporter may write that are not read (a face on one is refused).
const UNREAD_SURFACES: [i64; 8] = [114, 118, 140, 143, 192, 194, 196, 198];

/// Millimetres per unit of the global section's unit flag (IGES 5.3, parameter 14).
fn unit_to_mm(flag: i64, unit_name: &str) -> Option<f64> {
    Some(match flag {
        1 => 25.4,
        2 => 1.0,
        3 => match unit_name.trim().to_ascii_uppercase().as_str() {
            "MM" => 1.0,
            "CM" => 10.0,
            "M" => 1000.0,
            "IN" | "INCH" => 25.4,
            "FT" => 304.8,
            _ => return None,
        },
        4 => 304.8,
        5 => 1_609_344.0,
        6 => 1000.0,
        7 => 1.0e6,
        8 => 0.0254,
        9 => 1.0e-3,
        10 => 10.0,
        11 => 2.54e-5,
        _ => return None,
    })
}

/// Free-format IGES text split into parameters.
struct Tokens {
    tokens: Vec<Token>,
    /// Texts of the Hollerith string tokens, in order.
    strings: Vec<String>,
    /// Character offset where each token starts.
    starts: Vec<usize>,
    /// The record delimiter was reached.
    ended: bool,
}

/// Splits free-format IGES text into tokens up to the record delimiter. Hollerith strings
/// `nH...` are skipped whole (they may hold delimiters).
fn tokenize(text: &str, delimiter: char, record: char) -> Tokens {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut strings = Vec::new();
    let mut starts = Vec::new();
    let mut i = 0;
    let mut ended = false;
    while i <= chars.len() {
        // Skip leading blanks of a field.
        while i < chars.len() && chars[i] == ' ' {
            i += 1;
        }
        let start = i;
        starts.push(start);
        let mut hollerith = None;
        while i < chars.len() && chars[i] != delimiter && chars[i] != record {
            if chars[i] == 'H' {
                let count: String = chars[start..i].iter().filter(|c| **c != ' ').collect();
                if let Ok(n) = count.parse::<usize>() {
                    let end = (i + 1 + n).min(chars.len());
                    hollerith = Some(chars[i + 1..end].iter().collect::<String>());
                    i = end;
                    continue;
                }
            }
            i += 1;
        }
        let field: String = chars[start..i.min(chars.len())].iter().collect();
        let field = field.trim();
        if let Some(s) = hollerith {
            strings.push(s);
            tokens.push(Token::Text);
        } else if field.is_empty() {
            tokens.push(Token::Empty);
        } else {
            let normal = field.replace(['D', 'd'], "E");
            match normal.parse::<f64>() {
                Ok(x) => tokens.push(Token::Number(x)),
                Err(_) => tokens.push(Token::Text),
            }
        }
        if i >= chars.len() {
            break;
        }
        if chars[i] == record {
            ended = true;
            break;
        }
        i += 1;
    }
    Tokens {
        tokens,
        strings,
        starts,
        ended,
    }
}

/// Parameters of one entity, with the context for messages.
pub(super) struct Params<'a> {
    tokens: Vec<Token>,
    at: String,
    source: &'a str,
    line: usize,
}

impl Params<'_> {
    pub(super) fn fail(&self, message: String) -> Error {
        Error::Input(format!(
            "{}:{}: {}: {message}",
            self.source, self.line, self.at
        ))
    }

    /// Parameter `i` (1 = the first after the entity type) as a number; empty means 0.
    pub(super) fn real(&self, i: usize, what: &str) -> Result<f64> {
        match self.tokens.get(i) {
            Some(Token::Number(x)) if x.is_finite() => Ok(*x),
            Some(Token::Empty) => Ok(0.0),
            Some(_) => Err(self.fail(format!("parameter {i} ({what}) is not a number"))),
            None => Err(self.fail(format!(
                "parameter {i} ({what}) is missing: the parameter data is truncated"
            ))),
        }
    }

    pub(super) fn int(&self, i: usize, what: &str) -> Result<i64> {
        let x = self.real(i, what)?;
        if x.fract() != 0.0 || x.abs() > 1e12 {
            return Err(self.fail(format!("parameter {i} ({what}) = {x} is not an integer")));
        }
        Ok(x as i64)
    }

    pub(super) fn count(&self, i: usize, what: &str) -> Result<usize> {
        let x = self.int(i, what)?;
        if !(0..=1_000_000).contains(&x) {
            return Err(self.fail(format!("parameter {i} ({what}) = {x} is out of range")));
        }
        Ok(x as usize)
    }

    pub(super) fn reals(&self, from: usize, n: usize, what: &str) -> Result<Vec<f64>> {
        (from..from + n).map(|i| self.real(i, what)).collect()
    }
}

/// Reads the faces of an IGES file's text; `source` (the file name) starts every message.
pub fn faces_from_iges(source: &str, text: &str) -> Result<Vec<Face>> {
    let iges = Iges::parse(source, text)?;
    iges.faces()
}

/// An input error at `source:line`.
fn input_error(source: &str, line: usize, message: &str) -> Error {
    Error::Input(format!("{source}:{line}: {message}"))
}

/// The global section's parameter and record delimiters: its first two parameters in the
/// `1H,` form (`1H,,1H;` names `,` and `;`), or the defaults `,` and `;` where a field is
/// empty or not of that form.
fn global_delimiters(g: &str) -> (char, char) {
    // Parameter and record delimiters: "1H," forms, or defaults when the field is empty.
    let mut chars = g.chars();
    let (delimiter, rest) = match (chars.next(), chars.next(), chars.next()) {
        (Some('1'), Some('H'), Some(c)) => (c, &g[3..]),
        _ => (',', g),
    };
    let rest = rest.strip_prefix(delimiter).unwrap_or(rest);
    let record = {
        let mut c = rest.chars();
        match (c.next(), c.next(), c.next()) {
            (Some('1'), Some('H'), Some(r)) => r,
            _ => ';',
        }
    };
    (delimiter, record)
}

impl<'a> Iges<'a> {
    fn parse(source: &'a str, text: &'a str) -> Result<Iges<'a>> {
        let [_, global, directory, data, terminate] = Self::sections(source, text)?;
        Self::check_terminate(source, text, &terminate, directory.len(), data.len())?;
        if global.is_empty() {
            return Err(input_error(source, 1, "no global (G) section"));
        }
        let g: String = global.iter().map(|(_, s)| *s).collect();
        let (delimiter, record) = global_delimiters(&g);
        let to_mm = Self::global_scale(source, &global, &g, delimiter, record)?;
        let entries = Self::directory_entries(source, &directory)?;
        Ok(Iges {
            source,
            entries,
            data: data.iter().map(|(l, s)| (*l, &s[..64])).collect(),
            delimiter,
            record,
            to_mm,
        })
    }

    /// The lines of the five sections (start, global, directory, parameter data,
    /// terminate), each as (physical line, columns 1-72), blank lines skipped. Fails on a
    /// line that is not fixed-format ASCII (80 columns, the section letter in column 73),
    /// on an unknown section letter and on sections out of order.
    fn sections(source: &str, text: &'a str) -> Result<[Vec<(usize, &'a str)>; 5]> {
        let fail = |line: usize, m: &str| input_error(source, line, m);
        let mut sections: [Vec<(usize, &str)>; 5] = Default::default();
        let order = ['S', 'G', 'D', 'P', 'T'];
        let mut current = 0;
        for (k, raw) in text.lines().enumerate() {
            let line = k + 1;
            let raw = raw.trim_end_matches('\r');
            if raw.trim().is_empty() {
                continue;
            }
            if !raw.is_ascii() || raw.len() < 73 {
                return Err(fail(
                    line,
                    "not a fixed-format ASCII IGES line (80 columns, section letter in column \
                     73); compressed and binary IGES are not read",
                ));
            }
            let letter = raw.as_bytes()[72] as char;
            let Some(s) = order.iter().position(|&c| c == letter) else {
                return Err(fail(
                    line,
                    &format!("section letter '{letter}' in column 73 is not one of S, G, D, P, T"),
                ));
            };
            if s < current {
                return Err(fail(
                    line,
                    &format!("{letter} line after the {} section", order[current]),
                ));
            }
            current = s;
            sections[s].push((line, &raw[..72]));
        }
        Ok(sections)
    }

    /// Checks that the file is whole: the terminate section exists, and the counts of D and
    /// P lines it announces (`"S      1G      4D    123P    456"`) are the lines read.
    fn check_terminate(
        source: &str,
        text: &str,
        terminate: &[(usize, &str)],
        directory_lines: usize,
        data_lines: usize,
    ) -> Result<()> {
        let fail = |line: usize, m: &str| input_error(source, line, m);
        let last_line = text.lines().count();
        if terminate.is_empty() {
            return Err(fail(
                last_line,
                "the file ends without its terminate (T) section: it is truncated",
            ));
        }
        // T: "S      1G      4D    123P    456" - counts of each section's lines.
        let t = terminate[0].1;
        for (k, (letter, lines)) in [('D', directory_lines), ('P', data_lines)]
            .iter()
            .enumerate()
        {
            let field = &t[8 * (k + 2)..8 * (k + 3)];
            let announced = field.get(1..).unwrap_or("").trim().parse::<usize>().ok();
            if field.starts_with(*letter) && announced != Some(*lines) {
                return Err(fail(
                    terminate[0].0,
                    &format!(
                        "the terminate section announces {} {letter} lines, the file has \
                         {lines}: it is truncated or damaged",
                        announced.map_or("?".to_string(), |n| n.to_string())
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Millimetres per model unit, `unit / model_scale`, from the global section's units
    /// flag (parameter 14, with the unit name of parameter 15 for flag 3) and model space
    /// scale (parameter 13; both defaulted when absent). `global` are the G lines, `g`
    /// their text joined. Fails, naming the G line, on an unknown unit or a scale that is
    /// not positive.
    fn global_scale(
        source: &str,
        global: &[(usize, &str)],
        g: &str,
        delimiter: char,
        record: char,
    ) -> Result<f64> {
        let fail = |line: usize, m: &str| input_error(source, line, m);
        let Tokens {
            tokens,
            strings,
            starts,
            ..
        } = tokenize(g, delimiter, record);
        // The G line holding global parameter k (1-based).
        let line_of = |k: usize| {
            let offset = starts.get(k - 1).copied().unwrap_or(0);
            global[(offset / 72).min(global.len() - 1)].0
        };
        // Parameter k (1-based) of the global section.
        let number = |k: usize| match tokens.get(k - 1) {
            Some(Token::Number(x)) => Some(*x),
            _ => None,
        };
        let model_scale = number(13).unwrap_or(1.0);
        let unit_flag = number(14).unwrap_or(1.0) as i64;
        let text_index = tokens[..tokens.len().min(14)]
            .iter()
            .filter(|t| **t == Token::Text)
            .count();
        let unit_name = match tokens.get(14) {
            Some(Token::Text) => strings.get(text_index).cloned().unwrap_or_default(),
            _ => String::new(),
        };
        let unit = unit_to_mm(unit_flag, &unit_name).ok_or_else(|| {
            fail(
                line_of(14),
                &format!("global parameter 14 (units flag) = {unit_flag} is not an IGES unit"),
            )
        })?;
        if !(model_scale.is_finite() && model_scale > 0.0) {
            return Err(fail(
                line_of(13),
                &format!("global parameter 13 (model space scale) = {model_scale} must be > 0"),
            ));
        }
        Ok(unit / model_scale)
    }

    /// The directory entries, one per pair of D lines: entity type, parameter data pointer
    /// and transformation matrix from the first line, parameter line count and form number
    /// from the second. Fails on an odd number of D lines (a truncated entry), a field that
    /// is not an integer and a negative pointer or count.
    fn directory_entries(source: &str, directory: &[(usize, &str)]) -> Result<Vec<Entry>> {
        let fail = |line: usize, m: &str| input_error(source, line, m);
        if directory.len() % 2 != 0 {
            return Err(fail(
                directory.last().map_or(1, |d| d.0),
                "the directory (D) section has an odd number of lines: an entry is truncated",
            ));
        }
        let field = |text: &str, k: usize, line: usize, what: &str| -> Result<i64> {
            let f = text[8 * k..8 * (k + 1)].trim();
            if f.is_empty() {
                return Ok(0);
            }
            f.parse::<i64>().map_err(|_| {
                fail(
                    line,
                    &format!("directory field {} ({what}) is not an integer", k + 1),
                )
            })
        };
        let mut entries = Vec::with_capacity(directory.len() / 2);
        for pair in directory.chunks(2) {
            let ((l1, d1), (l2, d2)) = (pair[0], pair[1]);
            let nonneg = |x: i64, line: usize, what: &str| -> Result<usize> {
                usize::try_from(x)
                    .map_err(|_| fail(line, &format!("directory {what} = {x} must be >= 0")))
            };
            entries.push(Entry {
                kind: field(d1, 0, l1, "entity type")?,
                data: nonneg(
                    field(d1, 1, l1, "parameter data pointer")?,
                    l1,
                    "parameter data pointer",
                )?,
                matrix: nonneg(
                    field(d1, 6, l1, "transformation matrix")?,
                    l1,
                    "transformation matrix",
                )?,
                data_lines: nonneg(
                    field(d2, 3, l2, "parameter line count")?,
                    l2,
                    "parameter line count",
                )?,
                form: field(d2, 4, l2, "form number")?,
                file_line: l1,
            });
        }
        Ok(entries)
    }

    /// The directory entries, in order (entry `i` is at D line `2 i + 1`).
    pub(super) fn entries(&self) -> &[Entry] {
        &self.entries
    }

    /// The entry a directory pointer (odd D line number) names.
    pub(super) fn entry(&self, pointer: i64, from: &Params, what: &str) -> Result<&Entry> {
        let index = usize::try_from(pointer - 1)
            .ok()
            .filter(|i| i % 2 == 0)
            .map(|i| i / 2);
        index.and_then(|i| self.entries.get(i)).ok_or_else(|| {
            from.fail(format!(
                "{what} pointer {pointer} is not a directory entry (odd D line 1..{})",
                2 * self.entries.len()
            ))
        })
    }

    pub(super) fn describe(e: &Entry) -> String {
        format!(
            "entity {} ({}) at D line {}",
            e.kind,
            name(e.kind),
            e.file_line
        )
    }

    pub(super) fn params(&self, e: &Entry) -> Result<Params<'a>> {
        let at = Self::describe(e);
        let fail = |m: String| Error::Input(format!("{}:{}: {at}: {m}", self.source, e.file_line));
        if e.data == 0 || e.data_lines == 0 || e.data - 1 + e.data_lines > self.data.len() {
            return Err(fail(format!(
                "its parameter data (P lines {}..{}) lies beyond the P section's {} lines: \
                 the file is truncated or the directory damaged",
                e.data,
                e.data + e.data_lines.max(1) - 1,
                self.data.len()
            )));
        }
        let lines = &self.data[e.data - 1..e.data - 1 + e.data_lines];
        let text: String = lines.iter().map(|(_, s)| *s).collect();
        let Tokens { tokens, ended, .. } = tokenize(&text, self.delimiter, self.record);
        let first_line = lines[0].0;
        if !ended {
            return Err(Error::Input(format!(
                "{}:{first_line}: {at}: its parameter data has no record end '{}': truncated",
                self.source, self.record
            )));
        }
        if tokens.first() != Some(&Token::Number(e.kind as f64)) {
            return Err(Error::Input(format!(
                "{}:{first_line}: {at}: its parameter data does not start with the entity type \
                 {} (the directory and the data disagree)",
                self.source, e.kind
            )));
        }
        Ok(Params {
            tokens,
            at,
            source: self.source,
            line: first_line,
        })
    }

    /// The faces: those of the BRep entities (186 solids, 514 shells, 510 faces:
    /// [`super::iges_brep`]), the 144 entities, and the 128, 120, 122 and bounded 108
    /// entities that no 144, 142 or 510 uses.
    fn faces(&self) -> Result<Vec<Face>> {
        let mut used = HashSet::new();
        for e in &self.entries {
            if matches!(e.kind, 144 | 142 | 510) {
                let p = self.params(e)?;
                let k = if e.kind == 142 { 2 } else { 1 };
                used.insert(p.int(k, "surface pointer")?);
            }
        }
        let mut faces = self.brep_faces()?;
        for (i, e) in self.entries.iter().enumerate() {
            let pointer = (2 * i + 1) as i64;
            match e.kind {
                144 => faces.push(self.trimmed_face(e)?),
                128 | 120 | 122 if !used.contains(&pointer) => {
                    let (surface, arcs) = match e.kind {
                        128 => (self.surface(e)?, [None, None]),
                        120 => self.revolution(e)?,
                        _ => {
                            let (surface, arcs, _) = self.tabulated_cylinder(e)?;
                            (surface, arcs)
                        }
                    };
                    faces.push(Face {
                        surface,
                        trim: None,
                        origin: Self::describe(e),
                        flip: false,
                        arcs,
                        names: Vec::new(),
                    });
                }
                108 | 190 if !used.contains(&pointer) => faces.push(self.bounded_plane(e)?),
                k if UNREAD_SURFACES.contains(&k) && !used.contains(&pointer) => {
                    return Err(self.unread_surface(e))
                }
                _ => {}
            }
        }
        if faces.is_empty() {
            return Err(Error::Input(format!(
                "{}: no face (entity 510, 128, 144, 120, 122 or bounded 108) in the file",
                self.source
            )));
        }
        Ok(faces)
    }

    fn unread_surface(&self, e: &Entry) -> Error {
        Error::Input(format!(
            "{}:{}: {}: this surface type is not read (192-198 only as the surface of a 510 \
             BRep face); export the faces as rational B-spline surfaces (entity 128; \
             OpenCascade: BRepBuilderAPI_NurbsConvert before writing)",
            self.source,
            e.file_line,
            Self::describe(e)
        ))
    }

    /// `x -> R x + t` of a 124 entity (and of the 124s it chains to), identity for 0.
    pub(super) fn matrix(&self, e: &Entry, depth: usize) -> Result<(Mat3, Vec3)> {
        if e.matrix == 0 {
            return Ok((Mat3::identity(), Vec3::zeros()));
        }
        let here = self.params(e)?;
        let m = self.entry(e.matrix as i64, &here, "transformation matrix")?;
        if m.kind != 124 || depth > 16 {
            return Err(here.fail(format!(
                "its transformation pointer names {}, not a 124 matrix (or a loop of them)",
                Self::describe(m)
            )));
        }
        let p = self.params(m)?;
        let v = p.reals(1, 12, "matrix entry")?;
        let r = Mat3::new(v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]);
        let t = Vec3::new(v[3], v[7], v[11]);
        let (outer_r, outer_t) = self.matrix(m, depth + 1)?;
        Ok((outer_r * r, outer_r * t + outer_t))
    }

    /// A 128 entity as a NURBS surface in mm, restricted to its parameter range.
    pub(super) fn surface(&self, e: &Entry) -> Result<NurbsSurface> {
        let p = self.params(e)?;
        let k1 = p.count(1, "K1, upper index of u")?;
        let k2 = p.count(2, "K2, upper index of v")?;
        let m1 = p.count(3, "M1, degree in u")?;
        let m2 = p.count(4, "M2, degree in v")?;
        let (nu, nv) = (k1 + 1, k2 + 1);
        let mut at = 10;
        let ku = p.reals(at, k1 + m1 + 2, "u knot")?;
        at += k1 + m1 + 2;
        let kv = p.reals(at, k2 + m2 + 2, "v knot")?;
        at += k2 + m2 + 2;
        let w = p.reals(at, nu * nv, "weight")?;
        at += nu * nv;
        let xyz = p.reals(at, 3 * nu * nv, "control point coordinate")?;
        at += 3 * nu * nv;
        let range = p.reals(at, 4, "parameter range U0 U1 V0 V1")?;
        // IGES lists control points with the u index fastest.
        let points = (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| {
                        let k = 3 * (j * nu + i);
                        Vec3::new(xyz[k], xyz[k + 1], xyz[k + 2])
                    })
                    .collect()
            })
            .collect();
        let weights = (0..nu)
            .map(|i| (0..nv).map(|j| w[j * nu + i]).collect())
            .collect();
        let wrap = |e: Error| p.fail(super::strip(e));
        let surface = NurbsSurface::new([m1, m2], [ku, kv], points, Some(weights))
            .and_then(|s| s.restricted([range[0], range[1]], [range[2], range[3]]))
            .map_err(wrap)?;
        let (r, t) = self.matrix(e, 0)?;
        Ok(surface.transformed(&(r * self.to_mm), &(t * self.to_mm)))
    }

    /// A 144 entity: its surface (a 128, in mm, after the 144's own matrix) and trim.
    fn trimmed_face(&self, e: &Entry) -> Result<Face> {
        let p = self.params(e)?;
        let s = self.entry(p.int(1, "PTS, surface pointer")?, &p, "surface")?;
        // IGES's `u` of a 122 is normalised; its surface runs by the directrix's own.
        let mut u_map = None;
        let (surface, arcs) = match s.kind {
            128 => (self.surface(s)?, [None, None]),
            120 => self.revolution(s)?,
            122 => {
                let (surface, arcs, map) = self.tabulated_cylinder(s)?;
                u_map = Some(map);
                (surface, arcs)
            }
            108 | 190 => return self.trimmed_plane(e, &p, s),
            k if UNREAD_SURFACES.contains(&k) => return Err(self.unread_surface(s)),
            _ => {
                return Err(p.fail(format!(
                    "its surface pointer names {}, not a surface",
                    Self::describe(s)
                )))
            }
        };
        let outer = p.int(2, "N1, outer boundary flag")?;
        let holes = p.count(3, "N2, inner boundary count")?;
        let [u, v] = surface.domain();
        let mut loops = Vec::with_capacity(holes + 1);
        if outer == 0 {
            let corners = [[u[0], v[0]], [u[1], v[0]], [u[1], v[1]], [u[0], v[1]]];
            loops.push(
                (0..4)
                    .map(|k| TrimSegment::line(corners[k], corners[(k + 1) % 4]))
                    .collect(),
            );
        } else {
            loops.push(self.boundary(p.int(4, "PTO, outer boundary pointer")?, &p)?);
        }
        for k in 0..holes {
            loops.push(self.boundary(p.int(5 + k, "PTI, inner boundary pointer")?, &p)?);
        }
        if let Some([a, b]) = u_map {
            let from_file = usize::from(outer != 0);
            for segment in loops.iter_mut().skip(1 - from_file).flatten() {
                *segment = segment.u_mapped(a, b);
            }
        }
        let trim = TrimRegion::new(loops).map_err(|e| p.fail(super::strip(e)))?;
        let (r, t) = self.matrix(e, 0)?;
        Ok(Face {
            surface: surface.transformed(&r, &(t * self.to_mm)),
            trim: Some(trim),
            origin: Self::describe(e),
            flip: false,
            arcs,
            names: Vec::new(),
        })
    }

    /// The parameters of the 142 curve on surface a face's boundary `pointer` names.
    pub(super) fn curve_on_surface(&self, pointer: i64, face: &Params) -> Result<Params<'a>> {
        let c = self.entry(pointer, face, "boundary")?;
        if c.kind != 142 {
            return Err(face.fail(format!(
                "its boundary pointer names {}, not a 142 curve on surface",
                Self::describe(c)
            )));
        }
        self.params(c)
    }

    /// A 142 curve on surface: the segments of its parameter-space curve.
    fn boundary(&self, pointer: i64, face: &Params) -> Result<Vec<TrimSegment>> {
        let p = self.curve_on_surface(pointer, face)?;
        let b = p.int(3, "BPTR, parameter-space curve pointer")?;
        if b == 0 {
            return Err(p.fail(
                "it has no parameter-space curve (only a model-space one), which is not read"
                    .to_string(),
            ));
        }
        let mut out = Vec::new();
        self.param_curve(self.entry(b, &p, "parameter-space curve")?, &mut out, 0)?;
        Ok(out)
    }

    /// Appends the segments of a parameter-space curve (126, 110, 100, or 102 of those).
    pub(super) fn param_curve(
        &self,
        e: &Entry,
        out: &mut Vec<TrimSegment>,
        depth: usize,
    ) -> Result<()> {
        let p = self.params(e)?;
        if e.matrix != 0 {
            return Err(p.fail(
                "a transformation matrix on a parameter-space curve is not read".to_string(),
            ));
        }
        match e.kind {
            102 if depth < 8 => {
                let n = p.count(1, "N, curve count")?;
                for k in 0..n {
                    let c = self.entry(p.int(2 + k, "curve pointer")?, &p, "curve")?;
                    self.param_curve(c, out, depth + 1)?;
                }
            }
            110 => {
                let v = p.reals(1, 6, "end point coordinate")?;
                out.push(TrimSegment::line([v[0], v[1]], [v[3], v[4]]));
            }
            100 => out.extend(arc(&p.reals(1, 7, "arc parameter")?)),
            126 => {
                let BsplineCurve {
                    degree: m,
                    knots,
                    weights: w,
                    xyz,
                    range,
                } = bspline_curve(&p)?;
                let uv: Vec<f64> = xyz.chunks(3).flat_map(|c| [c[0], c[1]]).collect();
                for (h, _) in curve_segments(m, &knots, &uv, &w, 2, range) {
                    out.push(TrimSegment::new(
                        h.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
                    ));
                }
            }
            _ => {
                return Err(p.fail(format!(
                    "this entity (form {}) is not read as a parameter-space trimming curve \
                     (read: 126, 110, 100, 102)",
                    e.form
                )))
            }
        }
        Ok(())
    }
}

/// The data of a 126 rational B-spline curve, checked.
pub(super) struct BsplineCurve {
    pub(super) degree: usize,
    pub(super) knots: Vec<f64>,
    pub(super) weights: Vec<f64>,
    /// Control points, three coordinates each.
    pub(super) xyz: Vec<f64>,
    pub(super) range: [f64; 2],
}

/// Reads a 126 entity's parameters: knots (see [`check_knots`]), weights > 0, and the
/// parameter range inside the knot domain.
pub(super) fn bspline_curve(p: &Params) -> Result<BsplineCurve> {
    let k = p.count(1, "K, upper index")?;
    let m = p.count(2, "M, degree")?;
    let n = k + 1;
    let knots = p.reals(7, k + m + 2, "knot")?;
    let w = p.reals(7 + k + m + 2, n, "weight")?;
    let xyz = p.reals(7 + k + m + 2 + n, 3 * n, "control point coordinate")?;
    let range = p.reals(7 + k + m + 2 + 4 * n, 2, "parameter range V0 V1")?;
    check_knots("curve", m, n, &knots).map_err(|e| p.fail(super::strip(e)))?;
    if let Some(bad) = w.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(p.fail(format!("weight {bad} = {} must be > 0", w[bad])));
    }
    let (a, b) = (knots[m], knots[n]);
    if !(a <= range[0] && range[0] < range[1] && range[1] <= b) {
        return Err(p.fail(format!(
            "parameter range [{}, {}] must be inside the knot domain [{a}, {b}]",
            range[0], range[1]
        )));
    }
    Ok(BsplineCurve {
        degree: m,
        knots,
        weights: w,
        xyz,
        range: [range[0], range[1]],
    })
}

/// A 100 circular arc (`ZT, centre, start, end`, counter-clockwise) as rational quadratic
/// pieces of at most 90°.
fn arc(v: &[f64]) -> Vec<TrimSegment> {
    let (c, s, e) = ([v[1], v[2]], [v[3], v[4]], [v[5], v[6]]);
    let r = (s[0] - c[0]).hypot(s[1] - c[1]);
    let a0 = (s[1] - c[1]).atan2(s[0] - c[0]);
    let a1 = (e[1] - c[1]).atan2(e[0] - c[0]);
    let tau = std::f64::consts::TAU;
    let mut sweep = (a1 - a0).rem_euclid(tau);
    if sweep <= 1e-14 {
        sweep = tau;
    }
    let n = (sweep / std::f64::consts::FRAC_PI_2 - 1e-9).ceil().max(1.0) as usize;
    let h = 0.5 * sweep / n as f64;
    let at = |a: f64, rho: f64| [c[0] + rho * a.cos(), c[1] + rho * a.sin()];
    (0..n)
        .map(|k| {
            let start = a0 + 2.0 * h * k as f64;
            let (p0, p1) = (
                if k == 0 { s } else { at(start, r) },
                at(start + h, r / h.cos()),
            );
            let p2 = if k + 1 == n {
                e
            } else {
                at(start + 2.0 * h, r)
            };
            let w = h.cos();
            TrimSegment::new(vec![
                [p0[0], p0[1], 1.0],
                [p1[0] * w, p1[1] * w, w],
                [p2[0], p2[1], 1.0],
            ])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hollerith_strings_may_hold_delimiters() {
        let Tokens {
            tokens,
            strings,
            starts,
            ended,
        } = tokenize("1H,,1H;,4Ha,b;,2.5D1,,7;", ',', ';');
        assert!(ended);
        assert_eq!(strings, vec![",", ";", "a,b;"]);
        assert_eq!(starts[3], 15);
        assert_eq!(tokens[3], Token::Number(25.0));
        assert_eq!(tokens[4], Token::Empty);
        assert_eq!(tokens[5], Token::Number(7.0));
    }

    #[test]
    fn arcs_end_where_they_say() {
        let segs = arc(&[0.0, 1.0, 1.0, 3.0, 1.0, 1.0, 3.0]);
        assert_eq!(segs.len(), 1);
        let mid = segs[0].point(0.5);
        assert!(((mid[0] - 1.0).hypot(mid[1] - 1.0) - 2.0).abs() < 1e-14);
        let full = arc(&[0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0]);
        assert_eq!(full.len(), 4);
        let e = full[3].end();
        assert!((e[0] - 1.0).abs() < 1e-15 && e[1].abs() < 1e-15);
    }
}
