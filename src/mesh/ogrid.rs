//! Round blanks meshed with hexahedra: an O-grid of a disk (or of its quadrant
//! `x, y >= 0`) extruded through the thickness.
//!
//! # Layout in the plane
//!
//! ```text
//!   core        square [-a, a]^2 (quarter: [0, a]^2), n cells per quarter side, node lines
//!               x_i = a tan(pi/4 * i/n): straight, and the boundary node i lies on the ray
//!               at the angle pi/4 * i/n
//!   transition  rows j = 1..m_t along the rays phi_k = k * pi/(4n): the point
//!               (1 - j/m_t) P_k + (j/m_t) r_t d_k between the core boundary node P_k and
//!               the circle of radius r_t (r_t > a sqrt 2, so every row moves outward)
//!   ring        rows j = 1..m on the same rays, circles of radius r_t + (R - r_t) s_j with
//!               s_j geometric (last cell / first cell = ring_ratio), the last on the rim R
//! ```
//!
//! Every ray is at an equal angle `pi/(4n)` (8n rays around the disk, 2n + 1 across the
//! quadrant), so beyond `r_t` the mesh is a polar grid invariant under rotation by any
//! multiple of that angle, 45° included: only the core and the transition (inside `r_t`)
//! break rotational symmetry. Put them where the sheet barely strains (under a flat punch
//! bottom) and a cup's draw-in differs between 0° and 45° only through that. The ray
//! directions are built from one octant's `(cos, sin)` by exact swaps and sign changes, so
//! the mesh is exactly symmetric about the diagonals and the quadrant's edges lie exactly
//! on `x = 0` and `y = 0`.
//!
//! The elements are straight-sided (trilinear), so the mesh fills the inscribed polygon of
//! the rim with `8n` sides: its volume is `4n R^2 sin(pi/(4n)) t`, short of `pi R^2 t` by
//! the relative error `(pi/(4n))^2 / 6 + O(n^-4)`, second order in the rim cell size.
//!
//! # Numbering and sets
//!
//! Plane points are numbered core first (row by row, x fastest), then ring row by ring row
//! (ray by ray within a row); the node of plane point `p` in layer `k` (from the bottom) is
//! `p + P k` (`P` plane points). Node sets: `"z-"`, `"z+"` (bottom `z = 0` and top
//! `z = t`), `"rim"` (the cylindrical edge, all layers), `"centre"` (the column on the
//! axis), and for the quadrant `"x-"` and `"y-"` (the symmetry planes `x = 0`, `y = 0`), so
//! a quarter script fixes them as it would a `block()`'s. Each plane point's column
//! through the thickness is kept for thickness output. Cost: O(nodes).

use std::collections::BTreeMap;

use super::block::{axis_coordinates, End, Grading, MAX_BLOCK_NODES};
use super::Mesh;
use crate::geometry::Vec3;
use crate::{Error, Result};
use std::f64::consts::FRAC_PI_4;

/// The parameters of a round blank (see the module documentation for the layout).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoundBlank {
    /// Blank radius R.
    pub radius: f64,
    /// Sheet thickness t: the blank spans `0 <= z <= t`.
    pub thickness: f64,
    /// The quadrant `x, y >= 0` only (a quarter model), or the whole disk.
    pub quarter: bool,
    /// Cells along a quarter side of the core square, n; the rim has 8n cells (2n for the
    /// quadrant).
    pub core_cells: usize,
    /// Half side a of the core square.
    pub core_size: f64,
    /// Radius r_t from which the rows are circles; > a sqrt 2 and < R.
    pub round_radius: f64,
    /// Rows between the core square and the circle r_t.
    pub transition_cells: usize,
    /// Rows between the circle r_t and the rim.
    pub ring_cells: usize,
    /// Radial width of the rim cell over that of the first circular cell (1: uniform).
    pub ring_ratio: f64,
    /// Cells through the thickness.
    pub layers: usize,
}

impl RoundBlank {
    /// A blank of radius `radius` and thickness `thickness` with the default layout: n = 4,
    /// a = R/5, r_t = 2a, m_t = n, uniform ring rows about as wide as the rim cells, one
    /// layer, the whole disk.
    pub fn new(radius: f64, thickness: f64) -> RoundBlank {
        let mut blank = RoundBlank {
            radius,
            thickness,
            quarter: false,
            core_cells: 4,
            core_size: 0.2 * radius,
            round_radius: 0.4 * radius,
            transition_cells: 4,
            ring_cells: 1,
            ring_ratio: 1.0,
            layers: 1,
        };
        blank.ring_cells = blank.square_ring_cells();
        blank
    }

