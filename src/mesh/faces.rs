//! Boundary faces of a hexahedral mesh and nodal tributary areas.

use std::collections::HashMap;

use super::Mesh;
use crate::geometry::Vec3;
use crate::{Error, Result};

/// The 6 faces of a hexahedron as local node indices (VTK_HEXAHEDRON order), each listed
/// counter-clockwise seen from outside the element, so that
/// `(x[f[1]] - x[f[0]]) x (x[f[3]] - x[f[0]])` points outward. Order: xi = -1, xi = +1,
/// eta = -1, eta = +1, zeta = -1, zeta = +1.
pub const HEX_FACES: [[usize; 4]; 6] = [
    [0, 4, 7, 3],
    [1, 2, 6, 5],
    [0, 1, 5, 4],
    [3, 7, 6, 2],
    [0, 3, 2, 1],
    [4, 5, 6, 7],
];

/// Gauss points (1/sqrt 3) of the 2x2 rule on [-1, 1]^2, all with weight 1.
const G: f64 = 0.577_350_269_189_625_8;
const FACE_POINTS: [[f64; 2]; 4] = [[-G, -G], [G, -G], [G, G], [-G, G]];
/// Natural coordinates of the 4 corners of a quadrilateral, counter-clockwise.
const QUAD_CORNERS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// `∫ N_a dA` for the 4 bilinear shape functions of the quadrilateral `x` (2x2 Gauss rule).
///
/// The face is the bilinear surface `x(s, t) = Σ N_a(s, t) x_a`, `dA = |x_s × x_t| ds dt`.
/// The rule is exact for plane faces (|x_s × x_t| is then linear in s and t) and the four
/// values always sum to the face area computed with the same rule.
fn quad_nodal_areas(x: &[Vec3; 4]) -> [f64; 4] {
    let mut out = [0.0; 4];
    for [s, t] in FACE_POINTS {
        let mut xs = Vec3::zeros();
        let mut xt = Vec3::zeros();
        let mut n = [0.0; 4];
        for (a, [sa, ta]) in QUAD_CORNERS.iter().enumerate() {
            n[a] = 0.25 * (1.0 + sa * s) * (1.0 + ta * t);
            xs += x[a] * (0.25 * sa * (1.0 + ta * t));
            xt += x[a] * (0.25 * ta * (1.0 + sa * s));
        }
        let da = xs.cross(&xt).norm();
        for a in 0..4 {
            out[a] += n[a] * da;
        }
    }
    out
}

/// Area of the bilinear quadrilateral with corners `x` (counter-clockwise or clockwise),
/// exact for plane quadrilaterals.
pub fn quad_area(x: &[Vec3; 4]) -> f64 {
    quad_nodal_areas(x).iter().sum()
}

impl Mesh {
    /// The boundary faces: quadrilateral element faces that belong to exactly one
    /// hexahedron, as global node indices ordered counter-clockwise seen from outside the
    /// body (outward normal `(x1 - x0) × (x3 - x0)`, see [`HEX_FACES`]).
    ///
    /// Faces are listed element by element (element index, then local face order of
    /// [`HEX_FACES`]), so the result is deterministic. Two faces match when they have the
    /// same 4 nodes, whatever their order; a face shared by two elements is interior.
    /// Node indices must be in range ([`Mesh::validate`]); an empty mesh has no faces.
    pub fn boundary_faces(&self) -> Vec<[usize; 4]> {
        let key = |f: &[usize; 4]| {
            let mut k = *f;
            k.sort_unstable();
            k
        };
        let mut count: HashMap<[usize; 4], u32> = HashMap::with_capacity(6 * self.hexes.len());
        for hex in &self.hexes {
            for lf in &HEX_FACES {
                *count.entry(key(&lf.map(|i| hex[i]))).or_insert(0) += 1;
            }
        }
        let mut faces = Vec::new();
        for hex in &self.hexes {
            for lf in &HEX_FACES {
                let f = lf.map(|i| hex[i]);
                if count[&key(&f)] == 1 {
                    faces.push(f);
                }
            }
        }
        faces
    }

