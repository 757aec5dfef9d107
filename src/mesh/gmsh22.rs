//! Gmsh MSH 2.2 meshes (ASCII and binary), read by hand: the `mshio` crate that reads 4.1
//! (`gmsh.rs`) reads no other version.
//!
//! The format (Gmsh reference manual, "Legacy formats: MSH file format version 2"):
//! `$MeshFormat` `2.2 file-type data-size` (file-type 0 ASCII, 1 binary, then in binary the
//! int 1 that fixes the byte order), `$PhysicalNames` (as in 4.1), `$Nodes` (count, then per
//! node `id x y z`) and `$Elements` (count, then per element `id type ntags tag... node...`;
//! in binary, blocks headed by `type count ntags` of elements `id tag... node...`, 4-byte
//! ints and 8-byte reals). The first tag is the physical group (0: none), the second the
//! elementary entity. Gmsh writes an element once per physical group it belongs to, with
//! the same id: a hexahedron id seen again is the same hexahedron in one more group. Other
//! sections are skipped to their `$End...` line.
//!
//! Kept as in 4.1: 8-node hexahedra (type 5, VTK node order); physical groups become node
//! sets, of quadrangles (type 3) also face sets, of hexahedra also element sets; lines
//! (type 1) and points (type 15) only feed node sets; any other type is refused. A group is
//! of the dimension of its elements. Errors name `file:line` (ASCII) or `file (byte N)`
//! (binary) of the fault. Cost: O(file size).

use std::collections::{BTreeMap, HashMap};

use super::gmsh::{group_name, line_of, physical_names};
use super::import::{FileFace, Imported};
use crate::geometry::Vec3;
use crate::{Error, Result};

/// Reads an MSH 2.2 file (its `$MeshFormat` says 2.x) into the importer's structure.
pub(super) fn read_msh22(bytes: &[u8], file: &str) -> Result<Imported> {
    let mut c = Cursor {
        bytes,
        pos: 0,
        file,
        binary: false,
        little: true,
    };
    c.header()?;
    let names = physical_names(bytes, file)?;
    let mut r = Reader {
        names,
        tag_index: HashMap::new(),
        hex_of_id: HashMap::new(),
        out: Imported::default(),
    };
    let (mut nodes, mut elements) = (false, false);
    while let Some((at, line)) = c.line() {
        match line.as_str() {
            "" => {}
            "$Nodes" => {
                r.nodes(&mut c)?;
                nodes = true;
            }
            "$Elements" => {
                if !nodes {
                    return Err(c.error(at, "$Elements comes before $Nodes"));
                }
                r.elements(&mut c)?;
                elements = true;
            }
            s if s.starts_with('$') && !s.starts_with("$End") => c.skip_section(at, &s[1..])?,
            s => return Err(c.error(at, &format!("expected a section, found `{s}`"))),
        }
    }
    match (nodes, elements) {
        (true, true) => Ok(r.out),
        (false, _) => Err(Error::Input(format!(
            "{file}: the file has no $Nodes section"
        ))),
        (true, false) => Err(Error::Input(format!(
            "{file}: the file has no $Elements section"
        ))),
    }
}

/// A position in the file's bytes and how to read numbers there.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    file: &'a str,
    binary: bool,
    /// Byte order of a binary file's numbers.
    little: bool,
}

