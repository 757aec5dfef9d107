//! Non-uniform rational B-splines (surfaces, and curves of any dimension) and their exact
//! split into rational Bézier pieces by knot insertion.
//!
//! A NURBS surface of degrees `(p, q)` on knot vectors `U` (`n + p + 1` knots) and `V`
//! (`m + q + 1`) with control points `P_ij` and weights `w_ij > 0` is
//!
//! ```text
//! S(u, v) = sum_ij w_ij P_ij N_i^p(u) N_j^q(v) / sum_ij w_ij N_i^p(u) N_j^q(v)
//! ```
//!
//! on the domain `[U_p, U_n] x [V_q, V_m]`. It is exactly a polynomial spline in homogeneous
//! coordinates `(w P, w)`, so knot insertion (Boehm: inserting `t` in span `k` of current
//! multiplicity `s` replaces `Q_i` for `k-p < i <= k-s` by `a_i Q_i + (1 - a_i) Q_{i-1}`,
//! `a_i = (t - U_i)/(U_{i+p} - U_i)`) changes the basis, not the surface. Once every
//! breakpoint of the domain (ends included, so unclamped vectors work too) has multiplicity
//! `p`, the `p + 1` control points of each non-empty span are the Bernstein coefficients of
//! that span: a rational Bézier piece, with positive weights (convex combinations).
//! Cost: `O(p)` insertions per breakpoint, each `O(n D)` for points of dimension `D`.
//!
//! Surfaces are refined along `u` with whole rows over `v` as the "points", then along `v`.

use super::bezier::BezierPatch;
use super::*;
use crate::{Error, Result};

/// A rational B-spline surface; control points row-major, `i` along `u`.
#[derive(Debug, Clone)]
pub struct NurbsSurface {
    degree: [usize; 2],
    knots: [Vec<f64>; 2],
    count: [usize; 2],
    points: Vec<Vec3>,
    weights: Vec<f64>,
    /// Parameter rectangle used (within the knot domain): `[[u0, u1], [v0, v1]]`.
    domain: [[f64; 2]; 2],
}

/// One rational Bézier piece of a NURBS surface and the parameter rectangle it covers:
/// the patch's `(s, t)` in `[0, 1]^2` is the surface's `(u0 + s (u1 - u0), v0 + t (v1 - v0))`.
#[derive(Debug, Clone)]
pub struct BezierPiece {
    pub patch: BezierPatch,
    pub u: [f64; 2],
    pub v: [f64; 2],
}

const DIRECTION: [&str; 2] = ["u", "v"];

/// Checks a knot vector for `count` control points of degree `degree`: length, finite,
/// non-decreasing, non-empty domain, no interior knot repeated more than `degree` times
/// (the spline would break apart there). `what` names the owner in messages.
pub fn check_knots(what: &str, degree: usize, count: usize, knots: &[f64]) -> Result<()> {
    if degree == 0 {
        return Err(Error::input(&format!("{what} degree"), 0, "must be >= 1"));
    }
    if count < degree + 1 {
        return Err(Error::input(
            &format!("{what} control point count"),
            count,
            &format!("must be >= degree + 1 = {}", degree + 1),
        ));
    }
    let expected = count + degree + 1;
    if knots.len() != expected {
        return Err(Error::input(
            &format!("{what} knot count"),
            knots.len(),
            &format!("must be control points + degree + 1 = {expected}"),
        ));
    }
    for (i, k) in knots.iter().enumerate() {
        if !k.is_finite() {
            return Err(Error::input(
                &format!("{what} knot [{i}]"),
                k,
                "must be finite",
            ));
        }
        if i > 0 && *k < knots[i - 1] {
            return Err(Error::input(
                &format!("{what} knot [{i}]"),
                k,
                &format!("must be >= the previous knot {}", knots[i - 1]),
            ));
        }
    }
    let (a, b) = (knots[degree], knots[count]);
    if a >= b {
        return Err(Error::input(
            &format!("{what} parameter domain"),
            format!("[{a}, {b}]"),
            "must not be empty",
        ));
    }
    let mut i = degree + 1;
    while i < count {
        let run = knots[i..count]
            .iter()
            .take_while(|&&k| k == knots[i])
            .count();
        if run > degree {
            return Err(Error::input(
                &format!("{what} interior knot {} multiplicity", knots[i]),
                run,
                &format!("must be <= the degree {degree} (the spline would be discontinuous)"),
            ));
        }
        i += run;
    }
    Ok(())
}

