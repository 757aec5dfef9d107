//! The 8-node trilinear hexahedron with selective reduced integration (B-bar).
//!
//! # Interpolation
//!
//! `N_a(ξ, η, ζ) = ⅛ (1 + ξ ξ_a)(1 + η η_a)(1 + ζ ζ_a)` with `(ξ_a, η_a, ζ_a)` the
//! natural coordinates of corner `a` ([`HEX_CORNERS`], VTK_HEXAHEDRON order). The
//! Jacobian is `J = ∂x/∂ξ = Σ_a x_a ⊗ ∂N_a/∂ξ` and the spatial gradients
//! `∇N_a = J⁻ᵀ ∂N_a/∂ξ`.
//!
//! # B-bar (selective reduced integration of the volumetric strain)
//!
//! A fully integrated trilinear hexahedron locks when the material is (nearly)
//! incompressible, as in plastic flow: the 8 Gauss points impose too many
//! incompressibility constraints. The B-bar method (Hughes 1980) keeps the deviatoric
//! strain at the 2x2x2 Gauss points and replaces the volumetric strain by its element
//! average (mean dilatation), i.e. one volumetric constraint per element.
//!
//! With Voigt strains `ε = [εxx, εyy, εzz, γxy, γyz, γzx]` (engineering shear) and
//! `b_a = ∇N_a`, the standard strain-displacement block of node `a` is
//!
//! ```text
//!       | b_x  0    0   |
//!       | 0    b_y  0   |
//! B_a = | 0    0    b_z |        ε = Σ_a B_a u_a,
//!       | b_y  b_x  0   |
//!       | 0    b_z  b_y |
//!       | b_z  0    b_x |
//! ```
//!
//! Its volumetric part is `B_a^vol = ⅓ m b_aᵀ` with `m = [1,1,1,0,0,0]ᵀ` (the trace of
//! the strain, `tr ε = Σ_a b_a·u_a`, spread equally on the three normal components). B-bar
//! swaps it for the volume average `b̄_a = (1/V_e) ∫_e ∇N_a dV`:
//!
//! ```text
//! B̄_a = B_a - ⅓ m b_aᵀ + ⅓ m b̄_aᵀ = B_a + ⅓ m (b̄_a - b_a)ᵀ.
//! ```
//!
//! So the deviatoric strain at each Gauss point is exact and `tr ε̄` is the same at all 8
//! points: `(1/V_e) ∫ tr ε dV`. Then `f_int = Σ_g B̄_gᵀ σ_g w_g det J_g` and
//! `K = Σ_g B̄_gᵀ D_g B̄_g w_g det J_g`, which is the exact derivative of `f_int` because
//! `B̄` does not depend on `u` (small strain) and `D_g = ∂σ_g/∂ε̄_g` is the material's
//! consistent tangent. The element passes the patch test (a linear displacement field is
//! reproduced exactly: both `B` and `B̄` give its constant strain) and its stiffness has
//! exactly the 6 rigid-body zero-energy modes (no hourglass modes, since the deviatoric
//! part is fully integrated).

use nalgebra::{SMatrix, SVector};

use super::{prefix, Element, ElementResponse};
use crate::geometry::{Mat3, Vec3};
use crate::material::{Kinematics, Material, PointState};
use crate::mesh::HEX_CORNERS;
use crate::{Error, Result};

/// Nodes per element.
pub const NODES: usize = 8;
/// Degrees of freedom per element.
pub const DOFS: usize = 24;
/// Integration points per element (2x2x2 Gauss rule).
pub const POINTS: usize = 8;

/// 1/√3, the abscissa of the 2-point Gauss rule (weights 1).
const GAUSS: f64 = 0.577_350_269_189_625_8;

/// Strain-displacement matrix of the element, one 6x24 block per integration point.
pub type StrainDisplacement = SMatrix<f64, 6, DOFS>;

/// Shape functions `N_a` at the natural coordinates `xi`.
pub fn shape_functions(xi: &Vec3) -> [f64; NODES] {
    std::array::from_fn(|a| {
        let c = HEX_CORNERS[a];
        0.125 * (1.0 + c[0] * xi.x) * (1.0 + c[1] * xi.y) * (1.0 + c[2] * xi.z)
    })
}

/// Natural derivatives `∂N_a/∂(ξ, η, ζ)` at the natural coordinates `xi`.
pub fn shape_derivatives(xi: &Vec3) -> [Vec3; NODES] {
    std::array::from_fn(|a| {
        let c = HEX_CORNERS[a];
        let (f0, f1, f2) = (1.0 + c[0] * xi.x, 1.0 + c[1] * xi.y, 1.0 + c[2] * xi.z);
        0.125 * Vec3::new(c[0] * f1 * f2, c[1] * f0 * f2, c[2] * f0 * f1)
    })
}

