//! Hexahedral meshes of the deformable body: nodes, 8-node hexahedra, named node sets,
//! boundary faces and nodal tributary areas.
//!
//! # Node ordering of a hexahedron
//!
//! Every hexahedron lists its nodes in the VTK_HEXAHEDRON order, given here by the natural
//! (reference) coordinates of each corner, [`HEX_CORNERS`]:
//!
//! ```text
//!        7 -------- 6          node  (xi, eta, zeta)
//!       /|         /|           0    (-1, -1, -1)
//!      4 -------- 5 |           1    (+1, -1, -1)
//!      | |        | |           2    (+1, +1, -1)
//!      | 3 -------|-2           3    (-1, +1, -1)
//!      |/         |/            4    (-1, -1, +1)
//!      0 -------- 1             5    (+1, -1, +1)
//!                               6    (+1, +1, +1)
//!   zeta ^  eta                 7    (-1, +1, +1)
//!        | /
//!        |/--> xi
//! ```
//!
//! Nodes 0-3 form the face zeta = -1, counter-clockwise seen from +zeta, and nodes 4-7 the
//! face zeta = +1 in the same order; for an undistorted element aligned with the axes,
//! xi, eta, zeta point along x, y, z and the Jacobian determinant is positive.
//! [`Mesh::validate`] rejects any element whose Jacobian determinant is not positive at one
//! of its corners (an inverted or degenerate element).

use std::collections::BTreeMap;

use crate::geometry::{Mat3, Vec3};
use crate::{Error, Result};

mod block;
mod columns;
mod faces;
pub mod gmsh;
mod gmsh22;
mod grading;
mod import;
pub mod inp;
mod map;
mod merge;
mod ogrid;
mod sets;

pub use block::{End, Grading, MAX_BLOCK_NODES};
pub use faces::{quad_area, HEX_FACES};
pub use grading::core_and_growth;
pub use ogrid::RoundBlank;

/// Natural coordinates (xi, eta, zeta) of the 8 corners of the reference hexahedron
/// [-1, 1]^3, in VTK_HEXAHEDRON order (see the module documentation).
pub const HEX_CORNERS: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// For corner `c` and natural axis `d`, the corner at the other end of the element edge
/// through `c` along axis `d` (the corner whose natural coordinates differ from `c`'s in
/// component `d` only).
const HEX_EDGE_NEIGHBOUR: [[usize; 3]; 8] = [
    [1, 3, 4],
    [0, 2, 5],
    [3, 1, 6],
    [2, 0, 7],
    [5, 7, 0],
    [4, 6, 1],
    [7, 5, 2],
    [6, 4, 3],
];

/// A mesh of 8-node hexahedra.
///
/// `nodes` and `hexes` are public so that the solver can read them without copies; a
/// caller that edits them directly should call [`Mesh::validate`] afterwards. Node sets are
/// kept private so that every set stays sorted, duplicate-free and in range.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Reference (undeformed) coordinates of the nodes.
    pub nodes: Vec<Vec3>,
    /// Element connectivity: 8 node indices per hexahedron, VTK_HEXAHEDRON order.
    pub hexes: Vec<[usize; 8]>,
    /// Named node sets, each sorted ascending without duplicates.
    node_sets: BTreeMap<String, Vec<usize>>,
    /// Through-thickness node columns of a sheet (see [`Mesh::columns`]).
    columns: Vec<Vec<usize>>,
    /// Why [`Mesh::detect_columns`] found no columns (`columns.rs`), naming the element.
    columns_fault: Option<String>,
    /// Named element sets and face sets of imported meshes (see `sets.rs`).
    sets: sets::Sets,
}

