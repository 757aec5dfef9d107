//! In-plane principal logarithmic strains of a sheet's mid-surface and its thickness, per
//! through-thickness node column ([`Mesh::columns`]).
//!
//! # Mathematics
//!
//! The mid-surface point of a column is the mean of its bottom and top nodes,
//! `M = (x_bottom + x_top) / 2` (reference `M0` from the reference positions). The
//! mid-surface is meshed by the bottom surface's quadrilaterals with each node replaced by
//! its column: the element faces whose 4 nodes are all at the bottom of their columns.
//!
//! At a corner `a` of such a quadrilateral, with the corners `b` after it and `d` before it,
//! the edge vectors `G1 = M0_b - M0_a`, `G2 = M0_d - M0_a` (reference) and `g1, g2`
//! (current) span the tangent plane. With the metrics `G_ij = G_i · G_j`, `g_ij = g_i · g_j`,
//! the squared principal stretches `μ = λ²` of the surface solve `det(g - μ G) = 0`: they
//! are the eigenvalues of `G⁻¹ g` (real and positive, `G` and `g` being positive definite),
//! and the principal logarithmic strains are `ε = ½ ln μ`, major `ε1 >= ε2` minor. Under a
//! homogeneous deformation the corner edges map exactly, so every corner gives the exact
//! strains whatever the mesh.
//!
//! A column's value is the mean of its corners' `ε1` and `ε2`, each corner weighted by its
//! reference parallelogram area `|G1 × G2|`. The thickness is the column's current length
//! (the polyline through its nodes, [`Mesh::column_thicknesses`]), `t0` its reference
//! length. Cost: O(elements + columns).

use crate::geometry::Vec3;
use crate::mesh::{Mesh, HEX_FACES};

/// Per column, in [`Mesh::columns`] order.
#[derive(Clone, Debug, Default)]
pub struct ColumnStrains {
    pub major: Vec<f64>,
    pub minor: Vec<f64>,
    /// Current thickness `t`.
    pub thickness: Vec<f64>,
    /// Reference thickness `t0`.
    pub initial_thickness: Vec<f64>,
}

/// The mid-surface quadrilaterals as column indices (module doc), in element order.
pub fn mid_surface_quads(mesh: &Mesh) -> Vec<[usize; 4]> {
    let mut column_of_bottom = vec![usize::MAX; mesh.nodes.len()];
    for (c, col) in mesh.columns().iter().enumerate() {
        if let Some(&b) = col.first() {
            column_of_bottom[b] = c;
        }
    }
    let mut quads = Vec::new();
    for hex in &mesh.hexes {
        for face in &HEX_FACES {
            let q = face.map(|i| column_of_bottom[hex[i]]);
            if q.iter().all(|&c| c != usize::MAX) {
                quads.push(q);
            }
        }
    }
    quads
}

/// Principal logarithmic strains `(ε1, ε2)`, `ε1 >= ε2`, of the surface element spanned by
/// `(big_g1, big_g2)` in the reference and `(g1, g2)` now (module doc).
///
/// The roots are the eigenvalues of `M = G⁻¹ g`, computed as `p ± sqrt(h²)` with
/// `p = tr M / 2` and `h² = ((M11 - M22) / 2)² + M12 M21`: under an equibiaxial stretch
/// `M` is a multiple of the identity and `h²` a sum of round-off-sized terms, where the
/// discriminant of the quadratic would lose half the digits.
pub fn principal_strains(big_g1: Vec3, big_g2: Vec3, g1: Vec3, g2: Vec3) -> (f64, f64) {
    let (a11, a12, a22) = (
        big_g1.dot(&big_g1),
        big_g1.dot(&big_g2),
        big_g2.dot(&big_g2),
    );
    let (b11, b12, b22) = (g1.dot(&g1), g1.dot(&g2), g2.dot(&g2));
    let det = a11 * a22 - a12 * a12;
    // M = G⁻¹ g with G⁻¹ = [[a22, -a12], [-a12, a11]] / det.
    let m11 = (a22 * b11 - a12 * b12) / det;
    let m12 = (a22 * b12 - a12 * b22) / det;
    let m21 = (a11 * b12 - a12 * b11) / det;
    let m22 = (a11 * b22 - a12 * b12) / det;
    let p = 0.5 * (m11 + m22);
    let h = (0.25 * (m11 - m22).powi(2) + m12 * m21).max(0.0).sqrt();
    (0.5 * (p + h).ln(), 0.5 * (p - h).ln())
}