/// Natural coordinates of the integration points: point `g` is `HEX_CORNERS[g] / √3`, the
/// Gauss point nearest to node `g` (handy for extrapolating to nodes). All weights are 1.
pub fn integration_points() -> [Vec3; POINTS] {
    std::array::from_fn(|g| {
        let c = HEX_CORNERS[g];
        Vec3::new(c[0], c[1], c[2]) * GAUSS
    })
}

/// Jacobian `J = ∂x/∂ξ = Σ_a x_a ⊗ ∂N_a/∂ξ` of the trilinear map of `x` at `xi`.
pub fn jacobian(x: &[Vec3; NODES], xi: &Vec3) -> Mat3 {
    shape_derivatives(xi)
        .iter()
        .zip(x)
        .fold(Mat3::zeros(), |j, (dn, xa)| j + xa * dn.transpose())
}

/// Reference-configuration geometry of one element at its integration points.
pub(super) struct Geometry {
    /// Spatial gradients `∇N_a` at each integration point, `grad[g][a]`.
    pub(super) grad: [[Vec3; NODES]; POINTS],
    /// Volume weights `w_g det J_g` (the weights are 1).
    pub(super) dvol: [f64; POINTS],
    /// Volume-averaged gradients `b̄_a = (1/V) Σ_g ∇N_a(g) dvol[g]`.
    mean_grad: [Vec3; NODES],
}

impl Geometry {
    /// Errors if `det J` is not positive (or not finite) at an integration point.
    pub(super) fn new(x: &[Vec3; NODES]) -> Result<Geometry> {
        let mut grad = [[Vec3::zeros(); NODES]; POINTS];
        let mut dvol = [0.0; POINTS];
        for (g, xi) in integration_points().iter().enumerate() {
            let j = jacobian(x, xi);
            let det = j.determinant();
            // `!(det > 0)` also catches NaN from non-finite coordinates.
            let inv_t = match j.try_inverse() {
                Some(inv) if det > 0.0 && det.is_finite() => inv.transpose(),
                _ => {
                    return Err(Error::input(
                        &format!("Jacobian determinant at integration point {g}"),
                        det,
                        "must be > 0 (inverted or degenerate element)",
                    ))
                }
            };
            for (a, dn) in shape_derivatives(xi).iter().enumerate() {
                grad[g][a] = inv_t * dn;
            }
            dvol[g] = det;
        }
        let volume: f64 = dvol.iter().sum();
        let mean_grad = std::array::from_fn(|a| {
            (0..POINTS).map(|g| grad[g][a] * dvol[g]).sum::<Vec3>() / volume
        });
        Ok(Geometry {
            grad,
            dvol,
            mean_grad,
        })
    }

    /// `B̄` at integration point `g` (see the module documentation).
    fn bbar(&self, g: usize) -> StrainDisplacement {
        let mut b = StrainDisplacement::zeros();
        for a in 0..NODES {
            let n = self.grad[g][a];
            let dv = (self.mean_grad[a] - n) / 3.0;
            let c = 3 * a;
            // Normal rows: standard B_a plus the volumetric correction ⅓ (b̄_a - b_a)ᵀ.
            for i in 0..3 {
                for k in 0..3 {
                    b[(i, c + k)] = dv[k];
                }
                b[(i, c + i)] += n[i];
            }
            // Shear rows (engineering shear): γxy, γyz, γzx.
            b[(3, c)] = n.y;
            b[(3, c + 1)] = n.x;
            b[(4, c + 1)] = n.z;
            b[(4, c + 2)] = n.y;
            b[(5, c)] = n.z;
            b[(5, c + 2)] = n.x;
        }
        b
    }
}

/// The 8-node hexahedron with B-bar selective reduced integration, small strain.
///
/// Integration points and states are ordered as [`integration_points`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Hex8;

impl Hex8 {
    /// The `B̄` matrices at the 8 integration points and their volume weights
    /// `w_g det J_g`, for the reference coordinates `ref_coords`.
    pub fn strain_displacement(
        &self,
        ref_coords: &[Vec3],
    ) -> Result<([StrainDisplacement; POINTS], [f64; POINTS])> {
        let geo = Geometry::new(&nodes_array("ref_coords", ref_coords)?)?;
        Ok((std::array::from_fn(|g| geo.bbar(g)), geo.dvol))
    }

    /// Reference positions of the integration points, for output.
    pub fn point_positions(&self, ref_coords: &[Vec3]) -> Result<[Vec3; POINTS]> {
        let x = nodes_array("ref_coords", ref_coords)?;
        Ok(integration_points().map(|xi| {
            shape_functions(&xi)
                .iter()
                .zip(&x)
                .map(|(n, xa)| xa * *n)
                .sum()
        }))
    }
}

impl Element<DOFS> for Hex8 {
    fn node_count(&self) -> usize {
        NODES
    }

