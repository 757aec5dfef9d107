//! VTK XML unstructured grid (`.vtu`) frames of a hexahedral mesh (the blank) or of
//! quadrilaterals (a tool's display surface).
//!
//! [`Frame`] is a format-neutral description of one output frame; [`write_vtu`] writes it as an
//! XML `.vtu` file (VTK file version 1.0, little-endian, `header_type="UInt64"`, inline base64
//! binary arrays, *uncompressed*), which ParaView and VTK read. Float data is written as
//! `Float64`, so values read back bit-exactly. [`read_vtu`] / [`read_vtu_point_field`] read such a
//! file back (through vtkio's reader) for tests and tools.
//!
//! Component names (`ComponentName0="xx"` ... on a `<DataArray>`, which ParaView shows as
//! `stress_xx` and so on) are not part of vtkio's model: they are added to the tags of the
//! encoded XML and read back from them with quick-xml.

use crate::{Error, Result};
use std::path::Path;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    Piece, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// One output frame: hexahedra and/or quadrilaterals with point and cell fields.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// 8-node hexahedra, node order as VTK_HEXAHEDRON (bottom face 0-1-2-3 counter-clockwise seen
    /// from the top, then top face 4-5-6-7 above 0-1-2-3), indices into `points`.
    pub hexes: Vec<[usize; 8]>,
    /// 4-node quadrilaterals (VTK_QUAD), after the hexahedra in the file's cell order.
    pub quads: Vec<[usize; 4]>,
    /// 3-node triangles (VTK_TRIANGLE), after the quadrilaterals in the file's cell order
    /// (the trimmed parts of a tool's display surface).
    pub triangles: Vec<[usize; 3]>,
    /// Fields with one tuple per point.
    pub point_data: Vec<Field>,
    /// Fields with one tuple per cell (hexahedra first, then quadrilaterals).
    pub cell_data: Vec<Field>,
}

/// A named field: `components` values per point (or cell), tuples stored one after another, so
/// `values.len() == components * count`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Field {
    pub name: String,
    pub components: usize,
    pub values: Vec<f64>,
    /// Names of the components (`xx`, `yy`, ...), written as VTK `ComponentName`s; empty for
    /// none (ParaView then numbers them, or says X, Y, Z for 3 components).
    pub component_names: Vec<String>,
}

/// Component names of a symmetric tensor in VTK's (and tribo's Voigt) order.
pub const SYMMETRIC_TENSOR_COMPONENTS: [&str; 6] = ["xx", "yy", "zz", "xy", "yz", "xz"];

impl Field {
    /// A field with `components` values per tuple.
    pub fn new(name: impl Into<String>, components: usize, values: Vec<f64>) -> Self {
        Field {
            name: name.into(),
            components,
            values,
            component_names: Vec::new(),
        }
    }

    /// A symmetric tensor field, 6 values per tuple in the order of
    /// [`SYMMETRIC_TENSOR_COMPONENTS`], with those component names.
    pub fn symmetric_tensor(name: impl Into<String>, values: Vec<f64>) -> Self {
        Field::new(name, 6, values).named_components(&SYMMETRIC_TENSOR_COMPONENTS)
    }

    /// The field with the given component names.
    pub fn named_components(mut self, names: &[&str]) -> Self {
        self.component_names = names.iter().map(|s| s.to_string()).collect();
        self
    }

    /// A scalar field (one value per tuple).
    pub fn scalar(name: impl Into<String>, values: Vec<f64>) -> Self {
        Field::new(name, 1, values)
    }

    /// A 3-vector field.
    pub fn vector(name: impl Into<String>, values: &[[f64; 3]]) -> Self {
        Field::new(name, 3, values.iter().flatten().copied().collect())
    }

    /// Number of tuples (`values.len() / components`; 0 if `components` is 0).
    pub fn count(&self) -> usize {
        self.values.len().checked_div(self.components).unwrap_or(0)
    }
}

impl Frame {
    /// Number of cells (hexahedra, quadrilaterals and triangles).
    pub fn cell_count(&self) -> usize {
        self.hexes.len() + self.quads.len() + self.triangles.len()
    }

