//! Gmsh MSH 4.1 meshes (ASCII and binary), parsed by the `mshio` crate; MSH 2.2 (ASCII and
//! binary), which `mshio` does not read, by `gmsh22.rs` into the same structure.
//!
//! Kept: 8-node hexahedra (Gmsh type 5, whose node order is tribo's VTK order). Physical
//! groups become named sets: every group is a node set (the nodes of its elements), a
//! group of dimension 2 also a face set (its 4-node quadrangles, type 3, matched to
//! hexahedron faces), a group of dimension 3 also an element set. Points (type 15) and
//! 2-node lines (type 1) only feed node sets. Any other element type (tetrahedra, prisms,
//! second-order elements, triangles, ...) is refused, naming the block and, in an ASCII file,
//! the line. A group without a name in `$PhysicalNames` is called `"physical <tag>"`.
//!
//! Node tags: where the file's tags are dense (`max - min + 1 = count`, what Gmsh writes),
//! `mshio` drops them and the node of tag `min + k` is the `k`-th node in file order.
//! Cost: O(file size).

use std::collections::{BTreeMap, HashMap};

use super::import::{FileFace, Imported};
use super::Mesh;
use crate::geometry::Vec3;
use crate::{Error, Result};
use mshio::ElementType;

/// Reads a Gmsh MSH 4.1 or 2.2 file from its bytes; `file` names it in messages.
pub fn read_gmsh(bytes: &[u8], file: &str) -> Result<Mesh> {
    if is_version_2(bytes) {
        return super::gmsh22::read_msh22(bytes, file)?.build(file);
    }
    let ascii = is_ascii_format(bytes);
    let msh = mshio::parse_msh_bytes(bytes).map_err(|e| parse_error(&e, bytes, file, ascii))?;
    let names = physical_names(bytes, file)?;
    let physical = entity_physical_tags(&msh);
    let mut out = Imported::default();
    let nodes = read_nodes(&msh, &mut out);
    let block_lines = if ascii {
        element_block_lines(bytes)
    } else {
        Vec::new()
    };
    let Some(elements) = &msh.data.elements else {
        return Err(Error::Input(format!(
            "{file}: the file has no $Elements section"
        )));
    };
    for (b, block) in elements.element_blocks.iter().enumerate() {
        let dim = block.entity_dim;
        let where_ = match block_lines.get(b) {
            Some(line) => format!("{file}:{line}"),
            None => format!("{file}: element block {}", b + 1),
        };
        let groups: Vec<String> = physical
            .get(&(dim, block.entity_tag))
            .map(|tags| tags.iter().map(|&t| group_name(&names, dim, t)).collect())
            .unwrap_or_default();
        add_element_block(block, &where_, &groups, &nodes, file, &mut out)?;
    }
    out.build(file)
}

/// The message of a file `mshio` cannot parse: the first MSH error's kind (or "not a Gmsh
/// MSH 4.1 file"), where it happened (`file:line` in an ASCII file, the byte offset in a
/// binary one) and the sections it happened within.
fn parse_error(e: &mshio::MshParserError<&[u8]>, bytes: &[u8], file: &str, ascii: bool) -> Error {
    let kind = e
        .first_msh_error()
        .map_or_else(|| "not a Gmsh MSH 4.1 file".to_string(), |k| k.to_string());
    let contexts: Vec<String> = e
        .filter_msh_errors()
        .filter_map(|(_, k)| k.context().map(str::to_string))
        .collect();
    let at = e
        .backtrace
        .first()
        .map(|(rest, _)| bytes.len() - rest.len())
        .unwrap_or(0);
    let place = if ascii {
        format!("{file}:{}", line_of(bytes, at))
    } else {
        format!("{file} (byte {at})")
    };
    let within = if contexts.is_empty() {
        String::new()
    } else {
        format!(" (in {})", contexts.join(", in "))
    };
    Error::Input(format!("{place}: {kind}{within}"))
}

