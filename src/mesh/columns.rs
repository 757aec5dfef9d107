//! Through-thickness node columns of a hexahedral sheet found from the mesh's topology, so
//! that imported and merged blanks have them as a `block` has them by construction.
//!
//! # Mathematics
//!
//! A sheet meshed in hexahedra is, topologically, a quadrilateral surface mesh extruded
//! through `L >= 1` layers: every hexahedron has one pair of opposite faces across the
//! thickness, and the hexahedra of one stack are joined through exactly those faces. The
//! columns are found in three steps.
//!
//! 1. **The two sheet surfaces.** The boundary faces (element faces of one hexahedron only)
//!    are grouped into smooth patches: two boundary faces sharing an edge are in one patch
//!    when their unit normals `n_i, n_j` satisfy `n_i · n_j > cos 60°`. A sheet's rim meets
//!    its surfaces at about 90°, so the rim is cut off from them, while a curved sheet
//!    (2 mesh faces per 90° of bend at least) stays one patch. The two patches of largest
//!    area are the sheet's surfaces (ties broken by the larger `|n_z|` of the mean normal,
//!    so that a cube's z faces win). The **bottom** surface is the one whose area-weighted
//!    mean outward normal `m_B` has the smaller component along the axis `k` of largest
//!    `|m_A,k - m_B,k|` (for a blank in the xy plane: the surface facing -z), so that
//!    columns run bottom to top as a block's do along +z.
//! 2. **Stacks.** From every bottom face `(e, f)` the walk enters element `e` through local
//!    face `f`, leaves it through the opposite face `f ^ 1` ([`HEX_FACES`] lists opposite
//!    faces in pairs), and enters the neighbour across that face, until it leaves through a
//!    boundary face, which must be on the top surface. Each step records, for the 4 corners
//!    `c` of `f`, the edge to the corner across the element along the face's natural axis
//!    `d = f / 2` ([`HEX_EDGE_NEIGHBOUR`]): the node above `hex[c]` is `hex[up(c)]`.
//! 3. **Columns.** A column starts at each node of the bottom surface and follows "the node
//!    above" to the top. The result is a set of columns only if every element is in exactly
//!    one stack, every node has at most one node above and one below, and every node is in
//!    one column; otherwise the error names the element (or node) where this fails.
//!
//! Each element is then renumbered, where needed, so that its natural `ζ` axis runs up the
//! column (local nodes 4-7 one step above 0-3), as the solid-shell requires: new local
//! nodes 0-3 are the bottom face's corners `[p0, p3, p2, p1]` (`HEX_FACES` lists a face
//! counter-clockwise seen from outside, i.e. from below), and node `4 + i` is the corner
//! above node `i`. This is a rotation of the reference cube, so the Jacobian keeps its sign;
//! the 2x2x2 rule and the F-bar centre are invariant under it, so hexahedron results change
//! only by round-off. Cost: O(elements) with hashing.

use std::collections::HashMap;

use super::{quad_area, Mesh, HEX_EDGE_NEIGHBOUR, HEX_FACES};
use crate::geometry::Vec3;
use crate::{Error, Result};

/// Cosine of the largest angle between the normals of two boundary faces of one surface.
const SMOOTH_COS: f64 = 0.5;

/// Columns found from the topology, and the elements renumbered to stand in them.
struct Found {
    columns: Vec<Vec<usize>>,
    hexes: Vec<[usize; 8]>,
}

impl Mesh {
    /// Finds the through-thickness columns from the topology (see the module doc), keeping
    /// them as [`Mesh::columns`] and renumbering elements to stand in them. Where the mesh
    /// is no sheet, it gets no columns and [`Mesh::columns_fault`] says why (naming the
    /// element), for the solid-shell's error.
    pub fn detect_columns(&mut self) {
        match self.find_columns() {
            Ok(found) => {
                self.columns = found.columns;
                self.hexes = found.hexes;
                self.columns_fault = None;
            }
            Err(e) => {
                self.columns.clear();
                self.columns_fault = Some(e.to_string());
            }
        }
    }

    /// Why [`Mesh::detect_columns`] found no columns, when it was run and failed.
    pub fn columns_fault(&self) -> Option<&str> {
        self.columns_fault.as_deref()
    }

    fn find_columns(&self) -> Result<Found> {
        let faces = FaceIndex::new(self);
        let (bottom, top) = sheet_surfaces(self, &faces)?;
        let stacks = walk_stacks(self, &faces, &bottom, &top)?;
        let columns = follow_columns(self, &faces, &bottom, &stacks.up)?;
        let hexes = (0..self.hexes.len())
            .map(|e| stand_upright(self.hexes[e], stacks.entry_face[e]))
            .collect();
        Ok(Found { columns, hexes })
    }
}