/// Inserts `t` once into a spline of degree `p` whose control points (each `dim` numbers,
/// flattened in `points`) sit on `knots` (Boehm's algorithm, see the module docs).
fn insert_knot(p: usize, knots: &mut Vec<f64>, points: &mut Vec<f64>, dim: usize, t: f64) {
    let n = points.len() / dim;
    let k = knots
        .iter()
        .rposition(|&x| x <= t)
        .expect("t inside the knots");
    let s = knots.iter().filter(|&&x| x == t).count();
    let mut out = Vec::with_capacity(points.len() + dim);
    for i in 0..=n {
        if i + p <= k {
            out.extend_from_slice(&points[i * dim..(i + 1) * dim]);
        } else if i + s <= k {
            let a = (t - knots[i]) / (knots[i + p] - knots[i]);
            for c in 0..dim {
                out.push(a * points[i * dim + c] + (1.0 - a) * points[(i - 1) * dim + c]);
            }
        } else {
            out.extend_from_slice(&points[(i - 1) * dim..i * dim]);
        }
    }
    knots.insert(k + 1, t);
    *points = out;
}

/// The spline refined so that every breakpoint in `[a, b]` (the knots there, and `a`, `b`)
/// has multiplicity at least `p`; returns the new knots and points, and the spans
/// `(k, [U_k, U_k+1])` inside `[a, b]` whose points `k - p ..= k` are Bézier coefficients.
fn split_into_spans(
    p: usize,
    knots: &[f64],
    points: &[f64],
    dim: usize,
    [a, b]: [f64; 2],
) -> (Vec<f64>, Vec<(usize, [f64; 2])>) {
    let mut breaks: Vec<f64> = knots.iter().copied().filter(|&k| a < k && k < b).collect();
    breaks.extend([a, b]);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let mut knots = knots.to_vec();
    let mut points = points.to_vec();
    for t in breaks {
        let s = knots.iter().filter(|&&x| x == t).count();
        for _ in s..p {
            insert_knot(p, &mut knots, &mut points, dim, t);
        }
    }
    let n = points.len() / dim;
    let spans = (p..n)
        .filter(|&k| knots[k] < knots[k + 1] && a <= knots[k] && knots[k + 1] <= b)
        .map(|k| (k, [knots[k], knots[k + 1]]))
        .collect();
    (points, spans)
}

/// Rational Bézier segments of a NURBS curve of any dimension `dim`, in homogeneous form:
/// each segment is `p + 1` points of `dim + 1` numbers `(w x_1, .., w x_dim, w)`, with its
/// parameter interval. `points` are `dim` numbers each; `range` must lie in the domain.
pub fn curve_segments(
    p: usize,
    knots: &[f64],
    points: &[f64],
    weights: &[f64],
    dim: usize,
    range: [f64; 2],
) -> Vec<(Vec<f64>, [f64; 2])> {
    let mut homogeneous = Vec::with_capacity(weights.len() * (dim + 1));
    for (x, w) in points.chunks(dim).zip(weights) {
        homogeneous.extend(x.iter().map(|c| c * w));
        homogeneous.push(*w);
    }
    let h = dim + 1;
    let (refined, spans) = split_into_spans(p, knots, &homogeneous, h, range);
    spans
        .into_iter()
        .map(|(k, interval)| (refined[(k - p) * h..(k + 1) * h].to_vec(), interval))
        .collect()
}