/// The physical tags of every geometric entity: (dim, entity tag) -> physical tags, from
/// the `$Entities` section (empty without one).
fn entity_physical_tags(msh: &mshio::MshFile<u64, i32, f64>) -> HashMap<(i32, i32), Vec<i32>> {
    let mut physical: HashMap<(i32, i32), Vec<i32>> = HashMap::new();
    if let Some(ent) = &msh.data.entities {
        for p in &ent.points {
            physical.insert((0, p.tag), p.physical_tags.clone());
        }
        for c in &ent.curves {
            physical.insert((1, c.tag), c.physical_tags.clone());
        }
        for s in &ent.surfaces {
            physical.insert((2, s.tag), s.physical_tags.clone());
        }
        for v in &ent.volumes {
            physical.insert((3, v.tag), v.physical_tags.clone());
        }
    }
    physical
}

/// The set name of physical group `tag` (of dimension `dim`; a negative tag, an oriented
/// reference, names the same group): its `$PhysicalNames` name, or `"physical <tag>"`.
pub(super) fn group_name(names: &BTreeMap<(i32, i32), String>, dim: i32, tag: i32) -> String {
    names
        .get(&(dim, tag.abs()))
        .cloned()
        .unwrap_or_else(|| format!("physical {}", tag.abs()))
}

/// How element node tags map to node indices ([`NodeTags::index`]).
struct NodeTags {
    /// Tag -> index, for blocks that list their tags.
    index_of_tag: HashMap<u64, usize>,
    /// The smallest tag, where `mshio` dropped dense tags (tag `min + k` is node `k`).
    dense_min: Option<u64>,
    /// Number of nodes read.
    count: usize,
}

impl NodeTags {
    /// The index of the node of `tag`; an error naming `file` if the file defines no such
    /// node.
    fn index(&self, tag: u64, file: &str) -> Result<usize> {
        let k = match self.dense_min {
            Some(min) => tag.checked_sub(min).map(|k| k as usize),
            None => self.index_of_tag.get(&tag).copied(),
        };
        k.filter(|&k| k < self.count).ok_or_else(|| {
            Error::Input(format!(
                "{file}: an element names node {tag}, which the file does not define"
            ))
        })
    }
}

/// Appends the `$Nodes` section's nodes to `out.nodes`, in file order, and returns how
/// their tags map to indices.
fn read_nodes(msh: &mshio::MshFile<u64, i32, f64>, out: &mut Imported) -> NodeTags {
    let mut index_of_tag: HashMap<u64, usize> = HashMap::new();
    let mut dense_min: Option<u64> = None;
    if let Some(nodes) = &msh.data.nodes {
        for block in &nodes.node_blocks {
            if let Some(tags) = &block.node_tags {
                for (&tag, &k) in tags {
                    index_of_tag.insert(tag, out.nodes.len() + k);
                }
            } else {
                dense_min = Some(nodes.min_node_tag);
            }
            out.nodes
                .extend(block.nodes.iter().map(|n| Vec3::new(n.x, n.y, n.z)));
        }
    }
    NodeTags {
        index_of_tag,
        dense_min,
        count: out.nodes.len(),
    }
}

/// Adds one element block (at `where_` for messages, in physical groups `groups`) to
/// `out`: hexahedra ([`add_hexahedra`]); quadrangles, lines and points to the groups' sets
/// ([`add_group_elements`]). Any other element type is refused.
fn add_element_block(
    block: &mshio::ElementBlock<u64, i32>,
    where_: &str,
    groups: &[String],
    nodes: &NodeTags,
    file: &str,
    out: &mut Imported,
) -> Result<()> {
    let dim = block.entity_dim;
    match block.element_type {
        ElementType::Hex8 => add_hexahedra(block, where_, groups, nodes, file, out),
        ElementType::Qua4 | ElementType::Lin2 | ElementType::Pnt => {
            add_group_elements(block, where_, groups, nodes, file, out)
        }
        other => Err(Error::Input(format!(
            "{where_}: element type {} ({other:?}, entity of dimension {dim}, tag {}) is \
             not supported: tribo meshes are 8-node hexahedra (Gmsh type 5); quadrangles, \
             lines and points may only carry physical groups (recombine and mesh \
             transfinite, first order)",
            other as i32, block.entity_tag
        ))),
    }
}

