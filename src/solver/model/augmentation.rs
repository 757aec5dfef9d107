//! Default augmentation (or penalty) parameter r of each contact node, from the body's
//! stiffness and the element size, so that a user tunes no magic number.
//!
//! The augmented multiplier `sigma = lambda + r g` adds a force and a gap. Its solution does
//! not depend on r, Newton's path does: the status of a node (gap, stick, slip) follows the
//! sign of `sigma_n`, so with r far above the stiffness that actually resists the node's
//! motion a gap error of round-off size flips the status of a barely touching node, and the
//! active-set search chatters; with r far below it the multiplier rows dominate and the gap
//! closes slowly. The scale is the membrane stiffness of the layer under the node, shared
//! out by tributary area:
//!
//! ```text
//! k_a = E * sum over contact faces f at a of  (A_{a,f} / A_f) h_f,   h_f = V_e / A_f
//! ```
//!
//! with `E` Young's modulus (from the elastic tangent), `A_{a,f} = A_f / 4` the node's share
//! of face f and `h_f` the height of the face's element normal to it (element volume over
//! face area): `E t` at an interior node of a sheet of one layer of thickness t, half at
//! an edge node, a quarter at a corner, `E h` on a block of cubes of side h. A candidate on
//! no contact face (a lone node) gets `E V_e^(1/3)` from its elements. Cost O(elements).
//!
//! Under the augmented Lagrangian the default r is a fraction of it, the setting
//! `r_fraction` (`MEMBRANE_FRACTION`, a tenth, by default; `0.1 E h` on a block of cubes is
//! GetFEM's customary choice); under penalty, where r is the penalty stiffness and sets the
//! penetration `p / r`, it is `k_a` itself. Why a tenth: a tool pressing a sheet is resisted
//! by the sheet's bending more than by its membrane, and the barely touching nodes of a
//! sheet wrapping a radius flip their status on gaps of `lambda / r`. Measured
//! (docs/history/benchmarks.md, "Default r a tenth of the membrane stiffness"): the U-channel
//! (tests/scenes) is cut back 8 and 7 times instead of 30 and 34, the 25 x 25 x 1 cups take
//! 304 and 436 Newton iterations instead of 432 and 522 with no cutback, at the same
//! converged answers. The first default, the column stiffness `M A / h` (M the P-wave
//! modulus), was about 200 times the present one on the cup's cells and made the
//! active-set search oscillate (docs/history/benchmarks.md, issue 14).

use crate::element::{Element, Hex8};
use crate::material::Tangent;
use crate::mesh::{quad_area, Mesh, HEX_FACES};
use crate::Result;
use std::collections::HashMap;

/// Young's modulus of an isotropic elastic tangent (Voigt order xx, yy, zz, ...):
/// `E = mu (3 lambda + 2 mu) / (lambda + mu)` with `lambda = C_01`, `mu = (C_00 - C_01) / 2`.
pub fn young_modulus(c: &Tangent) -> f64 {
    let lambda = c[(0, 1)];
    let mu = 0.5 * (c[(0, 0)] - c[(0, 1)]);
    mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu)
}

/// The default fraction of the membrane stiffness under a node that is its r under the
/// augmented Lagrangian, the setting `r_fraction` (module doc); kept with the settings.
pub use crate::solver::settings::MEMBRANE_FRACTION;

/// The membrane stiffness `k_a` per candidate (same order as `candidates`), for Young's
/// modulus `young`: the default penalty stiffness, and `1 / MEMBRANE_FRACTION` times the
/// default augmentation parameter.
pub fn membrane_stiffness(mesh: &Mesh, young: f64, candidates: &[usize]) -> Result<Vec<f64>> {
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
                    r[n] += young * 0.25 * height;
                }
            }
        }
    }
    Ok(candidates
        .iter()
        .map(|&n| if r[n] > 0.0 { r[n] } else { young * lone[n] })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;
    use crate::material::{LinearElastic, Material};

    #[test]
    fn membrane_stiffness_on_cubes_and_on_a_sheet() {
        // Cubes of side 0.5: E h at interior face nodes, E h / 2 at edges, E h / 4 at corners.
        let mesh = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 2.0, 1.0), [4, 4, 2]).unwrap();
        let top = mesh.node_set("z+").unwrap().to_vec();
        let r = membrane_stiffness(&mesh, 10.0, &top).unwrap();
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
        // A sheet of one layer 0.1 thick on 0.5 x 0.5 cells: E t at interior nodes whatever
        // the cell size.
        let thin = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 2.0, 0.1), [4, 4, 1]).unwrap();
        let top = thin.node_set("z+").unwrap().to_vec();
        let r = membrane_stiffness(&thin, 10.0, &top).unwrap();
        let max = r.iter().cloned().fold(0.0, f64::max);
        assert!((max - 1.0).abs() < 1e-12, "{max}");
        // A lone node: E times the cube root of its element's volume.
        let r = membrane_stiffness(&mesh, 10.0, &[0]).unwrap();
        assert!((r[0] - 10.0 * 0.125f64.cbrt()).abs() < 1e-12);
    }

    #[test]
    fn young_modulus_from_the_elastic_tangent() {
        let m = LinearElastic::new(210e3, 0.3).unwrap();
        let e = young_modulus(&m.elastic_tangent());
        // Round-off of lambda and mu formed from E and nu.
        assert!((e - 210e3).abs() < 1e-9 * 210e3, "{e}");
    }
}
