//! The solid-shell's original kernel, kept verbatim (as [`super::hex8_fbar_reference`] is
//! for the F-bar hexahedron) as the reference the tuned kernel of [`super::solid_shell`]
//! is tested against: same discrete element, different order of operations and a warm
//! start of the enhanced parameters, so equal to round-off and the local tolerance.

use nalgebra::{DMatrix, DVector, SMatrix, SymmetricEigen};

use super::hex8::{jacobian, nodes_array, shape_derivatives, DOFS, NODES};
use super::prefix;
use super::solid_shell::{
    in_plane, location, samples, thickness_rule, SolidShell, COMPONENTS, LOCATIONS,
    MAX_LOCAL_ITERATIONS,
};
use crate::geometry::{Mat3, Vec3};
use crate::material::{
    strain_from_tensor, strain_to_tensor, Kinematics, Material, PointState, Tangent, Voigt,
    ENHANCED_PARAMETERS,
};
use crate::{Error, Result};

/// What one integration point keeps between the local iterations and the assembly.
struct Point {
    /// Cartesian Green-Lagrange strain from the displacements alone (engineering shear).
    strain: Voigt,
    /// `∂E/∂u` (6 x 24).
    b: SMatrix<f64, 6, DOFS>,
    /// Covariant-to-Cartesian map of engineering strain vectors.
    t: Tangent,
    /// EAS modes (Cartesian, engineering shear), one column per parameter.
    modes: [Voigt; ENHANCED_PARAMETERS],
    /// Reference volume weight.
    dv: f64,
    /// Compatible deformation gradient at the point (for the Cauchy stress and the
    /// rotation measure of the step control).
    f: Mat3,
    /// Thickness level and in-plane index.
    level: usize,
    q: usize,
}

/// Kinematics of one tying location: natural derivatives, `J = [G_α]`, `D = [d_α]`.
struct Location {
    dn: [Vec3; NODES],
    j: Mat3,
    d: Mat3,
}

/// `U - I` for `C = I + a` (`a = 2E`), without round-off against `I`.
fn stretch_minus_identity(a: &Mat3) -> Result<Mat3> {
    if !a.iter().all(|v| v.is_finite()) {
        return Err(Error::no_convergence(
            crate::error::Failure::Local,
            "non-finite enhanced strain",
        ));
    }
    let eig = SymmetricEigen::new((a + a.transpose()) * 0.5);
    let mut d = Vec3::zeros();
    for i in 0..3 {
        let mu = eig.eigenvalues[i];
        if mu.is_nan() || mu <= -1.0 {
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                format!(
                    "enhanced strain with a stretch eigenvalue {} (inverted material)",
                    1.0 + mu
                ),
            ));
        }
        d[i] = mu / (1.0 + (1.0 + mu).sqrt());
    }
    let q = eig.eigenvectors;
    Ok(q * Mat3::from_diagonal(&d) * q.transpose())
}

/// The original kernel on a [`SolidShell`].
struct Reference<'a>(&'a SolidShell);

impl std::ops::Deref for Reference<'_> {
    type Target = SolidShell;
    fn deref(&self) -> &SolidShell {
        self.0
    }
}