impl NurbsSurface {
    /// `points[i][j]`, `weights[i][j]` with `i` along `u`. Errs naming the entry at fault
    /// (see [`check_knots`]; weights finite and > 0, points finite).
    pub fn new(
        degree: [usize; 2],
        knots: [Vec<f64>; 2],
        points: Vec<Vec<Vec3>>,
        weights: Option<Vec<Vec<f64>>>,
    ) -> Result<NurbsSurface> {
        let count = [points.len(), points.first().map_or(0, |r| r.len())];
        for (i, row) in points.iter().enumerate() {
            if row.len() != count[1] {
                return Err(Error::input(
                    &format!("nurbs points row {i} length"),
                    row.len(),
                    &format!("must equal row 0's length {}", count[1]),
                ));
            }
        }
        for d in 0..2 {
            check_knots(
                &format!("nurbs {}", DIRECTION[d]),
                degree[d],
                count[d],
                &knots[d],
            )?;
        }
        let weights: Vec<f64> = match weights {
            None => vec![1.0; count[0] * count[1]],
            Some(w) => {
                let shape_ok = w.len() == count[0] && w.iter().all(|r| r.len() == count[1]);
                if !shape_ok {
                    return Err(Error::input(
                        "nurbs weights shape",
                        format!("{} rows", w.len()),
                        &format!("must be {} x {} like the points", count[0], count[1]),
                    ));
                }
                w.into_iter().flatten().collect()
            }
        };
        for (k, w) in weights.iter().enumerate() {
            if !w.is_finite() || *w <= 0.0 {
                let (i, j) = (k / count[1], k % count[1]);
                return Err(Error::input(
                    &format!("nurbs weight [{i}][{j}]"),
                    w,
                    "must be finite and > 0",
                ));
            }
        }
        let points: Vec<Vec3> = points.into_iter().flatten().collect();
        for (k, p) in points.iter().enumerate() {
            let (i, j) = (k / count[1], k % count[1]);
            finite_vec3(&format!("nurbs control point [{i}][{j}]"), p)?;
        }
        let domain = [0, 1].map(|d| [knots[d][degree[d]], knots[d][count[d]]]);
        Ok(NurbsSurface {
            degree,
            knots,
            count,
            points,
            weights,
            domain,
        })
    }

    /// The same surface restricted to `[u0, u1] x [v0, v1]` (inside the knot domain, each
    /// interval non-empty): what IGES calls the surface's parameter range.
    pub fn restricted(mut self, u: [f64; 2], v: [f64; 2]) -> Result<NurbsSurface> {
        for (d, range) in [u, v].into_iter().enumerate() {
            let [a, b] = [self.knots[d][self.degree[d]], self.knots[d][self.count[d]]];
            let inside = range[0] < range[1] && a <= range[0] && range[1] <= b;
            if !inside {
                return Err(Error::input(
                    &format!("nurbs {} parameter range", DIRECTION[d]),
                    format!("[{}, {}]", range[0], range[1]),
                    &format!("must be a non-empty interval inside the knot domain [{a}, {b}]"),
                ));
            }
            self.domain[d] = range;
        }
        Ok(self)
    }

    /// The parameter rectangle `[[u0, u1], [v0, v1]]`.
    pub fn domain(&self) -> [[f64; 2]; 2] {
        self.domain
    }

    /// The same surface with `u` and `v` exchanged: `T(u, v) = S(v, u)`. Exact (the control
    /// net is transposed); the normal `T_u x T_v = -(S_u x S_v)` is reversed.
    pub fn transposed(self) -> NurbsSurface {
        let [nu, nv] = self.count;
        let mut points = Vec::with_capacity(self.points.len());
        let mut weights = Vec::with_capacity(self.weights.len());
        for j in 0..nv {
            for i in 0..nu {
                points.push(self.points[i * nv + j]);
                weights.push(self.weights[i * nv + j]);
            }
        }
        let [ku, kv] = self.knots;
        NurbsSurface {
            degree: [self.degree[1], self.degree[0]],
            knots: [kv, ku],
            count: [nv, nu],
            points,
            weights,
            domain: [self.domain[1], self.domain[0]],
        }
    }

    /// The surface moved rigidly (or scaled): every control point `x -> R x + t`.
    pub fn transformed(mut self, rotation: &Mat3, translation: &Vec3) -> NurbsSurface {
        for p in &mut self.points {
            *p = rotation * *p + translation;
        }
        self
    }

    /// `S(u, v)` by the B-spline basis (Cox-de Boor), independent of the Bézier split:
    /// used to check it.
    pub fn point(&self, u: f64, v: f64) -> Vec3 {
        let (su, nu) = basis(self.degree[0], &self.knots[0], self.count[0], u);
        let (sv, nv) = basis(self.degree[1], &self.knots[1], self.count[1], v);
        let (mut a, mut w) = (Vec3::zeros(), 0.0);
        for (a_i, bu) in nu.iter().enumerate() {
            for (b_j, bv) in nv.iter().enumerate() {
                let k = (su - self.degree[0] + a_i) * self.count[1] + sv - self.degree[1] + b_j;
                let c = self.weights[k] * bu * bv;
                a += self.points[k] * c;
                w += c;
            }
        }
        a / w
    }

