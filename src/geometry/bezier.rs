//! Rational tensor-product Bézier patches: point, first and second derivatives, normal.
//!
//! A patch of degree `(p, q)` with control points `P_ij` and weights `w_ij > 0` is
//!
//! ```text
//! S(u, v) = A(u, v) / W(u, v),   A = sum_ij w_ij P_ij B_i^p(u) B_j^q(v),
//!                                W = sum_ij w_ij      B_i^p(u) B_j^q(v),
//! ```
//!
//! on `(u, v)` in `[0, 1]^2`, with Bernstein polynomials `B_i^p`. Derivatives are exact:
//! the homogeneous pair `(A, W)` is polynomial, and the quotient rule gives
//!
//! ```text
//! S_u  = (A_u - W_u S) / W
//! S_uu = (A_uu - 2 W_u S_u - W_uu S) / W
//! S_uv = (A_uv - W_u S_v - W_v S_u - W_uv S) / W      (and symmetrically in v).
//! ```
//!
//! Positive weights keep `W > 0` and the patch inside the convex hull of its control
//! points, which the projection uses for bounding boxes.

use super::*;
use crate::{Error, Result};

/// A rational Bézier patch; control points and weights row-major, `(p+1) x (q+1)`
/// (index `i * (q + 1) + j`, `i` along `u`).
#[derive(Debug, Clone)]
pub struct BezierPatch {
    degree_u: usize,
    degree_v: usize,
    points: Vec<Vec3>,
    weights: Vec<f64>,
    /// Outward normal is `-S_u x S_v` instead of `S_u x S_v`.
    flip: bool,
}

/// Point and derivatives of a patch at one `(u, v)`.
#[derive(Debug, Clone, Copy)]
pub struct PatchPoint {
    pub point: Vec3,
    pub su: Vec3,
    pub sv: Vec3,
    pub suu: Vec3,
    pub suv: Vec3,
    pub svv: Vec3,
}

/// Degrees up to this are evaluated in stack buffers (no allocation per evaluation).
const STACK_DEGREE: usize = 15;

/// Bernstein values of degree `n` at `t` and their first and second derivatives, from the
/// lower-degree bases: `B'_i^n = n (B_{i-1}^{n-1} - B_i^{n-1})` and similarly twice. All
/// degrees come from the triangle `B_i^k = (1-t) B_i^{k-1} + t B_{i-1}^{k-1}`, run in place;
/// `out` holds `[B, B', B'']`, each of length at least `n + 1`.
fn bernstein_into(n: usize, t: f64, out: [&mut [f64]; 3]) {
    let [b, d1, d2] = out;
    let (mut lower1, mut lower2) = ([0.0; STACK_DEGREE + 2], [0.0; STACK_DEGREE + 2]);
    let mut heap1;
    let mut heap2;
    let (deg1, deg2): (&mut [f64], &mut [f64]) = if n <= STACK_DEGREE {
        (&mut lower1[..], &mut lower2[..])
    } else {
        heap1 = vec![0.0; n + 2];
        heap2 = vec![0.0; n + 2];
        (&mut heap1[..], &mut heap2[..])
    };
    b[0] = 1.0;
    for k in 1..=n {
        if k == n {
            deg1[..n].copy_from_slice(&b[..n]);
        }
        if k + 1 == n {
            deg2[..n - 1].copy_from_slice(&b[..n - 1]);
        }
        b[k] = t * b[k - 1];
        for i in (1..k).rev() {
            b[i] = (1.0 - t) * b[i] + t * b[i - 1];
        }
        b[0] *= 1.0 - t;
    }
    let nf = n as f64;
    let lower = |arr: &[f64], k: usize, i: isize| -> f64 {
        if i < 0 || i as usize > k {
            0.0
        } else {
            arr[i as usize]
        }
    };
    for i in 0..=n as isize {
        d1[i as usize] = if n == 0 {
            0.0
        } else {
            nf * (lower(deg1, n - 1, i - 1) - lower(deg1, n - 1, i))
        };
        d2[i as usize] = if n < 2 {
            0.0
        } else {
            nf * (nf - 1.0)
                * (lower(deg2, n - 2, i - 2) - 2.0 * lower(deg2, n - 2, i - 1)
                    + lower(deg2, n - 2, i))
        };
    }
}

