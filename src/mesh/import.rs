//! What the mesh readers (Gmsh, CalculiX/Abaqus) share: turning the nodes, hexahedra and
//! named groups read from a file into a checked [`Mesh`].
//!
//! * Only nodes used by a hexahedron are kept (files also hold reference nodes, nodes of
//!   lower-dimensional elements, ...), in file order; a set loses its nodes that are not
//!   kept. An unused node would have no stiffness and make the system singular.
//! * A hexahedron numbered as the mirror image (all 8 corner Jacobian determinants
//!   negative: bottom and top face swapped) is renumbered `[4, 5, 6, 7, 0, 1, 2, 3]`; one
//!   with mixed signs is refused, naming the file's element and line.
//! * Face sets given by 4 nodes are matched to the element face with those nodes.
//! * The through-thickness node columns are found from the topology
//!   ([`Mesh::detect_columns`], `columns.rs`), elements renumbered to stand in them; a mesh
//!   that is no sheet gets none, and the reason is kept for the solid-shell's error.

use std::collections::BTreeMap;

use super::{corner_jacobian, Mesh};
use crate::geometry::Vec3;
use crate::{Error, Result};

/// An element face in a file: by its 4 nodes (a Gmsh quadrangle, file node indices), or by
/// element (file element index) and local face ([`super::HEX_FACES`] index).
#[derive(Clone, Copy, Debug)]
pub(super) enum FileFace {
    Nodes([usize; 4]),
    Element(usize, usize),
}

/// A mesh as read from a file, before checks. Indices are file order (0-based).
#[derive(Debug, Default)]
pub(super) struct Imported {
    pub nodes: Vec<Vec3>,
    pub hexes: Vec<[usize; 8]>,
    /// Where each hexahedron is defined, for messages ("mesh.inp:12, element 7").
    pub hex_origin: Vec<String>,
    pub node_sets: BTreeMap<String, Vec<usize>>,
    pub element_sets: BTreeMap<String, Vec<usize>>,
    pub face_sets: BTreeMap<String, (Vec<FileFace>, String)>,
}

impl Imported {
    /// The checked mesh; `file` names the file in messages.
    pub fn build(self, file: &str) -> Result<Mesh> {
        if self.hexes.is_empty() {
            return Err(Error::Input(format!(
                "{file}: the mesh has no 8-node hexahedra"
            )));
        }
        let mut new_index = vec![usize::MAX; self.nodes.len()];
        let mut nodes = Vec::new();
        for hex in &self.hexes {
            for &n in hex {
                if new_index[n] == usize::MAX {
                    new_index[n] = 0;
                }
            }
        }
        for (old, slot) in new_index.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = nodes.len();
                nodes.push(self.nodes[old]);
            }
        }
        let mut hexes = Vec::with_capacity(self.hexes.len());
        for (e, hex) in self.hexes.iter().enumerate() {
            let mut h = hex.map(|n| new_index[n]);
            let x = h.map(|n| nodes[n]);
            let dets = (0..8).map(|c| corner_jacobian(&x, c).determinant());
            let (mut neg, mut pos) = (0, 0);
            for d in dets {
                if d > 0.0 {
                    pos += 1;
                } else if d < 0.0 {
                    neg += 1;
                }
            }
            if neg == 8 {
                h = [h[4], h[5], h[6], h[7], h[0], h[1], h[2], h[3]];
            } else if pos != 8 {
                return Err(Error::Input(format!(
                    "{}: the hexahedron is distorted, folded or degenerate (the Jacobian \
                     determinant is positive at {pos} of its 8 corners, negative at {neg})",
                    self.hex_origin[e]
                )));
            }
            hexes.push(h);
        }
        let mut mesh = Mesh::new(nodes, hexes)?;
        for (name, set) in &self.node_sets {
            let kept = set
                .iter()
                .map(|&n| new_index[n])
                .filter(|&n| n != usize::MAX)
                .collect();
            mesh.add_node_set(name, kept)?;
        }
        for (name, set) in &self.element_sets {
            mesh.add_element_set(name, set.clone())?;
        }
        let by_nodes = mesh.faces_by_nodes();
        for (name, (faces, origin)) in &self.face_sets {
            let mut pairs = Vec::with_capacity(faces.len());
            for face in faces {
                match *face {
                    FileFace::Element(e, f) => pairs.push((e, f)),
                    FileFace::Nodes(q) => {
                        let mut key = q.map(|n| new_index.get(n).copied().unwrap_or(usize::MAX));
                        key.sort_unstable();
                        let pair = by_nodes.get(&key).ok_or_else(|| {
                            Error::Input(format!(
                                "{origin}: a quadrangle of {name:?} (file nodes {:?}) is not a \
                                 face of any hexahedron",
                                q.map(|n| n + 1)
                            ))
                        })?;
                        pairs.push(*pair);
                    }
                }
            }
            mesh.add_face_set(name, &pairs)?;
            // The face set is also a node set (its faces' nodes), so that it can be named
            // wherever a node set is ("z+" in sim.fix, sim.add_tool), unless the file
            // defines a node set of that name itself.
            if mesh.node_set(name).is_err() {
                let nodes = mesh.face_set(name)?.iter().flatten().copied().collect();
                mesh.add_node_set(name, nodes)?;
            }
        }
        // Last: it may renumber elements, and face sets above name faces by local index.
        mesh.detect_columns();
        Ok(mesh)
    }
}