    /// The exact rational Bézier pieces covering the parameter rectangle, in order of `u`
    /// spans then `v` spans. Errs only if a piece is degenerate (no area anywhere).
    pub fn to_bezier(&self) -> Result<Vec<BezierPiece>> {
        let [p, q] = self.degree;
        let [nu, nv] = self.count;
        // Rows over v as points of the u-spline: dimension 4 nv.
        let mut rows = Vec::with_capacity(nu * nv * 4);
        for k in 0..nu * nv {
            let (x, w) = (self.points[k], self.weights[k]);
            rows.extend([x.x * w, x.y * w, x.z * w, w]);
        }
        let (rows, u_spans) = split_into_spans(p, &self.knots[0], &rows, 4 * nv, self.domain[0]);
        let nu2 = rows.len() / (4 * nv);
        // Transpose: columns over the refined u as points of the v-spline.
        let mut cols = vec![0.0; rows.len()];
        for i in 0..nu2 {
            for j in 0..nv {
                for c in 0..4 {
                    cols[(j * nu2 + i) * 4 + c] = rows[(i * nv + j) * 4 + c];
                }
            }
        }
        let (cols, v_spans) = split_into_spans(q, &self.knots[1], &cols, 4 * nu2, self.domain[1]);
        let mut pieces = Vec::with_capacity(u_spans.len() * v_spans.len());
        for &(ku, u) in &u_spans {
            for &(kv, v) in &v_spans {
                let mut points = Vec::with_capacity((p + 1) * (q + 1));
                let mut weights = Vec::with_capacity((p + 1) * (q + 1));
                for i in ku - p..=ku {
                    for j in kv - q..=kv {
                        let h = &cols[(j * nu2 + i) * 4..(j * nu2 + i) * 4 + 4];
                        points.push(Vec3::new(h[0], h[1], h[2]) / h[3]);
                        weights.push(h[3]);
                    }
                }
                let patch = BezierPatch::new(p, q, points, weights).map_err(|e| match e {
                    Error::Input(m) => Error::Input(format!(
                        "nurbs piece [{}, {}] x [{}, {}]: {m}",
                        u[0], u[1], v[0], v[1]
                    )),
                    other => other,
                })?;
                pieces.push(BezierPiece { patch, u, v });
            }
        }
        Ok(pieces)
    }
}