/// The mid-surface strains and thickness of every column at displacement `u` (3 per node).
pub fn column_strains(mesh: &Mesh, u: &[f64]) -> ColumnStrains {
    let disp = |n: usize| Vec3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2]);
    let mid = |col: &Vec<usize>, moved: bool| {
        let (b, t) = (col[0], col[col.len() - 1]);
        let shift = |n| if moved { disp(n) } else { Vec3::zeros() };
        ((mesh.nodes[b] + shift(b)) + (mesh.nodes[t] + shift(t))) * 0.5
    };
    let cols = mesh.columns();
    let reference: Vec<Vec3> = cols.iter().map(|c| mid(c, false)).collect();
    let current: Vec<Vec3> = cols.iter().map(|c| mid(c, true)).collect();
    let (mut major, mut minor, mut weight) = (
        vec![0.0; cols.len()],
        vec![0.0; cols.len()],
        vec![0.0; cols.len()],
    );
    for q in mid_surface_quads(mesh) {
        for k in 0..4 {
            let (a, b, d) = (q[k], q[(k + 1) % 4], q[(k + 3) % 4]);
            let (big_g1, big_g2) = (reference[b] - reference[a], reference[d] - reference[a]);
            let (g1, g2) = (current[b] - current[a], current[d] - current[a]);
            let w = big_g1.cross(&big_g2).norm();
            let (e1, e2) = principal_strains(big_g1, big_g2, g1, g2);
            major[a] += w * e1;
            minor[a] += w * e2;
            weight[a] += w;
        }
    }
    for c in 0..cols.len() {
        if weight[c] > 0.0 {
            major[c] /= weight[c];
            minor[c] /= weight[c];
        }
    }
    ColumnStrains {
        major,
        minor,
        thickness: mesh.column_thicknesses(disp),
        initial_thickness: mesh.column_thicknesses(|_| Vec3::zeros()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A homogeneous in-plane stretch with shear and a rigid rotation: the strains are the
    /// logarithms of the stretches to round-off (1e-14: a few ulps of the metrics).
    #[test]
    fn principal_strains_of_a_rotated_stretch() {
        let (l1, l2) = (1.3_f64, 0.8_f64);
        let (c, s) = (0.6_f64, 0.8_f64);
        // Stretch along axes rotated by theta in the plane, then a rigid rotation about x.
        let stretch = |v: Vec3| {
            let (p, q) = (c * v.x + s * v.y, -s * v.x + c * v.y);
            let (p, q) = (l1 * p, l2 * q);
            let w = Vec3::new(c * p - s * q, s * p + c * q, 0.0);
            Vec3::new(w.x, 0.6 * w.y - 0.8 * w.z, 0.8 * w.y + 0.6 * w.z)
        };
        let (big_g1, big_g2) = (Vec3::new(1.0, 0.2, 0.0), Vec3::new(-0.3, 0.7, 0.0));
        let (e1, e2) = principal_strains(big_g1, big_g2, stretch(big_g1), stretch(big_g2));
        assert!((e1 - l1.ln()).abs() < 1e-14, "{e1}");
        assert!((e2 - l2.ln()).abs() < 1e-14, "{e2}");
    }

    #[test]
    fn block_mid_surface_has_one_quad_per_bottom_face() {
        let m = Mesh::block(Vec3::zeros(), Vec3::new(3.0, 2.0, 1.0), [3, 2, 2]).unwrap();
        assert_eq!(mid_surface_quads(&m).len(), 6);
        let s = column_strains(&m, &vec![0.0; 3 * m.node_count()]);
        assert!(s.major.iter().chain(&s.minor).all(|e| *e == 0.0));
        assert!(s.thickness.iter().all(|t| (t - 1.0).abs() < 1e-15));
    }
}
