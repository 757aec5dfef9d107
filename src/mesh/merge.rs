//! Merging two meshes that share a face: the nodes of the second mesh that coincide with
//! nodes of the first (within a tolerance) become those nodes, so the shared face turns
//! interior.
//!
//! Coincidence is found with a hash of positions quantised to cells of the tolerance's
//! size, looking in the 27 neighbouring cells: O(n) expected. Sets of the same name are
//! united (node, element and face sets). The through-thickness columns of the result are
//! found from its topology ([`Mesh::detect_columns`]): two sheets side by side or stacked
//! through the thickness are one sheet; a result that is no sheet has none. The meshes must
//! conform on the shared face: a node of one lying on a face of the other without a twin
//! (a hanging node) is not detected here.

use std::collections::HashMap;

use super::Mesh;
use crate::geometry::Vec3;
use crate::{Error, Result};

impl Mesh {
    /// `self` and `other` as one mesh, with the nodes of `other` closer than `tolerance`
    /// to a node of `self` merged into it. Errors: `tolerance` not finite and > 0, no node
    /// shared (the meshes do not touch), two nodes of `self` within the tolerance of one
    /// node of `other` (the tolerance is larger than the mesh size).
    pub fn merged(&self, other: &Mesh, tolerance: f64) -> Result<Mesh> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(Error::input(
                "merge tolerance",
                tolerance,
                "must be finite and > 0",
            ));
        }
        let cell = |x: &Vec3| x.map(|c| (c / tolerance).floor() as i64);
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, x) in self.nodes.iter().enumerate() {
            let c = cell(x);
            grid.entry([c.x, c.y, c.z]).or_default().push(i);
        }
        let mut nodes = self.nodes.clone();
        let mut map = Vec::with_capacity(other.nodes.len());
        let mut shared = 0;
        for (j, x) in other.nodes.iter().enumerate() {
            let c = cell(x);
            let mut twins = Vec::new();
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(list) = grid.get(&[c.x + dx, c.y + dy, c.z + dz]) {
                            twins.extend(
                                list.iter()
                                    .copied()
                                    .filter(|&i| (self.nodes[i] - x).norm() < tolerance),
                            );
                        }
                    }
                }
            }
            match twins.as_slice() {
                [] => {
                    map.push(nodes.len());
                    nodes.push(*x);
                }
                [i] => {
                    map.push(*i);
                    shared += 1;
                }
                _ => {
                    return Err(Error::input(
                        "merge tolerance",
                        tolerance,
                        &format!(
                            "must be smaller than the node spacing: node {j} of the second mesh \
                             is within it of {} nodes of the first",
                            twins.len()
                        ),
                    ))
                }
            }
        }
        if shared == 0 {
            return Err(Error::Input(
                "merge: the two meshes share no node (within the tolerance); they must share a face"
                    .to_string(),
            ));
        }
        let offset = self.hexes.len();
        let mut hexes = self.hexes.clone();
        hexes.extend(other.hexes.iter().map(|h| h.map(|n| map[n])));
        let mut mesh = Mesh {
            nodes,
            hexes,
            node_sets: self.node_sets.clone(),
            columns: Vec::new(),
            columns_fault: None,
            sets: self.sets.clone(),
        };
        mesh.validate()?;
        for name in other.node_set_names() {
            let mut set: Vec<usize> = other.node_set(name)?.iter().map(|&n| map[n]).collect();
            if let Ok(mine) = self.node_set(name) {
                set.extend(mine);
            }
            mesh.add_node_set(name, set)?;
        }
        for name in other.element_set_names() {
            let mut set: Vec<usize> = other
                .element_set(name)?
                .iter()
                .map(|&e| e + offset)
                .collect();
            if let Ok(mine) = self.element_set(name) {
                set.extend(mine);
            }
            mesh.add_element_set(name, set)?;
        }
        let by_nodes = mesh.faces_by_nodes();
        for name in other.face_set_names() {
            let mut pairs = Vec::new();
            let quads = other.face_set(name)?.iter().map(|q| q.map(|n| map[n]));
            let own = self.face_set(name).map(|s| s.to_vec()).unwrap_or_default();
            for q in own.into_iter().chain(quads) {
                let mut key = q;
                key.sort_unstable();
                pairs.push(by_nodes[&key]);
            }
            mesh.add_face_set(name, &pairs)?;
        }
        mesh.detect_columns();
        Ok(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_blocks_sharing_a_face_are_one_block() {
        let left = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 0.5), [2, 2, 1]).unwrap();
        let right = Mesh::block(
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.5),
            [3, 2, 1],
        )
        .unwrap();
        let both = left.merged(&right, 1e-9).unwrap();
        let whole = Mesh::block(Vec3::zeros(), Vec3::new(3.0, 1.0, 0.5), [5, 2, 1]).unwrap();
        assert_eq!(both.node_count(), whole.node_count());
        assert_eq!(both.element_count(), whole.element_count());
        // The shared face is interior: the boundary is the whole block's.
        assert_eq!(both.boundary_faces().len(), whole.boundary_faces().len());
        // "z+" is the union of both tops; "x+" of the left block is now interior but kept.
        assert_eq!(
            both.node_set("z+").unwrap().len(),
            whole.node_set("z+").unwrap().len()
        );
        assert_eq!(both.columns().len(), 6 * 3);
        assert!(left
            .merged(&right, 0.6)
            .unwrap_err()
            .to_string()
            .contains("smaller"));
        let far = Mesh::block(
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.5),
            [1, 1, 1],
        )
        .unwrap();
        assert!(left
            .merged(&far, 1e-9)
            .unwrap_err()
            .to_string()
            .contains("share no node"));
    }
}
