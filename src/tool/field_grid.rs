//! A grid of cells in one Bézier patch's parameter square, with the physical area of each
//! cell and of any polygon's part in each cell: the carrier of the tool-side fields
//! (`surface_fields.rs`).
//!
//! Mathematics. The patch `S(u, v)`, `(u, v) in [0, 1]^2`, is cut into `nu x nv` equal
//! cells. Physical area is `dA = J du dv` with the metric `J = |S_u x S_v|`. `J` is sampled
//! at the `(nu + 1)(nv + 1)` grid nodes and taken bilinear in each cell (`J_h`), so that
//!
//! - a cell's area is `|C| = du dv (J_00 + J_10 + J_01 + J_11) / 4`, exactly `∫_C J_h`;
//! - a polygon `P` (parameter-space vertices) is clipped against each cell it overlaps
//!   (Sutherland-Hodgman against the cell's four half-planes; `P` need not be convex, the
//!   cell is) and `∫_{P ∩ C} J_h` is integrated exactly: the clipped polygon is fanned into
//!   signed triangles from its first vertex and each triangle integrated with the
//!   edge-midpoint rule (exact for degree 2, so for the bilinear `J_h`). Signed fans give the
//!   right integral for any simple polygon.
//!
//! So the pieces of a polygon sum to its integral of `J_h`, and polygons tiling a cell sum
//! to `|C|`, both to round-off: that is what makes the transfer of `surface_fields.rs`
//! conservative and exact for uniform fields. `J_h` differs from `J` by O(cell^2) (exact on
//! flat parallelogram patches, where `J` is constant); that is the only approximation of
//! the surface's area, and it refines with the grid.

use crate::geometry::BezierPatch;

/// The cells of one patch and the bilinear metric over them.
#[derive(Clone, Debug)]
pub struct PatchGrid {
    pub nu: usize,
    pub nv: usize,
    /// `J` at the grid nodes, `(nu + 1) x (nv + 1)`, index `i * (nv + 1) + j`.
    metric: Vec<f64>,
    /// Physical area of each cell, `nu x nv`, index `i * nv + j` (`i` along u).
    pub cell_area: Vec<f64>,
}

