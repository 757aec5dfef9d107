//! Rigid-body modes of the sheet left free by its supports (the Dirichlet conditions), for
//! a step that releases the sheet from every tool (`Step::release`).
//!
//! The six rigid-body motions of the mesh are `u = t` (three translations) and
//! `u = w x (x - c)` (three rotations about the centroid `c` of the nodes). Restricted to
//! the fixed degrees of freedom they give the matrix `A` (one row per fixed component of a
//! node, one column per mode: `A[(3n + i), j] = m_j(x_n)_i`); the rotations' columns are
//! divided by the mesh's size `L` (largest distance of a node from `c`) so that all
//! columns are O(1). A combination `a` of modes is left free exactly when `A a = 0`, i.e.
//! `a` is in the null space of `A`, that of `G = A^T A` (6 x 6, symmetric): the modes with
//! `G_jj = 0` (free on their own, named as they are) and the eigenvectors of `G` on the
//! other modes whose eigenvalue is below `1e-10 max(1, max G_jj)`: a fixed component moved
//! by a mode contributes at least O(h^2 / L^2) to its eigenvalue (h the smallest node
//! spacing), far above that threshold for any mesh of fewer than 10^4 elements per side.
//! The check reads the constraints, never a message, and handles symmetry conditions as
//! they are: a half model fixed in x on its symmetry plane needs supports only for the
//! modes that leaves free. The same count chooses the 3-2-1 default supports of a step
//! (`three_two_one`): candidate components are added one at a time and kept when the
//! number of free modes drops.

use super::Model;
use crate::geometry::Vec3;
use nalgebra::{DMatrix, Matrix6, SymmetricEigen, Vector6};

/// Names of the six modes, in column order.
const MODES: [&str; 6] = [
    "translation x",
    "translation y",
    "translation z",
    "rotation about x",
    "rotation about y",
    "rotation about z",
];

/// The rigid-body modes the model's Dirichlet conditions leave free, each described by
/// its components (`translation z`, or `0.71 translation x + 0.71 rotation about y` for a
/// combination); empty when the supports hold the sheet. Rotations are about the nodes'
/// centroid. O(fixed components).
pub fn free_rigid_body_modes(model: &Model) -> Vec<String> {
    Gram::new(model, dirichlet_components(model)).free_modes()
}

/// The rigid-body modes left free in step `k`: by the Dirichlet conditions and the step's
/// own supports (`Step::supports`).
pub fn free_rigid_body_modes_in_step(model: &Model, k: usize) -> Vec<String> {
    let supports = model.steps[k]
        .supports
        .iter()
        .flat_map(|s| s.nodes.iter().map(move |&n| (n, s.component)));
    Gram::new(model, dirichlet_components(model).chain(supports)).free_modes()
}

/// The 3-2-1 default supports of step `k`: node components that, added to the Dirichlet
/// conditions and the step's named supports, remove exactly the rigid-body modes they
/// leave free, each one removing one (so none is redundant: at an equilibrium without
/// tools their reactions vanish). Candidates, in order: the node `A` nearest the nodes'
/// centroid, the node `B` farthest from `A`, the node `C` farthest from the line `AB`;
/// each with its x, y and z, a component taken when it lowers the number of free modes
/// (the rank of `G` rises by one). So a free sheet gets x, y, z at `A`, two components at
/// `B` and one at `C` (3-2-1), and a symmetric plane-strain strip, whose conditions leave
/// only the vertical translation free, gets z at `A` alone. Empty for an empty mesh.
pub fn three_two_one(model: &Model, k: usize) -> Vec<(usize, usize)> {
    let nodes = &model.mesh.nodes;
    if nodes.is_empty() {
        return Vec::new();
    }
    let named = model.steps[k]
        .supports
        .iter()
        .flat_map(|s| s.nodes.iter().map(move |&n| (n, s.component)));
    let mut constraints: Vec<(usize, usize)> = dirichlet_components(model).chain(named).collect();
    let c = centroid(nodes);
    let nearest = |key: &dyn Fn(&Vec3) -> f64| {
        (0..nodes.len())
            .min_by(|&a, &b| key(&nodes[a]).total_cmp(&key(&nodes[b])))
            .unwrap_or(0)
    };
    let a = nearest(&|p| (p - c).norm());
    let b = nearest(&|p| -(p - nodes[a]).norm());
    let ab = (nodes[b] - nodes[a])
        .try_normalize(0.0)
        .unwrap_or(Vec3::x());
    let c_node = nearest(&|p| -(p - nodes[a]).cross(&ab).norm());
    let mut free = Gram::new(model, constraints.iter().copied())
        .free_modes()
        .len();
    let mut chosen = Vec::new();
    for node in [a, b, c_node] {
        for component in 0..3 {
            if free == 0 {
                return chosen;
            }
            constraints.push((node, component));
            let now = Gram::new(model, constraints.iter().copied())
                .free_modes()
                .len();
            if now < free {
                free = now;
                chosen.push((node, component));
            } else {
                constraints.pop();
            }
        }
    }
    chosen
}