    /// The number of ring rows that makes the ring cells about as wide radially as the rim
    /// cells are along the rim (at least 1).
    pub fn square_ring_cells(&self) -> usize {
        let rim_cell = FRAC_PI_4 * self.radius / self.core_cells.max(1) as f64;
        let rows = ((self.radius - self.round_radius) / rim_cell).ceil();
        if rows.is_finite() && rows >= 1.0 {
            (rows as usize).min(1 << 20)
        } else {
            1
        }
    }

    fn check(&self) -> Result<()> {
        let positive = |what: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::input(
                    &format!("round blank {what}"),
                    v,
                    "must be finite and > 0",
                ))
            }
        };
        positive("radius", self.radius)?;
        positive("thickness", self.thickness)?;
        positive("core_size", self.core_size)?;
        positive("ring_ratio", self.ring_ratio)?;
        for (what, n) in [
            ("core_cells", self.core_cells),
            ("transition_cells", self.transition_cells),
            ("ring_cells", self.ring_cells),
            ("layers", self.layers),
        ] {
            if n == 0 {
                return Err(Error::input(
                    &format!("round blank {what}"),
                    0,
                    "must be >= 1",
                ));
            }
        }
        let corner = self.core_size * std::f64::consts::SQRT_2;
        if !(self.round_radius > corner) {
            return Err(Error::input(
                "round blank round_radius",
                self.round_radius,
                &format!(
                    "must be > core_size * sqrt(2) = {corner} (the circle r_t must enclose the core square)"
                ),
            ));
        }
        if !(self.round_radius < self.radius) {
            return Err(Error::input(
                "round blank round_radius",
                self.round_radius,
                &format!("must be < the radius {}", self.radius),
            ));
        }
        if self
            .node_count()
            .filter(|&n| n <= MAX_BLOCK_NODES)
            .is_none()
        {
            return Err(Error::input(
                "round blank cells",
                format!(
                    "core {}, transition {}, ring {}, layers {}",
                    self.core_cells, self.transition_cells, self.ring_cells, self.layers
                ),
                &format!("must give at most {MAX_BLOCK_NODES} nodes"),
            ));
        }
        Ok(())
    }

    /// Number of nodes of the mesh (None when it overflows).
    pub fn node_count(&self) -> Option<usize> {
        self.plane_point_count()?
            .checked_mul(self.layers.checked_add(1)?)
    }

    /// Number of points in the plane (None on overflow).
    fn plane_point_count(&self) -> Option<usize> {
        let n = self.core_cells;
        let (lines, rays) = if self.quarter {
            (n.checked_add(1)?, n.checked_mul(2)?.checked_add(1)?)
        } else {
            (n.checked_mul(2)?.checked_add(1)?, n.checked_mul(8)?)
        };
        let rows = self.transition_cells.checked_add(self.ring_cells)?;
        lines
            .checked_mul(lines)?
            .checked_add(rays.checked_mul(rows)?)
    }
}

/// Unit direction of ray `k` of `8n` around the circle, at the angle `k pi / (4n)`: one
/// octant's `(cos, sin)`, mirrored about the diagonal and turned by quarter turns exactly,
/// so that mirror images of rays are exact mirror images.
fn ray_direction(k: usize, n: usize) -> [f64; 2] {
    let (quadrant, q) = (k / (2 * n), k % (2 * n));
    let angle = |i: usize| FRAC_PI_4 * i as f64 / n as f64;
    let (c, s) = if q == n {
        (
            std::f64::consts::FRAC_1_SQRT_2,
            std::f64::consts::FRAC_1_SQRT_2,
        )
    } else if q < n {
        (angle(q).cos(), angle(q).sin())
    } else {
        (angle(2 * n - q).sin(), angle(2 * n - q).cos())
    };
    match quadrant % 4 {
        0 => [c, s],
        1 => [-s, c],
        2 => [-c, -s],
        _ => [s, -c],
    }
}

