//! Follower face tractions, and the end moment made of one: a traction on boundary faces
//! that acts along their *current* outward normal, with a magnitude linear in the
//! reference coordinates,
//!
//! ```text
//! p(X, t) = s(t) g · (X - X₀)      (force per unit current area),
//! f_a = ∫ N_a p n da = ∫∫ N_a(ξ, η) p(X(ξ, η)) (x_ξ × x_η) dξ dη      (2 x 2 Gauss per face),
//! ```
//!
//! `x = X + u` the bilinear face in the current configuration, `N_a` its shape functions.
//! The load stiffness (non-symmetric) follows from `∂(x_ξ × x_η)/∂x_b = N_b,η [x_ξ]× -
//! N_b,ξ [x_η]×` (`[v]×` the cross-product matrix): `∂f_a/∂x_b = ∫∫ N_a p (N_b,η [x_ξ]× -
//! N_b,ξ [x_η]×) dξ dη`. Cost: 4 points per face, a 12 x 12 block per face.
//!
//! [`FollowerTraction::end_moment`] (through `Model::add_end_moment`): `g = (M / I) d`, `X₀` the centroid of the faces and `I =
//! ∫ ((X - X₀)·d)² dA` over them (reference), so that the resultant force is zero and the
//! resultant moment `∫ p (X - X₀)·d dA = M` about the axis `d × n`, in the reference
//! configuration; the distribution turns with the face, as a bending moment at the end
//! of a beam does (the roll-up of a cantilever into a circle).

use crate::geometry::{Mat3, Vec3};
use crate::mesh::Mesh;
use crate::tool::ScalarSchedule;
use crate::{Error, Result};

/// Gauss abscissa of the 2 x 2 face rule (weights 1).
const G: f64 = 0.577_350_269_189_625_8;
const FACE_POINTS: [[f64; 2]; 4] = [[-G, -G], [G, -G], [G, G], [-G, G]];
const CORNERS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// A follower traction; see the module docs.
#[derive(Clone, Debug)]
pub struct FollowerTraction {
    pub label: String,
    /// Boundary faces, counter-clockwise seen from outside ([`Mesh::faces_within`]).
    pub faces: Vec<[usize; 4]>,
    /// `X₀`.
    pub origin: Vec3,
    /// `g`: the traction per unit current area grows by `g · dX` (at scale 1).
    pub gradient: Vec3,
    pub scale: ScalarSchedule,
}

/// Shape functions and their `(ξ, η)` derivatives of the bilinear face at `(s, t)`.
fn face_shape(s: f64, t: f64) -> ([f64; 4], [[f64; 2]; 4]) {
    let mut n = [0.0; 4];
    let mut dn = [[0.0; 2]; 4];
    for (a, [sa, ta]) in CORNERS.iter().enumerate() {
        n[a] = 0.25 * (1.0 + sa * s) * (1.0 + ta * t);
        dn[a] = [0.25 * sa * (1.0 + ta * t), 0.25 * ta * (1.0 + sa * s)];
    }
    (n, dn)
}

