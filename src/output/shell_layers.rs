//! The solid-shell's through-thickness values as VTK cell fields: at the bottom face, the
//! mid-surface and the top face of each element (issue 15; docs/solid-shell.md, "Output").
//!
//! A solid-shell element has `n` thickness levels of 4 in-plane points each (point
//! `k * 4 + q` is in-plane point `q` at level `k`, bottom to top,
//! [`crate::element::solid_shell`]). For each face `f` of bottom, mid, top the fields are
//! the in-plane means of the integration-point values at one level: the first, the middle
//! and the last. With the default rules (odd `n ≥ 3`: [`thickness_rule`]) those levels are
//! at `ζ = -1, 0, 1`, the faces and the mid-surface themselves, so the values are the
//! element's own, not extrapolated. With an even `n` (Gauss points, none on a face) the
//! outermost points are written as they are and `mid` is the mean of the two middle
//! levels: extrapolating a plastic stress profile to the faces across the kinks of its
//! elastic core overshoots, a sampled value never does. `shell_<f>_zeta` says where the
//! values were taken.
//!
//! Fields (per hexahedron; none when the model's element is not the solid-shell):
//! `shell_<f>_stress` (Cauchy, 6 named components), `shell_<f>_von_mises` (of that mean
//! tensor), `shell_<f>_equivalent_plastic_strain`, `shell_<f>_thickness_strain`
//! (`N · ε · N`, `N` the element's reference unit normal at its centre, `ε` the point's
//! strain: the logarithmic (Hencky) strain of the enhanced `C` under finite strain, so
//! `ln λ₃` when `N` is a principal direction; the small strain otherwise), and
//! `shell_thickness`: the mean current length of the element's four edges `a → a + 4`.
//! Cost: O(points).

use super::Field;
use crate::element::solid_shell::thickness_rule;
use crate::element::ElementKind;
use crate::geometry::Vec3;
use crate::material::PointState;
use crate::solver::Simulation;

/// The three faces written, with the level each samples among `n`: `(name, levels)`, the
/// value being the mean over `levels`.
fn faces(n: usize) -> [(&'static str, Vec<usize>); 3] {
    let mid = if n % 2 == 1 {
        vec![n / 2]
    } else {
        vec![n / 2 - 1, n / 2]
    };
    [("bottom", vec![0]), ("mid", mid), ("top", vec![n - 1])]
}

/// The element's reference unit thickness normal at its centre: `G₁ × G₂` normalised, with
/// `G_α` the centre's in-plane covariant base vectors of the trilinear map.
fn centre_normal(x: &[Vec3; 8]) -> Vec3 {
    let g1 = (x[1] - x[0]) + (x[2] - x[3]) + (x[5] - x[4]) + (x[6] - x[7]);
    let g2 = (x[3] - x[0]) + (x[2] - x[1]) + (x[7] - x[4]) + (x[6] - x[5]);
    g1.cross(&g2).normalize()
}

/// `N · ε · N` for a Voigt strain with engineering shears (`xx yy zz xy yz xz`).
fn normal_strain(e: &crate::material::Voigt, n: &Vec3) -> f64 {
    n.x * n.x * e[0]
        + n.y * n.y * e[1]
        + n.z * n.z * e[2]
        + n.x * n.y * e[3]
        + n.y * n.z * e[4]
        + n.x * n.z * e[5]
}

/// Von Mises stress of a Voigt stress (tensor shears).
fn von_mises(s: &[f64]) -> f64 {
    (0.5 * ((s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2))
        + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))
        .sqrt()
}

/// The solid-shell face and mid-surface cell fields of `sim` (module docs); empty when its
/// element is not the solid-shell.
pub fn cell_fields(sim: &Simulation) -> Vec<Field> {
    let settings = &sim.model.settings;
    let mesh = &sim.model.mesh;
    let elements = mesh.hexes.len();
    let n = settings.thickness_points;
    if settings.element != ElementKind::SolidShell
        || elements == 0
        || sim.points().len() != 4 * n * elements
    {
        return Vec::new();
    }
    let (zeta, _) = thickness_rule(n);
    let u = sim.displacements();
    let current =
        |node: usize| mesh.nodes[node] + Vec3::new(u[3 * node], u[3 * node + 1], u[3 * node + 2]);
    let mut fields = Vec::new();
    for (face, levels) in faces(n) {
        let mut stress = vec![0.0; 6 * elements];
        let mut mises = vec![0.0; elements];
        let mut plastic = vec![0.0; elements];
        let mut thickness_strain = vec![0.0; elements];
        for (e, hex) in mesh.hexes.iter().enumerate() {
            let normal = centre_normal(&hex.map(|a| mesh.nodes[a]));
            let points: Vec<&PointState> = (levels.iter())
                .flat_map(|&k| &sim.points()[4 * (n * e + k)..4 * (n * e + k + 1)])
                .collect();
            let share = 1.0 / points.len() as f64;
            for p in points {
                for i in 0..6 {
                    stress[6 * e + i] += share * p.stress[i];
                }
                plastic[e] += share * p.eq_plastic_strain;
                thickness_strain[e] += share * normal_strain(&p.strain, &normal);
            }
            mises[e] = von_mises(&stress[6 * e..6 * e + 6]);
        }
        let at = levels.iter().map(|&k| zeta[k]).sum::<f64>() / levels.len() as f64;
        fields.push(Field::symmetric_tensor(
            format!("shell_{face}_stress"),
            stress,
        ));
        fields.push(Field::scalar(format!("shell_{face}_von_mises"), mises));
        fields.push(Field::scalar(
            format!("shell_{face}_equivalent_plastic_strain"),
            plastic,
        ));
        fields.push(Field::scalar(
            format!("shell_{face}_thickness_strain"),
            thickness_strain,
        ));
        fields.push(Field::scalar(
            format!("shell_{face}_zeta"),
            vec![at; elements],
        ));
    }
    let thickness = (mesh.hexes.iter())
        .map(|hex| {
            (0..4)
                .map(|a| (current(hex[a + 4]) - current(hex[a])).norm())
                .sum::<f64>()
                / 4.0
        })
        .collect();
    fields.push(Field::scalar("shell_thickness", thickness));
    fields
}