/// Every element face by its sorted nodes, and the boundary faces (one element only).
struct FaceIndex {
    by_nodes: HashMap<[usize; 4], Vec<(usize, usize)>>,
    /// Boundary faces as (element, local face), in element order.
    boundary: Vec<(usize, usize)>,
}

impl FaceIndex {
    fn new(mesh: &Mesh) -> Self {
        let mut by_nodes: HashMap<[usize; 4], Vec<(usize, usize)>> =
            HashMap::with_capacity(6 * mesh.hexes.len());
        for (e, hex) in mesh.hexes.iter().enumerate() {
            for f in 0..6 {
                by_nodes.entry(key(hex, f)).or_default().push((e, f));
            }
        }
        let mut boundary = Vec::new();
        for (e, hex) in mesh.hexes.iter().enumerate() {
            for f in 0..6 {
                if by_nodes[&key(hex, f)].len() == 1 {
                    boundary.push((e, f));
                }
            }
        }
        FaceIndex { by_nodes, boundary }
    }
}

fn key(hex: &[usize; 8], f: usize) -> [usize; 4] {
    let mut k = HEX_FACES[f].map(|i| hex[i]);
    k.sort_unstable();
    k
}

fn face_points(mesh: &Mesh, e: usize, f: usize) -> [Vec3; 4] {
    HEX_FACES[f].map(|i| mesh.nodes[mesh.hexes[e][i]])
}

/// The bottom and top sheet surfaces as sets of boundary faces (indices into
/// `faces.boundary`), step 1 of the module doc.
fn sheet_surfaces(mesh: &Mesh, faces: &FaceIndex) -> Result<(Vec<usize>, Vec<usize>)> {
    let nb = faces.boundary.len();
    let normals: Vec<Vec3> = (faces.boundary.iter())
        .map(|&(e, f)| {
            let x = face_points(mesh, e, f);
            (x[2] - x[0]).cross(&(x[3] - x[1])).normalize()
        })
        .collect();
    // Union-find over boundary faces joined across smooth edges.
    let mut parent: Vec<usize> = (0..nb).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut edges: HashMap<(usize, usize), Vec<usize>> = HashMap::with_capacity(2 * nb);
    for (i, &(e, f)) in faces.boundary.iter().enumerate() {
        let q = HEX_FACES[f].map(|l| mesh.hexes[e][l]);
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            edges.entry((a.min(b), a.max(b))).or_default().push(i);
        }
    }
    for list in edges.values() {
        for (x, &i) in list.iter().enumerate() {
            for &j in &list[x + 1..] {
                if normals[i].dot(&normals[j]) > SMOOTH_COS {
                    let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                    parent[ri.max(rj)] = ri.min(rj);
                }
            }
        }
    }
    let mut groups: HashMap<usize, (f64, Vec3, Vec<usize>)> = HashMap::new();
    for i in 0..nb {
        let r = root(&mut parent, i);
        let (e, f) = faces.boundary[i];
        let area = quad_area(&face_points(mesh, e, f));
        let g = groups.entry(r).or_insert((0.0, Vec3::zeros(), Vec::new()));
        g.0 += area;
        g.1 += normals[i] * area;
        g.2.push(i);
    }
    let mut groups: Vec<(f64, Vec3, Vec<usize>)> = groups.into_values().collect();
    if groups.len() < 2 {
        return Err(Error::Input(
            "the mesh's boundary is one smooth surface (no rim between two sheet surfaces); \
             it is no sheet and has no through-thickness node columns"
                .into(),
        ));
    }
    // Largest area first; equal areas (to round-off): the larger |n_z| first; then the
    // first face's index, so the order never depends on hashing.
    groups.sort_by(|a, b| {
        let tol = 1e-9 * a.0.max(b.0);
        if (a.0 - b.0).abs() > tol {
            return b.0.total_cmp(&a.0);
        }
        let (za, zb) = (a.1.z.abs() / a.0, b.1.z.abs() / b.0);
        if (za - zb).abs() > 1e-9 {
            return zb.total_cmp(&za);
        }
        a.2[0].cmp(&b.2[0])
    });
    let (a, b) = (&groups[0], &groups[1]);
    let d = a.1 / a.0 - b.1 / b.0;
    let k = d.iamax();
    Ok(if d[k] < 0.0 {
        (a.2.clone(), b.2.clone())
    } else {
        (b.2.clone(), a.2.clone())
    })
}

/// Step 2: every element's entry face from below, and the node above each node.
struct Stacks {
    entry_face: Vec<usize>,
    up: Vec<Option<usize>>,
}

