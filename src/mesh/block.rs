//! Structured block meshes: a box split into `cells[0] x cells[1] x cells[2]` hexahedra,
//! with uniform or geometrically graded spacing along each axis.

use std::collections::BTreeMap;

use super::Mesh;
use crate::geometry::Vec3;
use crate::{Error, Result};

/// Largest number of nodes [`Mesh::block`] will generate. It guards against a typo such as
/// `cells = [1000, 1000, 1000]` exhausting memory (an allocation failure aborts the process
/// instead of returning an error).
pub const MAX_BLOCK_NODES: usize = 50_000_000;

/// One end of an axis of a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// The end at the smallest coordinate (`origin`).
    Min,
    /// The end at the largest coordinate (`origin + size`).
    Max,
}

/// Spacing of the cells along one axis of a block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Grading {
    /// All cells have the same width `size / cells`.
    Uniform,
    /// Cell widths form a geometric progression along the axis:
    ///
    /// `ratio` = (width of the cell farthest from `end`) / (width of the cell next to `end`).
    ///
    /// So `ratio > 1` makes the cells next to `end` the smallest (the mesh is refined toward
    /// `end`, e.g. toward a contact surface), `ratio < 1` makes them the largest, and
    /// `ratio = 1` is uniform. With `n` cells, consecutive cells (moving away from `end`)
    /// grow by the factor `q = ratio^(1/(n-1))`; a single cell ignores the ratio. `ratio`
    /// must be finite and > 0.
    Toward { end: End, ratio: f64 },
}

impl Mesh {
    /// A box `[origin, origin + size]` split uniformly into `cells[0] x cells[1] x cells[2]`
    /// hexahedra. See [`Mesh::block_graded`].
    pub fn block(origin: Vec3, size: Vec3, cells: [usize; 3]) -> Result<Mesh> {
        Mesh::block_graded(origin, size, cells, [Grading::Uniform; 3])
    }

    /// A box `[origin, origin + size]` split into `cells[0] x cells[1] x cells[2]`
    /// hexahedra, with the spacing along axis `d` given by `grading[d]`.
    ///
    /// Numbering: node (i, j, k) (i along x, from 0 to cells[0]) has index
    /// `i + (cells[0] + 1) * (j + (cells[1] + 1) * k)`; the element (i, j, k) has index
    /// `i + cells[0] * (j + cells[1] * k)` and VTK_HEXAHEDRON connectivity (positive
    /// Jacobian). The six faces of the box are the node sets "x-", "x+", "y-", "y+", "z-",
    /// "z+" ("x-" = the nodes with i = 0, ...). The through-thickness node columns along z
    /// (i, j fixed, k from 0 up) are kept as [`Mesh::columns`] for thickness output.
    ///
    /// Errors: a zero cell count, a non-positive or non-finite size, a non-finite origin, a
    /// grading ratio that is not finite and > 0 (or so extreme that cells collapse), more
    /// than [`MAX_BLOCK_NODES`] nodes.
    pub fn block_graded(
        origin: Vec3,
        size: Vec3,
        cells: [usize; 3],
        grading: [Grading; 3],
    ) -> Result<Mesh> {
        for d in 0..3 {
            if cells[d] == 0 {
                return Err(Error::input(&format!("cells[{d}]"), 0, "must be >= 1"));
            }
            if !origin[d].is_finite() {
                return Err(Error::input(
                    &format!("origin[{d}]"),
                    origin[d],
                    "must be finite",
                ));
            }
            if !size[d].is_finite() {
                return Err(Error::input(
                    &format!("size[{d}]"),
                    size[d],
                    "must be finite",
                ));
            }
            if size[d] <= 0.0 {
                return Err(Error::input(&format!("size[{d}]"), size[d], "must be > 0"));
            }
        }
        let per_axis = cells.map(|c| c.checked_add(1));
        let node_count = per_axis
            .iter()
            .try_fold(1usize, |acc, n| n.and_then(|n| acc.checked_mul(n)))
            .filter(|&n| n <= MAX_BLOCK_NODES)
            .ok_or_else(|| {
                Error::input(
                    "cells",
                    format!("[{}, {}, {}]", cells[0], cells[1], cells[2]),
                    &format!("must give at most {MAX_BLOCK_NODES} nodes"),
                )
            })?;

        let coords: Vec<Vec<f64>> = (0..3)
            .map(|d| axis_coordinates(d, origin[d], size[d], cells[d], grading[d]))
            .collect::<Result<_>>()?;
        Ok(Mesh::grid(&coords, node_count))
    }