/// The core's node line coordinates `a tan(pi/4 i/n)`, i = -n..n (quarter: 0..n), exactly
/// antisymmetric, 0 at i = 0 and +-a at the ends.
fn core_lines(a: f64, n: usize, quarter: bool) -> Vec<f64> {
    let half: Vec<f64> = (0..=n)
        .map(|i| match i {
            0 => 0.0,
            i if i == n => a,
            i => a * (FRAC_PI_4 * i as f64 / n as f64).tan(),
        })
        .collect();
    if quarter {
        half
    } else {
        // `0.0 - x`, not `-x`: the middle line is +0, not -0.
        half.iter()
            .rev()
            .map(|x| 0.0 - x)
            .chain(half.iter().skip(1).copied())
            .collect()
    }
}

/// The ray of a core boundary point (its angle in units of pi/(4n), rounded).
fn ray_of(p: [f64; 2], n: usize) -> usize {
    let rays = 8 * n;
    let angle = p[1].atan2(p[0]).rem_euclid(std::f64::consts::TAU);
    (angle / (FRAC_PI_4 / n as f64)).round() as usize % rays
}

impl Mesh {
    /// The O-grid round blank `spec` (see the module documentation). Errors name the
    /// parameter: non-finite or non-positive sizes, zero cell counts, `round_radius` not
    /// between `core_size sqrt 2` and `radius`, more than [`MAX_BLOCK_NODES`] nodes.
    pub fn round_blank(spec: &RoundBlank) -> Result<Mesh> {
        spec.check()?;
        let n = spec.core_cells;
        let lines = core_lines(spec.core_size, n, spec.quarter);
        let nl = lines.len();

        // Plane points: the core grid, x fastest.
        let mut plane: Vec<[f64; 2]> = Vec::new();
        for &y in &lines {
            for &x in &lines {
                plane.push([x, y]);
            }
        }
        let mut quads: Vec<[usize; 4]> = Vec::new();
        for j in 0..nl - 1 {
            for i in 0..nl - 1 {
                let p = |i: usize, j: usize| i + nl * j;
                quads.push([p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)]);
            }
        }

        // Rays, each starting at its core boundary point.
        let ray_count = if spec.quarter { 2 * n + 1 } else { 8 * n };
        let mut inner = vec![usize::MAX; 8 * n];
        for (idx, p) in plane.iter().enumerate() {
            let (i, j) = (idx % nl, idx / nl);
            let on_boundary = if spec.quarter {
                i == nl - 1 || j == nl - 1
            } else {
                i == 0 || j == 0 || i == nl - 1 || j == nl - 1
            };
            if on_boundary {
                inner[ray_of(*p, n)] = idx;
            }
        }
        let mut row: Vec<usize> = inner[..ray_count].to_vec();
        debug_assert!(row.iter().all(|&i| i != usize::MAX));
        let directions: Vec<[f64; 2]> = (0..ray_count).map(|k| ray_direction(k, n)).collect();

        let (r, rt, mt) = (spec.radius, spec.round_radius, spec.transition_cells);
        let mut ring = axis_coordinates(
            0,
            rt,
            r - rt,
            spec.ring_cells,
            Grading::Toward {
                end: End::Min,
                ratio: spec.ring_ratio,
            },
        )
        .map_err(|_| {
            Error::input(
                "round blank ring_ratio",
                spec.ring_ratio,
                "makes a ring cell of zero width (too extreme)",
            )
        })?;
        ring[0] = rt;
        *ring.last_mut().expect("ring has >= 2 lines") = r;

        let mut rim = Vec::new();
        for j in 1..=mt + spec.ring_cells {
            let next: Vec<usize> = (0..ray_count)
                .map(|k| {
                    let d = directions[k];
                    let p = if j < mt {
                        let w = j as f64 / mt as f64;
                        let start = plane[inner[k]];
                        [
                            (1.0 - w) * start[0] + w * rt * d[0],
                            (1.0 - w) * start[1] + w * rt * d[1],
                        ]
                    } else {
                        let radius = ring[j - mt];
                        [radius * d[0], radius * d[1]]
                    };
                    plane.push(p);
                    plane.len() - 1
                })
                .collect();
            let segments = if spec.quarter {
                ray_count - 1
            } else {
                ray_count
            };
            for k in 0..segments {
                let k1 = (k + 1) % ray_count;
                quads.push([row[k], next[k], next[k1], row[k1]]);
            }
            row = next;
            rim.clone_from(&row);
        }
        Ok(extrude(&plane, &quads, &rim, spec))
    }
}