fn walk_stacks(mesh: &Mesh, faces: &FaceIndex, bottom: &[usize], top: &[usize]) -> Result<Stacks> {
    let mut on_top = vec![false; faces.boundary.len()];
    for &i in top {
        on_top[i] = true;
    }
    let boundary_index: HashMap<(usize, usize), usize> = (faces.boundary.iter().enumerate())
        .map(|(i, &ef)| (ef, i))
        .collect();
    let n = mesh.nodes.len();
    let mut entry_face: Vec<Option<usize>> = vec![None; mesh.hexes.len()];
    let mut stack_of: Vec<usize> = vec![usize::MAX; mesh.hexes.len()];
    let mut up: Vec<Option<usize>> = vec![None; n];
    let mut down: Vec<Option<usize>> = vec![None; n];
    for &b in bottom {
        let (start, _) = faces.boundary[b];
        let (mut e, mut f) = faces.boundary[b];
        loop {
            if entry_face[e].is_some() {
                return Err(Error::Input(format!(
                    "element {e}: it lies in two through-thickness stacks (from the bottom faces \
                     of elements {} and {start}); the mesh has no through-thickness node columns",
                    stack_of[e]
                )));
            }
            entry_face[e] = Some(f);
            stack_of[e] = start;
            let hex = &mesh.hexes[e];
            for c in HEX_FACES[f] {
                let (lo, hi) = (hex[c], hex[HEX_EDGE_NEIGHBOUR[c][f / 2]]);
                link(&mut up, lo, hi, e, "above")?;
                link(&mut down, hi, lo, e, "below")?;
            }
            let out = f ^ 1;
            let next = faces.by_nodes[&key(hex, out)]
                .iter()
                .find(|&&(o, _)| o != e);
            match next {
                Some(&(e2, f2)) => (e, f) = (e2, f2),
                None if on_top[boundary_index[&(e, out)]] => break,
                None => {
                    return Err(Error::Input(format!(
                        "element {e}: the stack of elements rising from the bottom sheet surface \
                         at element {start} leaves the mesh through its local face {out}, which \
                         is not on the top sheet surface; the mesh has no through-thickness \
                         node columns"
                    )))
                }
            }
        }
    }
    let entry_face = (entry_face.iter().enumerate())
        .map(|(e, f)| {
            f.ok_or_else(|| {
                Error::Input(format!(
                    "element {e}: no stack of elements rising from the bottom sheet surface \
                     reaches it; the mesh has no through-thickness node columns"
                ))
            })
        })
        .collect::<Result<Vec<usize>>>()?;
    Ok(Stacks { entry_face, up })
}

/// Records `map[from] = to`, an error naming `element` if `from` already has another.
fn link(
    map: &mut [Option<usize>],
    from: usize,
    to: usize,
    element: usize,
    side: &str,
) -> Result<()> {
    match map[from] {
        Some(other) if other != to => Err(Error::Input(format!(
            "element {element}: node {from} has two nodes {side} it ({other} and {to}); the \
             mesh has no through-thickness node columns"
        ))),
        _ => {
            map[from] = Some(to);
            Ok(())
        }
    }
}

/// Step 3: one column per node of the bottom surface, bottom to top, in ascending order of
/// the bottom node.
fn follow_columns(
    mesh: &Mesh,
    faces: &FaceIndex,
    bottom: &[usize],
    up: &[Option<usize>],
) -> Result<Vec<Vec<usize>>> {
    let mut starts: Vec<usize> = (bottom.iter())
        .flat_map(|&b| {
            let (e, f) = faces.boundary[b];
            HEX_FACES[f].map(|l| mesh.hexes[e][l])
        })
        .collect();
    starts.sort_unstable();
    starts.dedup();
    let mut seen = vec![false; mesh.nodes.len()];
    let mut columns = Vec::with_capacity(starts.len());
    for s in starts {
        let mut col = vec![s];
        let mut at = s;
        while let Some(next) = up[at] {
            col.push(next);
            at = next;
        }
        for &n in &col {
            if std::mem::replace(&mut seen[n], true) {
                return Err(Error::Input(format!(
                    "node {n}: it is in two through-thickness columns; the mesh has no \
                     through-thickness node columns"
                )));
            }
        }
        columns.push(col);
    }
    if let Some(n) = seen.iter().position(|s| !s) {
        return Err(Error::Input(format!(
            "node {n}: it is in no through-thickness column rising from the bottom sheet \
             surface; the mesh has no through-thickness node columns"
        )));
    }
    Ok(columns)
}