/// Span index `k` (`U_k <= t < U_k+1`, the last non-empty span at the domain's end) and the
/// `p + 1` non-zero basis values `N_{k-p..=k}^p(t)` (Piegl and Tiller, A2.2).
pub fn basis(p: usize, knots: &[f64], count: usize, t: f64) -> (usize, Vec<f64>) {
    let t = t.clamp(knots[p], knots[count]);
    let k = if t >= knots[count] {
        (p..count)
            .rev()
            .find(|&k| knots[k] < knots[k + 1])
            .unwrap_or(p)
    } else {
        knots
            .iter()
            .rposition(|&x| x <= t)
            .unwrap()
            .clamp(p, count - 1)
    };
    let mut n = vec![0.0; p + 1];
    let (mut left, mut right) = (vec![0.0; p + 1], vec![0.0; p + 1]);
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[k + 1 - j];
        right[j] = knots[k + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = n[r] / (right[r + 1] + left[j - r]);
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    (k, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::Rng;
    use std::f64::consts::FRAC_1_SQRT_2;

    /// A random bicubic-by-quadratic NURBS with repeated and unclamped knots.
    fn random_surface(rng: &mut Rng, clamped: bool) -> NurbsSurface {
        let (p, q, nu, nv) = (3, 2, 7, 5);
        let mut ku: Vec<f64> = if clamped {
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 0.3, 1.1, 2.0, 2.0, 2.0, 2.0]
        } else {
            vec![-0.3, -0.2, -0.1, 0.0, 0.3, 0.3, 1.1, 2.0, 2.2, 2.5, 2.6]
        };
        ku.iter_mut().for_each(|k| *k += 0.5);
        let kv = vec![0.0, 0.0, 0.0, 0.25, 0.7, 1.0, 1.0, 1.0];
        let points = (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| Vec3::new(i as f64, j as f64, rng.uniform(-0.5, 0.5)))
                    .collect()
            })
            .collect();
        let weights = (0..nu)
            .map(|_| (0..nv).map(|_| rng.uniform(0.5, 2.0)).collect())
            .collect();
        NurbsSurface::new([p, q], [ku, kv], points, Some(weights)).unwrap()
    }

    #[test]
    fn bezier_pieces_equal_the_nurbs_everywhere() {
        let mut rng = Rng::new(71);
        for clamped in [true, false] {
            let s = random_surface(&mut rng, clamped);
            let pieces = s.to_bezier().unwrap();
            // Distinct interior breakpoints: 3 spans in u (0.8, 1.6), 3 in v (0.25, 0.7).
            assert_eq!(pieces.len(), 9);
            for piece in &pieces {
                for _ in 0..50 {
                    let (a, b) = (rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
                    let u = piece.u[0] + a * (piece.u[1] - piece.u[0]);
                    let v = piece.v[0] + b * (piece.v[1] - piece.v[0]);
                    let d = (piece.patch.point(a, b) - s.point(u, v)).norm();
                    assert!(d < 1e-13, "{d} at ({u}, {v})");
                }
            }
        }
    }

    #[test]
    fn a_restricted_range_splits_at_its_ends() {
        let mut rng = Rng::new(72);
        let s = random_surface(&mut rng, true)
            .restricted([0.6, 1.2], [0.1, 0.9])
            .unwrap();
        let pieces = s.to_bezier().unwrap();
        assert_eq!(pieces.len(), 2 * 3);
        assert_eq!(pieces[0].u, [0.6, 0.8]);
        assert_eq!(pieces[0].v, [0.1, 0.25]);
        for piece in &pieces {
            let (u, v) = (piece.u[1], piece.v[1]);
            assert!((piece.patch.point(1.0, 1.0) - s.point(u, v)).norm() < 1e-13);
        }
        let err = random_surface(&mut rng, true)
            .restricted([0.0, 1.0], [0.0, 1.0])
            .unwrap_err()
            .to_string();
        assert!(err.contains("nurbs u parameter range = [0, 1] must be a non-empty interval inside the knot domain [0.5, 2.5]"), "{err}");
    }

    /// A full circle as the usual 9-point rational quadratic NURBS (knots doubled at the
    /// quarters) extruded: the cylinder's pieces are exact quarter cylinders.
    #[test]
    fn nine_point_circle_cylinder_is_exact() {
        let r = 2.5;
        let circle = [
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
            (1.0, 0.0),
        ];
        let points = circle
            .iter()
            .map(|&(x, y)| vec![Vec3::new(r * x, r * y, 0.0), Vec3::new(r * x, r * y, 3.0)])
            .collect();
        let weights = (0..9)
            .map(|i| vec![if i % 2 == 1 { FRAC_1_SQRT_2 } else { 1.0 }; 2])
            .collect();
        let ku = vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0];
        let s = NurbsSurface::new(
            [2, 1],
            [ku, vec![0.0, 0.0, 1.0, 1.0]],
            points,
            Some(weights),
        )
        .unwrap();
        let pieces = s.to_bezier().unwrap();
        assert_eq!(pieces.len(), 4);
        let mut rng = Rng::new(73);
        for piece in &pieces {
            for _ in 0..100 {
                let e = piece
                    .patch
                    .evaluate(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
                let radius = e.point.xy().norm();
                assert!((radius - r).abs() < 1e-14, "{radius}");
            }
        }
    }

    #[test]
    fn bad_knots_and_weights_are_named() {
        let pts = |n: usize| vec![vec![Vec3::zeros(); 2]; n];
        let msg = |r: Result<NurbsSurface>| r.unwrap_err().to_string();
        let kv = vec![0.0, 0.0, 1.0, 1.0];
        let e = msg(NurbsSurface::new(
            [2, 1],
            [vec![0.0, 0.0, 0.0, 1.0, 1.0], kv.clone()],
            pts(3),
            None,
        ));
        assert!(
            e.contains("nurbs u knot count = 5 must be control points + degree + 1 = 6"),
            "{e}"
        );
        let e = msg(NurbsSurface::new(
            [2, 1],
            [vec![0.0, 0.0, 0.0, 0.5, 0.4, 1.0, 1.0, 1.0], kv.clone()],
            pts(5),
            None,
        ));
        assert!(
            e.contains("nurbs u knot [4] = 0.4 must be >= the previous knot 0.5"),
            "{e}"
        );
        let e = msg(NurbsSurface::new(
            [2, 1],
            [
                vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0],
                kv.clone(),
            ],
            pts(6),
            None,
        ));
        assert!(
            e.contains("interior knot 0.5 multiplicity = 3 must be <= the degree 2"),
            "{e}"
        );
        let e = msg(NurbsSurface::new(
            [1, 1],
            [kv.clone(), kv.clone()],
            pts(2),
            Some(vec![vec![1.0, 1.0], vec![1.0, -1.0]]),
        ));
        assert!(
            e.contains("nurbs weight [1][1] = -1 must be finite and > 0"),
            "{e}"
        );
    }
}