/// The hexahedra of a block: each appended to `out.hexes` (with its origin for messages),
/// and to the element set and node set of each of the block's groups.
fn add_hexahedra(
    block: &mshio::ElementBlock<u64, i32>,
    where_: &str,
    groups: &[String],
    nodes: &NodeTags,
    file: &str,
    out: &mut Imported,
) -> Result<()> {
    for el in &block.elements {
        let mut hex = [0usize; 8];
        for (k, &tag) in el.nodes.iter().take(8).enumerate() {
            hex[k] = nodes.index(tag, file)?;
        }
        let e = out.hexes.len();
        out.hexes.push(hex);
        out.hex_origin
            .push(format!("{where_}: hexahedron {}", el.element_tag));
        for g in groups {
            out.element_sets.entry(g.clone()).or_default().push(e);
            out.node_sets.entry(g.clone()).or_default().extend(hex);
        }
    }
    Ok(())
}

/// The quadrangles, lines or points of a block, which only carry physical groups: their
/// nodes join each group's node set, and a quadrangle also each group's face set (matched
/// to a hexahedron face when the mesh is built).
fn add_group_elements(
    block: &mshio::ElementBlock<u64, i32>,
    where_: &str,
    groups: &[String],
    nodes: &NodeTags,
    file: &str,
    out: &mut Imported,
) -> Result<()> {
    let ty = block.element_type;
    for el in &block.elements {
        let ns = el
            .nodes
            .iter()
            .map(|&t| nodes.index(t, file))
            .collect::<Result<Vec<usize>>>()?;
        for g in groups {
            out.node_sets.entry(g.clone()).or_default().extend(&ns);
            if ty == ElementType::Qua4 {
                let entry = out
                    .face_sets
                    .entry(g.clone())
                    .or_insert_with(|| (Vec::new(), where_.to_string()));
                entry.0.push(FileFace::Nodes([ns[0], ns[1], ns[2], ns[3]]));
            }
        }
    }
    Ok(())
}

/// Whether the `$MeshFormat` header's version is 2.x.
fn is_version_2(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]);
    let mut lines = head.lines();
    lines.next().map(str::trim) == Some("$MeshFormat")
        && lines
            .next()
            .and_then(|l| l.split_whitespace().next())
            .is_some_and(|v| v.starts_with("2."))
}

/// Whether the `$MeshFormat` header says ASCII (file-type 0).
fn is_ascii_format(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]);
    head.lines()
        .nth(1)
        .and_then(|l| l.split_whitespace().nth(1))
        == Some("0")
}