impl Mesh {
    /// A mesh from explicit nodes and hexahedra, checked by [`Mesh::validate`]. It has no
    /// node sets.
    pub fn new(nodes: Vec<Vec3>, hexes: Vec<[usize; 8]>) -> Result<Mesh> {
        let mesh = Mesh {
            nodes,
            hexes,
            ..Mesh::default()
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Through-thickness node columns, bottom to top, when the mesh is a sheet whose
    /// thickness direction is known (a block: its z axis, the sheet normal; an imported or
    /// merged mesh: found from its topology, `columns.rs`); empty otherwise. Each column's current length is the sheet's current thickness there.
    pub fn columns(&self) -> &[Vec<usize>] {
        &self.columns
    }

    /// Current thickness of every column (the length of the polyline through its nodes at
    /// the reference positions plus `displacement(node)`), in column order.
    pub fn column_thicknesses(&self, displacement: impl Fn(usize) -> Vec3) -> Vec<f64> {
        self.columns
            .iter()
            .map(|col| {
                col.windows(2)
                    .map(|w| {
                        let a = self.nodes[w[0]] + displacement(w[0]);
                        let b = self.nodes[w[1]] + displacement(w[1]);
                        (b - a).norm()
                    })
                    .sum()
            })
            .collect()
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of hexahedra.
    pub fn element_count(&self) -> usize {
        self.hexes.len()
    }

    /// Checks that the mesh can be analysed: at least one element, every node coordinate
    /// finite, every node index in range, and every hexahedron with a positive Jacobian
    /// determinant at each of its 8 corners.
    ///
    /// Why the corners: the Jacobian determinant of a trilinear map is positive everywhere
    /// in the element if it is positive at the 8 corners for all but strongly warped
    /// elements, and a non-positive corner value is always a sign of an inverted, folded or
    /// degenerate (collapsed) element. The element routines check the Gauss points too.
    pub fn validate(&self) -> Result<()> {
        if self.hexes.is_empty() {
            return Err(Error::input(
                "number of elements",
                0,
                "must be >= 1 (the mesh is empty)",
            ));
        }
        for (i, x) in self.nodes.iter().enumerate() {
            if !x.iter().all(|c| c.is_finite()) {
                return Err(Error::input(
                    &format!("coordinates of node {i}"),
                    format!("({}, {}, {})", x.x, x.y, x.z),
                    "must be finite",
                ));
            }
        }
        for (e, hex) in self.hexes.iter().enumerate() {
            for (k, &n) in hex.iter().enumerate() {
                if n >= self.nodes.len() {
                    return Err(Error::input(
                        &format!("node {k} of element {e}"),
                        n,
                        &format!("must be < {} (the number of nodes)", self.nodes.len()),
                    ));
                }
            }
            let x = self.hex_coordinates(e);
            for c in 0..8 {
                let det = corner_jacobian(&x, c).determinant();
                // `!(det > 0)` also rejects NaN.
                if !(det > 0.0) {
                    return Err(Error::input(
                        &format!("Jacobian determinant of element {e} at its corner {c} (node {})", hex[c]),
                        det,
                        "must be > 0 (the element is inverted or degenerate; nodes must follow the VTK_HEXAHEDRON order)",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Reference coordinates of the 8 nodes of element `e`.
    ///
    /// Panics if `e` or one of its node indices is out of range: call it on a validated
    /// mesh with an index below [`Mesh::element_count`].
    pub fn hex_coordinates(&self, e: usize) -> [Vec3; 8] {
        self.hexes[e].map(|n| self.nodes[n])
    }

    /// The node set called `name` (sorted ascending, no duplicates). An unknown name is an
    /// error listing the known names.
    pub fn node_set(&self, name: &str) -> Result<&[usize]> {
        self.node_sets.get(name).map(Vec::as_slice).ok_or_else(|| {
            let known: Vec<&str> = self.node_sets.keys().map(String::as_str).collect();
            Error::input(
                "node set",
                format!("{name:?}"),
                &format!("is unknown; known node sets: {}", known.join(", ")),
            )
        })
    }

    /// Names of all node sets, in alphabetical order.
    pub fn node_set_names(&self) -> impl Iterator<Item = &str> {
        self.node_sets.keys().map(String::as_str)
    }

    /// Adds (or replaces) the node set `name`. The nodes are sorted and duplicates removed;
    /// an index out of range or an empty name is an error.
    pub fn add_node_set(&mut self, name: &str, mut nodes: Vec<usize>) -> Result<()> {
        if name.is_empty() {
            return Err(Error::input("node set name", "\"\"", "must not be empty"));
        }
        if let Some(&bad) = nodes.iter().find(|&&n| n >= self.nodes.len()) {
            return Err(Error::input(
                &format!("node index in node set {name:?}"),
                bad,
                &format!("must be < {} (the number of nodes)", self.nodes.len()),
            ));
        }
        nodes.sort_unstable();
        nodes.dedup();
        self.node_sets.insert(name.to_string(), nodes);
        Ok(())
    }

    /// Indices (ascending) of the nodes whose reference position satisfies `pred`, e.g.
    /// `mesh.select_nodes(|x| x.z > 0.99)`.
    pub fn select_nodes(&self, pred: impl Fn(&Vec3) -> bool) -> Vec<usize> {
        self.nodes
            .iter()
            .enumerate()
            .filter(|(_, x)| pred(x))
            .map(|(i, _)| i)
            .collect()
    }

    /// Axis-aligned bounding box (min, max) of the nodes, `None` for a mesh without nodes.
    pub fn bounding_box(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.nodes.first()?;
        Some(
            self.nodes
                .iter()
                .fold((first, first), |(lo, hi), x| (lo.inf(x), hi.sup(x))),
        )
    }
}

/// Jacobian dx/d(xi, eta, zeta) of the trilinear map at corner `c`.
///
/// At a corner the other two natural coordinates sit at +-1, where the trilinear map is
/// linear along each edge, so column d is half the edge vector along natural axis d,
/// oriented from the -1 end to the +1 end.
fn corner_jacobian(x: &[Vec3; 8], c: usize) -> Mat3 {
    let col = |d: usize| {
        let other = HEX_EDGE_NEIGHBOUR[c][d];
        (x[c] - x[other]) * (0.5 * HEX_CORNERS[c][d])
    };
    Mat3::from_columns(&[col(0), col(1), col(2)])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> (Vec<Vec3>, Vec<[usize; 8]>) {
        let nodes = HEX_CORNERS
            .iter()
            .map(|c| Vec3::new(0.5 * (c[0] + 1.0), 0.5 * (c[1] + 1.0), 0.5 * (c[2] + 1.0)))
            .collect();
        (nodes, vec![[0, 1, 2, 3, 4, 5, 6, 7]])
    }

    #[test]
    fn edge_neighbour_table_matches_corners() {
        for c in 0..8 {
            for d in 0..3 {
                let o = HEX_EDGE_NEIGHBOUR[c][d];
                for k in 0..3 {
                    let same = HEX_CORNERS[c][k] == HEX_CORNERS[o][k];
                    assert_eq!(same, k != d, "corner {c} axis {d}");
                }
            }
        }
    }

    #[test]
    fn unit_cube_is_valid_with_corner_jacobian_one_eighth() {
        let (nodes, hexes) = unit_cube();
        let mesh = Mesh::new(nodes, hexes).unwrap();
        let x = mesh.hex_coordinates(0);
        for c in 0..8 {
            // Unit cube = [-1,1]^3 scaled by 1/2: det J = 1/8 everywhere.
            assert!((corner_jacobian(&x, c).determinant() - 0.125).abs() < 1e-15);
        }
    }

    #[test]
    fn validate_rejects_empty_out_of_range_and_inverted() {
        let err = Mesh::new(vec![], vec![]).unwrap_err().to_string();
        assert!(err.contains("number of elements = 0"), "{err}");

        let (nodes, _) = unit_cube();
        let err = Mesh::new(nodes.clone(), vec![[0, 1, 2, 3, 4, 5, 6, 8]])
            .unwrap_err()
            .to_string();
        assert!(err.contains("node 7 of element 0 = 8"), "{err}");

        // Two elements, the second with bottom and top swapped (mirror image: inverted).
        let mut nodes2 = nodes.clone();
        nodes2.extend(nodes.iter().map(|x| x + Vec3::new(2.0, 0.0, 0.0)));
        let hexes = vec![[0, 1, 2, 3, 4, 5, 6, 7], [12, 13, 14, 15, 8, 9, 10, 11]];
        let err = Mesh::new(nodes2, hexes).unwrap_err().to_string();
        assert!(err.contains("element 1"), "{err}");
        assert!(err.contains("must be > 0"), "{err}");

        // A collapsed element: node 6 moved onto node 2, so the edge 2-6 has zero length.
        let mut nodes3 = nodes.clone();
        nodes3[6] = nodes3[2];
        let err = Mesh::new(nodes3, vec![[0, 1, 2, 3, 4, 5, 6, 7]])
            .unwrap_err()
            .to_string();
        assert!(err.contains("element 0"), "{err}");

        let mut nodes4 = nodes;
        nodes4[3].y = f64::NAN;
        let err = Mesh::new(nodes4, vec![[0, 1, 2, 3, 4, 5, 6, 7]])
            .unwrap_err()
            .to_string();
        assert!(err.contains("coordinates of node 3"), "{err}");
    }

    #[test]
    fn node_sets_add_select_and_unknown_name() {
        let (nodes, hexes) = unit_cube();
        let mut mesh = Mesh::new(nodes, hexes).unwrap();
        mesh.add_node_set("top", vec![7, 4, 5, 6, 4]).unwrap();
        assert_eq!(mesh.node_set("top").unwrap(), &[4, 5, 6, 7]);
        assert_eq!(mesh.select_nodes(|x| x.z > 0.5), vec![4, 5, 6, 7]);

        let err = mesh.node_set("bottom").unwrap_err().to_string();
        assert!(err.contains("\"bottom\""), "{err}");
        assert!(err.contains("known node sets: top"), "{err}");

        let err = mesh
            .add_node_set("bad", vec![1, 99])
            .unwrap_err()
            .to_string();
        assert!(err.contains("= 99 must be < 8"), "{err}");
        assert!(mesh.add_node_set("", vec![]).is_err());
        assert_eq!(mesh.node_set_names().collect::<Vec<_>>(), vec!["top"]);
    }

    #[test]
    fn bounding_box_of_unit_cube() {
        let (nodes, hexes) = unit_cube();
        let mesh = Mesh::new(nodes, hexes).unwrap();
        let (lo, hi) = mesh.bounding_box().unwrap();
        assert_eq!(lo, Vec3::zeros());
        assert_eq!(hi, Vec3::new(1.0, 1.0, 1.0));
    }
}