/// Bernstein values and derivatives of degree `n` at `t` in a buffer on the stack for
/// degrees up to [`STACK_DEGREE`], on the heap beyond.
struct Basis {
    stack: [[f64; STACK_DEGREE + 1]; 3],
    heap: Vec<Vec<f64>>,
    n: usize,
}

impl Basis {
    /// Inlined so that the 384-byte buffer is built in the caller's frame, not copied
    /// there (a visible share of the contact phase's samples).
    #[inline(always)]
    fn new(n: usize, t: f64) -> Basis {
        let mut basis = Basis {
            stack: [[0.0; STACK_DEGREE + 1]; 3],
            heap: Vec::new(),
            n,
        };
        if n <= STACK_DEGREE {
            let [b, d1, d2] = &mut basis.stack;
            bernstein_into(n, t, [b, d1, d2]);
        } else {
            let mut v = vec![vec![0.0; n + 1]; 3];
            let (b, rest) = v.split_at_mut(1);
            let (d1, d2) = rest.split_at_mut(1);
            bernstein_into(n, t, [&mut b[0], &mut d1[0], &mut d2[0]]);
            basis.heap = v;
        }
        basis
    }

    /// `[B, B', B'']`.
    fn get(&self, k: usize) -> &[f64] {
        if self.n <= STACK_DEGREE {
            &self.stack[k][..=self.n]
        } else {
            &self.heap[k]
        }
    }
}

impl BezierPatch {
    /// Errs if a degree is 0, the counts differ from `(p+1)(q+1)`, a point or weight is not
    /// finite, a weight is not > 0, or the patch is degenerate (no normal anywhere, e.g. all
    /// control points equal).
    pub fn new(
        degree_u: usize,
        degree_v: usize,
        points: Vec<Vec3>,
        weights: Vec<f64>,
    ) -> Result<BezierPatch> {
        for (what, d) in [
            ("bezier patch degree_u", degree_u),
            ("bezier patch degree_v", degree_v),
        ] {
            if d == 0 {
                return Err(Error::input(what, d, "must be >= 1"));
            }
        }
        let count = (degree_u + 1) * (degree_v + 1);
        let requirement = format!("must be (degree_u + 1) * (degree_v + 1) = {count}");
        if points.len() != count {
            return Err(Error::input(
                "bezier patch control point count",
                points.len(),
                &requirement,
            ));
        }
        if weights.len() != count {
            return Err(Error::input(
                "bezier patch weight count",
                weights.len(),
                &requirement,
            ));
        }
        for (k, p) in points.iter().enumerate() {
            let (i, j) = (k / (degree_v + 1), k % (degree_v + 1));
            finite_vec3(&format!("bezier patch control point [{i}][{j}]"), p)?;
        }
        for (k, &w) in weights.iter().enumerate() {
            let (i, j) = (k / (degree_v + 1), k % (degree_v + 1));
            let what = format!("bezier patch weight [{i}][{j}]");
            if !w.is_finite() {
                return Err(Error::input(&what, w, "must be finite"));
            }
            if w <= 0.0 {
                return Err(Error::input(&what, w, "must be > 0"));
            }
        }
        let patch = BezierPatch {
            degree_u,
            degree_v,
            points,
            weights,
            flip: false,
        };
        // Degenerate if |S_u x S_v| vanishes on a grid of samples relative to the size:
        // isolated degenerate points (a pole) are allowed, a patch without area is not.
        let size = patch.extent();
        let samples = 6;
        let max_area = (0..=samples)
            .flat_map(|a| (0..=samples).map(move |b| (a, b)))
            .map(|(a, b)| {
                let e = patch.evaluate(a as f64 / samples as f64, b as f64 / samples as f64);
                e.su.cross(&e.sv).norm()
            })
            .fold(0.0, f64::max);
        if max_area.is_nan() || max_area <= 1e-12 * size * size {
            return Err(Error::input(
                "bezier patch area element max |S_u x S_v|",
                max_area,
                "must be > 0: the patch is degenerate (control points coincide or lie on a curve)",
            ));
        }
        patch.check_no_fold(samples)?;
        Ok(patch)
    }