impl Cursor<'_> {
    /// Where byte `at` is: `file:line` in an ASCII file, `file (byte N)` in a binary one.
    fn place(&self, at: usize) -> String {
        if self.binary {
            format!("{} (byte {at})", self.file)
        } else {
            format!("{}:{}", self.file, line_of(self.bytes, at))
        }
    }

    fn error(&self, at: usize, what: &str) -> Error {
        Error::Input(format!("{}: {what}", self.place(at)))
    }

    /// The next line (trimmed) and the byte it starts at; `None` at the end of the file.
    fn line(&mut self) -> Option<(usize, String)> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let at = self.pos;
        let rest = &self.bytes[at..];
        let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos = at + len + 1;
        Some((at, String::from_utf8_lossy(&rest[..len]).trim().to_string()))
    }

    /// The next line, which must be `expected`.
    fn expect(&mut self, expected: &str) -> Result<()> {
        match self.line() {
            Some((_, l)) if l == expected => Ok(()),
            Some((at, l)) => Err(self.error(at, &format!("expected {expected}, found `{l}`"))),
            None => Err(self.error(
                self.bytes.len(),
                &format!("the file ends before {expected}"),
            )),
        }
    }

    /// `$MeshFormat`, `2.2 file-type data-size`, the binary byte-order int, `$EndMeshFormat`.
    fn header(&mut self) -> Result<()> {
        self.expect("$MeshFormat")?;
        let (at, l) = self.line().unwrap_or((self.bytes.len(), String::new()));
        let f: Vec<&str> = l.split_whitespace().collect();
        let bad = |c: &Self| c.error(at, &format!("`{l}` is no MSH 2 format line"));
        if f.len() != 3 || !f[0].starts_with("2.") {
            return Err(bad(self));
        }
        if f[2] != "8" {
            return Err(self.error(at, &format!("data-size {} is not read (only 8)", f[2])));
        }
        self.binary = match f[1] {
            "0" => false,
            "1" => true,
            _ => return Err(bad(self)),
        };
        if self.binary {
            let at = self.pos;
            let one = self.take::<4>()?;
            self.little = match (i32::from_le_bytes(one), i32::from_be_bytes(one)) {
                (1, _) => true,
                (_, 1) => false,
                _ => return Err(self.error(at, "the byte-order int is not 1")),
            };
            self.line(); // the rest of that line
        }
        self.expect("$EndMeshFormat")
    }

    /// Skips section `name` to its `$End` line.
    fn skip_section(&mut self, at: usize, name: &str) -> Result<()> {
        let end = format!("\n$End{name}");
        match super::gmsh::find(&self.bytes[self.pos.saturating_sub(1)..], end.as_bytes()) {
            Some(k) => {
                self.pos = self.pos.saturating_sub(1) + k + end.len();
                Ok(())
            }
            None => Err(self.error(at, &format!("${name} has no $End{name}"))),
        }
    }

    /// A count on a line of its own (ASCII in both kinds of file).
    fn count(&mut self, what: &str) -> Result<usize> {
        let (at, l) = self.line().unwrap_or((self.bytes.len(), String::new()));
        l.parse()
            .map_err(|_| self.error(at, &format!("expected the number of {what}, found `{l}`")))
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let Some(b) = self.bytes.get(self.pos..self.pos + N) else {
            return Err(self.error(self.bytes.len(), "the file ends inside binary data"));
        };
        self.pos += N;
        Ok(b.try_into().expect("N bytes"))
    }

    fn int(&mut self) -> Result<i32> {
        let b = self.take::<4>()?;
        Ok(if self.little {
            i32::from_le_bytes(b)
        } else {
            i32::from_be_bytes(b)
        })
    }

    fn real(&mut self) -> Result<f64> {
        let b = self.take::<8>()?;
        Ok(if self.little {
            f64::from_le_bytes(b)
        } else {
            f64::from_be_bytes(b)
        })
    }
}

/// Nodes per element of the types read; other types are refused.
fn nodes_of_type(ty: i32) -> Option<(usize, i32)> {
    // (nodes, dimension of the element and so of its physical group)
    match ty {
        15 => Some((1, 0)),
        1 => Some((2, 1)),
        3 => Some((4, 2)),
        5 => Some((8, 3)),
        _ => None,
    }
}

/// The file's content read so far.
struct Reader {
    names: BTreeMap<(i32, i32), String>,
    /// Node id -> index in `out.nodes`.
    tag_index: HashMap<i64, usize>,
    /// Hexahedron id -> index in `out.hexes` (an element is repeated per physical group).
    hex_of_id: HashMap<i64, usize>,
    out: Imported,
}

