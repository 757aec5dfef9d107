//! Default augmentation (or penalty) parameter r of each contact node, from the body's
//! stiffness and the element size, so that a user tunes no magic number.
//!
//! The augmented multiplier `sigma = lambda + r g` adds a force and a gap; it weighs them
//! alike when r is the stiffness with which the body resists moving the node normal to its
//! surface, i.e. the size of the node's diagonal entry of K. For a node on the contact
//! surface that is
//!
//! ```text
//! r_a = M * sum over contact faces f at a of  A_{a,f} / h_f,   h_f = V_e / A_f
//! ```
//!
//! with `M = lambda + 2 mu` the P-wave modulus (first diagonal entry of the elastic tangent),
//! `A_{a,f} = A_f / 4` the node's share of face f and `h_f` the height of the face's element
//! normal to it (element volume over face area): the stiffness `M A / h` of the column of
//! material under the node. On a mesh of cubes of side h this is `M h` at an interior face
//! node (the former default `M sqrt(A)`), and on flat elements of thickness t and width L it
//! is `M L^2 / t`, which `M sqrt(A) = M L` underestimates by L / t. A candidate on no contact
//! face (a lone node) gets `M V_e^(1/3)` from its elements. Cost O(elements).

use crate::element::{Element, Hex8};
use crate::mesh::{quad_area, Mesh, HEX_FACES};
use crate::Result;
use std::collections::HashMap;

/// r per candidate (same order as `candidates`), for P-wave modulus `modulus`.
pub fn default_r(mesh: &Mesh, modulus: f64, candidates: &[usize]) -> Result<Vec<f64>> {
    let key = |f: &[usize; 4]| {
        let mut k = *f;
        k.sort_unstable();
        k
    };
    let faces: HashMap<[usize; 4], [usize; 4]> = mesh
        .faces_within(candidates)?
        .into_iter()
        .map(|f| (key(&f), f))
        .collect();
    let mut r = vec![0.0; mesh.nodes.len()];
    let mut lone = vec![f64::INFINITY; mesh.nodes.len()];
    for (e, hex) in mesh.hexes.iter().enumerate() {
        let volume = Hex8.volume(&mesh.hex_coordinates(e))?;
        for &n in hex {
            lone[n] = lone[n].min(volume.cbrt());
        }
        for lf in &HEX_FACES {
            let f = lf.map(|i| hex[i]);
            if let Some(face) = faces.get(&key(&f)) {
                let area = quad_area(&face.map(|n| mesh.nodes[n]));
                let height = volume / area;
                for &n in face {
                    r[n] += modulus * 0.25 * area / height;
                }
            }
        }
    }
    Ok(candidates
        .iter()
        .map(|&n| if r[n] > 0.0 { r[n] } else { modulus * lone[n] })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    #[test]
    fn column_stiffness_on_cubes_and_on_flat_elements() {
        // Cubes of side 0.5: M h at interior face nodes, M h / 2 at edges, M h / 4 at corners.
        let mesh = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 2.0, 1.0), [4, 4, 2]).unwrap();
        let top = mesh.node_set("z+").unwrap().to_vec();
        let r = default_r(&mesh, 10.0, &top).unwrap();
        let at = |x: f64, y: f64| {
            let k = top
                .iter()
                .position(|&n| (mesh.nodes[n] - Vec3::new(x, y, 1.0)).norm() < 1e-12)
                .unwrap();
            r[k]
        };
        // Exact for parallelepiped elements up to round-off.
        assert!((at(1.0, 1.0) - 5.0).abs() < 1e-12);
        assert!((at(0.0, 1.0) - 2.5).abs() < 1e-12);
        assert!((at(0.0, 0.0) - 1.25).abs() < 1e-12);
        // Flat elements 0.5 x 0.5 x 0.05: M A / t = 10 * 0.25 / 0.05 at interior nodes,
        // ten times the cube value, as the stiffness of the thin layer.
        let thin = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 2.0, 0.1), [4, 4, 2]).unwrap();
        let top = thin.node_set("z+").unwrap().to_vec();
        let r = default_r(&thin, 10.0, &top).unwrap();
        let max = r.iter().cloned().fold(0.0, f64::max);
        assert!((max - 50.0).abs() < 1e-9, "{max}");
        // A lone node: M times the cube root of its element's volume.
        let r = default_r(&mesh, 10.0, &[0]).unwrap();
        assert!((r[0] - 10.0 * 0.125f64.cbrt()).abs() < 1e-12);
    }
}