/// The fixed (node, component) pairs of the Dirichlet conditions.
fn dirichlet_components(model: &Model) -> impl Iterator<Item = (usize, usize)> + '_ {
    model
        .dirichlet
        .iter()
        .flat_map(|bc| bc.nodes.iter().map(move |&n| (n, bc.component)))
}

fn centroid(nodes: &[Vec3]) -> Vec3 {
    nodes.iter().fold(Vec3::zeros(), |s, p| s + p) / nodes.len().max(1) as f64
}

/// `G = A^T A` of a set of fixed components (module doc).
struct Gram(Matrix6<f64>);

impl Gram {
    fn new(model: &Model, fixed: impl Iterator<Item = (usize, usize)>) -> Gram {
        let nodes = &model.mesh.nodes;
        let mut g = Matrix6::<f64>::zeros();
        if nodes.is_empty() {
            return Gram(g);
        }
        let c = centroid(nodes);
        let size = nodes.iter().map(|p| (p - c).norm()).fold(0.0, f64::max);
        let size = if size > 0.0 { size } else { 1.0 };
        for (n, component) in fixed {
            let row = mode_row(&((nodes[n] - c) / size), component);
            g += row * row.transpose();
        }
        Gram(g)
    }

    /// The modes in the null space of `G`, described (module doc).
    fn free_modes(&self) -> Vec<String> {
        let g = &self.0;
        let tol = 1e-10 * (0..6).map(|j| g[(j, j)]).fold(1.0, f64::max);
        // A mode no fixed component sees has a zero row and column in G: it is free on its
        // own and named as it is; the null space of G on the other modes (combinations) is
        // described by its eigenvectors.
        let (pure, rest): (Vec<usize>, Vec<usize>) = (0..6).partition(|&j| g[(j, j)] <= tol);
        let mut free: Vec<String> = pure.iter().map(|&j| MODES[j].to_string()).collect();
        if rest.is_empty() {
            // nalgebra's eigensolver refuses an empty matrix.
            return free;
        }
        let sub = DMatrix::from_fn(rest.len(), rest.len(), |a, b| g[(rest[a], rest[b])]);
        let eigen = SymmetricEigen::new(sub);
        for k in (0..rest.len()).filter(|&k| eigen.eigenvalues[k] <= tol) {
            let mut v = Vector6::zeros();
            for (a, &j) in rest.iter().enumerate() {
                v[j] = eigen.eigenvectors[(a, k)];
            }
            free.push(describe(&v));
        }
        free
    }
}

/// Component `i` of the six modes at the scaled position `r`: `e_i` for the translations,
/// `(e_j x r)_i` for the rotations.
fn mode_row(r: &Vec3, i: usize) -> Vector6<f64> {
    let mut row = Vector6::zeros();
    row[i] = 1.0;
    for j in 0..3 {
        let mut axis = Vec3::zeros();
        axis[j] = 1.0;
        row[3 + j] = axis.cross(r)[i];
    }
    row
}