/// 1-based line of byte `at`.
pub(super) fn line_of(bytes: &[u8], at: usize) -> usize {
    1 + bytes[..at.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// `$PhysicalNames` (ASCII in both formats): (dim, tag) -> name.
pub(super) fn physical_names(bytes: &[u8], file: &str) -> Result<BTreeMap<(i32, i32), String>> {
    let mut names = BTreeMap::new();
    let Some(start) = find(bytes, b"$PhysicalNames") else {
        return Ok(names);
    };
    let Some(len) = find(&bytes[start..], b"$EndPhysicalNames") else {
        return Err(Error::Input(format!(
            "{file}:{}: $PhysicalNames has no $EndPhysicalNames",
            line_of(bytes, start)
        )));
    };
    let first_line = line_of(bytes, start);
    let text = String::from_utf8_lossy(&bytes[start..start + len]);
    for (k, line) in text.lines().enumerate().skip(2) {
        let mut parts = line.splitn(3, char::is_whitespace);
        let bad = || {
            Error::Input(format!(
                "{file}:{}: $PhysicalNames entry must be `dim tag \"name\"`",
                first_line + k
            ))
        };
        let dim: i32 = parts.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let tag: i32 = parts.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let name = parts.next().ok_or_else(bad)?.trim().trim_matches('"');
        names.insert((dim, tag), name.to_string());
    }
    Ok(names)
}

pub(super) fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// In an ASCII file, the 1-based line of each element block's header.
fn element_block_lines(bytes: &[u8]) -> Vec<usize> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text.lines().enumerate();
    let mut out = Vec::new();
    if !lines.any(|(_, l)| l.trim() == "$Elements") {
        return out;
    }
    let Some(blocks) = lines
        .next()
        .and_then(|(_, l)| l.split_whitespace().next()?.parse::<usize>().ok())
    else {
        return out;
    };
    for _ in 0..blocks {
        let Some((i, header)) = lines.next() else {
            break;
        };
        out.push(i + 1);
        let count: usize = header
            .split_whitespace()
            .nth(3)
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        for _ in 0..count {
            lines.next();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture(name: &str) -> Vec<u8> {
        let path = format!("{}/tests/data/mesh/{name}", env!("CARGO_MANIFEST_DIR"));
        std::fs::read(path).unwrap()
    }

    #[test]
    fn ascii_and_binary_block_are_the_same_mesh() {
        let a = read_gmsh(&fixture("block_4x2x2.msh"), "a.msh").unwrap();
        let b = read_gmsh(&fixture("block_4x2x2_bin.msh"), "b.msh").unwrap();
        assert_eq!(a.nodes, b.nodes);
        assert_eq!(a.hexes, b.hexes);
        assert_eq!((a.node_count(), a.element_count()), (45, 16));
        for name in ["x-", "x+", "y-", "y+", "z-", "z+", "blank", "origin"] {
            assert_eq!(
                a.node_set(name).unwrap(),
                b.node_set(name).unwrap(),
                "{name}"
            );
        }
        assert_eq!(a.node_set("origin").unwrap().len(), 1);
        assert_eq!(a.element_set("blank").unwrap().len(), 16);
        assert_eq!(a.face_set("z+").unwrap().len(), 8);
        assert_eq!(a.face_set("x-").unwrap().len(), 4);
    }

    #[test]
    fn tetrahedra_are_refused_with_the_line() {
        let e = read_gmsh(&fixture("tetra_box.msh"), "tetra_box.msh")
            .unwrap_err()
            .to_string();
        assert!(e.contains("tetra_box.msh:"), "{e}");
        assert!(e.contains("element type"), "{e}");
        // The line named is an element block header of that type.
        let text = String::from_utf8(fixture("tetra_box.msh")).unwrap();
        let line: usize = e
            .split("tetra_box.msh:")
            .nth(1)
            .unwrap()
            .split(':')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        let header: Vec<&str> = text
            .lines()
            .nth(line - 1)
            .unwrap()
            .split_whitespace()
            .collect();
        assert_eq!(header.len(), 4, "{header:?}");
        let ty: i32 = header[2].parse().unwrap();
        assert!(e.contains(&format!("element type {ty} ")), "{e}");
    }

    #[test]
    fn broken_files_name_the_line() {
        let mut text = String::from_utf8(fixture("block_4x2x2.msh")).unwrap();
        // A node coordinate that is not a number.
        let at = text.find("$Nodes").unwrap();
        let line = line_of(text.as_bytes(), at);
        let node_line = text[at..].lines().nth(4).unwrap().to_string();
        let pos = at + text[at..].find(&node_line).unwrap();
        text.replace_range(pos..pos + node_line.len(), "0 zero 1");
        let e = read_gmsh(text.as_bytes(), "bad.msh")
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("bad.msh:{}", line + 4)), "{e}");

        // MSH 2 is read by gmsh22.rs; a version neither 2 nor 4.1 is refused.
        let e = read_gmsh(b"$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", "old.msh")
            .unwrap_err()
            .to_string();
        assert!(e.contains("old.msh:") && e.contains("4.1"), "{e}");
        assert!(read_gmsh(b"", "empty.msh").is_err());
        let full = fixture("block_4x2x2_bin.msh");
        let e = read_gmsh(&full[..full.len() / 2], "cut.msh")
            .unwrap_err()
            .to_string();
        assert!(e.contains("cut.msh (byte"), "{e}");
    }
}