    /// The structured grid on the node coordinates `coords[d]` along axis `d` (each
    /// strictly increasing, checked by the caller), numbered, with face sets and columns,
    /// as [`Mesh::block_graded`] documents.
    pub(super) fn grid(coords: &[Vec<f64>], node_count: usize) -> Mesh {
        let cells = [0, 1, 2].map(|d| coords[d].len() - 1);
        let [nx, ny, nz] = cells;
        let node = |i: usize, j: usize, k: usize| i + (nx + 1) * (j + (ny + 1) * k);

        let mut nodes = Vec::with_capacity(node_count);
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    nodes.push(Vec3::new(coords[0][i], coords[1][j], coords[2][k]));
                }
            }
        }

        let mut hexes = Vec::with_capacity(nx * ny * nz);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    hexes.push([
                        node(i, j, k),
                        node(i + 1, j, k),
                        node(i + 1, j + 1, k),
                        node(i, j + 1, k),
                        node(i, j, k + 1),
                        node(i + 1, j, k + 1),
                        node(i + 1, j + 1, k + 1),
                        node(i, j + 1, k + 1),
                    ]);
                }
            }
        }

        // Face sets: all nodes whose grid index along `axis` is `at`. Generated in
        // increasing node index order (k outermost), so they are already sorted.
        let face = |axis: usize, at: usize| -> Vec<usize> {
            let mut set = Vec::new();
            for k in 0..=nz {
                for j in 0..=ny {
                    for i in 0..=nx {
                        if [i, j, k][axis] == at {
                            set.push(node(i, j, k));
                        }
                    }
                }
            }
            set
        };
        let mut node_sets = BTreeMap::new();
        for (axis, name) in ["x", "y", "z"].iter().enumerate() {
            node_sets.insert(format!("{name}-"), face(axis, 0));
            node_sets.insert(format!("{name}+"), face(axis, cells[axis]));
        }

        // Sheet columns along z (the thickness direction of a block used as a sheet).
        let columns = (0..=ny)
            .flat_map(|j| (0..=nx).map(move |i| (i, j)))
            .map(|(i, j)| (0..=nz).map(|k| node(i, j, k)).collect())
            .collect();
        Mesh {
            nodes,
            hexes,
            node_sets,
            columns,
            ..Mesh::default()
        }
    }
}