impl Reference<'_> {
    fn modes(&self) -> usize {
        if self.membrane_modes {
            6
        } else {
            2
        }
    }

    /// The reference quantities and displacement strains of every point.
    fn points(&self, x: &[Vec3; NODES], u: &[Vec3; NODES]) -> Result<Vec<Point>> {
        let n = self.thickness_points;
        let (zeta, wz) = thickness_rule(n);
        let centre = jacobian(x, &Vec3::zeros());
        let j0 = centre.determinant();
        let inv0 = match centre.try_inverse() {
            Some(inv) if j0 > 0.0 && j0.is_finite() => inv,
            _ => {
                return Err(Error::input(
                    "Jacobian determinant at the element centre",
                    j0,
                    "must be > 0 (inverted or degenerate element)",
                ))
            }
        };
        let contra: [Vec3; 3] = std::array::from_fn(|i| inv0.row(i).transpose());
        let len: [f64; 3] = std::array::from_fn(|i| centre.column(i).norm());
        let n3 = contra[2].normalize();
        let tensor_mode = |m: Mat3| strain_from_tensor(&m);
        let thickness_mode = tensor_mode(n3 * n3.transpose());
        let m11 = tensor_mode(contra[0] * contra[0].transpose() * (len[0] * len[0]));
        let m22 = tensor_mode(contra[1] * contra[1].transpose() * (len[1] * len[1]));
        let g12 = contra[0] * contra[1].transpose() * (len[0] * len[1]);
        let m12 = tensor_mode((g12 + g12.transpose()) * 0.5);
        // Jacobian determinants of every point, for ζ̄.
        let dets: Vec<f64> = (0..4 * n)
            .map(|p| {
                let (xi, eta) = in_plane(p % 4);
                jacobian(x, &Vec3::new(xi, eta, zeta[p / 4])).determinant()
            })
            .collect();
        // Column means of ζ and ζ² (weights w j), so that the thickness modes have zero
        // mean along every column.
        let column_mean = |f: &dyn Fn(f64) -> f64| -> [f64; 4] {
            std::array::from_fn(|q| {
                let (mut num, mut den) = (0.0, 0.0);
                for k in 0..n {
                    num += wz[k] * f(zeta[k]) * dets[4 * k + q];
                    den += wz[k] * dets[4 * k + q];
                }
                num / den
            })
        };
        let zeta_bar = column_mean(&|z| z);
        let zeta2_bar = column_mean(&|z| z * z);
        let mut points = Vec::with_capacity(4 * n);
        for (k, &z) in zeta.iter().enumerate() {
            let locations: [Location; LOCATIONS] = std::array::from_fn(|l| {
                let (xi, eta) = location(l);
                let dn = shape_derivatives(&Vec3::new(xi, eta, z));
                let j = (0..NODES).fold(Mat3::zeros(), |m, a| m + x[a] * dn[a].transpose());
                let d = (0..NODES).fold(Mat3::zeros(), |m, a| m + u[a] * dn[a].transpose());
                Location { dn, j, d }
            });
            for q in 0..4 {
                let p = 4 * k + q;
                let jp = locations[q].j;
                let det = dets[p];
                let inv = match jp.try_inverse() {
                    Some(inv) if det > 0.0 && det.is_finite() => inv,
                    _ => {
                        return Err(Error::input(
                            &format!("Jacobian determinant at integration point {p}"),
                            det,
                            "must be > 0 (inverted or degenerate element)",
                        ))
                    }
                };
                let mut e_cov = Voigt::zeros();
                let mut b_cov = SMatrix::<f64, 6, DOFS>::zeros();
                for (c, &(al, be)) in COMPONENTS.iter().enumerate() {
                    let s = if al == be { 0.5 } else { 1.0 };
                    let (list, count) = samples(q, c);
                    for &(l, phi) in &list[..count] {
                        let loc = &locations[l];
                        let (ga, gb) = (loc.j.column(al), loc.j.column(be));
                        let (da, db) = (loc.d.column(al), loc.d.column(be));
                        let mut value = ga.dot(&db) + da.dot(&gb);
                        let (cur_a, cur_b) = if self.finite {
                            value += da.dot(&db);
                            (ga + da, gb + db)
                        } else {
                            (ga.into_owned(), gb.into_owned())
                        };
                        e_cov[c] += phi * s * value;
                        for a in 0..NODES {
                            let v = (cur_b * loc.dn[a][al] + cur_a * loc.dn[a][be]) * (phi * s);
                            for kk in 0..3 {
                                b_cov[(c, 3 * a + kk)] += v[kk];
                            }
                        }
                    }
                }
                let t = Tangent::from_fn(|_, _| 0.0);
                let t = (0..6).fold(t, |mut t, m| {
                    let mut unit = Voigt::zeros();
                    unit[m] = 1.0;
                    let cart = inv.transpose() * strain_to_tensor(&unit) * inv;
                    t.set_column(m, &strain_from_tensor(&cart));
                    t
                });
                let (xi, eta) = in_plane(q);
                let scale = j0 / det;
                let mut modes = [Voigt::zeros(); ENHANCED_PARAMETERS];
                modes[0] = thickness_mode * (z - zeta_bar[q]);
                modes[1] = thickness_mode * (z * z - zeta2_bar[q]);
                if self.membrane_modes {
                    modes[2] = m11 * (scale * xi);
                    modes[3] = m22 * (scale * eta);
                    modes[4] = m12 * (scale * xi);
                    modes[5] = m12 * (scale * eta);
                }
                let h = locations[q].d * inv;
                points.push(Point {
                    strain: t * e_cov,
                    b: t * b_cov,
                    t,
                    modes,
                    dv: wz[k] * det,
                    f: Mat3::identity() + h,
                    level: k,
                    q,
                });
            }
            // The locations are needed again for the geometric stiffness: recomputed
            // there (cheap), not kept.
        }
        Ok(points)
    }

    /// The material at point `p` with the EAS parameters `alpha`: PK2 (or small-strain)
    /// stress and tangent; writes `trial`.
    fn material_at(
        &self,
        point: &Point,
        alpha: &[f64],
        committed: &PointState,
        trial: &mut PointState,
        material: &dyn Material,
    ) -> Result<(Voigt, Tangent)> {
        let mut e = point.strain;
        for (m, a) in alpha.iter().enumerate() {
            e += point.modes[m] * *a;
        }
        let (s, c) = if self.finite {
            let h = stretch_minus_identity(&(strain_to_tensor(&e) * 2.0))?;
            let resp = material.update_finite_displacement_gradient(&h, committed, trial)?;
            trial.stress = super::solid_shell::cauchy_stress(&point.f, &e, &resp.pk2)?;
            (resp.pk2, resp.tangent)
        } else {
            let kin = Kinematics {
                strain: e,
                deformation_gradient: point.f,
            };
            let c = material.update(&kin, committed, trial)?;
            (trial.stress, c)
        };
        trial.deformation_gradient = point.f;
        trial.enhanced = [0.0; ENHANCED_PARAMETERS];
        trial.enhanced[..alpha.len()].copy_from_slice(alpha);
        Ok((s, c))
    }

    /// Adds the geometric stiffness `Σ_c S^c ∂²E_c/∂u²` of every point to `k`.
    fn add_geometric(
        &self,
        points: &[Point],
        stresses: &[Voigt],
        k: &mut SMatrix<f64, DOFS, DOFS>,
    ) {
        let (zeta, _) = thickness_rule(self.thickness_points);
        let mut g = [[0.0; NODES]; NODES];
        for (point, s) in points.iter().zip(stresses) {
            let s_cov = point.t.transpose() * s * point.dv;
            let z = zeta[point.level];
            for (c, &(al, be)) in COMPONENTS.iter().enumerate() {
                let half = if al == be { 0.5 } else { 1.0 };
                let (list, count) = samples(point.q, c);
                for &(l, phi) in &list[..count] {
                    let (xi, eta) = location(l);
                    let dn = shape_derivatives(&Vec3::new(xi, eta, z));
                    let coef = s_cov[c] * phi * half;
                    for a in 0..NODES {
                        for b in 0..NODES {
                            g[a][b] += coef * (dn[a][al] * dn[b][be] + dn[a][be] * dn[b][al]);
                        }
                    }
                }
            }
        }
        for a in 0..NODES {
            for b in 0..NODES {
                for d in 0..3 {
                    k[(3 * a + d, 3 * b + d)] += g[a][b];
                }
            }
        }
    }
}