    fn point_count(&self) -> usize {
        POINTS
    }

    fn evaluate(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
    ) -> Result<ElementResponse<DOFS>> {
        response_through_into(self, ref_coords, u, committed, trial, material)
    }

    /// `f = Σ_g B̄ᵀσ dV`, `K = Σ_g B̄ᵀ (D B̄ dV)` accumulated straight into the caller's
    /// buffers (column-major `K`); residual only (`stiffness = None`): no tangent, the
    /// material's stress update alone.
    fn evaluate_into(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
        force: &mut [f64],
        stiffness: Option<&mut [f64]>,
    ) -> Result<()> {
        let (force, mut stiffness) = cleared_outputs(force, stiffness)?;
        let (_, u, geo) = checked_inputs(ref_coords, u, committed, trial)?;
        let ue = SVector::<f64, DOFS>::from_fn(|i, _| u[i / 3][i % 3]);
        for g in 0..POINTS {
            let b = geo.bbar(g);
            // F = I + ∂u/∂X with the unmodified gradients (unused by small-strain
            // materials; kept for finite-strain ones).
            let f = (0..NODES).fold(Mat3::identity(), |f, a| {
                f + u[a] * geo.grad[g][a].transpose()
            });
            let kin = Kinematics {
                strain: b * ue,
                deformation_gradient: f,
            };
            let at_point = |e| prefix(e, &format!("integration point {g}"));
            let d = if stiffness.is_some() {
                Some(
                    material
                        .update(&kin, &committed[g], &mut trial[g])
                        .map_err(at_point)?,
                )
            } else {
                material
                    .update_stress(&kin, &committed[g], &mut trial[g])
                    .map_err(at_point)?;
                None
            };
            let dv = geo.dvol[g];
            let sdv = trial[g].stress * dv;
            for (i, out) in force.iter_mut().enumerate() {
                *out += (0..6).map(|v| b[(v, i)] * sdv[v]).sum::<f64>();
            }
            if let (Some(k), Some(d)) = (stiffness.as_deref_mut(), d) {
                let db = d * b * dv;
                for (j, col) in k.chunks_exact_mut(DOFS).enumerate() {
                    for (i, out) in col.iter_mut().enumerate() {
                        *out += (0..6).map(|v| b[(v, i)] * db[(v, j)]).sum::<f64>();
                    }
                }
            }
        }
        Ok(())
    }

    fn point_volumes(&self, ref_coords: &[Vec3]) -> Result<Vec<f64>> {
        Ok(Geometry::new(&nodes_array("ref_coords", ref_coords)?)?
            .dvol
            .to_vec())
    }
}

/// [`Element::evaluate`] through the element's own `evaluate_into`, into new matrices.
pub(super) fn response_through_into(
    element: &dyn Element<DOFS>,
    ref_coords: &[Vec3],
    u: &[Vec3],
    committed: &[PointState],
    trial: &mut [PointState],
    material: &dyn Material,
) -> Result<ElementResponse<DOFS>> {
    let mut force = SVector::<f64, DOFS>::zeros();
    let mut stiffness = SMatrix::<f64, DOFS, DOFS>::zeros();
    element.evaluate_into(
        ref_coords,
        u,
        committed,
        trial,
        material,
        force.as_mut_slice(),
        Some(stiffness.as_mut_slice()),
    )?;
    Ok(ElementResponse { force, stiffness })
}

/// The output buffers of [`Element::evaluate_into`], length-checked and zeroed.
#[allow(clippy::type_complexity)]
pub(super) fn cleared_outputs<'a>(
    force: &'a mut [f64],
    stiffness: Option<&'a mut [f64]>,
) -> Result<(&'a mut [f64; DOFS], Option<&'a mut [f64; DOFS * DOFS]>)> {
    check_len("force", force.len(), DOFS)?;
    let force: &mut [f64; DOFS] = force.try_into().expect("length checked");
    force.fill(0.0);
    let stiffness = match stiffness {
        Some(k) => {
            check_len("stiffness", k.len(), DOFS * DOFS)?;
            let k: &mut [f64; DOFS * DOFS] = k.try_into().expect("length checked");
            k.fill(0.0);
            Some(k)
        }
        None => None,
    };
    Ok((force, stiffness))
}

/// Nodal arrays and reference geometry for [`Element::evaluate`], after checking every
/// slice length.
pub(super) fn checked_inputs(
    ref_coords: &[Vec3],
    u: &[Vec3],
    committed: &[PointState],
    trial: &[PointState],
) -> Result<([Vec3; NODES], [Vec3; NODES], Geometry)> {
    let x = nodes_array("ref_coords", ref_coords)?;
    let u = nodes_array("u", u)?;
    check_len("committed", committed.len(), POINTS)?;
    check_len("trial", trial.len(), POINTS)?;
    let geo = Geometry::new(&x)?;
    Ok((x, u, geo))
}