    /// The boundary faces (see [`Mesh::boundary_faces`]) whose 4 nodes all belong to
    /// `nodes`, e.g. the faces of a contact surface given by a node set. Errors: an empty
    /// mesh, a node index out of range.
    pub fn faces_within(&self, nodes: &[usize]) -> Result<Vec<[usize; 4]>> {
        let member = self.membership(nodes)?;
        Ok(self
            .boundary_faces()
            .into_iter()
            .filter(|f| f.iter().all(|&n| member[n]))
            .collect())
    }

    /// The tributary area of each node of `nodes` (same order, same length), for turning a
    /// pressure or a contact traction into nodal forces.
    ///
    /// Rule: only the boundary faces whose 4 nodes are all in `nodes` count
    /// ([`Mesh::faces_within`]); each contributes `∫_face N_a dA` to each of its nodes `a`,
    /// with `N_a` the bilinear face shape function. This is the consistent nodal area of a
    /// uniform pressure: one quarter of the face area for a parallelogram face, and in all
    /// cases the areas sum to the total area of the counted faces. A node of `nodes` on no
    /// counted face (e.g. a set holding a single node) gets 0. A node listed twice gets its
    /// area at each occurrence.
    ///
    /// Errors: an empty mesh, a node index out of range.
    pub fn tributary_areas(&self, nodes: &[usize]) -> Result<Vec<f64>> {
        let faces = self.faces_within(nodes)?;
        let mut area = vec![0.0; self.nodes.len()];
        for f in &faces {
            let a = quad_nodal_areas(&f.map(|n| self.nodes[n]));
            for k in 0..4 {
                area[f[k]] += a[k];
            }
        }
        Ok(nodes.iter().map(|&n| area[n]).collect())
    }

    /// Total area of the boundary faces whose nodes all belong to `nodes`.
    pub fn surface_area(&self, nodes: &[usize]) -> Result<f64> {
        Ok(self
            .faces_within(nodes)?
            .iter()
            .map(|f| quad_area(&f.map(|n| self.nodes[n])))
            .sum())
    }

    /// Boolean membership table of `nodes`, checking the mesh is not empty and the indices
    /// are in range.
    fn membership(&self, nodes: &[usize]) -> Result<Vec<bool>> {
        if self.hexes.is_empty() {
            return Err(Error::input(
                "number of elements",
                0,
                "must be >= 1 (the mesh is empty)",
            ));
        }
        let mut member = vec![false; self.nodes.len()];
        for &n in nodes {
            if n >= self.nodes.len() {
                return Err(Error::input(
                    "node index",
                    n,
                    &format!("must be < {} (the number of nodes)", self.nodes.len()),
                ));
            }
            member[n] = true;
        }
        Ok(member)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{End, Grading};

    #[test]
    fn hex_faces_point_outward_on_reference_cube() {
        let x: Vec<Vec3> = crate::mesh::HEX_CORNERS
            .iter()
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect();
        for (k, f) in HEX_FACES.iter().enumerate() {
            let n = (x[f[1]] - x[f[0]]).cross(&(x[f[3]] - x[f[0]]));
            let centre = f.iter().map(|&i| x[i]).sum::<Vec3>() / 4.0;
            assert!(n.dot(&centre) > 0.0, "face {k}");
            // Each face is a face of the cube: its 4 nodes share one natural coordinate.
            let axis = k / 2;
            let side = if k % 2 == 0 { -1.0 } else { 1.0 };
            assert!(f.iter().all(|&i| x[i][axis] == side), "face {k}");
        }
    }

    #[test]
    fn boundary_faces_of_block_are_outward_and_close_the_surface() {
        let mesh = Mesh::block(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 3.0, 1.0),
            [2, 3, 2],
        )
        .unwrap();
        let faces = mesh.boundary_faces();
        assert_eq!(faces.len(), 2 * (2 * 3 + 3 * 2 + 2 * 2));

        // Closed oriented surface: Σ n dA = 0, and the divergence theorem gives the volume,
        // V = (1/3) Σ ∫ x·n dA (exact for plane faces with the face-centre rule on boxes).
        let mut sum_n = Vec3::zeros();
        let mut volume = 0.0;
        for f in &faces {
            let x = f.map(|n| mesh.nodes[n]);
            let n = (x[1] - x[0]).cross(&(x[3] - x[0]));
            let centre = x.iter().sum::<Vec3>() / 4.0;
            sum_n += n;
            volume += centre.dot(&n) / 3.0;
        }
        assert!(sum_n.norm() < 1e-12);
        assert!((volume - 6.0).abs() < 1e-12, "{volume}");

        // A single hexahedron: all 6 faces are boundary faces, interior faces vanish.
        let one = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
        assert_eq!(one.boundary_faces().len(), 6);
    }