/// A null vector in words: its components above 0.05 (of a unit vector), largest first.
fn describe(v: &Vector6<f64>) -> String {
    let mut parts: Vec<(f64, &str)> = (0..6)
        .filter(|&j| v[j].abs() > 0.05)
        .map(|j| (v[j], MODES[j]))
        .collect();
    parts.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
    if parts.len() == 1 {
        return parts[0].1.to_string();
    }
    let sign = parts[0].0.signum();
    parts
        .iter()
        .map(|(a, name)| format!("{:.2} {name}", a * sign))
        .collect::<Vec<_>>()
        .join(" + ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::LinearElastic;
    use crate::mesh::Mesh;
    use crate::solver::model::Dirichlet;
    use crate::tool::ScalarSchedule;

    /// A 4 x 1 x 1 block of 4 x 1 x 2 cells with `fixes` (node predicate, component).
    fn model(fixes: &[(&dyn Fn(&Vec3) -> bool, usize)]) -> Model {
        let mesh = Mesh::block(Vec3::zeros(), Vec3::new(4.0, 1.0, 1.0), [4, 1, 2]).unwrap();
        let material = std::sync::Arc::new(LinearElastic::new(1000.0, 0.3).unwrap());
        let mut model = Model::new(mesh, material).unwrap();
        for (i, (on, component)) in fixes.iter().enumerate() {
            let nodes = (0..model.mesh.nodes.len())
                .filter(|&n| on(&model.mesh.nodes[n]))
                .collect();
            model.dirichlet.push(Dirichlet {
                label: format!("fix {i}"),
                nodes,
                component: *component,
                value: ScalarSchedule::constant(0.0),
            });
        }
        model
    }

    #[test]
    fn no_support_leaves_all_six_modes_free() {
        assert_eq!(free_rigid_body_modes(&model(&[])).len(), 6);
    }

    #[test]
    fn a_symmetric_strip_needs_a_vertical_support_only() {
        // The U-channel strip's conditions: x fixed on the symmetry plane x = 0, y on both
        // faces y = 0 and y = 1 (plane strain). Free: the vertical translation only.
        let x0 = |p: &Vec3| p.x == 0.0;
        let y0 = |p: &Vec3| p.y == 0.0;
        let y1 = |p: &Vec3| p.y == 1.0;
        let strip = [(&x0 as &dyn Fn(&Vec3) -> bool, 0), (&y0, 1), (&y1, 1)];
        assert_eq!(free_rigid_body_modes(&model(&strip)), ["translation z"]);
        // A vertical support at one node of the symmetry plane holds it.
        let node = |p: &Vec3| p.x == 0.0 && p.y == 0.0 && p.z == 0.0;
        let held = [
            strip[0],
            strip[1],
            strip[2],
            (&node as &dyn Fn(&Vec3) -> bool, 2),
        ];
        assert!(free_rigid_body_modes(&model(&held)).is_empty());
    }

    #[test]
    fn three_two_one_supports_hold_the_sheet_and_one_fewer_does_not() {
        // 3-2-1: z at three corners not on a line, y at two, x at one.
        let a = |p: &Vec3| p.x == 0.0 && p.y == 0.0 && p.z == 0.0;
        let b = |p: &Vec3| p.x == 4.0 && p.y == 0.0 && p.z == 0.0;
        let d = |p: &Vec3| p.x == 0.0 && p.y == 1.0 && p.z == 0.0;
        let ab = |p: &Vec3| a(p) || b(p);
        let abd = |p: &Vec3| a(p) || b(p) || d(p);
        let full = [
            (&abd as &dyn Fn(&Vec3) -> bool, 2),
            (&ab as &dyn Fn(&Vec3) -> bool, 1),
            (&a as &dyn Fn(&Vec3) -> bool, 0),
        ];
        assert!(free_rigid_body_modes(&model(&full)).is_empty());
        // Without the x support the sheet slides along x.
        assert_eq!(free_rigid_body_modes(&model(&full[..2])), ["translation x"]);
        // With z at two corners only, it turns about the line through them (the x axis
        // through y = 0, z = 0: a rotation about x with the translations that move that
        // line onto the centroid's axis).
        let two = [(&ab as &dyn Fn(&Vec3) -> bool, 2), full[1], full[2]];
        let free = free_rigid_body_modes(&model(&two));
        assert_eq!(free.len(), 1, "{free:?}");
        assert!(free[0].contains("rotation about x"), "{free:?}");
    }

    /// `model` with its 3-2-1 default supports of a one-step process added as Dirichlet
    /// conditions (what the step holds).
    fn with_three_two_one(mut model: Model) -> (Model, Vec<(usize, usize)>) {
        model
            .steps
            .push(crate::solver::model::steps::Step::plain("release", 1.0, 1));
        let chosen = three_two_one(&model, 0);
        for &(n, component) in &chosen {
            model.dirichlet.push(Dirichlet {
                label: "3-2-1".into(),
                nodes: vec![n],
                component,
                value: ScalarSchedule::constant(0.0),
            });
        }
        (model, chosen)
    }

    #[test]
    fn the_three_two_one_default_removes_exactly_the_free_modes() {
        // A free block: six components, three at one node, two at a second, one at a third.
        let (held, chosen) = with_three_two_one(model(&[]));
        assert_eq!(chosen.len(), 6, "{chosen:?}");
        let mut per_node: Vec<usize> = chosen
            .iter()
            .map(|&(n, _)| chosen.iter().filter(|c| c.0 == n).count())
            .collect();
        per_node.dedup();
        assert_eq!(per_node, [3, 2, 1], "{chosen:?}");
        assert!(free_rigid_body_modes(&held).is_empty());
        // The symmetric plane-strain strip: its conditions leave the vertical translation
        // free, and one vertical component holds it.
        let x0 = |p: &Vec3| p.x == 0.0;
        let y0 = |p: &Vec3| p.y == 0.0;
        let y1 = |p: &Vec3| p.y == 1.0;
        let strip = [(&x0 as &dyn Fn(&Vec3) -> bool, 0), (&y0, 1), (&y1, 1)];
        let (held, chosen) = with_three_two_one(model(&strip));
        assert_eq!(chosen.len(), 1, "{chosen:?}");
        assert_eq!(chosen[0].1, 2, "a vertical support: {chosen:?}");
        assert!(free_rigid_body_modes(&held).is_empty());
        // A held model needs none.
        assert!(with_three_two_one(held).1.is_empty());
    }
}