pub(super) fn check_len(what: &str, len: usize, expected: usize) -> Result<()> {
    if len != expected {
        return Err(Error::input(
            &format!("length of {what}"),
            len,
            &format!("must be {expected} for an 8-node hexahedron"),
        ));
    }
    Ok(())
}

pub(super) fn nodes_array(what: &str, v: &[Vec3]) -> Result<[Vec3; NODES]> {
    check_len(what, v.len(), NODES)?;
    Ok(std::array::from_fn(|a| v[a]))
}

#[cfg(test)]
pub(super) mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;
    use crate::element::{element_average_stresses, in_element, total_strain_energy};
    use crate::material::{strain_from_tensor, LinearElastic, Tangent, Voigt};
    use crate::mesh::Mesh;

    /// A cheap deterministic pseudo-random sequence in [-1, 1) (no dev-dependencies).
    pub(crate) struct Lcg(pub(crate) u64);
    impl Lcg {
        pub(crate) fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
        pub(crate) fn vec(&mut self) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next())
        }
    }

    /// A test material with a nonlinear, history-free law, so that the finite-difference
    /// check exercises the use of the material tangent (for a linear law f_int is linear
    /// and any consistent matrix would pass):
    /// σ = (1 + β ε·Dε) D ε,  ∂σ/∂ε = (1 + β ε·Dε) D + 2β (Dε)(Dε)ᵀ.
    #[derive(Debug)]
    struct Cubic {
        d: Tangent,
        beta: f64,
    }
    impl Material for Cubic {
        fn update(
            &self,
            kin: &Kinematics,
            committed: &PointState,
            trial: &mut PointState,
        ) -> Result<Tangent> {
            let de = self.d * kin.strain;
            let s = 1.0 + self.beta * kin.strain.dot(&de);
            *trial = PointState {
                stress: de * s,
                strain: kin.strain,
                ..*committed
            };
            Ok(self.d * s + de * de.transpose() * (2.0 * self.beta))
        }
        fn elastic_tangent(&self) -> Tangent {
            self.d
        }
        fn elastic_energy_density(&self, state: &PointState) -> f64 {
            0.5 * state.strain.dot(&(self.d * state.strain))
        }
        fn describe(&self) -> String {
            "cubic test material".into()
        }
    }

    /// A unit cube with every node moved by up to 0.15 in each direction: far from a
    /// parallelepiped, still a valid element.
    pub(crate) fn distorted_element() -> [Vec3; 8] {
        let mut rng = Lcg(7);
        let x: [Vec3; 8] = std::array::from_fn(|a| {
            let c = HEX_CORNERS[a];
            Vec3::new(0.5 * (c[0] + 1.0), 0.5 * (c[1] + 1.0), 0.5 * (c[2] + 1.0)) + rng.vec() * 0.15
        });
        Mesh::new(x.to_vec(), vec![[0, 1, 2, 3, 4, 5, 6, 7]]).unwrap();
        x
    }

    fn states() -> [PointState; POINTS] {
        [PointState::default(); POINTS]
    }

    /// Global internal force, tangent and states for the displacements `u` (dense, for
    /// small test meshes). States are stored element by element.
    fn assemble(
        mesh: &Mesh,
        u: &[Vec3],
        material: &dyn Material,
    ) -> (DVector<f64>, DMatrix<f64>, Vec<PointState>) {
        let n = 3 * mesh.node_count();
        let mut f = DVector::zeros(n);
        let mut k = DMatrix::zeros(n, n);
        let mut all = Vec::new();
        for (e, hex) in mesh.hexes.iter().enumerate() {
            let ue: Vec<Vec3> = hex.iter().map(|&i| u[i]).collect();
            let mut trial = states();
            let r = Hex8
                .evaluate(
                    &mesh.hex_coordinates(e),
                    &ue,
                    &states(),
                    &mut trial,
                    material,
                )
                .map_err(|err| in_element(err, e))
                .unwrap();
            for (a, &na) in hex.iter().enumerate() {
                for i in 0..3 {
                    f[3 * na + i] += r.force[3 * a + i];
                    for (b, &nb) in hex.iter().enumerate() {
                        for j in 0..3 {
                            k[(3 * na + i, 3 * nb + j)] += r.stiffness[(3 * a + i, 3 * b + j)];
                        }
                    }
                }
            }
            all.extend_from_slice(&trial);
        }
        (f, k, all)
    }

    /// Block of `cells^3` unit cells with its nodes moved: interior nodes randomly by up to
    /// `0.25`, boundary nodes within their face plane (some also out of it), keeping all
    /// Jacobians positive (checked).
    fn distorted_block(cells: usize, seed: u64) -> (Mesh, Vec<usize>) {
        let s = cells as f64;
        let mut mesh = Mesh::block(Vec3::zeros(), Vec3::new(s, s, s), [cells; 3]).unwrap();
        let mut boundary = Vec::new();
        for name in ["x-", "x+", "y-", "y+", "z-", "z+"] {
            boundary.extend_from_slice(mesh.node_set(name).unwrap());
        }
        boundary.sort_unstable();
        boundary.dedup();
        let mut rng = Lcg(seed);
        for (i, x) in mesh.nodes.iter_mut().enumerate() {
            let d = rng.vec() * 0.25;
            let on_face = |v: f64| v == 0.0 || v == s;
            let mut moved = *x + d;
            // Keep corners and edges fixed, slide face nodes in their plane (and push
            // every third one out of it: its value is prescribed anyway).
            let faces = (0..3).filter(|&k| on_face(x[k])).count();
            if faces >= 2 {
                moved = *x;
            } else if faces == 1 {
                let k = (0..3).find(|&k| on_face(x[k])).unwrap();
                moved[k] = x[k] + if i % 3 == 0 { 0.5 * d[k] } else { 0.0 };
            }
            *x = moved;
        }
        mesh.validate().unwrap();
        (mesh, boundary)
    }

    /// Patch test: prescribe u = A x + b on the boundary, solve for the interior nodes,
    /// check the interior displacements, the stress at every Gauss point and the interior
    /// residual.
    fn patch_test(cells: usize, seed: u64, material: &LinearElastic) {
        let (mesh, boundary) = distorted_block(cells, seed);
        let a = nalgebra::Matrix3::new(1.0, 0.3, -0.2, 0.5, -0.7, 0.4, -0.1, 0.25, 0.6) * 1e-3;
        let b = Vec3::new(0.3, -0.2, 0.1);
        let exact = |x: &Vec3| a * x + b;

        let mut fixed = vec![false; mesh.node_count()];
        for &n in &boundary {
            fixed[n] = true;
        }
        let interior: Vec<usize> = (0..mesh.node_count()).filter(|&n| !fixed[n]).collect();
        assert_eq!(interior.len(), (cells - 1).pow(3));

        // One Newton step from the boundary values (exact for a linear material):
        // K_ii du_i = -f_i(u0).
        let mut u: Vec<Vec3> = mesh
            .nodes
            .iter()
            .enumerate()
            .map(|(n, x)| if fixed[n] { exact(x) } else { Vec3::zeros() })
            .collect();
        let (f, k, _) = assemble(&mesh, &u, material);
        let dofs: Vec<usize> = interior
            .iter()
            .flat_map(|&n| [3 * n, 3 * n + 1, 3 * n + 2])
            .collect();
        let kii = DMatrix::from_fn(dofs.len(), dofs.len(), |i, j| k[(dofs[i], dofs[j])]);
        let fi = DVector::from_fn(dofs.len(), |i, _| -f[dofs[i]]);
        let du = kii.lu().solve(&fi).expect("interior stiffness is regular");
        for (i, &d) in dofs.iter().enumerate() {
            u[d / 3][d % 3] += du[i];
        }

        for &n in &interior {
            let err = (u[n] - exact(&mesh.nodes[n])).norm();
            assert!(err < 1e-12, "node {n}: {err}");
        }
        let sigma = material.stress(&strain_from_tensor(&a));
        let (f, _, states) = assemble(&mesh, &u, material);
        for (p, s) in states.iter().enumerate() {
            let rel = (s.stress - sigma).norm() / sigma.norm();
            assert!(
                rel < 1e-10,
                "element {} point {}: rel {rel:e}",
                p / 8,
                p % 8
            );
        }
        let scale = sigma.norm(); // force scale: stress x unit area
        for &n in &interior {
            for i in 0..3 {
                assert!(
                    f[3 * n + i].abs() < 1e-10 * scale,
                    "node {n}: {}",
                    f[3 * n + i]
                );
            }
        }
        // Output helpers on the same states.
        for avg in element_average_stresses(&mesh, &Hex8, &states).unwrap() {
            assert!((avg - sigma).norm() < 1e-10 * scale);
        }
    }

    #[test]
    fn patch_test_distorted_2x2x2() {
        patch_test(2, 11, &LinearElastic::new(210e3, 0.3).unwrap());
    }

    #[test]
    fn patch_test_distorted_3x3x3_random_nearly_incompressible() {
        patch_test(3, 5, &LinearElastic::new(210e3, 0.3).unwrap());
        patch_test(3, 23, &LinearElastic::new(1.0, 0.4999).unwrap());
    }

    #[test]
    fn tangent_matches_central_differences() {
        let x = distorted_element();
        let lin = LinearElastic::new(1.0, 0.3).unwrap();
        let cubic = Cubic {
            d: lin.tangent(),
            beta: 2e3,
        };
        let mut rng = Lcg(3);
        let u: Vec<Vec3> = (0..8).map(|_| rng.vec() * 1e-2).collect();
        let force = |u: &[Vec3]| {
            let mut trial = states();
            Hex8.evaluate(&x, u, &states(), &mut trial, &cubic)
                .unwrap()
                .force
        };
        let mut trial = states();
        let r = Hex8
            .evaluate(&x, &u, &states(), &mut trial, &cubic)
            .unwrap();
        // The nonlinearity matters at this displacement (otherwise the check is weak).
        let strain = trial[0].strain;
        assert!(cubic.beta * strain.dot(&(cubic.d * strain)) > 0.05);

        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for j in 0..DOFS {
            let (mut up, mut um) = (u.clone(), u.clone());
            up[j / 3][j % 3] += h;
            um[j / 3][j % 3] -= h;
            let col = (force(&up) - force(&um)) / (2.0 * h);
            worst = worst.max((col - r.stiffness.column(j)).abs().max());
        }
        let rel = worst / r.stiffness.abs().max();
        assert!(rel < 1e-6, "relative tangent error {rel:e}");
    }

    /// The direct kernel (`evaluate_into`) against the matrix form `Σ_g B̄ᵀσ dV`,
    /// `Σ_g B̄ᵀ D B̄ dV` built from [`Hex8::strain_displacement`] and the material's own
    /// update, for an elastoplastic material yielding at every point: force and tangent to
    /// 1e-13 relative (only the order of the sums differs). A residual-only call gives the
    /// same force and trial states bit for bit.
    #[test]
    fn direct_kernel_equals_the_matrix_form_and_residual_only_the_same_force() {
        use crate::material::{ElastoPlastic, Hardening, Hill48};
        let x = distorted_element();
        let m = ElastoPlastic::new(
            LinearElastic::new(70e3, 0.33).unwrap(),
            Hill48::from_lankford(0.7, 1.3, 2.1).unwrap(),
            Hardening::swift(500.0, 0.01, 0.22).unwrap(),
        );
        let mut rng = Lcg(11);
        let u: Vec<Vec3> = (0..8).map(|_| rng.vec() * 0.03).collect();
        let mut trial = states();
        let r = Hex8.evaluate(&x, &u, &states(), &mut trial, &m).unwrap();
        assert!(
            trial.iter().all(|t| t.eq_plastic_strain > 0.0),
            "must yield"
        );
        let (b, dv) = Hex8.strain_displacement(&x).unwrap();
        let ue = SVector::<f64, DOFS>::from_fn(|i, _| u[i / 3][i % 3]);
        let (mut force, mut stiffness) = (
            SVector::<f64, DOFS>::zeros(),
            SMatrix::<f64, DOFS, DOFS>::zeros(),
        );
        for g in 0..POINTS {
            let mut point = PointState::default();
            let d = m
                .update(
                    &Kinematics::from_strain(b[g] * ue),
                    &PointState::default(),
                    &mut point,
                )
                .unwrap();
            assert_eq!(point.stress, trial[g].stress);
            force += b[g].transpose() * point.stress * dv[g];
            stiffness += b[g].transpose() * d * b[g] * dv[g];
        }
        assert!((r.force - force).amax() <= 1e-13 * force.amax());
        assert!((r.stiffness - stiffness).amax() <= 1e-13 * stiffness.amax());
        let mut residual_trial = states();
        let mut residual = [0.0; DOFS];
        Hex8.evaluate_into(
            &x,
            &u,
            &states(),
            &mut residual_trial,
            &m,
            &mut residual,
            None,
        )
        .unwrap();
        assert_eq!(residual.as_slice(), r.force.as_slice());
        assert_eq!(residual_trial, trial);
    }

    #[test]
    fn rigid_body_motion_gives_zero_force() {
        let x = distorted_element();
        let m = LinearElastic::new(210e3, 0.3).unwrap();
        let t = Vec3::new(0.3, -1.2, 0.7);
        let mut trial = states();
        let r = Hex8
            .evaluate(&x, &[t; 8], &states(), &mut trial, &m)
            .unwrap();
        // Force scale of a unit strain on a unit element: E.
        assert!(
            r.force.abs().max() < 1e-12 * m.young(),
            "{}",
            r.force.abs().max()
        );
        assert!(trial
            .iter()
            .all(|s| s.stress.abs().max() < 1e-12 * m.young()));

        // An infinitesimal rotation u = W x (W skew) has zero small strain too.
        let w = Mat3::new(0.0, -0.3, 0.2, 0.3, 0.0, -0.1, -0.2, 0.1, 0.0);
        let u: Vec<Vec3> = x.iter().map(|p| w * p + t).collect();
        let r = Hex8.evaluate(&x, &u, &states(), &mut trial, &m).unwrap();
        assert!(
            r.force.abs().max() < 1e-11 * m.young(),
            "{}",
            r.force.abs().max()
        );
    }

    #[test]
    fn stiffness_has_exactly_six_zero_eigenvalues() {
        for nu in [0.3, 0.4999] {
            let m = LinearElastic::new(1.0, nu).unwrap();
            for x in [
                distorted_element(),
                std::array::from_fn(|a| {
                    let c = HEX_CORNERS[a];
                    Vec3::new(c[0] + 1.0, 0.5 * c[1], 0.25 * c[2])
                }),
            ] {
                let mut trial = states();
                let k = Hex8
                    .evaluate(&x, &[Vec3::zeros(); 8], &states(), &mut trial, &m)
                    .unwrap()
                    .stiffness;
                assert!((k - k.transpose()).abs().max() < 1e-14 * k.abs().max());
                let mut ev: Vec<f64> = k.symmetric_eigenvalues().iter().copied().collect();
                ev.sort_by(|a, b| a.partial_cmp(b).unwrap());
                let max = ev[DOFS - 1];
                for (i, v) in ev.iter().take(6).enumerate() {
                    assert!(
                        v.abs() < 1e-12 * max,
                        "nu {nu}: eigenvalue {i} = {v:e}, max {max:e}"
                    );
                }
                // The 7th is a genuine deformation mode (no spurious zero-energy /
                // hourglass mode): many orders of magnitude above the rigid modes'
                // round-off, and not small compared with the shear stiffness μ L
                // (L = V^⅓; the slender box's softest mode, a bending-like one, is
                // ~ μ L (h/L)^2). The largest eigenvalue is no yardstick: near
                // incompressibility it is the much larger volumetric stiffness K L.
                let rigid = ev[..6].iter().fold(0.0f64, |a, b| a.max(b.abs()));
                let shear_scale = m.shear_modulus() * Hex8.volume(&x).unwrap().cbrt();
                assert!(
                    ev[6] > 1e-3 * shear_scale && ev[6] > 1e10 * rigid,
                    "nu {nu}: 7th eigenvalue {:e}, μ L = {shear_scale:e}, rigid {rigid:e}",
                    ev[6]
                );
            }
        }
    }

    #[test]
    fn bbar_volumetric_strain_is_the_element_average() {
        let x = distorted_element();
        let m = LinearElastic::new(1.0, 0.3).unwrap();
        let mut rng = Lcg(99);
        let u: Vec<Vec3> = (0..8).map(|_| rng.vec() * 1e-3).collect();
        let mut trial = states();
        Hex8.evaluate(&x, &u, &states(), &mut trial, &m).unwrap();
        let tr = |s: &PointState| s.strain[0] + s.strain[1] + s.strain[2];

        // (1/V) ∫ div u dV with the full (unmodified) gradients.
        let (_, dvol) = Hex8.strain_displacement(&x).unwrap();
        let geo = Geometry::new(&x).unwrap();
        let mean_div: f64 = (0..POINTS)
            .map(|g| (0..8).map(|a| geo.grad[g][a].dot(&u[a])).sum::<f64>() * dvol[g])
            .sum::<f64>()
            / dvol.iter().sum::<f64>();
        for s in &trial {
            assert!((tr(s) - mean_div).abs() < 1e-15, "{} vs {mean_div}", tr(s));
        }
        // ... while the deviatoric strain does vary from point to point.
        assert!((trial[0].strain - trial[6].strain).abs().max() > 1e-5);
        // The deformation gradient is the unmodified one.
        let f0 = (0..8).fold(Mat3::identity(), |f, a| {
            f + u[a] * geo.grad[0][a].transpose()
        });
        assert_eq!(trial[0].deformation_gradient, f0);
    }

    #[test]
    fn strain_energy_is_half_u_k_u_and_volume_is_exact() {
        let x = distorted_element();
        let m = LinearElastic::new(3.0, 0.2).unwrap();
        let mut rng = Lcg(42);
        let u: Vec<Vec3> = (0..8).map(|_| rng.vec() * 1e-2).collect();
        let ue = SVector::<f64, DOFS>::from_fn(|i, _| u[i / 3][i % 3]);
        let mut trial = states();
        let r = Hex8.evaluate(&x, &u, &states(), &mut trial, &m).unwrap();
        let w = Hex8.strain_energy(&x, &trial, &m).unwrap();
        let half_uku = 0.5 * ue.dot(&(r.stiffness * ue));
        assert!((w - half_uku).abs() < 1e-12 * half_uku, "{w} vs {half_uku}");
        // For a linear material, f_int = K u.
        assert!((r.force - r.stiffness * ue).abs().max() < 1e-14);

        let mesh = Mesh::new(x.to_vec(), vec![[0, 1, 2, 3, 4, 5, 6, 7]]).unwrap();
        let total = total_strain_energy(&mesh, &Hex8, &trial, &m).unwrap();
        assert!((total - w).abs() < 1e-15);

        // Volume: a sheared, stretched box (affine map) of volume 2 x 3 x 0.5.
        let g = Mat3::new(2.0, 0.4, 0.1, 0.0, 3.0, -0.3, 0.0, 0.0, 0.5);
        let xs: Vec<Vec3> = HEX_CORNERS
            .iter()
            .map(|c| g * Vec3::new(0.5 * (c[0] + 1.0), 0.5 * (c[1] + 1.0), 0.5 * (c[2] + 1.0)))
            .collect();
        assert!((Hex8.volume(&xs).unwrap() - 3.0).abs() < 1e-14);
        // The volume of a trilinear hexahedron is a cubic polynomial integral: the 2x2x2
        // rule is exact, so it equals the divergence-theorem volume of the distorted one.
        let centre: Vec3 = x.iter().sum::<Vec3>() / 8.0;
        let div_volume: f64 = crate::mesh::HEX_FACES
            .iter()
            .map(|f| {
                // Exact ∫ x·n dA over a bilinear face: x·(x_s × x_t) is cubic → 2x2 Gauss.
                let mut v = 0.0;
                for (s, t) in [
                    (-GAUSS, -GAUSS),
                    (GAUSS, -GAUSS),
                    (GAUSS, GAUSS),
                    (-GAUSS, GAUSS),
                ] {
                    let c = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
                    let (mut p, mut xs, mut xt) = (Vec3::zeros(), Vec3::zeros(), Vec3::zeros());
                    for k in 0..4 {
                        let (sa, ta) = c[k];
                        let xk = x[f[k]] - centre;
                        p += xk * (0.25 * (1.0 + sa * s) * (1.0 + ta * t));
                        xs += xk * (0.25 * sa * (1.0 + ta * t));
                        xt += xk * (0.25 * ta * (1.0 + sa * s));
                    }
                    v += p.dot(&xs.cross(&xt)) / 3.0;
                }
                v
            })
            .sum();
        let vol = Hex8.volume(&x).unwrap();
        assert!((vol - div_volume).abs() < 1e-14, "{vol} vs {div_volume}");
    }

    #[test]
    fn average_stress_and_point_positions() {
        let x = distorted_element();
        let sigma = Voigt::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0);
        let st = [PointState {
            stress: sigma,
            ..PointState::default()
        }; POINTS];
        assert!((Hex8.average_stress(&x, &st).unwrap() - sigma).abs().max() < 1e-14);
        let p = Hex8.point_positions(&x).unwrap();
        // Point g is nearest node g.
        for g in 0..POINTS {
            let nearest = (0..8)
                .min_by(|&a, &b| {
                    (x[a] - p[g])
                        .norm()
                        .partial_cmp(&(x[b] - p[g]).norm())
                        .unwrap()
                })
                .unwrap();
            assert_eq!(nearest, g);
        }
        let n = shape_functions(&Vec3::new(0.2, -0.4, 0.9));
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn inverted_element_and_bad_lengths_are_errors() {
        let m = LinearElastic::new(1.0, 0.3).unwrap();
        let x = distorted_element();
        // Swap bottom and top faces: a mirror image, negative Jacobian everywhere.
        let inverted: Vec<Vec3> = (0..8).map(|a| x[(a + 4) % 8]).collect();
        let mut trial = states();
        let err = Hex8
            .evaluate(&inverted, &[Vec3::zeros(); 8], &states(), &mut trial, &m)
            .map_err(|e| in_element(e, 17))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("element 17: Jacobian determinant at integration point 0 = -"),
            "{err}"
        );
        assert!(err.contains("inverted"), "{err}");
        assert!(Hex8.volume(&inverted).is_err());

        let err = Hex8
            .evaluate(&x[..7], &[Vec3::zeros(); 8], &states(), &mut trial, &m)
            .unwrap_err()
            .to_string();
        assert!(err.contains("length of ref_coords = 7 must be 8"), "{err}");
        let err = Hex8
            .evaluate(&x, &[Vec3::zeros(); 8], &states()[..4], &mut trial, &m)
            .unwrap_err()
            .to_string();
        assert!(err.contains("length of committed = 4 must be 8"), "{err}");

        // A material failure is reported with its integration point.
        let mut u = [Vec3::zeros(); 8];
        u[3].x = f64::NAN;
        let err = Hex8
            .evaluate(&x, &u, &states(), &mut trial, &m)
            .unwrap_err();
        assert!(matches!(err, Error::NoConvergence { .. }));
        assert!(
            err.to_string()
                .contains("integration point 0: non-finite strain"),
            "{err}"
        );

        let mesh = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [2, 1, 1]).unwrap();
        let err = total_strain_energy(&mesh, &Hex8, &states(), &m)
            .unwrap_err()
            .to_string();
        assert!(err.contains("states = 8 must be 16"), "{err}");
        assert_eq!((Hex8.node_count(), Hex8.point_count()), (8, 8));
    }
}