/// Force (and stiffness, column-major) of `el` as computed before the kernel was tuned,
/// the enhanced parameters started from the committed ones.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_into(
    el: &SolidShell,
    ref_coords: &[Vec3],
    u: &[Vec3],
    committed: &[PointState],
    trial: &mut [PointState],
    material: &dyn Material,
    force: &mut [f64],
    stiffness: Option<&mut [f64]>,
) -> Result<()> {
    super::hex8::check_len("force", force.len(), DOFS)?;
    if let Some(k) = &stiffness {
        super::hex8::check_len("stiffness", k.len(), DOFS * DOFS)?;
    }
    el.check(committed, trial)?;
    let this = Reference(el);
    let x = nodes_array("ref_coords", ref_coords)?;
    let u = nodes_array("u", u)?;
    let points = this.points(&x, &u)?;
    let ne = this.modes();
    let mut alpha: Vec<f64> = committed[0].enhanced[..ne].to_vec();
    let strain_scale = points.iter().map(|p| p.strain.amax()).fold(0.0, f64::max);
    let mut stresses = vec![Voigt::zeros(); points.len()];
    let mut tangents = vec![Tangent::zeros(); points.len()];
    let mut k_aa = DMatrix::<f64>::zeros(ne, ne);
    let mut previous_step = f64::INFINITY;
    for iteration in 0.. {
        let mut r_a = DVector::<f64>::zeros(ne);
        k_aa.fill(0.0);
        for (p, point) in points.iter().enumerate() {
            let (s, c) = this
                .material_at(point, &alpha, &committed[p], &mut trial[p], material)
                .map_err(|e| prefix(e, &format!("integration point {p}")))?;
            for m in 0..ne {
                let cm = c * point.modes[m];
                r_a[m] += point.dv * point.modes[m].dot(&s);
                for l in 0..ne {
                    k_aa[(l, m)] += point.dv * point.modes[l].dot(&cm);
                }
            }
            stresses[p] = s;
            tangents[p] = c;
        }
        let step = k_aa.clone().lu().solve(&r_a).ok_or_else(|| {
            Error::no_convergence(
                crate::error::Failure::Local,
                "singular enhanced-strain stiffness",
            )
        })?;
        let size = step.amax();
        let scale = strain_scale.max(alpha.iter().fold(0.0, |m, a| m.max(a.abs())));
        // Converged, or stalled at round-off (the step no longer shrinks).
        if size <= 1e-14 * scale
            || (iteration >= 2 && size <= 1e-9 * scale && size > 0.25 * previous_step)
        {
            break;
        }
        if iteration >= MAX_LOCAL_ITERATIONS || !size.is_finite() {
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                format!(
                    "enhanced-strain parameters not converged after {iteration} local \
                 iterations (last step {size:e})"
                ),
            ));
        }
        previous_step = size;
        for (a, d) in alpha.iter_mut().zip(step.iter()) {
            *a -= d;
        }
    }
    let force: &mut [f64; DOFS] = force.try_into().expect("length checked");
    force.fill(0.0);
    for (point, s) in points.iter().zip(&stresses) {
        let f = point.b.transpose() * s * point.dv;
        for i in 0..DOFS {
            force[i] += f[i];
        }
    }
    let Some(k_out) = stiffness else {
        return Ok(());
    };
    let mut k = SMatrix::<f64, DOFS, DOFS>::zeros();
    let mut k_ua = DMatrix::<f64>::zeros(DOFS, ne);
    let mut k_au = DMatrix::<f64>::zeros(ne, DOFS);
    for (point, c) in points.iter().zip(&tangents) {
        let cb = c * point.b * point.dv;
        k += point.b.transpose() * cb;
        for m in 0..ne {
            let mode = &point.modes[m];
            let row = mode.transpose() * cb;
            let col = point.b.transpose() * (c * mode) * point.dv;
            for i in 0..DOFS {
                k_au[(m, i)] += row[i];
                k_ua[(i, m)] += col[i];
            }
        }
    }
    if this.finite {
        this.add_geometric(&points, &stresses, &mut k);
    }
    let lu = k_aa.lu();
    let correction = lu.solve(&k_au).ok_or_else(|| {
        Error::no_convergence(
            crate::error::Failure::Local,
            "singular enhanced-strain stiffness",
        )
    })?;
    let condensed = &k_ua * correction;
    for j in 0..DOFS {
        for i in 0..DOFS {
            k[(i, j)] -= condensed[(i, j)];
        }
    }
    k_out.copy_from_slice(k.as_slice());
    Ok(())
}