    /// Checks that every cell references existing points and that every field has a non-empty
    /// unique name, at least one component, exactly `components * count` values, and either
    /// no component names or one per component.
    pub fn validate(&self) -> Result<()> {
        let np = self.points.len();
        let cells = (self.hexes.iter().map(|h| ("hexahedron", &h[..])))
            .enumerate()
            .chain(
                self.quads
                    .iter()
                    .enumerate()
                    .map(|(i, q)| (i, ("quadrilateral", &q[..]))),
            )
            .chain(
                self.triangles
                    .iter()
                    .enumerate()
                    .map(|(i, t)| (i, ("triangle", &t[..]))),
            );
        for (i, (kind, nodes)) in cells {
            if let Some(&bad) = nodes.iter().find(|&&n| n >= np) {
                return Err(Error::input(
                    &format!("node index of {kind} {i}"),
                    bad,
                    &format!("must be < number of points ({np})"),
                ));
            }
        }
        check_fields(&self.point_data, "point", np)?;
        check_fields(&self.cell_data, "cell", self.cell_count())
    }
}

fn check_fields(fields: &[Field], kind: &str, count: usize) -> Result<()> {
    for (i, f) in fields.iter().enumerate() {
        if f.name.is_empty() {
            return Err(Error::input(
                &format!("name of {kind} field #{i}"),
                "\"\"",
                "must not be empty",
            ));
        }
        if fields[..i].iter().any(|g| g.name == f.name) {
            return Err(Error::input(
                &format!("{kind} field name"),
                format!("\"{}\"", f.name),
                "is used twice",
            ));
        }
        if f.components == 0 {
            return Err(Error::input(
                &format!("components of {kind} field \"{}\"", f.name),
                0,
                "must be >= 1",
            ));
        }
        let names = f.component_names.len();
        if names != 0 && names != f.components {
            return Err(Error::input(
                &format!("component names of {kind} field \"{}\"", f.name),
                names,
                &format!("must be 0 or the number of components ({})", f.components),
            ));
        }
        let expected = f.components.checked_mul(count);
        if expected != Some(f.values.len()) {
            return Err(Error::input(
                &format!("length of {kind} field \"{}\"", f.name),
                f.values.len(),
                &format!(
                    "must be components ({}) x number of {kind}s ({count}) = {}",
                    f.components,
                    f.components.saturating_mul(count)
                ),
            ));
        }
    }
    Ok(())
}

fn to_attributes(fields: &[Field]) -> Vec<Attribute> {
    fields
        .iter()
        .map(|f| {
            Attribute::DataArray(DataArray {
                name: f.name.clone(),
                elem: ElementType::Generic(f.components as u32),
                data: IOBuffer::F64(f.values.clone()),
            })
        })
        .collect()
}

/// Writes `frame` to `path` as an uncompressed XML `.vtu` (atomically: temp file + rename).
/// The folder must exist. Returns `Error::Input` naming the offending hex or field if the frame is
/// inconsistent (see [`Frame::validate`]), `Error::Io` if the file cannot be written.
pub fn write_vtu(path: &Path, frame: &Frame) -> Result<()> {
    frame.validate()?;
    for f in frame.point_data.iter().chain(&frame.cell_data) {
        if u32::try_from(f.components).is_err() {
            return Err(Error::input(
                &format!("components of field \"{}\"", f.name),
                f.components,
                "is too large",
            ));
        }
    }
    let points: Vec<f64> = frame.points.iter().flatten().copied().collect();
    let connectivity: Vec<u64> = (frame.hexes.iter().flatten())
        .chain(frame.quads.iter().flatten())
        .chain(frame.triangles.iter().flatten())
        .map(|&n| n as u64)
        .collect();
    let offsets = cell_offsets(frame.hexes.len(), frame.quads.len(), frame.triangles.len());
    let mut types = vec![CellType::Hexahedron; frame.hexes.len()];
    types.resize(frame.hexes.len() + frame.quads.len(), CellType::Quad);
    types.resize(frame.cell_count(), CellType::Triangle);
    let vtk = Vtk {
        version: Version::new_xml(1, 0),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity,
                    offsets,
                },
                types,
            },
            data: Attributes {
                point: to_attributes(&frame.point_data),
                cell: to_attributes(&frame.cell_data),
            },
        }),
    };
    // `write_xml` converts through `xml::VTKFile::try_from`, which uses no compressor.
    let mut bytes = Vec::new();
    vtk.write_xml(&mut bytes)
        .map_err(|e| Error::io(path, format!("VTK XML encoding failed: {e}")))?;
    let text =
        String::from_utf8(bytes).map_err(|_| Error::io(path, "VTK XML encoding is not UTF-8"))?;
    let text = with_component_names(text, "PointData", &frame.point_data);
    let text = with_component_names(text, "CellData", &frame.cell_data);
    super::write_atomic(path, text.as_bytes())
}