    /// A patch that folds over itself has a part facing inward: its area element
    /// `S_u x S_v` reverses between neighbouring samples of a `samples`-cell grid (a turn of
    /// more than 90° between samples; a smooth patch turns by far less: a 120° arc sampled
    /// in 6 cells turns 20° per cell). Poles (no normal) are skipped.
    fn check_no_fold(&self, samples: usize) -> Result<()> {
        let n = samples as f64;
        let normal_at = |a: usize, b: usize| {
            let e = self.evaluate(a as f64 / n, b as f64 / n);
            self.normal(&e)
        };
        let grid: Vec<Vec<Option<Vec3>>> = (0..=samples)
            .map(|a| (0..=samples).map(|b| normal_at(a, b)).collect())
            .collect();
        for a in 0..=samples {
            for b in 0..=samples {
                let here = grid[a][b];
                for (c, d) in [(a + 1, b), (a, b + 1)] {
                    if c > samples || d > samples {
                        continue;
                    }
                    if let (Some(p), Some(q)) = (here, grid[c][d]) {
                        if p.dot(&q) < 0.0 {
                            return Err(Error::input(
                                "bezier patch normal",
                                format!(
                                    "reversal between (u, v) = ({:.3}, {:.3}) and ({:.3}, {:.3})",
                                    a as f64 / n,
                                    b as f64 / n,
                                    c as f64 / n,
                                    d as f64 / n
                                ),
                                "is refused: the patch folds over itself, so part of it faces \
                                 inward (check the order of its control points)",
                            ));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The same patch with the opposite outward normal.
    pub fn flipped(mut self) -> BezierPatch {
        self.flip = !self.flip;
        self
    }

    pub fn degrees(&self) -> (usize, usize) {
        (self.degree_u, self.degree_v)
    }

    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// True if the outward normal is `-S_u x S_v`.
    pub fn is_flipped(&self) -> bool {
        self.flip
    }

    /// Axis-aligned box of the control points; it contains the patch (convex hull property).
    pub fn bounding_box(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for p in &self.points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }

    /// Diagonal of the bounding box: the length scale of tolerances.
    pub fn extent(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).norm()
    }

    /// The point `S(u, v)` alone (cheaper than [`BezierPatch::evaluate`]; for sampling).
    pub fn point(&self, u: f64, v: f64) -> Vec3 {
        if self.degree_u > STACK_DEGREE || self.degree_v > STACK_DEGREE {
            return self.evaluate(u, v).point;
        }
        let values = |n: usize, t: f64| {
            let mut b = [0.0; STACK_DEGREE + 1];
            b[0] = 1.0;
            for k in 1..=n {
                b[k] = t * b[k - 1];
                for i in (1..k).rev() {
                    b[i] = (1.0 - t) * b[i] + t * b[i - 1];
                }
                b[0] *= 1.0 - t;
            }
            b
        };
        let (bu, bv) = (values(self.degree_u, u), values(self.degree_v, v));
        let nv = self.degree_v + 1;
        let (mut a, mut w) = (Vec3::zeros(), 0.0);
        let rows = self.points.chunks(nv).zip(self.weights.chunks(nv));
        for ((points, weights), bi) in rows.zip(&bu) {
            for ((p, wij), bj) in points.iter().zip(weights).zip(&bv) {
                let wb = wij * bi * bj;
                a += p * wb;
                w += wb;
            }
        }
        a / w
    }

    /// Point, first and second derivatives at `(u, v)` (any real values; the patch is
    /// usually queried on `[0, 1]^2`).
    pub fn evaluate(&self, u: f64, v: f64) -> PatchPoint {
        let (basis_u, basis_v) = (Basis::new(self.degree_u, u), Basis::new(self.degree_v, v));
        let (bu, du, ddu) = (basis_u.get(0), basis_u.get(1), basis_u.get(2));
        let (bv, dv, ddv) = (basis_v.get(0), basis_v.get(1), basis_v.get(2));
        // Homogeneous sums: index 0 value, 1 d/du, 2 d/dv, 3 d2/du2, 4 d2/dudv, 5 d2/dv2.
        let mut a = [Vec3::zeros(); 6];
        let mut w = [0.0; 6];
        let nv = self.degree_v + 1;
        for i in 0..=self.degree_u {
            for j in 0..nv {
                let wij = self.weights[i * nv + j];
                let pij = self.points[i * nv + j] * wij;
                let basis = [
                    bu[i] * bv[j],
                    du[i] * bv[j],
                    bu[i] * dv[j],
                    ddu[i] * bv[j],
                    du[i] * dv[j],
                    bu[i] * ddv[j],
                ];
                for k in 0..6 {
                    a[k] += pij * basis[k];
                    w[k] += wij * basis[k];
                }
            }
        }
        let s = a[0] / w[0];
        let su = (a[1] - s * w[1]) / w[0];
        let sv = (a[2] - s * w[2]) / w[0];
        PatchPoint {
            point: s,
            su,
            sv,
            suu: (a[3] - su * (2.0 * w[1]) - s * w[3]) / w[0],
            suv: (a[4] - sv * w[1] - su * w[2] - s * w[4]) / w[0],
            svv: (a[5] - sv * (2.0 * w[2]) - s * w[5]) / w[0],
        }
    }

    /// Unit outward normal `±(S_u x S_v)/|S_u x S_v|` at an evaluated point, or `None` where
    /// the patch is degenerate (`|S_u x S_v| <= 1e-14 |S_u| |S_v|`, e.g. a collapsed edge).
    pub fn normal(&self, e: &PatchPoint) -> Option<Vec3> {
        let c = e.su.cross(&e.sv);
        let len = c.norm();
        if len.is_nan() || len == 0.0 || len <= 1e-14 * e.su.norm() * e.sv.norm() {
            return None;
        }
        Some(if self.flip { -c / len } else { c / len })
    }

    /// Where the parametrisation folds over itself (a "bow-tie" patch): the Jacobian
    /// `S_u x S_v`, sampled on a 16 x 16 grid of `[0, 1]^2`, reverses between two samples one
    /// or two steps apart along u or v. Smoothly curved patches turn their normal by far less
    /// than 90 degrees over two steps (a half cylinder: 24 degrees); a fold turns it by 180.
    /// Degenerate samples (collapsed edges, or a sample right on the fold line) are skipped,
    /// which is why two steps are looked at. Returns the `(u, v)` of the first reversal.
    /// Cost: 256 evaluations.
    pub fn fold(&self) -> Option<(f64, f64)> {
        const N: usize = 16;
        let at = |i: usize, j: usize| {
            let (u, v) = (i as f64 / (N - 1) as f64, j as f64 / (N - 1) as f64);
            let e = self.evaluate(u, v);
            let c = e.su.cross(&e.sv);
            let scale = e.su.norm() * e.sv.norm();
            (c.norm() > 1e-10 * scale).then_some((c, (u, v)))
        };
        let grid: Vec<Vec<_>> = (0..N).map(|i| (0..N).map(|j| at(i, j)).collect()).collect();
        for i in 0..N {
            for j in 0..N {
                let Some((c, uv)) = grid[i][j] else { continue };
                for (a, b) in [(i + 1, j), (i, j + 1), (i + 2, j), (i, j + 2)] {
                    if let Some(Some((d, _))) = grid.get(a).map(|row| row.get(b).copied().flatten())
                    {
                        if c.dot(&d) < 0.0 {
                            return Some(uv);
                        }
                    }
                }
            }
        }
        None
    }

    /// Quarter of a cylinder: [`BezierPatch::cylinder_patch`] with a 90° sweep.
    pub fn quarter_cylinder(
        axis_point: Vec3,
        axis_direction: Vec3,
        reference: Vec3,
        start_angle: f64,
        radius: f64,
        length: f64,
    ) -> Result<BezierPatch> {
        BezierPatch::cylinder_patch(
            axis_point,
            axis_direction,
            reference,
            start_angle,
            std::f64::consts::FRAC_PI_2,
            radius,
            length,
        )
    }

    /// Piece of a cylinder of radius `radius` around the axis through `axis_point` along
    /// `axis_direction`, from angle `start_angle` (measured around the axis from
    /// `reference`, made orthogonal to the axis) over `sweep` (0 < sweep <= 120°), and
    /// `length` along the axis. Degree 2 x 1 with weights `1, cos(sweep/2), 1` (exact
    /// circle). `u` runs around, `v` along the axis; the normal points away from the axis.
    pub fn cylinder_patch(
        axis_point: Vec3,
        axis_direction: Vec3,
        reference: Vec3,
        start_angle: f64,
        sweep: f64,
        radius: f64,
        length: f64,
    ) -> Result<BezierPatch> {
        let c = finite_vec3("cylinder patch axis point", &axis_point)?;
        let (a, e1, e2) = frame("cylinder patch", &axis_direction, &reference, start_angle)?;
        let r = positive_length("cylinder patch radius", radius)?;
        let l = positive_length("cylinder patch length", length)?;
        let (ring, ring_w) = circular_arc("cylinder patch sweep", e1 * r, e2 * r, sweep)?;
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for (p, w) in ring.iter().zip(ring_w) {
            for t in [0.0, l] {
                points.push(c + p + a * t);
                weights.push(w);
            }
        }
        BezierPatch::new(2, 1, points, weights)
    }

    /// Quarter-by-quarter piece of a torus: [`BezierPatch::torus_patch`] with 90° sweeps.
    pub fn quarter_torus(
        center: Vec3,
        axis: Vec3,
        reference: Vec3,
        major_start: f64,
        minor_start: f64,
        major: f64,
        minor: f64,
    ) -> Result<BezierPatch> {
        let quarter = std::f64::consts::FRAC_PI_2;
        BezierPatch::torus_patch(
            center,
            axis,
            reference,
            [major_start, quarter],
            [minor_start, quarter],
            major,
            minor,
        )
    }

    /// Piece of a torus around the axis through `center` along `axis`: major radius `major`
    /// (centre circle), minor radius `minor` (tube; it may exceed `major` if the patch keeps
    /// off the axis). `u` runs around the axis from `major_angles[0]` (measured from
    /// `reference`) over `major_angles[1]`; `v` runs around the tube from `minor_angles[0]`
    /// over `minor_angles[1]`, the minor angle `phi` measured from the outward radial
    /// direction towards `axis`. Sweeps in (0, 120°].
    /// Degree 2 x 2, weights `w_i w_j` of the two arcs: the surface of revolution of an
    /// exact circle. The normal points out of the tube.
    pub fn torus_patch(
        center: Vec3,
        axis: Vec3,
        reference: Vec3,
        major_angles: [f64; 2],
        minor_angles: [f64; 2],
        major: f64,
        minor: f64,
    ) -> Result<BezierPatch> {
        let c = finite_vec3("torus patch center", &center)?;
        let (a, e1, e2) = frame("torus patch", &axis, &reference, major_angles[0])?;
        let big = positive_length("torus patch major radius", major)?;
        let small = positive_length("torus patch minor radius", minor)?;
        let minor_start = minor_angles[0];
        if !minor_start.is_finite() {
            return Err(Error::input(
                "torus patch minor start angle",
                minor_start,
                "must be finite",
            ));
        }
        // The tube may be wider than the centre circle (a spindle torus, as at a punch's
        // nose corner) as long as the patch keeps off the axis: the distance to the axis
        // major + minor cos(phi) stays positive over the patch's minor angles.
        let end = minor_start + minor_angles[1];
        let crosses_pi = ((minor_start - std::f64::consts::PI) / std::f64::consts::TAU).ceil()
            <= ((end - std::f64::consts::PI) / std::f64::consts::TAU).floor();
        let (phi_min, cos_min) = if crosses_pi {
            (std::f64::consts::PI, -1.0)
        } else if minor_start.cos() < end.cos() {
            (minor_start, minor_start.cos())
        } else {
            (end, end.cos())
        };
        let closest = big + small * cos_min;
        if closest <= 1e-9 * big {
            return Err(Error::input(
                "torus patch minor radius",
                small,
                &format!(
                    "must keep the patch off the axis: major + minor cos(phi) = {closest} at \
                     phi = {}°",
                    phi_min.to_degrees()
                ),
            ));
        }
        // Profile circle in the (radial, axial) half-plane, as 2-D points (rho, z).
        let (cs, sn) = (minor_start.cos(), minor_start.sin());
        let (profile, profile_w) = circular_arc(
            "torus patch minor sweep",
            Vec3::new(cs, sn, 0.0) * small,
            Vec3::new(-sn, cs, 0.0) * small,
            minor_angles[1],
        )?;
        let (ring, ring_w) = circular_arc("torus patch major sweep", e1, e2, major_angles[1])?;
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for (d, wu) in ring.iter().zip(ring_w) {
            for (q, wv) in profile.iter().zip(profile_w) {
                // Revolving a control point (rho, z) about the axis: rho scales the ring's
                // control direction (the middle one has length 1/cos(sweep/2), as it must).
                points.push(c + d * (big + q.x) + a * q.y);
                weights.push(wu * wv);
            }
        }
        BezierPatch::new(2, 2, points, weights)
    }

    /// Bilinear flat patch with corners `origin`, `origin + edge_u`, `origin + edge_v`,
    /// `origin + edge_u + edge_v` (a parallelogram); the normal is along `edge_u x edge_v`.
    pub fn parallelogram(origin: Vec3, edge_u: Vec3, edge_v: Vec3) -> Result<BezierPatch> {
        let o = finite_vec3("flat patch corner", &origin)?;
        let eu = finite_vec3("flat patch edge_u", &edge_u)?;
        let ev = finite_vec3("flat patch edge_v", &edge_v)?;
        BezierPatch::new(1, 1, vec![o, o + ev, o + eu, o + eu + ev], vec![1.0; 4])
    }

    /// The patch moved rigidly, `x -> R x + t` (exact: control points transform, weights
    /// do not). `R` must be a rotation (not checked beyond finiteness by the caller).
    pub fn transformed(&self, rotation: &Mat3, translation: &Vec3) -> BezierPatch {
        BezierPatch {
            points: self
                .points
                .iter()
                .map(|p| rotation * p + translation)
                .collect(),
            ..self.clone()
        }
    }

    /// The patch flipped if needed so that its normal at the parameter centre has a
    /// positive component along `outward`.
    pub fn oriented(self, outward: &Vec3) -> BezierPatch {
        let e = self.evaluate(0.5, 0.5);
        match self.normal(&e) {
            Some(n) if n.dot(outward) < 0.0 => self.flipped(),
            _ => self,
        }
    }
}

/// Unit axis `a` and an orthonormal pair `(e1, e2)` across it, `e1` at `angle` from
/// `reference` around `a`, `e2 = a x e1`.
fn frame(what: &str, axis: &Vec3, reference: &Vec3, angle: f64) -> Result<(Vec3, Vec3, Vec3)> {
    let a = unit_vec3(&format!("{what} axis"), axis)?;
    let r = finite_vec3(&format!("{what} reference direction"), reference)?;
    let across = r - a * a.dot(&r);
    let across_len = across.norm();
    if across_len.is_nan() || across_len <= 1e-12 * r.norm() {
        return Err(Error::input(
            &format!("{what} reference direction"),
            fmt_vec3(&r),
            "must not be parallel to the axis",
        ));
    }
    if !angle.is_finite() {
        return Err(Error::input(
            &format!("{what} start angle"),
            angle,
            "must be finite",
        ));
    }
    let f1 = across.normalize();
    let f2 = a.cross(&f1);
    let e1 = f1 * angle.cos() + f2 * angle.sin();
    Ok((a, e1, a.cross(&e1)))
}

/// Rational quadratic arc of angle `sweep` from `p` to `p` rotated by `sweep` towards `q`
/// (`p`, `q` orthogonal, equal length, centred at the origin): control points `p`,
/// `(p + tan(sweep/2) q) `, end, weights `1, cos(sweep/2), 1`. The 90° arc uses the exact
/// values `p + q` and `1/sqrt2`. Sweeps in (0, 120°] (beyond, the middle weight gets small
/// and the parametrisation uneven).
pub(crate) fn circular_arc(
    what: &str,
    p: Vec3,
    q: Vec3,
    sweep: f64,
) -> Result<([Vec3; 3], [f64; 3])> {
    let limit = 2.0 * std::f64::consts::FRAC_PI_3;
    if !sweep.is_finite() || sweep <= 0.0 || sweep > limit * (1.0 + 1e-12) {
        return Err(Error::input(
            what,
            sweep.to_degrees(),
            "(degrees) must be in (0, 120]",
        ));
    }
    if sweep == std::f64::consts::FRAC_PI_2 {
        return Ok(([p, p + q, q], [1.0, std::f64::consts::FRAC_1_SQRT_2, 1.0]));
    }
    let half = 0.5 * sweep;
    Ok((
        [p, p + q * half.tan(), p * sweep.cos() + q * sweep.sin()],
        [1.0, half.cos(), 1.0],
    ))
}

#[cfg(test)]
/// A wavy rational bicubic-by-quadratic patch with random weights in `[0.5, 2]`.
pub(crate) fn random_patch(rng: &mut crate::geometry::testutil::Rng) -> BezierPatch {
    let (p, q) = (3, 2);
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..=p {
        for j in 0..=q {
            points.push(Vec3::new(i as f64, j as f64 * 1.5, rng.uniform(-0.4, 0.4)));
            weights.push(rng.uniform(0.5, 2.0));
        }
    }
    BezierPatch::new(p, q, points, weights).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::*;

    #[test]
    fn derivatives_match_finite_differences() {
        let mut rng = Rng::new(41);
        let h = 1e-5;
        for _ in 0..50 {
            let patch = random_patch(&mut rng);
            let (u, v) = (rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
            let e = patch.evaluate(u, v);
            let (up, um) = (patch.evaluate(u + h, v), patch.evaluate(u - h, v));
            let (vp, vm) = (patch.evaluate(u, v + h), patch.evaluate(u, v - h));
            let close = |a: Vec3, b: Vec3, tol: f64| {
                assert!((a - b).norm() < tol * (1.0 + b.norm()), "{a:?} vs {b:?}")
            };
            close((up.point - um.point) / (2.0 * h), e.su, 1e-8);
            close((vp.point - vm.point) / (2.0 * h), e.sv, 1e-8);
            close((up.su - um.su) / (2.0 * h), e.suu, 1e-7);
            close((vp.sv - vm.sv) / (2.0 * h), e.svv, 1e-7);
            close((vp.su - vm.su) / (2.0 * h), e.suv, 1e-7);
            close((up.sv - um.sv) / (2.0 * h), e.suv, 1e-7);
        }
    }

    /// Partition of unity and central differences of the basis, on the stack (degree <= 15)
    /// and on the heap (beyond).
    #[test]
    fn bernstein_basis_on_stack_and_heap() {
        let h = 1e-6;
        for n in 0..=20 {
            for t in [0.0, 0.13, 0.5, 0.91, 1.0] {
                let b = Basis::new(n, t);
                let (bp, bm) = (Basis::new(n, t + h), Basis::new(n, t - h));
                assert!((b.get(0).iter().sum::<f64>() - 1.0).abs() < 1e-14);
                for i in 0..=n {
                    let fd1 = (bp.get(0)[i] - bm.get(0)[i]) / (2.0 * h);
                    let fd2 = (bp.get(1)[i] - bm.get(1)[i]) / (2.0 * h);
                    let scale = 1.0 + (n * n) as f64;
                    assert!(
                        (fd1 - b.get(1)[i]).abs() < 1e-7 * scale,
                        "n {n} t {t} i {i}"
                    );
                    assert!(
                        (fd2 - b.get(2)[i]).abs() < 1e-5 * scale * scale,
                        "n {n} t {t} i {i}"
                    );
                }
            }
        }
    }

    #[test]
    fn point_equals_the_full_evaluation() {
        let mut rng = Rng::new(44);
        for _ in 0..50 {
            let patch = random_patch(&mut rng);
            let (u, v) = (rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
            assert!((patch.point(u, v) - patch.evaluate(u, v).point).norm() < 1e-14);
        }
    }

    #[test]
    fn quarter_cylinder_is_exact() {
        let mut rng = Rng::new(42);
        let axis = Vec3::new(0.3, -1.0, 0.5).normalize();
        let c = Vec3::new(1.0, 2.0, -1.0);
        let patch = BezierPatch::quarter_cylinder(c, axis, Vec3::x(), 0.7, 2.5, 4.0).unwrap();
        for _ in 0..100 {
            let e = patch.evaluate(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
            let rel = e.point - c;
            let across = rel - axis * axis.dot(&rel);
            assert!((across.norm() - 2.5).abs() < 1e-13);
            let n = patch.normal(&e).unwrap();
            assert!(
                (n - across / 2.5).norm() < 1e-13,
                "normal points away from the axis"
            );
        }
    }

    #[test]
    fn quarter_torus_is_exact() {
        let mut rng = Rng::new(43);
        let axis = Vec3::new(0.2, 0.1, 1.0).normalize();
        let c = Vec3::new(-1.0, 0.5, 2.0);
        let patch = BezierPatch::quarter_torus(c, axis, Vec3::y(), 0.3, -1.0, 4.0, 1.5).unwrap();
        for _ in 0..100 {
            let e = patch.evaluate(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
            let rel = e.point - c;
            let across = rel - axis * axis.dot(&rel);
            let tube_centre = c + across.normalize() * 4.0;
            assert!(((e.point - tube_centre).norm() - 1.5).abs() < 1e-13);
            let n = patch.normal(&e).unwrap();
            assert!((n - (e.point - tube_centre) / 1.5).norm() < 1e-13);
        }
    }

    #[test]
    fn degenerate_point_gives_no_normal_and_no_nan() {
        // A triangle-like patch: the edge u = 0 collapses to one point.
        let apex = Vec3::new(0.0, 0.0, 1.0);
        let points = vec![
            apex,
            apex,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let patch = BezierPatch::new(1, 1, points, vec![1.0; 4]).unwrap();
        let e = patch.evaluate(0.0, 0.5);
        assert!(e.point.iter().chain(e.su.iter()).all(|c| c.is_finite()));
        assert!(patch.normal(&e).is_none());
        assert!(patch.normal(&patch.evaluate(0.5, 0.5)).is_some());
    }

    #[test]
    fn invalid_patches_are_refused() {
        let msg = |r: Result<BezierPatch>| r.unwrap_err().to_string();
        let p = Vec3::new(1.0, 2.0, 3.0);
        let err = msg(BezierPatch::new(1, 1, vec![p; 4], vec![1.0; 4]));
        assert!(err.contains("the patch is degenerate"), "{err}");
        // A quadratic-by-linear strip whose middle control row overshoots: the u curve
        // runs out and back, so the area element reverses halfway.
        let folded = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.5, 1.0, 0.0),
        ];
        let err = msg(BezierPatch::new(2, 1, folded, vec![1.0; 6]));
        assert!(err.contains("the patch folds over itself"), "{err}");
        let grid = vec![
            Vec3::zeros(),
            Vec3::y(),
            Vec3::x(),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let err = msg(BezierPatch::new(
            1,
            1,
            grid.clone(),
            vec![1.0, 1.0, 0.0, 1.0],
        ));
        assert!(
            err.contains("bezier patch weight [1][0] = 0 must be > 0"),
            "{err}"
        );
        let err = msg(BezierPatch::new(
            1,
            1,
            grid.clone(),
            vec![1.0, -2.0, 1.0, 1.0],
        ));
        assert!(
            err.contains("bezier patch weight [0][1] = -2 must be > 0"),
            "{err}"
        );
        let err = msg(BezierPatch::new(1, 1, grid.clone(), vec![1.0; 3]));
        assert!(
            err.contains("bezier patch weight count = 3 must be"),
            "{err}"
        );
        let err = msg(BezierPatch::new(2, 1, grid.clone(), vec![1.0; 6]));
        assert!(
            err.contains(
                "bezier patch control point count = 4 must be (degree_u + 1) * (degree_v + 1) = 6"
            ),
            "{err}"
        );
        let err = msg(BezierPatch::new(0, 1, grid[..2].to_vec(), vec![1.0; 2]));
        assert!(
            err.contains("bezier patch degree_u = 0 must be >= 1"),
            "{err}"
        );
        let mut bad = grid.clone();
        bad[3].z = f64::NAN;
        let err = msg(BezierPatch::new(1, 1, bad, vec![1.0; 4]));
        assert!(
            err.contains("bezier patch control point [1][1] = (1, 1, NaN) must be finite"),
            "{err}"
        );
        let err = msg(BezierPatch::quarter_torus(
            p,
            Vec3::z(),
            Vec3::x(),
            0.0,
            std::f64::consts::FRAC_PI_2,
            1.0,
            2.0,
        ));
        assert!(
            err.contains("torus patch minor radius = 2 must keep the patch off the axis: major + minor cos(phi) = -1 at phi = 180°"),
            "{err}"
        );
        let err = msg(BezierPatch::quarter_cylinder(
            p,
            Vec3::z(),
            Vec3::z(),
            0.0,
            1.0,
            1.0,
        ));
        assert!(err.contains("must not be parallel to the axis"), "{err}");
    }
}