fn cross_matrix(v: &Vec3) -> Mat3 {
    Mat3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

impl FollowerTraction {
    /// Adds the nodal forces at displacements `u` (3 per node, first in the unknowns) and
    /// time `t` to `f`, and, when `stiffness` is given, the load stiffness `∂f/∂u` through
    /// `stiffness(row, column, value)` (dof indices `3 node + component`).
    pub fn add_forces(
        &self,
        mesh: &Mesh,
        u: &[f64],
        t: f64,
        f: &mut [f64],
        mut stiffness: Option<&mut dyn FnMut(usize, usize, f64)>,
    ) {
        let s = self.scale.value(t);
        if s == 0.0 {
            return;
        }
        for face in &self.faces {
            let reference = face.map(|n| mesh.nodes[n]);
            let current: [Vec3; 4] = std::array::from_fn(|a| {
                let n = face[a];
                reference[a] + Vec3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2])
            });
            let mut k = [[Mat3::zeros(); 4]; 4];
            for [xi, eta] in FACE_POINTS {
                let (n, dn) = face_shape(xi, eta);
                let mut x_ref = Vec3::zeros();
                let (mut x_xi, mut x_eta) = (Vec3::zeros(), Vec3::zeros());
                for a in 0..4 {
                    x_ref += reference[a] * n[a];
                    x_xi += current[a] * dn[a][0];
                    x_eta += current[a] * dn[a][1];
                }
                let p = s * self.gradient.dot(&(x_ref - self.origin));
                let area_vector = x_xi.cross(&x_eta);
                for a in 0..4 {
                    let fa = area_vector * (n[a] * p);
                    for i in 0..3 {
                        f[3 * face[a] + i] += fa[i];
                    }
                }
                if stiffness.is_some() {
                    let (c_xi, c_eta) = (cross_matrix(&x_xi), cross_matrix(&x_eta));
                    for b in 0..4 {
                        let d = c_xi * dn[b][1] - c_eta * dn[b][0];
                        for a in 0..4 {
                            k[a][b] += d * (n[a] * p);
                        }
                    }
                }
            }
            if let Some(add) = stiffness.as_mut() {
                for a in 0..4 {
                    for b in 0..4 {
                        for i in 0..3 {
                            for j in 0..3 {
                                add(3 * face[a] + i, 3 * face[b] + j, k[a][b][(i, j)]);
                            }
                        }
                    }
                }
            }
        }
    }
}

impl FollowerTraction {
    /// A follower bending moment `moment · scale(t)` on the boundary faces of `mesh` within
    /// `nodes`, the node set `set` (an end face of a beam or strip): the traction
    /// `p = M y / I` along the current face normal, `y = (X - X₀)·d` the reference
    /// coordinate along the unit vector `direction` (the thickness direction) from the
    /// faces' centroid, `I = ∫ y² dA`. See the module docs. Errors: a set with no boundary
    /// face, a zero `I` (`direction` along the face normal), a non-finite moment or
    /// direction.
    pub fn end_moment(
        mesh: &Mesh,
        set: &str,
        nodes: &[usize],
        moment: f64,
        direction: Vec3,
        scale: ScalarSchedule,
    ) -> Result<FollowerTraction> {
        let faces = mesh.faces_within(nodes)?;
        if faces.is_empty() {
            return Err(Error::Input(format!(
                "end moment on node set '{set}': the set holds no boundary face"
            )));
        }
        if !(moment.is_finite() && direction.iter().all(|v| v.is_finite()))
            || direction.norm() == 0.0
        {
            return Err(Error::input(
                &format!("end moment on node set '{set}'"),
                format!("moment {moment}, direction {direction:?}"),
                "must be finite, with a non-zero direction",
            ));
        }
        let d = direction.normalize();
        // Area, first and second moments with the face rule (exact for plane faces).
        let quadrature = |f: &dyn Fn(Vec3) -> f64| -> f64 {
            let mut sum = 0.0;
            for face in &faces {
                let x = face.map(|n| mesh.nodes[n]);
                for [xi, eta] in FACE_POINTS {
                    let (n, dn) = face_shape(xi, eta);
                    let (mut p, mut a, mut b) = (Vec3::zeros(), Vec3::zeros(), Vec3::zeros());
                    for k in 0..4 {
                        p += x[k] * n[k];
                        a += x[k] * dn[k][0];
                        b += x[k] * dn[k][1];
                    }
                    sum += f(p) * a.cross(&b).norm();
                }
            }
            sum
        };
        let area = quadrature(&|_| 1.0);
        let origin = Vec3::new(
            quadrature(&|p| p.x),
            quadrature(&|p| p.y),
            quadrature(&|p| p.z),
        ) / area;
        let inertia = quadrature(&|p| (p - origin).dot(&d).powi(2));
        if !(inertia > 1e-14 * area * area) {
            return Err(Error::input(
                &format!(
                    "end moment on node set '{set}': second moment of area along the direction"
                ),
                inertia,
                "must be > 0 (is the direction in the plane of the face?)",
            ));
        }
        Ok(FollowerTraction {
            label: format!("end moment on {set}"),
            faces,
            origin,
            gradient: d * (moment / inertia),
            scale,
        })
    }
}
