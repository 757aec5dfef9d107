//! Named element sets and face sets of a mesh (imported meshes bring them: Gmsh physical
//! groups, `*ELSET` and `*SURFACE` of a CalculiX/Abaqus deck). Node sets live in
//! [`Mesh`] itself, since every boundary condition and contact pairing names one.

use std::collections::{BTreeMap, HashMap};

use super::{Mesh, HEX_FACES};
use crate::{Error, Result};

/// Element sets (element indices, sorted, no duplicates) and face sets (element faces as
/// global node quads, counter-clockwise seen from outside the element: [`HEX_FACES`]).
#[derive(Clone, Debug, Default)]
pub(super) struct Sets {
    elements: BTreeMap<String, Vec<usize>>,
    faces: BTreeMap<String, Vec<[usize; 4]>>,
}

fn unknown(kind: &str, name: &str, known: impl Iterator<Item = String>) -> Error {
    let known: Vec<String> = known.collect();
    Error::input(
        kind,
        format!("{name:?}"),
        &format!("is unknown; known {kind}s: {}", known.join(", ")),
    )
}

impl Mesh {
    /// The element set called `name` (sorted ascending, no duplicates).
    pub fn element_set(&self, name: &str) -> Result<&[usize]> {
        self.sets
            .elements
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| unknown("element set", name, self.sets.elements.keys().cloned()))
    }

    /// Names of all element sets, in alphabetical order.
    pub fn element_set_names(&self) -> impl Iterator<Item = &str> {
        self.sets.elements.keys().map(String::as_str)
    }

    /// Adds (or replaces) the element set `name`; sorted, duplicates removed. An element
    /// index out of range or an empty name is an error.
    pub fn add_element_set(&mut self, name: &str, mut elements: Vec<usize>) -> Result<()> {
        if name.is_empty() {
            return Err(Error::input(
                "element set name",
                "\"\"",
                "must not be empty",
            ));
        }
        if let Some(&bad) = elements.iter().find(|&&e| e >= self.hexes.len()) {
            return Err(Error::input(
                &format!("element index in element set {name:?}"),
                bad,
                &format!("must be < {} (the number of elements)", self.hexes.len()),
            ));
        }
        elements.sort_unstable();
        elements.dedup();
        self.sets.elements.insert(name.to_string(), elements);
        Ok(())
    }

    /// The face set called `name`: element faces as global node indices, counter-clockwise
    /// seen from outside their element.
    pub fn face_set(&self, name: &str) -> Result<&[[usize; 4]]> {
        self.sets
            .faces
            .get(name)
            .map(Vec::as_slice)
            .ok_or_else(|| unknown("face set", name, self.sets.faces.keys().cloned()))
    }

    /// Names of all face sets, in alphabetical order.
    pub fn face_set_names(&self) -> impl Iterator<Item = &str> {
        self.sets.faces.keys().map(String::as_str)
    }

    /// Adds (or replaces) the face set `name` from `(element, local face)` pairs, the local
    /// face an index into [`HEX_FACES`]; a face listed twice is kept once.
    pub fn add_face_set(&mut self, name: &str, faces: &[(usize, usize)]) -> Result<()> {
        if name.is_empty() {
            return Err(Error::input("face set name", "\"\"", "must not be empty"));
        }
        let mut quads = Vec::with_capacity(faces.len());
        for &(e, f) in faces {
            let hex = self.hexes.get(e).ok_or_else(|| {
                Error::input(
                    &format!("element of face set {name:?}"),
                    e,
                    &format!("must be < {} (the number of elements)", self.hexes.len()),
                )
            })?;
            let local = HEX_FACES.get(f).ok_or_else(|| {
                Error::input(
                    &format!("local face of face set {name:?}"),
                    f,
                    "must be < 6",
                )
            })?;
            quads.push(local.map(|i| hex[i]));
        }
        let mut seen = std::collections::HashSet::new();
        quads.retain(|q| seen.insert(*q));
        self.sets.faces.insert(name.to_string(), quads);
        Ok(())
    }

    /// Every element face by its sorted node quadruple: `(element, local face)`, the first
    /// element met for an interior face. Cost O(elements).
    pub fn faces_by_nodes(&self) -> HashMap<[usize; 4], (usize, usize)> {
        let mut map = HashMap::with_capacity(6 * self.hexes.len());
        for (e, hex) in self.hexes.iter().enumerate() {
            for (f, local) in HEX_FACES.iter().enumerate() {
                let mut key = local.map(|i| hex[i]);
                key.sort_unstable();
                map.entry(key).or_insert((e, f));
            }
        }
        map
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    #[test]
    fn element_and_face_sets() {
        let mut m = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 1.0, 1.0), [2, 1, 1]).unwrap();
        m.add_element_set("right", vec![1, 1]).unwrap();
        assert_eq!(m.element_set("right").unwrap(), &[1]);
        assert!(m.add_element_set("bad", vec![2]).is_err());
        let e = m.element_set("left").unwrap_err().to_string();
        assert!(e.contains("known element sets: right"), "{e}");

        // The top faces (local face 5, zeta = +1) of both elements: outward normal +z.
        m.add_face_set("top", &[(0, 5), (1, 5), (0, 5)]).unwrap();
        let top = m.face_set("top").unwrap().to_vec();
        assert_eq!(top.len(), 2);
        for q in &top {
            let x = q.map(|n| m.nodes[n]);
            let normal = (x[1] - x[0]).cross(&(x[3] - x[0]));
            assert!(normal.z > 0.0 && x.iter().all(|p| p.z == 1.0));
        }
        assert!(m.add_face_set("bad", &[(0, 6)]).is_err());
        let by_nodes = m.faces_by_nodes();
        // 2 elements x 6 faces, one shared.
        assert_eq!(by_nodes.len(), 11);
        let mut key = top[1];
        key.sort_unstable();
        assert_eq!(by_nodes[&key], (1, 5));
    }
}