impl PatchGrid {
    /// The `nu x nv` grid of `patch` (both >= 1).
    pub fn new(patch: &BezierPatch, nu: usize, nv: usize) -> PatchGrid {
        let (nu, nv) = (nu.max(1), nv.max(1));
        let mut metric = Vec::with_capacity((nu + 1) * (nv + 1));
        for i in 0..=nu {
            for j in 0..=nv {
                let e = patch.evaluate(i as f64 / nu as f64, j as f64 / nv as f64);
                let jac = e.su.cross(&e.sv).norm();
                metric.push(if jac.is_finite() { jac } else { 0.0 });
            }
        }
        let mut grid = PatchGrid {
            nu,
            nv,
            metric,
            cell_area: Vec::new(),
        };
        let dudv = 1.0 / (nu * nv) as f64;
        grid.cell_area = (0..nu * nv)
            .map(|c| {
                let (i, j) = (c / nv, c % nv);
                let m = |a: usize, b: usize| grid.metric[(i + a) * (nv + 1) + j + b];
                0.25 * dudv * (m(0, 0) + m(1, 0) + m(0, 1) + m(1, 1))
            })
            .collect();
        grid
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nu * self.nv
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cell holding parameter point `uv` (clamped into the square).
    pub fn cell_of(&self, uv: [f64; 2]) -> usize {
        let index = |t: f64, n: usize| ((t.clamp(0.0, 1.0) * n as f64) as usize).min(n - 1);
        index(uv[0], self.nu) * self.nv + index(uv[1], self.nv)
    }

    /// Parameter-space centre of cell `c`.
    pub fn cell_centre(&self, c: usize) -> [f64; 2] {
        let (i, j) = (c / self.nv, c % self.nv);
        [
            (i as f64 + 0.5) / self.nu as f64,
            (j as f64 + 0.5) / self.nv as f64,
        ]
    }

    /// `J_h` at parameter point `uv` inside cell `(i, j)`: bilinear in the cell's corners.
    fn metric_in(&self, i: usize, j: usize, uv: [f64; 2]) -> f64 {
        let s = uv[0] * self.nu as f64 - i as f64;
        let t = uv[1] * self.nv as f64 - j as f64;
        let m = |a: usize, b: usize| self.metric[(i + a) * (self.nv + 1) + j + b];
        (1.0 - s) * ((1.0 - t) * m(0, 0) + t * m(0, 1)) + s * ((1.0 - t) * m(1, 0) + t * m(1, 1))
    }

    /// Calls `visit(cell, area)` with the physical area `∫_{P ∩ C} J_h` of polygon `polygon`
    /// (parameter-space vertices, in order, either orientation) in every cell it overlaps;
    /// returns the polygon's whole area (the sum of the visited areas). Areas are >= 0.
    pub fn overlaps(&self, polygon: &[[f64; 2]], mut visit: impl FnMut(usize, f64)) -> f64 {
        if polygon.len() < 3 {
            return 0.0;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in polygon {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let range = |lo: f64, hi: f64, n: usize| {
            let a = ((lo.clamp(0.0, 1.0) * n as f64).floor() as usize).min(n - 1);
            let b = ((hi.clamp(0.0, 1.0) * n as f64).floor() as usize).min(n - 1);
            a..=b
        };
        // The polygon's orientation decides the sign of its fan; areas are reported >= 0.
        let orientation = signed_area(polygon).signum();
        let mut total = 0.0;
        let mut scratch = Vec::with_capacity(2 * polygon.len() + 8);
        for i in range(lo[0], hi[0], self.nu) {
            for j in range(lo[1], hi[1], self.nv) {
                let cell = [
                    i as f64 / self.nu as f64,
                    (i + 1) as f64 / self.nu as f64,
                    j as f64 / self.nv as f64,
                    (j + 1) as f64 / self.nv as f64,
                ];
                let clipped = clip_to_box(polygon, cell, &mut scratch);
                let area = orientation * self.integrate(i, j, &clipped);
                if area > 0.0 {
                    visit(i * self.nv + j, area);
                    total += area;
                }
            }
        }
        total
    }

    /// `∫ J_h` over a polygon inside cell `(i, j)`: signed fan, edge-midpoint rule.
    fn integrate(&self, i: usize, j: usize, polygon: &[[f64; 2]]) -> f64 {
        let mut sum = 0.0;
        let a = polygon.first().copied().unwrap_or([0.0; 2]);
        for w in polygon.windows(2).skip(1) {
            let (b, c) = (w[0], w[1]);
            let area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
            let mid = |p: [f64; 2], q: [f64; 2]| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
            let f = self.metric_in(i, j, mid(a, b))
                + self.metric_in(i, j, mid(b, c))
                + self.metric_in(i, j, mid(c, a));
            sum += area * f / 3.0;
        }
        sum
    }
}

/// Signed parameter-space area (shoelace), positive counter-clockwise.
pub fn signed_area(polygon: &[[f64; 2]]) -> f64 {
    let n = polygon.len();
    (0..n)
        .map(|k| {
            let (p, q) = (polygon[k], polygon[(k + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        * 0.5
}

/// Sutherland-Hodgman clipping of `polygon` to the box `[u0, u1] x [v0, v1]`
/// (`bounds = [u0, u1, v0, v1]`); `scratch` is reused between calls.
pub fn clip_to_box(
    polygon: &[[f64; 2]],
    bounds: [f64; 4],
    scratch: &mut Vec<[f64; 2]>,
) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = polygon.to_vec();
    // (axis, bound, keep the side above the bound)
    let planes = [
        (0, bounds[0], true),
        (0, bounds[1], false),
        (1, bounds[2], true),
        (1, bounds[3], false),
    ];
    for (axis, bound, above) in planes {
        if out.is_empty() {
            break;
        }
        scratch.clear();
        let inside = |p: &[f64; 2]| {
            if above {
                p[axis] >= bound
            } else {
                p[axis] <= bound
            }
        };
        for k in 0..out.len() {
            let (p, q) = (out[k], out[(k + 1) % out.len()]);
            let (pin, qin) = (inside(&p), inside(&q));
            if pin {
                scratch.push(p);
            }
            if pin != qin {
                // The crossing point, computed on the edge's own axis so that it lies
                // exactly on the bound.
                let t = (bound - p[axis]) / (q[axis] - p[axis]);
                let mut x = [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])];
                x[axis] = bound;
                scratch.push(x);
            }
        }
        std::mem::swap(&mut out, scratch);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    fn square_patch() -> BezierPatch {
        BezierPatch::parallelogram(
            Vec3::zeros(),
            Vec3::new(4.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        )
        .unwrap()
    }

    /// A triangle across several cells of a flat 4 x 2 patch: pieces sum to its area
    /// (4 x 2 physical per unit parameter area: J = 8), each piece <= its cell.
    #[test]
    fn polygon_pieces_sum_to_its_area_on_a_flat_patch() {
        let grid = PatchGrid::new(&square_patch(), 7, 5);
        let tri = [[0.05, 0.1], [0.9, 0.2], [0.3, 0.95]];
        let mut pieces = Vec::new();
        let total = grid.overlaps(&tri, |c, a| pieces.push((c, a)));
        let exact = 8.0 * signed_area(&tri);
        assert!((total - exact).abs() < 1e-14 * exact, "{total} {exact}");
        assert!(pieces.len() > 10);
        for (c, a) in pieces {
            assert!(a <= grid.cell_area[c] * (1.0 + 1e-14));
        }
        // Reversed orientation: same areas.
        let rev = [tri[2], tri[1], tri[0]];
        assert!((grid.overlaps(&rev, |_, _| ()) - exact).abs() < 1e-14 * exact);
    }

    /// A non-convex polygon covering whole cells gives each its full area.
    #[test]
    fn nonconvex_polygon_fills_covered_cells() {
        let grid = PatchGrid::new(&square_patch(), 4, 4);
        // An L over cells (0,0), (1,0), (0,1) in units of 1/4.
        let l = [
            [0.0, 0.0],
            [0.5, 0.0],
            [0.5, 0.25],
            [0.25, 0.25],
            [0.25, 0.5],
            [0.0, 0.5],
        ];
        let mut got = vec![0.0; grid.len()];
        grid.overlaps(&l, |c, a| got[c] += a);
        for c in 0..grid.len() {
            let want = if [0, 4, 1].contains(&c) {
                grid.cell_area[c]
            } else {
                0.0
            };
            assert!((got[c] - want).abs() < 1e-15, "cell {c}: {} {want}", got[c]);
        }
    }
}