/// The end offsets of `nhex` 8-node, then `nquad` 4-node, then `ntri` 3-node cells.
fn cell_offsets(nhex: usize, nquad: usize, ntri: usize) -> Vec<u64> {
    let sizes = (std::iter::repeat_n(8u64, nhex))
        .chain(std::iter::repeat_n(4, nquad))
        .chain(std::iter::repeat_n(3, ntri));
    sizes
        .scan(0u64, |end, n| {
            *end += n;
            Some(*end)
        })
        .collect()
}

/// Adds `ComponentName{i}="..."` to the `<DataArray Name="...">` tag of every field of
/// `fields` with component names, inside the `<section>` element (PointData or CellData) of
/// the encoded file. The arrays' data is base64 text, so no binary is touched.
fn with_component_names(mut text: String, section: &str, fields: &[Field]) -> String {
    let Some(start) = text.find(&format!("<{section}")) else {
        return text;
    };
    for f in fields.iter().filter(|f| !f.component_names.is_empty()) {
        let end = text[start..]
            .find(&format!("</{section}>"))
            .map_or(text.len(), |e| start + e);
        let key = format!("Name=\"{}\"", super::xml_escape(&f.name));
        let Some(at) = text[start..end].find(&key) else {
            continue;
        };
        let attrs: String = f
            .component_names
            .iter()
            .enumerate()
            .map(|(i, c)| format!(" ComponentName{i}=\"{}\"", super::xml_escape(c)))
            .collect();
        text.insert_str(start + at + key.len(), &attrs);
    }
    text
}

/// The component names of every `<DataArray>` in the `<section>` element (PointData or
/// CellData) of a VTK XML file's text, by array name.
fn read_component_names(
    text: &str,
    section: &str,
) -> std::result::Result<std::collections::HashMap<String, Vec<String>>, String> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    let mut inside = false;
    let mut names = std::collections::HashMap::new();
    loop {
        match reader.read_event().map_err(|e| e.to_string())? {
            Event::Start(e) | Event::Empty(e) if e.name().as_ref() == section.as_bytes() => {
                inside = true
            }
            Event::End(e) if e.name().as_ref() == section.as_bytes() => inside = false,
            Event::Start(e) | Event::Empty(e) if inside && e.name().as_ref() == b"DataArray" => {
                let mut name = String::new();
                let mut components: Vec<(usize, String)> = Vec::new();
                for a in e.attributes() {
                    let a = a.map_err(|e| e.to_string())?;
                    let value = a.unescape_value().map_err(|e| e.to_string())?.to_string();
                    let key = String::from_utf8_lossy(a.key.as_ref()).to_string();
                    if key == "Name" {
                        name = value;
                    } else if let Some(i) = key.strip_prefix("ComponentName") {
                        let i = i.parse().map_err(|_| format!("bad attribute {key}"))?;
                        components.push((i, value));
                    }
                }
                components.sort();
                if !components.is_empty() {
                    names.insert(name, components.into_iter().map(|(_, c)| c).collect());
                }
            }
            Event::Eof => return Ok(names),
            _ => {}
        }
    }
}