    #[test]
    fn tributary_areas_sum_to_face_area() {
        let mesh = Mesh::block_graded(
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(2.0, 3.0, 0.5),
            [4, 3, 2],
            [
                Grading::Toward {
                    end: End::Min,
                    ratio: 3.0,
                },
                Grading::Uniform,
                Grading::Uniform,
            ],
        )
        .unwrap();
        for (name, area) in [("z+", 6.0), ("z-", 6.0), ("x-", 1.5), ("y+", 1.0)] {
            let set = mesh.node_set(name).unwrap();
            let a = mesh.tributary_areas(set).unwrap();
            assert_eq!(a.len(), set.len());
            assert!((a.iter().sum::<f64>() - area).abs() < 1e-12, "{name}");
            assert!(a.iter().all(|&v| v > 0.0), "{name}");
            assert!((mesh.surface_area(set).unwrap() - area).abs() < 1e-12);
        }
        // Uniform 2x2 grid of unit cells on z+: a corner gets 1/4 of a cell, an edge node
        // 1/2, the centre node a full cell.
        let m = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 2.0, 1.0), [2, 2, 1]).unwrap();
        let set = m.node_set("z+").unwrap();
        let a = m.tributary_areas(set).unwrap();
        let expected = [0.25, 0.5, 0.25, 0.5, 1.0, 0.5, 0.25, 0.5, 0.25];
        for (got, want) in a.iter().zip(expected) {
            assert!((got - want).abs() < 1e-15, "{a:?}");
        }

        // Only faces entirely within the set count: one node alone has no area, and a set
        // made of the z+ nodes plus one z- node adds nothing for that node.
        assert_eq!(m.tributary_areas(&[set[4]]).unwrap(), vec![0.0]);
        let mut more = set.to_vec();
        more.push(0);
        let b = m.tributary_areas(&more).unwrap();
        assert_eq!(b[9], 0.0);
        assert!((b.iter().sum::<f64>() - 4.0).abs() < 1e-14);
    }

    #[test]
    fn tributary_areas_of_distorted_plane_face_are_exact() {
        // A single element whose top face is a plane, non-parallelogram quadrilateral
        // (a trapezoid): ∫ N_a dA is exact and the sum is the trapezoid area.
        let nodes = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(3.0, 0.0, 1.0),
            Vec3::new(2.0, 1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let mesh = Mesh::new(nodes, vec![[0, 1, 2, 3, 4, 5, 6, 7]]).unwrap();
        let a = mesh.tributary_areas(&[4, 5, 6, 7]).unwrap();
        assert!((a.iter().sum::<f64>() - 2.5).abs() < 1e-14);
        // Exact values: on this face x_s = (5 - t, 0)/4, x_t = (-(1 + s), 2)/4, so
        // dA = (5 - t)/8 ds dt and ∫ N_a dA = (10 - 2 t_a / 3)/16 with t_a = -1 for the
        // nodes 4, 5 of the long side and +1 for the nodes 6, 7 of the short side.
        let exact = [2.0 / 3.0, 2.0 / 3.0, 7.0 / 12.0, 7.0 / 12.0];
        for k in 0..4 {
            assert!((a[k] - exact[k]).abs() < 1e-14, "{a:?}");
        }
    }

    #[test]
    fn face_queries_reject_empty_mesh_and_bad_index() {
        let empty = Mesh::default();
        let e = empty.tributary_areas(&[]).unwrap_err().to_string();
        assert!(e.contains("mesh is empty"), "{e}");
        assert!(empty.boundary_faces().is_empty());
        let m = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
        let e = m.tributary_areas(&[0, 8]).unwrap_err().to_string();
        assert!(e.contains("node index = 8 must be < 8"), "{e}");
    }
}