/// The `n + 1` node coordinates along axis `d` of a block, strictly increasing from
/// `origin` to exactly `origin + size`.
pub(super) fn axis_coordinates(
    d: usize,
    origin: f64,
    size: f64,
    n: usize,
    grading: Grading,
) -> Result<Vec<f64>> {
    // Normalised positions t_0 = 0 < t_1 < ... < t_n = 1.
    let t: Vec<f64> = match grading {
        Grading::Uniform => (0..=n).map(|i| i as f64 / n as f64).collect(),
        Grading::Toward { end, ratio } => {
            if !(ratio.is_finite() && ratio > 0.0) {
                return Err(Error::input(
                    &format!("grading[{d}] ratio"),
                    ratio,
                    "must be finite and > 0",
                ));
            }
            // Cell i (counted from `end`) has width proportional to q^i, so the position of
            // node i is t_i = (q^i - 1) / (q^n - 1). Written with expm1(i ln q) because
            // (q^i - 1) loses all its digits when q is close to 1.
            let ln_q = if n > 1 {
                ratio.ln() / (n - 1) as f64
            } else {
                0.0
            };
            let from_end: Vec<f64> = if ln_q == 0.0 {
                (0..=n).map(|i| i as f64 / n as f64).collect()
            } else {
                let total = (n as f64 * ln_q).exp_m1();
                (0..=n)
                    .map(|i| (i as f64 * ln_q).exp_m1() / total)
                    .collect()
            };
            match end {
                End::Min => from_end,
                End::Max => (0..=n).map(|i| 1.0 - from_end[n - i]).collect(),
            }
        }
    };
    let mut x: Vec<f64> = t.iter().map(|t| origin + size * t).collect();
    // Pin both ends exactly, whatever the rounding of the progression.
    x[0] = origin;
    x[n] = origin + size;
    if let Some(i) = (0..n).find(|&i| !(x[i + 1] > x[i])) {
        return Err(Error::input(
            &format!("grading[{d}]"),
            format!("{grading:?}"),
            &format!("makes cell {i} of {n} along axis {d} have zero width (ratio too extreme)"),
        ));
    }
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn widths(mesh: &Mesh, axis: usize, n: usize, stride: usize) -> Vec<f64> {
        (0..n)
            .map(|i| mesh.nodes[(i + 1) * stride][axis] - mesh.nodes[i * stride][axis])
            .collect()
    }

    #[test]
    fn block_counts_connectivity_and_face_sets() {
        let mesh = Mesh::block(
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(2.0, 3.0, 4.0),
            [2, 3, 4],
        )
        .unwrap();
        assert_eq!(mesh.node_count(), 3 * 4 * 5);
        assert_eq!(mesh.element_count(), 2 * 3 * 4);
        mesh.validate().unwrap();
        assert_eq!(mesh.node_set("x-").unwrap().len(), 4 * 5);
        assert_eq!(mesh.node_set("x+").unwrap().len(), 4 * 5);
        assert_eq!(mesh.node_set("y-").unwrap().len(), 3 * 5);
        assert_eq!(mesh.node_set("y+").unwrap().len(), 3 * 5);
        assert_eq!(mesh.node_set("z-").unwrap().len(), 3 * 4);
        assert_eq!(mesh.node_set("z+").unwrap().len(), 3 * 4);
        let names: Vec<&str> = mesh.node_set_names().collect();
        assert_eq!(names, vec!["x+", "x-", "y+", "y-", "z+", "z-"]);

        // Face sets hold exactly the nodes on the corresponding face, in ascending order.
        let (lo, hi) = mesh.bounding_box().unwrap();
        assert_eq!(lo, Vec3::new(1.0, -2.0, 0.5));
        assert_eq!(hi, Vec3::new(3.0, 1.0, 4.5));
        for (axis, name) in ["x", "y", "z"].iter().enumerate() {
            let minus = mesh.select_nodes(|x| x[axis] == lo[axis]);
            let plus = mesh.select_nodes(|x| x[axis] == hi[axis]);
            assert_eq!(
                mesh.node_set(&format!("{name}-")).unwrap(),
                minus.as_slice()
            );
            assert_eq!(mesh.node_set(&format!("{name}+")).unwrap(), plus.as_slice());
        }

        // Element (1, 2, 3) (the last one): its node 0 is grid node (1, 2, 3), node 6 is
        // grid node (2, 3, 4), the opposite corner of the box.
        let last = mesh.hexes[2 * 3 * 4 - 1];
        assert_eq!(last[0], 1 + 3 * (2 + 4 * 3));
        assert_eq!(mesh.nodes[last[6]], hi);

        // Total volume = sum of the element volumes (each element is a box here).
        let vol: f64 = (0..mesh.element_count())
            .map(|e| {
                let x = mesh.hex_coordinates(e);
                let d = x[6] - x[0];
                d.x * d.y * d.z
            })
            .sum();
        assert!((vol - 24.0).abs() < 1e-12);
    }

    #[test]
    fn graded_spacing_has_constant_ratio_and_requested_end_ratio() {
        let n = 5;
        let ratio = 8.0;
        let mesh = Mesh::block_graded(
            Vec3::zeros(),
            Vec3::new(2.0, 1.0, 3.0),
            [n, 1, n],
            [
                Grading::Toward {
                    end: End::Min,
                    ratio,
                },
                Grading::Uniform,
                Grading::Toward {
                    end: End::Max,
                    ratio,
                },
            ],
        )
        .unwrap();
        mesh.validate().unwrap();
        let q = ratio.powf(1.0 / (n - 1) as f64);

        // x: refined toward x = 0, cells grow by q moving away from it.
        let wx = widths(&mesh, 0, n, 1);
        for i in 0..n - 1 {
            assert!((wx[i + 1] / wx[i] - q).abs() < 1e-12, "{wx:?}");
        }
        assert!((wx[n - 1] / wx[0] - ratio).abs() < 1e-12);
        assert!((wx.iter().sum::<f64>() - 2.0).abs() < 1e-14);

        // z: refined toward z = 3 (the Max end): the top cell is the smallest.
        let stride_z = (n + 1) * 2;
        let wz = widths(&mesh, 2, n, stride_z);
        for i in 0..n - 1 {
            assert!((wz[i] / wz[i + 1] - q).abs() < 1e-12, "{wz:?}");
        }
        assert!((wz[0] / wz[n - 1] - ratio).abs() < 1e-12);
        assert_eq!(mesh.nodes[n * stride_z].z, 3.0);

        // ratio < 1 coarsens toward the end; ratio = 1 is uniform; one cell ignores it.
        let m = Mesh::block_graded(
            Vec3::zeros(),
            Vec3::new(1.0, 1.0, 1.0),
            [4, 3, 1],
            [
                Grading::Toward {
                    end: End::Min,
                    ratio: 0.5,
                },
                Grading::Toward {
                    end: End::Max,
                    ratio: 1.0,
                },
                Grading::Toward {
                    end: End::Min,
                    ratio: 100.0,
                },
            ],
        )
        .unwrap();
        let wx = widths(&m, 0, 4, 1);
        assert!((wx[3] / wx[0] - 0.5).abs() < 1e-12);
        let wy = widths(&m, 1, 3, 5);
        for w in wy {
            assert!((w - 1.0 / 3.0).abs() < 1e-15);
        }
        assert_eq!(m.nodes[m.node_count() - 1].z, 1.0);

        // A ratio within rounding of 1 stays accurate (expm1 form).
        let m = Mesh::block_graded(
            Vec3::zeros(),
            Vec3::new(1.0, 1.0, 1.0),
            [10, 1, 1],
            [
                Grading::Toward {
                    end: End::Min,
                    ratio: 1.0 + 1e-12,
                },
                Grading::Uniform,
                Grading::Uniform,
            ],
        )
        .unwrap();
        for (i, w) in widths(&m, 0, 10, 1).iter().enumerate() {
            assert!((w - 0.1).abs() < 1e-12, "cell {i}: {w}");
        }
    }

    #[test]
    fn block_input_errors_name_the_value() {
        let one = Vec3::new(1.0, 1.0, 1.0);
        let err = |r: Result<Mesh>| r.unwrap_err().to_string();

        let e = err(Mesh::block(Vec3::zeros(), one, [2, 0, 2]));
        assert!(e.contains("cells[1] = 0 must be >= 1"), "{e}");
        let e = err(Mesh::block(
            Vec3::zeros(),
            Vec3::new(1.0, 1.0, -2.0),
            [1, 1, 1],
        ));
        assert!(e.contains("size[2] = -2 must be > 0"), "{e}");
        let e = err(Mesh::block(
            Vec3::zeros(),
            Vec3::new(0.0, 1.0, 1.0),
            [1, 1, 1],
        ));
        assert!(e.contains("size[0] = 0 must be > 0"), "{e}");
        let e = err(Mesh::block(
            Vec3::zeros(),
            Vec3::new(1.0, f64::INFINITY, 1.0),
            [1, 1, 1],
        ));
        assert!(e.contains("size[1] = inf must be finite"), "{e}");
        let e = err(Mesh::block(Vec3::new(f64::NAN, 0.0, 0.0), one, [1, 1, 1]));
        assert!(e.contains("origin[0] = NaN must be finite"), "{e}");
        let e = err(Mesh::block(Vec3::zeros(), one, [1000, 1000, 1000]));
        assert!(e.contains("must give at most"), "{e}");
        let e = err(Mesh::block(Vec3::zeros(), one, [usize::MAX, 1, 1]));
        assert!(e.contains("must give at most"), "{e}");

        let bad = Grading::Toward {
            end: End::Max,
            ratio: -2.0,
        };
        let e = err(Mesh::block_graded(
            Vec3::zeros(),
            one,
            [2, 2, 2],
            [Grading::Uniform, bad, Grading::Uniform],
        ));
        assert!(
            e.contains("grading[1] ratio = -2 must be finite and > 0"),
            "{e}"
        );
        let nan = Grading::Toward {
            end: End::Min,
            ratio: f64::NAN,
        };
        assert!(Mesh::block_graded(Vec3::zeros(), one, [2, 2, 2], [nan; 3]).is_err());
        let extreme = Grading::Toward {
            end: End::Min,
            ratio: 1e300,
        };
        let e = err(Mesh::block_graded(
            Vec3::zeros(),
            one,
            [2, 2, 2],
            [extreme, Grading::Uniform, Grading::Uniform],
        ));
        assert!(e.contains("zero width"), "{e}");
    }

    /// Columns run bottom to top through the thickness, one per (i, j), and their length
    /// is the thickness; a uniform through-thickness stretch scales it.
    #[test]
    fn columns_measure_the_thickness() {
        let m = Mesh::block(Vec3::zeros(), Vec3::new(4.0, 2.0, 0.8), [4, 2, 3]).unwrap();
        assert_eq!(m.columns().len(), 5 * 3);
        for col in m.columns() {
            assert_eq!(col.len(), 4);
            let p0 = m.nodes[col[0]];
            assert_eq!(p0.z, 0.0);
            for w in col.windows(2) {
                let (a, b) = (m.nodes[w[0]], m.nodes[w[1]]);
                assert!(a.x == b.x && a.y == b.y && b.z > a.z);
            }
        }
        let t = m.column_thicknesses(|n| Vec3::new(0.3, 0.0, -0.1 * m.nodes[n].z));
        assert!(t.iter().all(|t| (t - 0.72).abs() < 1e-14));
        assert!(Mesh::new(m.nodes.clone(), m.hexes.clone())
            .unwrap()
            .columns()
            .is_empty());
    }
}
