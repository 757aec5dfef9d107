//! VTK XML unstructured grid (`.vtu`) frames of a hexahedral mesh.
//!
//! [`Frame`] is a format-neutral description of one output frame; [`write_vtu`] writes it as an
//! XML `.vtu` file (VTK file version 1.0, little-endian, `header_type="UInt64"`, inline base64
//! binary arrays, *uncompressed*), which ParaView and VTK read. Float data is written as
//! `Float64`, so values read back bit-exactly. [`read_vtu`] / [`read_vtu_point_field`] read such a
//! file back (through vtkio's reader) for tests and tools.

use crate::{Error, Result};
use std::path::Path;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    Piece, UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// One output frame: a hexahedral mesh with point and cell fields.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// 8-node hexahedra, node order as VTK_HEXAHEDRON (bottom face 0-1-2-3 counter-clockwise seen
    /// from the top, then top face 4-5-6-7 above 0-1-2-3), indices into `points`.
    pub hexes: Vec<[usize; 8]>,
    /// Fields with one tuple per point.
    pub point_data: Vec<Field>,
    /// Fields with one tuple per hexahedron.
    pub cell_data: Vec<Field>,
}

/// A named field: `components` values per point (or cell), tuples stored one after another, so
/// `values.len() == components * count`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Field {
    pub name: String,
    pub components: usize,
    pub values: Vec<f64>,
}

impl Field {
    /// A field with `components` values per tuple.
    pub fn new(name: impl Into<String>, components: usize, values: Vec<f64>) -> Self {
        Field {
            name: name.into(),
            components,
            values,
        }
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
    /// Checks that every hex references existing points and that every field has a non-empty
    /// unique name, at least one component and exactly `components * count` values.
    pub fn validate(&self) -> Result<()> {
        let np = self.points.len();
        for (h, hex) in self.hexes.iter().enumerate() {
            if let Some(&bad) = hex.iter().find(|&&n| n >= np) {
                return Err(Error::input(
                    &format!("node index of hexahedron {h}"),
                    bad,
                    &format!("must be < number of points ({np})"),
                ));
            }
        }
        check_fields(&self.point_data, "point", np)?;
        check_fields(&self.cell_data, "cell", self.hexes.len())
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
    let connectivity: Vec<u64> = frame.hexes.iter().flatten().map(|&n| n as u64).collect();
    let offsets: Vec<u64> = (1..=frame.hexes.len() as u64).map(|i| 8 * i).collect();
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
                types: vec![CellType::Hexahedron; frame.hexes.len()],
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
    super::write_atomic(path, &bytes)
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

    let ncells = piece.cells.types.len();
    if let Some(t) = piece
        .cells
        .types
        .iter()
        .find(|&&t| t != CellType::Hexahedron)
    {
        return Err(bad(format!(
            "cell type {t:?} found, only hexahedra are supported"
        )));
    }
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
    let expected_offsets: Vec<u64> = (1..=ncells as u64).map(|i| 8 * i).collect();
    if offsets != expected_offsets.as_slice() || connectivity.len() != 8 * ncells {
        return Err(bad("cell offsets are not those of 8-node cells".into()));
    }
    let mut hexes = Vec::with_capacity(ncells);
    for c in connectivity.chunks_exact(8) {
        let mut hex = [0usize; 8];
        for (h, &n) in hex.iter_mut().zip(c) {
            *h = usize::try_from(n)
                .ok()
                .filter(|&n| n < points.len())
                .ok_or_else(|| bad(format!("node index {n} out of range")))?;
        }
        hexes.push(hex);
    }

    let fields = |attrs: Vec<Attribute>, kind: &str| -> Result<Vec<Field>> {
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
                    name: d.name,
                    values,
                })
            })
            .collect()
    };
    let frame = Frame {
        point_data: fields(piece.data.point, "point")?,
        cell_data: fields(piece.data.cell, "cell")?,
        points,
        hexes,
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
            point_data: vec![
                Field::scalar("temperature", temperature),
                Field::vector("displacement", &displacement),
            ],
            cell_data: vec![
                Field::scalar("pressure", vec![1.0 / 3.0, -2.0e-17]),
                Field::vector("traction", &[[0.1, 0.2, 0.3], [1e300, -5e-324, 0.0]]),
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
                assert_eq!(p.data.cell.len(), 2);
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