impl Reader {
    /// `$Nodes`: the count, the nodes, `$EndNodes`.
    fn nodes(&mut self, c: &mut Cursor) -> Result<()> {
        let n = c.count("nodes")?;
        for _ in 0..n {
            let at = c.pos;
            let (id, x) = if c.binary {
                (c.int()? as i64, [c.real()?, c.real()?, c.real()?])
            } else {
                let (at, l) = c.line().unwrap_or((c.bytes.len(), String::new()));
                let f: Vec<&str> = l.split_whitespace().collect();
                let num = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite());
                match (f.len(), f.first().and_then(|s| s.parse::<i64>().ok())) {
                    (4, Some(id)) => match (num(f[1]), num(f[2]), num(f[3])) {
                        (Some(x), Some(y), Some(z)) => (id, [x, y, z]),
                        _ => {
                            return Err(c.error(
                                at,
                                &format!("node `{l}`: a coordinate is not a finite number"),
                            ))
                        }
                    },
                    _ => {
                        return Err(c.error(at, &format!("expected a node `id x y z`, found `{l}`")))
                    }
                }
            };
            if x.iter().any(|v| !v.is_finite()) {
                return Err(c.error(at, &format!("node {id}: a coordinate is not finite")));
            }
            if self.tag_index.insert(id, self.out.nodes.len()).is_some() {
                return Err(c.error(at, &format!("node {id} is defined twice")));
            }
            self.out.nodes.push(Vec3::new(x[0], x[1], x[2]));
        }
        if c.binary {
            c.line(); // the end of the last binary line
        }
        c.expect("$EndNodes")
    }

    /// `$Elements`: the count, the elements (one a line in ASCII, in typed blocks in
    /// binary), `$EndElements`.
    fn elements(&mut self, c: &mut Cursor) -> Result<()> {
        let n = c.count("elements")?;
        if c.binary {
            let mut done = 0;
            while done < n {
                let at = c.pos;
                let (ty, count, ntags) = (c.int()?, c.int()?, c.int()?);
                let Some((nodes, _)) = nodes_of_type(ty) else {
                    return Err(self.unsupported(c, at, None, ty));
                };
                if count <= 0 || ntags < 0 || done + count as usize > n {
                    return Err(c.error(
                        at,
                        &format!("element block header `{ty} {count} {ntags}` is not valid"),
                    ));
                }
                // A valid header whose block the file cannot hold: cut short (checked before
                // reading, so that a huge count allocates nothing).
                let room = (c.bytes.len() - c.pos) / 4;
                let need = (count as usize).saturating_mul(1 + ntags as usize + nodes);
                if need > room {
                    return Err(c.error(
                        at,
                        &format!(
                            "the file ends inside element block `{ty} {count} {ntags}` \
                             ({need} values, {room} left)"
                        ),
                    ));
                }
                for _ in 0..count {
                    let at = c.pos;
                    let mut v = Vec::with_capacity(1 + ntags as usize + nodes);
                    for _ in 0..1 + ntags as usize + nodes {
                        v.push(c.int()? as i64);
                    }
                    self.element(
                        c,
                        at,
                        ty,
                        v[0],
                        &v[1..1 + ntags as usize],
                        &v[1 + ntags as usize..],
                    )?;
                }
                done += count as usize;
            }
            c.line();
        } else {
            for _ in 0..n {
                let (at, l) = c.line().unwrap_or((c.bytes.len(), String::new()));
                let v: Option<Vec<i64>> = l.split_whitespace().map(|s| s.parse().ok()).collect();
                let v = v.filter(|v| v.len() >= 3).ok_or_else(|| {
                    c.error(
                        at,
                        &format!("expected an element `id type ntags tag... node...`, found `{l}`"),
                    )
                })?;
                let (id, ty, ntags) = (v[0], v[1] as i32, v[2].max(0) as usize);
                let Some((nodes, _)) = nodes_of_type(ty) else {
                    return Err(self.unsupported(c, at, Some(id), ty));
                };
                let need = ntags.saturating_add(3 + nodes);
                if v.len() != need {
                    return Err(c.error(at, &format!(
                        "element {id} of type {ty} with {ntags} tags needs {need} numbers, the line has {}",
                        v.len()
                    )));
                }
                self.element(c, at, ty, id, &v[3..3 + ntags], &v[3 + ntags..])?;
            }
        }
        c.expect("$EndElements")
    }

    fn unsupported(&self, c: &Cursor, at: usize, id: Option<i64>, ty: i32) -> Error {
        let which = id.map(|i| format!("element {i}: ")).unwrap_or_default();
        c.error(
            at,
            &format!(
                "{which}element type {ty} is not supported: tribo meshes are 8-node hexahedra \
                 (Gmsh type 5); quadrangles, lines and points may only carry physical groups \
                 (recombine and mesh transfinite, first order)"
            ),
        )
    }

    /// One element (at byte `at`) of a read type, with its tags and node ids.
    fn element(
        &mut self,
        c: &Cursor,
        at: usize,
        ty: i32,
        id: i64,
        tags: &[i64],
        ids: &[i64],
    ) -> Result<()> {
        let (_, dim) = nodes_of_type(ty).expect("a read type");
        let mut ns = Vec::with_capacity(ids.len());
        for &t in ids {
            match self.tag_index.get(&t) {
                Some(&k) => ns.push(k),
                None => {
                    return Err(c.error(
                        at,
                        &format!("element {id} names node {t}, which the file does not define"),
                    ))
                }
            }
        }
        let group = tags
            .first()
            .filter(|&&p| p != 0)
            .map(|&p| group_name(&self.names, dim, p as i32));
        let out = &mut self.out;
        if ty == 5 {
            let e = *self.hex_of_id.entry(id).or_insert_with(|| {
                out.hexes.push(ns.clone().try_into().expect("8 nodes"));
                out.hex_origin
                    .push(format!("{}: hexahedron {id}", c.place(at)));
                out.hexes.len() - 1
            });
            if let Some(g) = &group {
                out.element_sets.entry(g.clone()).or_default().push(e);
            }
        }
        let Some(g) = group else { return Ok(()) };
        out.node_sets.entry(g.clone()).or_default().extend(&ns);
        if ty == 3 {
            let entry = out
                .face_sets
                .entry(g)
                .or_insert_with(|| (Vec::new(), c.place(at)));
            entry.0.push(FileFace::Nodes([ns[0], ns[1], ns[2], ns[3]]));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::gmsh::read_gmsh;

    fn fixture(name: &str) -> Vec<u8> {
        let path = format!("{}/tests/data/mesh/{name}", env!("CARGO_MANIFEST_DIR"));
        std::fs::read(path).unwrap()
    }

    /// The same Gmsh block written as 4.1, 2.2 ASCII and 2.2 binary: the same nodes (bit
    /// for bit: Gmsh writes the same doubles), hexahedra and sets.
    #[test]
    fn msh22_ascii_and_binary_give_the_mesh_of_msh41() {
        let reference = read_gmsh(&fixture("block_4x2x2.msh"), "a.msh").unwrap();
        for name in ["block_4x2x2_v22.msh", "block_4x2x2_v22_bin.msh"] {
            let m = read_gmsh(&fixture(name), name).unwrap();
            assert_eq!(m.nodes, reference.nodes, "{name}");
            assert_eq!(m.hexes, reference.hexes, "{name}");
            for set in ["x-", "x+", "y-", "y+", "z-", "z+", "blank", "origin"] {
                assert_eq!(
                    m.node_set(set).unwrap(),
                    reference.node_set(set).unwrap(),
                    "{name} {set}"
                );
            }
            assert_eq!(
                m.element_set("blank").unwrap(),
                reference.element_set("blank").unwrap()
            );
            for set in ["x-", "z+"] {
                assert_eq!(
                    m.face_set(set).unwrap(),
                    reference.face_set(set).unwrap(),
                    "{name} {set}"
                );
            }
        }
    }

    /// The line of an ASCII file's fault: a bad coordinate, a missing node, a tetrahedron.
    #[test]
    fn ascii_faults_name_their_line() {
        let text = String::from_utf8(fixture("block_4x2x2_v22.msh")).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let nodes = lines.iter().position(|l| *l == "$Nodes").unwrap();
        let elements = lines.iter().position(|l| *l == "$Elements").unwrap();
        let edit = |k: usize, new: &str| {
            let mut l = lines.clone();
            l[k] = new;
            l.join("\n")
        };
        let cases = [
            (nodes + 4, "3 0 two 1".to_string(), "not a finite number"),
            (
                elements + 3,
                lines[elements + 3].replacen(" 9 ", " 999 ", 1),
                "node 999",
            ),
            (
                elements + 3,
                "2 4 2 1 1 1 2 3 4".to_string(),
                "element type 4",
            ),
            (
                elements + 3,
                "2 3 2 1 1 9 29".to_string(),
                "needs 9 numbers",
            ),
        ];
        for (k, new, says) in cases {
            let e = read_gmsh(edit(k, &new).as_bytes(), "bad.msh")
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!("bad.msh:{}:", k + 1)) && e.contains(says),
                "{e}"
            );
        }
        let e = read_gmsh(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", "empty.msh")
            .unwrap_err()
            .to_string();
        assert!(e.contains("empty.msh") && e.contains("no $Nodes"), "{e}");
    }

    /// The byte offset of a binary file's fault: a file cut short, an element type not read.
    #[test]
    fn binary_faults_name_their_byte() {
        let full = fixture("block_4x2x2_v22_bin.msh");
        let e = read_gmsh(&full[..full.len() / 2], "cut.msh")
            .unwrap_err()
            .to_string();
        assert!(e.contains("cut.msh (byte") && e.contains("ends"), "{e}");
        // The first element block header follows the count line after $Elements.
        let at = super::super::gmsh::find(&full, b"$Elements\n").unwrap() + 10;
        let header = at + full[at..].iter().position(|&b| b == b'\n').unwrap() + 1;
        let mut bad = full.clone();
        bad[header..header + 4].copy_from_slice(&4i32.to_le_bytes());
        let e = read_gmsh(&bad, "tet.msh").unwrap_err().to_string();
        assert!(
            e.contains(&format!("tet.msh (byte {header})")) && e.contains("element type 4"),
            "{e}"
        );
    }
}