/// Reads a `.vtu` file of hexahedra (as written by [`write_vtu`]) back into a [`Frame`].
/// Point coordinates and fields of any numeric type are converted to `f64`.
/// Any other cell type, several pieces, or an unreadable file give an error naming the file.
pub fn read_vtu(path: &Path) -> Result<Frame> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let bad = |msg: String| Error::io(path, msg);
    // vtkio's XML-to-model conversion can panic on malformed files; turn that into an error.
    let parsed = std::panic::catch_unwind(|| Vtk::parse_xml(std::io::Cursor::new(&bytes[..])))
        .map_err(|_| bad("malformed VTK XML file".into()))?
        .map_err(|e| bad(format!("cannot parse VTK XML: {e}")))?;
    let pieces = match parsed.data {
        DataSet::UnstructuredGrid { pieces, .. } => pieces,
        _ => return Err(bad("not an UnstructuredGrid file".into())),
    };
    if pieces.len() != 1 {
        return Err(bad(format!("expected 1 piece, found {}", pieces.len())));
    }
    let piece = match pieces.into_iter().next() {
        Some(Piece::Inline(p)) => *p,
        _ => return Err(bad("piece is not stored inline".into())),
    };

    let coords = piece
        .points
        .cast_into::<f64>()
        .ok_or_else(|| bad("point coordinates are not numeric".into()))?;
    if coords.len() % 3 != 0 {
        return Err(bad(format!(
            "{} point coordinates is not a multiple of 3",
            coords.len()
        )));
    }
    let points: Vec<[f64; 3]> = coords.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();

    let types = piece.cells.types.clone();
    let rank = |t: &CellType| match t {
        CellType::Hexahedron => Some(0),
        CellType::Quad => Some(1),
        CellType::Triangle => Some(2),
        _ => None,
    };
    if let Some(t) = types.iter().find(|t| rank(t).is_none()) {
        return Err(bad(format!(
            "cell type {t:?} found, only hexahedra, quadrilaterals and triangles are supported"
        )));
    }
    if types.windows(2).any(|w| rank(&w[0]) > rank(&w[1])) {
        return Err(bad(
            "cells not in the order hexahedra, quadrilaterals, triangles".into(),
        ));
    }
    let count = |t: CellType| types.iter().filter(|&&c| c == t).count();
    let (nhex, nquad, ntri) = (
        count(CellType::Hexahedron),
        count(CellType::Quad),
        count(CellType::Triangle),
    );
    let (connectivity, offsets) = match piece.cells.cell_verts {
        VertexNumbers::XML {
            connectivity,
            offsets,
        } => (connectivity, offsets),
        VertexNumbers::Legacy { .. } => return Err(bad("legacy cell layout in XML file".into())),
    };
    // Offsets may or may not carry a leading 0.
    let offsets: &[u64] = match offsets.first() {
        Some(0) => &offsets[1..],
        _ => &offsets,
    };
    let expected_offsets = cell_offsets(nhex, nquad, ntri);
    if offsets != expected_offsets.as_slice()
        || connectivity.len() != 8 * nhex + 4 * nquad + 3 * ntri
    {
        return Err(bad(
            "cell offsets are not those of 8-node, 4-node and 3-node cells".into(),
        ));
    }
    let index = |n: u64| {
        usize::try_from(n)
            .ok()
            .filter(|&n| n < points.len())
            .ok_or_else(|| bad(format!("node index {n} out of range")))
    };
    let cells = |nodes: &[u64]| -> Result<Vec<usize>> { nodes.iter().map(|&n| index(n)).collect() };
    let (hex_nodes, rest) = connectivity.split_at(8 * nhex);
    let (quad_nodes, tri_nodes) = rest.split_at(4 * nquad);
    let hexes = (hex_nodes.chunks_exact(8))
        .map(|c| Ok(cells(c)?.try_into().expect("8 nodes")))
        .collect::<Result<Vec<[usize; 8]>>>()?;
    let quads = (quad_nodes.chunks_exact(4))
        .map(|c| Ok(cells(c)?.try_into().expect("4 nodes")))
        .collect::<Result<Vec<[usize; 4]>>>()?;
    let triangles = (tri_nodes.chunks_exact(3))
        .map(|c| Ok(cells(c)?.try_into().expect("3 nodes")))
        .collect::<Result<Vec<[usize; 3]>>>()?;
    let text = std::str::from_utf8(&bytes).map_err(|_| bad("file is not UTF-8".into()))?;
    let point_names =
        read_component_names(text, "PointData").map_err(|e| bad(format!("bad XML: {e}")))?;
    let cell_names =
        read_component_names(text, "CellData").map_err(|e| bad(format!("bad XML: {e}")))?;

    let fields = |attrs: Vec<Attribute>,
                  kind: &str,
                  names: &std::collections::HashMap<String, Vec<String>>|
     -> Result<Vec<Field>> {
        attrs
            .into_iter()
            .filter_map(|a| match a {
                Attribute::DataArray(d) => Some(d),
                Attribute::Field { .. } => None,
            })
            .map(|d| {
                let values = d
                    .data
                    .cast_into::<f64>()
                    .ok_or_else(|| bad(format!("{kind} field \"{}\" is not numeric", d.name)))?;
                Ok(Field {
                    components: d.elem.num_comp() as usize,
                    component_names: names.get(&d.name).cloned().unwrap_or_default(),
                    name: d.name,
                    values,
                })
            })
            .collect()
    };
    let frame = Frame {
        point_data: fields(piece.data.point, "point", &point_names)?,
        cell_data: fields(piece.data.cell, "cell", &cell_names)?,
        points,
        hexes,
        quads,
        triangles,
    };
    frame
        .validate()
        .map_err(|e| bad(format!("inconsistent file: {e}")))?;
    Ok(frame)
}