/// The element's nodes renumbered so that `entry` (its face towards the bottom surface)
/// becomes local face 4 (ζ = -1), by a rotation of the reference cube (module doc).
fn stand_upright(hex: [usize; 8], entry: usize) -> [usize; 8] {
    if entry == 4 {
        return hex;
    }
    let [p0, p1, p2, p3] = HEX_FACES[entry];
    let low = [p0, p3, p2, p1];
    let d = entry / 2;
    let mut out = [0; 8];
    for i in 0..4 {
        out[i] = hex[low[i]];
        out[i + 4] = hex[HEX_EDGE_NEIGHBOUR[low[i]][d]];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The block's own columns and the ones found from its topology are the same.
    #[test]
    fn block_columns_are_found_from_topology() {
        let mut m = Mesh::block(Vec3::zeros(), Vec3::new(4.0, 2.0, 1.0), [4, 2, 3]).unwrap();
        let built = m.columns().to_vec();
        let hexes = m.hexes.clone();
        m.detect_columns();
        assert_eq!(m.columns_fault(), None);
        assert_eq!(m.columns(), built.as_slice());
        assert_eq!(
            m.hexes, hexes,
            "a block's elements already stand in their columns"
        );
    }

    /// Every rotation of every element's numbering is undone: the elements stand upright
    /// again (zeta up the column) with positive Jacobians.
    #[test]
    fn rotated_elements_are_stood_upright() {
        let mut m = Mesh::block(Vec3::zeros(), Vec3::new(3.0, 2.0, 0.5), [3, 2, 2]).unwrap();
        let upright = m.hexes.clone();
        // Six proper rotations of the cube's numbering, putting each face at the bottom.
        let rotations: [[usize; 8]; 6] = [
            [0, 1, 2, 3, 4, 5, 6, 7],
            [4, 7, 6, 5, 0, 3, 2, 1],
            [1, 5, 6, 2, 0, 4, 7, 3],
            [4, 0, 3, 7, 5, 1, 2, 6],
            [3, 2, 6, 7, 0, 1, 5, 4],
            [0, 4, 5, 1, 3, 7, 6, 2],
        ];
        for (e, hex) in m.hexes.iter_mut().enumerate() {
            let r = rotations[e % 6];
            *hex = r.map(|i| hex[i]);
        }
        m.validate().expect("the rotations are proper");
        m.detect_columns();
        assert_eq!(m.columns_fault(), None);
        m.validate().unwrap();
        for (e, (got, want)) in m.hexes.iter().zip(&upright).enumerate() {
            let mut a = *got;
            let mut b = *want;
            a.sort_unstable();
            b.sort_unstable();
            assert_eq!(a, b, "element {e} keeps its nodes");
            assert_eq!(
                got[..4].iter().map(|&n| m.nodes[n].z).sum::<f64>(),
                want[..4].iter().map(|&n| m.nodes[n].z).sum::<f64>(),
                "element {e}"
            );
        }
        // What the solid-shell needs: local node a + 4 one step above node a in its column.
        let mut place = vec![(0, 0); m.node_count()];
        for (c, col) in m.columns().iter().enumerate() {
            for (k, &n) in col.iter().enumerate() {
                place[n] = (c, k);
            }
        }
        for hex in &m.hexes {
            for a in 0..4 {
                let ((c0, k0), (c1, k1)) = (place[hex[a]], place[hex[a + 4]]);
                assert!(c0 == c1 && k1 == k0 + 1, "{hex:?}");
            }
        }
    }

    /// Two blocks stacked through the thickness are one sheet of 3 layers.
    #[test]
    fn stacked_blocks_make_longer_columns() {
        let a = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 1.0, 0.5), [2, 1, 1]).unwrap();
        let b = Mesh::block(
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(2.0, 1.0, 0.5),
            [2, 1, 2],
        )
        .unwrap();
        let mut m = a.merged(&b, 1e-9).unwrap();
        m.detect_columns();
        assert_eq!(m.columns().len(), 6);
        assert!(m.columns().iter().all(|c| c.len() == 4));
        let t = m.column_thicknesses(|_| Vec3::zeros());
        assert!(t.iter().all(|t| (t - 1.0).abs() < 1e-12));
    }

    /// An L of two blocks is no sheet: the error names an element.
    #[test]
    fn non_sheet_names_an_element() {
        // 3 cells deep in y, so that the L is no sheet along y either.
        let a = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 3.0, 1.0), [2, 3, 1]).unwrap();
        let b = Mesh::block(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 3.0, 1.0),
            [1, 3, 1],
        )
        .unwrap();
        let mut m = a.merged(&b, 1e-9).unwrap();
        m.detect_columns();
        assert!(m.columns().is_empty());
        let fault = m.columns_fault().expect("a fault");
        assert!(fault.contains("element"), "{fault}");
    }
}