/// The plane mesh extruded through `spec.layers` uniform layers, with its sets and columns.
fn extrude(plane: &[[f64; 2]], quads: &[[usize; 4]], rim: &[usize], spec: &RoundBlank) -> Mesh {
    let (np, layers) = (plane.len(), spec.layers);
    let z = |k: usize| match k {
        0 => 0.0,
        k if k == layers => spec.thickness,
        k => spec.thickness * k as f64 / layers as f64,
    };
    let mut nodes = Vec::with_capacity(np * (layers + 1));
    for k in 0..=layers {
        nodes.extend(plane.iter().map(|p| Vec3::new(p[0], p[1], z(k))));
    }
    let mut hexes = Vec::with_capacity(quads.len() * layers);
    for k in 0..layers {
        for q in quads {
            let (lo, hi) = (np * k, np * (k + 1));
            hexes.push([
                q[0] + lo,
                q[1] + lo,
                q[2] + lo,
                q[3] + lo,
                q[0] + hi,
                q[1] + hi,
                q[2] + hi,
                q[3] + hi,
            ]);
        }
    }
    let through = |points: &[usize]| -> Vec<usize> {
        let mut set: Vec<usize> = (0..=layers)
            .flat_map(|k| points.iter().map(move |&p| p + np * k))
            .collect();
        set.sort_unstable();
        set
    };
    let on = |pred: &dyn Fn(&[f64; 2]) -> bool| -> Vec<usize> {
        (0..np).filter(|&p| pred(&plane[p])).collect()
    };
    let mut node_sets = BTreeMap::new();
    node_sets.insert("z-".to_string(), (0..np).collect());
    node_sets.insert("z+".to_string(), (np * layers..np * (layers + 1)).collect());
    node_sets.insert("rim".to_string(), through(rim));
    node_sets.insert("centre".to_string(), through(&on(&|p| p == &[0.0, 0.0])));
    if spec.quarter {
        // Exact zeros by construction (module documentation).
        node_sets.insert("x-".to_string(), through(&on(&|p| p[0] == 0.0)));
        node_sets.insert("y-".to_string(), through(&on(&|p| p[1] == 0.0)));
    }
    let columns = (0..np)
        .map(|p| (0..=layers).map(|k| p + np * k).collect())
        .collect();
    Mesh {
        nodes,
        hexes,
        node_sets,
        columns,
        ..Mesh::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{HEX_CORNERS, HEX_FACES};
    use std::collections::HashMap;
    use std::f64::consts::PI;

    /// det dx/dxi of element `e` at the natural point `xi`.
    fn jacobian_det(mesh: &Mesh, e: usize, xi: [f64; 3]) -> f64 {
        let x = mesh.hex_coordinates(e);
        let mut j = crate::geometry::Mat3::zeros();
        for (a, c) in HEX_CORNERS.iter().enumerate() {
            for d in 0..3 {
                let mut dn = 0.125 * c[d];
                for o in (0..3).filter(|&o| o != d) {
                    dn *= 1.0 + c[o] * xi[o];
                }
                for i in 0..3 {
                    j[(i, d)] += x[a][i] * dn;
                }
            }
        }
        j.determinant()
    }

    const GAUSS: f64 = 0.577_350_269_189_625_8;

    /// Volume by 2 x 2 x 2 Gauss points (exact: det J of a trilinear map is at most
    /// quadratic in each natural coordinate); asserts det J > 0 at every point used.
    fn volume(mesh: &Mesh) -> f64 {
        let mut v = 0.0;
        for e in 0..mesh.element_count() {
            for c in HEX_CORNERS {
                let det = jacobian_det(mesh, e, c.map(|s| s * GAUSS));
                assert!(det > 0.0, "element {e}: det J = {det}");
                v += det;
                assert!(jacobian_det(mesh, e, c) > 0.0, "element {e} corner");
            }
        }
        v
    }

    fn blank(quarter: bool, n: usize) -> RoundBlank {
        RoundBlank {
            quarter,
            core_cells: n,
            ..RoundBlank::new(50.0, 1.0)
        }
    }

    /// The mesh fills the inscribed 8n-gon exactly; its shortfall from pi R^2 t is second
    /// order: halving the rim cell divides it by 4 (to O(n^-2) relative).
    #[test]
    fn volume_is_the_inscribed_polygon_and_converges_at_second_order() {
        let mut errors = Vec::new();
        for n in [2, 4, 8, 16] {
            for quarter in [false, true] {
                let spec = RoundBlank {
                    layers: 2,
                    ring_ratio: 0.5,
                    ..blank(quarter, n)
                };
                let mesh = Mesh::round_blank(&spec).unwrap();
                mesh.validate().unwrap();
                let share = if quarter { 0.25 } else { 1.0 };
                let polygon = share * 4.0 * n as f64 * 2500.0 * (PI / (4.0 * n as f64)).sin();
                let v = volume(&mesh);
                assert!(
                    (v - polygon).abs() < 1e-12 * polygon,
                    "n {n}: {v} vs {polygon}"
                );
                let exact = share * PI * 2500.0;
                let relative = (exact - v) / exact;
                let predicted = (PI / (4.0 * n as f64)).powi(2) / 6.0;
                assert!(
                    (relative / predicted - 1.0).abs() < 0.02,
                    "n {n}: {relative}"
                );
                if !quarter {
                    errors.push(relative);
                }
            }
        }
        for w in errors.windows(2) {
            let rate = (w[0] / w[1]).log2();
            assert!((rate - 2.0).abs() < 0.01, "observed order {rate}");
        }
    }

    #[test]
    fn rim_nodes_lie_on_the_circle_and_sets_are_the_faces() {
        for quarter in [false, true] {
            let spec = RoundBlank {
                layers: 3,
                ring_ratio: 0.3,
                ..blank(quarter, 3)
            };
            let mesh = Mesh::round_blank(&spec).unwrap();
            let radial = |p: &Vec3| p.x.hypot(p.y);
            let rim = mesh.node_set("rim").unwrap();
            assert_eq!(rim.len(), (if quarter { 7 } else { 24 }) * 4);
            for &i in rim {
                assert!((radial(&mesh.nodes[i]) - 50.0).abs() < 1e-12);
            }
            assert_eq!(rim, mesh.select_nodes(|p| radial(p) > 50.0 - 1e-9));
            assert_eq!(
                mesh.node_set("z-").unwrap(),
                mesh.select_nodes(|p| p.z == 0.0)
            );
            assert_eq!(
                mesh.node_set("z+").unwrap(),
                mesh.select_nodes(|p| p.z == 1.0)
            );
            assert_eq!(
                mesh.node_set("centre").unwrap(),
                mesh.select_nodes(|p| radial(p) < 1e-12)
            );
            assert_eq!(mesh.node_set("centre").unwrap().len(), 4);
            if quarter {
                assert_eq!(
                    mesh.node_set("x-").unwrap(),
                    mesh.select_nodes(|p| p.x.abs() < 1e-12)
                );
                assert_eq!(
                    mesh.node_set("y-").unwrap(),
                    mesh.select_nodes(|p| p.y.abs() < 1e-12)
                );
                assert!(mesh.nodes.iter().all(|p| p.x >= 0.0 && p.y >= 0.0));
                // 4 core + 3 transition + ring rows on each symmetry edge, 4 layers.
                let edge = 4 + spec.transition_cells + spec.ring_cells;
                assert_eq!(mesh.node_set("x-").unwrap().len(), edge * 4);
            } else {
                assert!(mesh.node_set("x-").is_err());
            }
            // Columns: one per plane point, bottom to top, length t.
            assert_eq!(mesh.columns().len(), mesh.node_count() / 4);
            for t in mesh.column_thicknesses(|_| Vec3::zeros()) {
                assert!((t - 1.0).abs() < 1e-15);
            }
        }
    }

    /// Conforming: every face is shared by two elements or lies on the boundary, and the
    /// boundary is exactly top, bottom, rim (and the two symmetry planes): no gap, no
    /// duplicate node.
    #[test]
    fn mesh_is_conforming_with_the_expected_boundary() {
        for quarter in [false, true] {
            let spec = RoundBlank {
                layers: 2,
                ..blank(quarter, 3)
            };
            let mesh = Mesh::round_blank(&spec).unwrap();
            let mut count: HashMap<[usize; 4], usize> = HashMap::new();
            for h in &mesh.hexes {
                for f in HEX_FACES {
                    let mut key = f.map(|a| h[a]);
                    key.sort_unstable();
                    *count.entry(key).or_default() += 1;
                }
            }
            assert!(count.values().all(|&c| c <= 2));
            let boundary = count.values().filter(|&&c| c == 1).count();
            let per_layer = mesh.element_count() / 2;
            let rim_cells = if quarter { 6 } else { 24 };
            let edge_cells = 3 + spec.transition_cells + spec.ring_cells;
            let symmetry = if quarter { 2 * edge_cells } else { 0 };
            assert_eq!(boundary, 2 * per_layer + 2 * (rim_cells + symmetry));
            // No two nodes coincide.
            let mut seen = std::collections::HashSet::new();
            for p in &mesh.nodes {
                assert!(seen.insert(p.map(|c| (c * 1e6).round() as i64)), "{p}");
            }
        }
    }

    /// Exactly symmetric about the diagonal x = y; beyond r_t invariant under a 45° turn.
    #[test]
    fn diagonal_mirror_exact_and_ring_turns_into_itself() {
        for quarter in [false, true] {
            let mesh = Mesh::round_blank(&blank(quarter, 4)).unwrap();
            // `+ 0.0` makes -0 and +0 one key.
            let key = |p: Vec3| [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
            let all: std::collections::HashSet<_> = mesh.nodes.iter().map(|&p| key(p)).collect();
            for p in &mesh.nodes {
                assert!(
                    all.contains(&key(Vec3::new(p.y, p.x, p.z))),
                    "mirror of {p}"
                );
            }
            let c = std::f64::consts::FRAC_1_SQRT_2;
            for p in mesh.nodes.iter().filter(|p| p.x.hypot(p.y) > 20.0 - 1e-9) {
                let q = Vec3::new(c * (p.x - p.y), c * (p.x + p.y), p.z);
                if quarter && q.x < -1e-9 {
                    continue;
                }
                let nearest = mesh
                    .nodes
                    .iter()
                    .map(|n| (n - q).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(nearest < 1e-12, "{p} turned by 45 deg: {nearest}");
            }
        }
    }

    #[test]
    fn bad_parameters_are_named() {
        let err = |spec: RoundBlank| Mesh::round_blank(&spec).unwrap_err().to_string();
        let b = blank(true, 2);
        let e = err(RoundBlank { radius: -1.0, ..b });
        assert!(
            e.contains("round blank radius = -1 must be finite and > 0"),
            "{e}"
        );
        let e = err(RoundBlank {
            thickness: f64::NAN,
            ..b
        });
        assert!(e.contains("round blank thickness = NaN"), "{e}");
        let e = err(RoundBlank { core_cells: 0, ..b });
        assert!(e.contains("round blank core_cells = 0 must be >= 1"), "{e}");
        let e = err(RoundBlank { ring_cells: 0, ..b });
        assert!(e.contains("ring_cells = 0"), "{e}");
        let e = err(RoundBlank { layers: 0, ..b });
        assert!(e.contains("layers = 0"), "{e}");
        let e = err(RoundBlank {
            round_radius: 14.0,
            ..b
        });
        assert!(
            e.contains("round_radius = 14 must be > core_size * sqrt(2)"),
            "{e}"
        );
        let e = err(RoundBlank {
            round_radius: 60.0,
            ..b
        });
        assert!(
            e.contains("round_radius = 60 must be < the radius 50"),
            "{e}"
        );
        let e = err(RoundBlank {
            ring_ratio: 0.0,
            ..b
        });
        assert!(e.contains("ring_ratio = 0"), "{e}");
        let e = err(RoundBlank {
            ring_ratio: 1e300,
            ring_cells: 3,
            ..b
        });
        assert!(e.contains("ring_ratio") && e.contains("zero width"), "{e}");
        let e = err(RoundBlank {
            core_cells: usize::MAX / 2,
            ..b
        });
        assert!(e.contains("must give at most"), "{e}");
        let e = err(RoundBlank {
            layers: 1 << 40,
            ..b
        });
        assert!(e.contains("must give at most"), "{e}");
    }
}