/// Reads the point field `name` of a `.vtu` file as `f64` values (tuples one after another).
/// Error naming the field and the file if the file has no such point field.
pub fn read_vtu_point_field(path: &Path, name: &str) -> Result<Vec<f64>> {
    read_vtu(path)?
        .point_data
        .into_iter()
        .find(|f| f.name == name)
        .map(|f| f.values)
        .ok_or_else(|| Error::io(path, format!("no point field named \"{name}\"")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::test_util::temp_dir;

    /// Two unit hexes side by side along x (12 points), with irrational-ish values so the
    /// round-trip test exercises all 64 bits.
    fn two_hex_frame() -> Frame {
        let mut points = Vec::new();
        for z in [0.0, 1.0] {
            for y in [0.0, 1.0] {
                for x in [0.0, 1.0, 2.0] {
                    points.push([x + 0.1 * z / 3.0, y * std::f64::consts::PI, z]);
                }
            }
        }
        let id = |x: usize, y: usize, z: usize| x + 3 * y + 6 * z;
        let hex = |x: usize| {
            [
                id(x, 0, 0),
                id(x + 1, 0, 0),
                id(x + 1, 1, 0),
                id(x, 1, 0),
                id(x, 0, 1),
                id(x + 1, 0, 1),
                id(x + 1, 1, 1),
                id(x, 1, 1),
            ]
        };
        let n = points.len();
        let temperature: Vec<f64> = (0..n).map(|i| (i as f64).sqrt() / 7.0 - 0.3).collect();
        let displacement: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = i as f64;
                [t / 3.0, -t * 1e-9, (t * 0.7).sin()]
            })
            .collect();
        Frame {
            points,
            hexes: vec![hex(0), hex(1)],
            quads: Vec::new(),
            triangles: Vec::new(),
            point_data: vec![
                Field::scalar("temperature", temperature),
                Field::vector("displacement", &displacement),
            ],
            cell_data: vec![
                Field::scalar("pressure", vec![1.0 / 3.0, -2.0e-17]),
                Field::vector("traction", &[[0.1, 0.2, 0.3], [1e300, -5e-324, 0.0]]),
                Field::symmetric_tensor("stress", (0..12).map(|i| i as f64 / 7.0 - 1.0).collect()),
            ],
        }
    }

    #[test]
    fn vtu_two_hexes_round_trip() {
        let dir = temp_dir("vtu");
        let path = dir.join("two.vtu");
        let frame = two_hex_frame();
        write_vtu(&path, &frame).unwrap();

        // Uncompressed inline binary, 64-bit floats.
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("UnstructuredGrid"), "{text}");
        assert!(!text.contains("compressor"), "{text}");
        assert!(text.contains("Float64"), "{text}");

        let back = read_vtu(&path).unwrap();
        // Exact (bitwise) equality of points, connectivity and every field.
        assert_eq!(back, frame);
        for (a, b) in back
            .points
            .iter()
            .flatten()
            .zip(frame.points.iter().flatten())
        {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        assert_eq!(back.hexes, frame.hexes);
        assert_eq!(back.point_data[1].components, 3);
        assert_eq!(back.cell_data[0].components, 1);

        let temp = read_vtu_point_field(&path, "temperature").unwrap();
        assert_eq!(temp, frame.point_data[0].values);
        let disp = read_vtu_point_field(&path, "displacement").unwrap();
        assert_eq!(disp, frame.point_data[1].values);
        let err = read_vtu_point_field(&path, "nope").unwrap_err().to_string();
        assert!(err.contains("nope"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Component names are on the right arrays (a point and a cell field may share a name),
    /// and quadrilaterals round-trip after the hexahedra.
    #[test]
    fn vtu_component_names_quads_and_triangles_round_trip() {
        let dir = temp_dir("vtu-names");
        let path = dir.join("named.vtu");
        let mut frame = two_hex_frame();
        frame.point_data.push(
            Field::vector("stress", &vec![[1.0, 2.0, 3.0]; 12])
                .named_components(&["a", "b&c", "d"]),
        );
        frame.quads = vec![[0, 1, 7, 6], [1, 2, 8, 7]];
        frame.triangles = vec![[3, 4, 10], [4, 5, 11], [9, 10, 11]];
        frame.cell_data = (frame.cell_data.into_iter())
            .map(|mut f| {
                let per = f.components;
                let extra: Vec<f64> = (0..5 * per).map(|i| i as f64).collect();
                f.values.extend(extra);
                f
            })
            .collect();
        write_vtu(&path, &frame).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("ComponentName0=\"xx\""), "{text}");
        assert!(text.contains("ComponentName5=\"xz\""), "{text}");
        assert!(text.contains("ComponentName1=\"b&amp;c\""), "{text}");
        let back = read_vtu(&path).unwrap();
        assert_eq!(back, frame);
        assert_eq!(
            back.cell_data[2].component_names,
            SYMMETRIC_TENSOR_COMPONENTS
        );
        assert_eq!(back.point_data[2].component_names, ["a", "b&c", "d"]);
        assert_eq!((back.quads.len(), back.triangles.len()), (2, 3));
        // vtkio's own reader still accepts the tags with the extra attributes.
        assert!(Vtk::import(&path).is_ok());

        let mut bad = two_hex_frame();
        bad.cell_data[2].component_names.pop();
        let err = write_vtu(&path, &bad).unwrap_err().to_string();
        assert!(
            err.contains("component names") && err.contains("stress"),
            "{err}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn vtu_also_read_by_plain_vtkio_import() {
        // Independent of `read_vtu`: vtkio's own path-based importer must accept the file.
        let dir = temp_dir("vtu-import");
        let path = dir.join("f.vtu");
        write_vtu(&path, &two_hex_frame()).unwrap();
        let vtk = Vtk::import(&path).unwrap();
        match vtk.data {
            DataSet::UnstructuredGrid { pieces, .. } => {
                let p = pieces[0].load_piece_data(None).unwrap();
                assert_eq!(p.num_points(), 12);
                assert_eq!(p.cells.num_cells(), 2);
                assert_eq!(p.data.point.len(), 2);
                assert_eq!(p.data.cell.len(), 3);
            }
            other => panic!("unexpected data set {other:?}"),
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn vtu_bad_field_length_names_the_field() {
        let dir = temp_dir("vtu-bad");
        let path = dir.join("bad.vtu");
        let mut frame = two_hex_frame();
        frame.point_data[1].values.pop();
        let err = write_vtu(&path, &frame).unwrap_err().to_string();
        assert!(err.contains("displacement"), "{err}");
        assert!(!path.exists());

        let mut frame = two_hex_frame();
        frame.cell_data[0].values.push(0.0);
        let err = write_vtu(&path, &frame).unwrap_err().to_string();
        assert!(err.contains("pressure"), "{err}");

        let mut frame = two_hex_frame();
        frame.cell_data[1].components = 0;
        let err = write_vtu(&path, &frame).unwrap_err().to_string();
        assert!(err.contains("traction"), "{err}");

        let mut frame = two_hex_frame();
        frame.point_data[1].name = "temperature".into();
        let err = write_vtu(&path, &frame).unwrap_err().to_string();
        assert!(err.contains("temperature"), "{err}");

        let mut frame = two_hex_frame();
        frame.hexes[1][5] = 12;
        let err = write_vtu(&path, &frame).unwrap_err().to_string();
        assert!(err.contains("hexahedron 1"), "{err}");
        assert!(!path.exists());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn vtu_empty_frame_and_garbage_file() {
        let dir = temp_dir("vtu-empty");
        let path = dir.join("empty.vtu");
        write_vtu(&path, &Frame::default()).unwrap();
        assert_eq!(read_vtu(&path).unwrap(), Frame::default());

        // Bad input files give errors, never panics.
        let garbage = dir.join("garbage.vtu");
        std::fs::write(&garbage, "<VTKFile type=\"UnstructuredGrid\"><Unstr").unwrap();
        assert!(read_vtu(&garbage).is_err());
        std::fs::write(&garbage, "").unwrap();
        assert!(read_vtu(&garbage).is_err());
        assert!(read_vtu(&dir.join("missing.vtu")).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn vtu_non_finite_values_round_trip() {
        let dir = temp_dir("vtu-nonfinite");
        let path = dir.join("nf.vtu");
        let mut frame = two_hex_frame();
        let special = [f64::INFINITY, f64::NAN, f64::NEG_INFINITY, -0.0];
        frame.point_data[0].values[..4].copy_from_slice(&special);
        write_vtu(&path, &frame).unwrap();
        let back = read_vtu_point_field(&path, "temperature").unwrap();
        for (a, b) in back.iter().zip(&frame.point_data[0].values) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
