//! Trimmed faces: the region of a surface's parameter plane inside its trimming loops, and
//! the test whether a foot point's parameters lie in it.
//!
//! A loop is a closed chain of exact rational Bézier segments in the `(u, v)` plane (the
//! pieces of the file's B-spline or line trimming curves). A point is inside the region when
//! a ray from it towards `+u` crosses the loops an odd number of times (even-odd rule, so an
//! outer loop with holes needs no orientation). Each segment's crossings are counted
//! exactly: its control polygon's box rejects it or accepts it whole in `O(degree)`; a
//! segment whose control ordinates are monotone in `v` is monotone itself (variation
//! diminishing, weights > 0) and crosses at most once, found by bisection; any other is
//! split in two by de Casteljau (on the homogeneous points, exact) and both halves counted.
//! Crossings use the half-open rule `(v_start <= v) != (v_end <= v)`, so a loop's vertex on
//! the ray is counted once.
//!
//! A foot within `BAND` of the loop (relative to the region's size) counts as inside: a foot
//! on the edge a face shares with its neighbour then belongs to both, whatever the rounding.

/// Half width of the boundary band counted as inside, relative to the region's diagonal.
const BAND: f64 = 1e-10;
/// Subdivision depth for non-monotone segments (a segment is monotone long before).
const MAX_DEPTH: usize = 40;

/// A rational Bézier segment in the parameter plane: homogeneous points `(w u, w v, w)`.
#[derive(Debug, Clone)]
pub struct TrimSegment {
    points: Vec<[f64; 3]>,
}

impl TrimSegment {
    /// From homogeneous control points `(w u, w v, w)`, `w > 0` (the caller checked).
    pub fn new(points: Vec<[f64; 3]>) -> TrimSegment {
        TrimSegment { points }
    }

    /// The straight segment from `a` to `b`.
    pub fn line(a: [f64; 2], b: [f64; 2]) -> TrimSegment {
        TrimSegment::new(vec![[a[0], a[1], 1.0], [b[0], b[1], 1.0]])
    }

    fn euclidean(h: &[f64; 3]) -> [f64; 2] {
        [h[0] / h[2], h[1] / h[2]]
    }

    /// The segment with `u` mapped to `a + b u` (exact: the map is affine, so it acts on
    /// the homogeneous points as `w u -> a w + b w u`).
    pub fn u_mapped(&self, a: f64, b: f64) -> TrimSegment {
        let points = self
            .points
            .iter()
            .map(|h| [a * h[2] + b * h[0], h[1], h[2]])
            .collect();
        TrimSegment { points }
    }

    /// The box `[[u0, u1], [v0, v1]]` of the control points, which holds the segment
    /// (convex hull property, weights > 0).
    pub fn hull_box(&self) -> [[f64; 2]; 2] {
        let mut b = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
        for h in &self.points {
            let p = Self::euclidean(h);
            for d in 0..2 {
                b[d] = [b[d][0].min(p[d]), b[d][1].max(p[d])];
            }
        }
        b
    }

    /// The segment moved by `(du, dv)` (exact on the homogeneous points).
    pub fn shifted(&self, du: f64, dv: f64) -> TrimSegment {
        let points = self
            .points
            .iter()
            .map(|h| [h[0] + du * h[2], h[1] + dv * h[2], h[2]])
            .collect();
        TrimSegment { points }
    }

    /// The same segment run backwards.
    pub fn reversed(&self) -> TrimSegment {
        TrimSegment::new(self.points.iter().rev().copied().collect())
    }

    pub fn start(&self) -> [f64; 2] {
        Self::euclidean(&self.points[0])
    }

    pub fn end(&self) -> [f64; 2] {
        Self::euclidean(self.points.last().unwrap())
    }

    /// The point at parameter `t` in `[0, 1]` (de Casteljau on homogeneous points).
    pub fn point(&self, t: f64) -> [f64; 2] {
        let (left, _) = split(&self.points, t);
        Self::euclidean(left.last().unwrap())
    }

    /// True if the segment lies on the line `u = c` (`axis` 0) or `v = c` (`axis` 1).
    fn on_line(&self, axis: usize, c: f64, tol: f64) -> bool {
        self.points
            .iter()
            .all(|h| (h[axis] / h[2] - c).abs() <= tol)
    }

    /// Crossings of the ray from `(u, v)` towards `+u` with this segment.
    fn crossings(&self, u: f64, v: f64) -> usize {
        crossings(&self.points, u, v, 0)
    }
}

/// De Casteljau split of homogeneous control points at `t`.
fn split(points: &[[f64; 3]], t: f64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let mut work = points.to_vec();
    let n = work.len();
    let mut left = Vec::with_capacity(n);
    let mut right = Vec::with_capacity(n);
    left.push(work[0]);
    right.push(work[n - 1]);
    for level in 1..n {
        for i in 0..n - level {
            for c in 0..3 {
                work[i][c] = (1.0 - t) * work[i][c] + t * work[i + 1][c];
            }
        }
        left.push(work[0]);
        right.push(work[n - 1 - level]);
    }
    right.reverse();
    (left, right)
}

fn crossings(points: &[[f64; 3]], u: f64, v: f64, depth: usize) -> usize {
    let e: Vec<[f64; 2]> = points.iter().map(TrimSegment::euclidean).collect();
    let (first, last) = (e[0], *e.last().unwrap());
    let (vmin, vmax) = e
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[1]), b.max(p[1]))
        });
    let (umin, umax) = e
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[0]), b.max(p[0]))
        });
    // The curve lies in its control polygon's box (convex hull property).
    if v < vmin || v > vmax || umax < u {
        return 0;
    }
    let increasing = e.windows(2).all(|w| w[1][1] >= w[0][1]);
    let decreasing = e.windows(2).all(|w| w[1][1] <= w[0][1]);
    if increasing || decreasing {
        let straddles = (first[1] <= v) != (last[1] <= v);
        if !straddles {
            return 0;
        }
        if umin > u {
            return 1;
        }
        // Bisection on the monotone v(t) for the crossing, then its u against ours.
        let (mut lo, mut hi) = (0.0, 1.0);
        let below_at_start = first[1] <= v;
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            let (l, _) = split(points, mid);
            let p = TrimSegment::euclidean(l.last().unwrap());
            if (p[1] <= v) == below_at_start {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (l, _) = split(points, 0.5 * (lo + hi));
        let p = TrimSegment::euclidean(l.last().unwrap());
        return usize::from(p[0] > u);
    }
    if depth >= MAX_DEPTH {
        // Only reached for a segment of no extent: count it as its chord.
        let straddles = (first[1] <= v) != (last[1] <= v);
        return usize::from(straddles && 0.5 * (first[0] + last[0]) > u);
    }
    let (l, r) = split(points, 0.5);
    crossings(&l, u, v, depth + 1) + crossings(&r, u, v, depth + 1)
}

/// The part of a face's parameter plane inside its trimming loops.
#[derive(Debug, Clone)]
pub struct TrimRegion {
    loops: Vec<Vec<TrimSegment>>,
    band: f64,
}

impl TrimRegion {
    /// Loops of segments; each loop must close (end of each segment at the start of the
    /// next, last back to the first) within `1e-7` of the region's size, else the error
    /// names the loop and segment.
    pub fn new(loops: Vec<Vec<TrimSegment>>) -> crate::Result<TrimRegion> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in loops.iter().flatten().flat_map(|s| s.points.iter()) {
            let e = TrimSegment::euclidean(p);
            for c in 0..2 {
                lo[c] = lo[c].min(e[c]);
                hi[c] = hi[c].max(e[c]);
            }
        }
        let size = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
        if loops.iter().all(|l| l.is_empty()) || !size.is_finite() || size <= 0.0 {
            return Err(crate::Error::Input(
                "trimming loops enclose no area".to_string(),
            ));
        }
        for (l, segments) in loops.iter().enumerate() {
            for (s, seg) in segments.iter().enumerate() {
                let next = &segments[(s + 1) % segments.len()];
                let (a, b) = (seg.end(), next.start());
                let gap = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
                if gap > 1e-7 * size {
                    return Err(crate::Error::input(
                        &format!("trimming loop {l} segment {s}: gap to the next segment"),
                        gap,
                        "must be 0: the loop does not close",
                    ));
                }
            }
        }
        Ok(TrimRegion {
            loops,
            band: BAND * size,
        })
    }

    /// The trimming loops, each a closed chain of segments.
    pub fn loops(&self) -> &[Vec<TrimSegment>] {
        &self.loops
    }

    /// True if the only loop is the rectangle `u x v` itself (so nothing is trimmed away).
    pub fn is_rectangle(&self, u: [f64; 2], v: [f64; 2]) -> bool {
        let tol = 1e-9 * ((u[1] - u[0]).abs() + (v[1] - v[0]).abs());
        self.loops.len() == 1
            && self.loops[0].iter().all(|s| {
                s.on_line(0, u[0], tol)
                    || s.on_line(0, u[1], tol)
                    || s.on_line(1, v[0], tol)
                    || s.on_line(1, v[1], tol)
            })
    }

    fn strictly_inside(&self, u: f64, v: f64) -> bool {
        let n: usize = self.loops.iter().flatten().map(|s| s.crossings(u, v)).sum();
        n % 2 == 1
    }

    /// True if `(u, v)` is inside the region or within its boundary band.
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let b = self.band;
        [(0.0, 0.0), (b, 0.0), (-b, 0.0), (0.0, b), (0.0, -b)]
            .iter()
            .any(|(du, dv)| self.strictly_inside(u + du, v + dv))
    }
}

/// Where a Bézier piece of a trimmed face sits in the face's parameter plane: its
/// `(s, t)` in `[0, 1]^2` is `(u0 + f(s) (u1 - u0), v0 + f(t) (v1 - v0))` of `region`,
/// with `f` the identity, or along a direction whose pieces are circular arcs in normal
/// form of half angle `h` (the face's parameter being affine in the angle), the half-angle
/// tangent law `f(s) = 1/2 + atan((2 s - 1) tan(h / 2)) / h`
/// (see [`crate::geometry::analytic_nurbs`]).
#[derive(Debug, Clone)]
pub struct PieceTrim {
    pub region: std::sync::Arc<TrimRegion>,
    pub u: [f64; 2],
    pub v: [f64; 2],
    /// Arc half angle along `u` and along `v`, or `None` where `f` is the identity.
    pub arcs: [Option<f64>; 2],
}

/// The fraction of a piece's parameter interval at its own parameter `s` (see [`PieceTrim`]).
fn fraction(s: f64, arc: Option<f64>) -> f64 {
    match arc {
        None => s,
        Some(h) => 0.5 + ((2.0 * s - 1.0) * (0.5 * h).tan()).atan() / h,
    }
}

/// The inverse of [`fraction`]: the piece's own parameter at fraction `f`,
/// `s = 1/2 + tan(h (f - 1/2)) / (2 tan(h / 2))` along an arc (defined for
/// `|f - 1/2| < pi / (2 h)`, which holds on and near the piece, `h <= pi / 2`).
fn unfraction(f: f64, arc: Option<f64>) -> f64 {
    match arc {
        None => f,
        Some(h) => 0.5 + (h * (f - 0.5)).tan() / (2.0 * (0.5 * h).tan()),
    }
}

impl PieceTrim {
    /// True if the piece's point `(s, t)` is on the trimmed face.
    pub fn admits(&self, s: f64, t: f64) -> bool {
        let [u, v] = self.to_face(s, t);
        self.region.contains(u, v)
    }

    /// The face's parameters `(u, v)` of the piece's point `(s, t)`.
    pub fn to_face(&self, s: f64, t: f64) -> [f64; 2] {
        [
            self.u[0] + fraction(s, self.arcs[0]) * (self.u[1] - self.u[0]),
            self.v[0] + fraction(t, self.arcs[1]) * (self.v[1] - self.v[0]),
        ]
    }

    /// The piece's parameters `(s, t)` of the face's point `(u, v)` (the inverse of
    /// [`PieceTrim::to_face`]; for points on or near the piece).
    pub fn to_piece(&self, u: f64, v: f64) -> [f64; 2] {
        [
            unfraction((u - self.u[0]) / (self.u[1] - self.u[0]), self.arcs[0]),
            unfraction((v - self.v[0]) / (self.v[1] - self.v[0]), self.arcs[1]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::Rng;
    use std::f64::consts::FRAC_1_SQRT_2;

    /// Rounded square of half side `h` and corner radius `r` (lines and rational quadratic
    /// quarter arcs), centred at the origin.
    fn rounded_square(h: f64, r: f64) -> Vec<TrimSegment> {
        let c = h - r;
        let w = FRAC_1_SQRT_2;
        let mut loop_ = Vec::new();
        for k in 0..4 {
            let rot = |p: [f64; 2]| -> [f64; 2] {
                let (s, co) = (k as f64 * std::f64::consts::FRAC_PI_2).sin_cos();
                [co * p[0] - s * p[1], s * p[0] + co * p[1]]
            };
            let (a, b) = (rot([h, -c]), rot([h, c]));
            loop_.push(TrimSegment::line(a, b));
            let (p0, p1, p2) = (rot([h, c]), rot([h, h]), rot([c, h]));
            loop_.push(TrimSegment::new(vec![
                [p0[0], p0[1], 1.0],
                [p1[0] * w, p1[1] * w, w],
                [p2[0], p2[1], 1.0],
            ]));
        }
        loop_
    }

    fn inside_rounded_square(h: f64, r: f64, u: f64, v: f64) -> bool {
        let (au, av) = (u.abs(), v.abs());
        let c = h - r;
        au <= h && av <= h && (au <= c || av <= c || (au - c).hypot(av - c) <= r)
    }

    #[test]
    fn rounded_square_with_a_hole_classifies_points_exactly() {
        let outer = rounded_square(10.0, 3.0);
        let hole = rounded_square(4.0, 1.0);
        let region = TrimRegion::new(vec![outer, hole]).unwrap();
        let mut rng = Rng::new(81);
        let mut counted = [0; 2];
        for _ in 0..20_000 {
            let (u, v) = (rng.uniform(-12.0, 12.0), rng.uniform(-12.0, 12.0));
            let expected =
                inside_rounded_square(10.0, 3.0, u, v) && !inside_rounded_square(4.0, 1.0, u, v);
            // Points within 1e-8 of the boundary are left out (the band decides them).
            let near = [10.0, 3.0, 4.0, 1.0].chunks(2).any(|hr| {
                let d = (-1..=1)
                    .flat_map(|a| (-1..=1).map(move |b| (a, b)))
                    .map(|(a, b)| {
                        inside_rounded_square(
                            hr[0],
                            hr[1],
                            u + a as f64 * 1e-8,
                            v + b as f64 * 1e-8,
                        )
                    })
                    .collect::<Vec<_>>();
                d.iter().any(|&x| x) && d.iter().any(|&x| !x)
            });
            if near {
                continue;
            }
            assert_eq!(region.contains(u, v), expected, "({u}, {v})");
            counted[expected as usize] += 1;
        }
        assert!(counted[0] > 5000 && counted[1] > 5000, "{counted:?}");
        // On a vertex of the loop and on an arc: inside by the band.
        assert!(region.contains(10.0, 0.0));
        let s = FRAC_1_SQRT_2 * 3.0;
        assert!(region.contains(7.0 + s, 7.0 + s));
        assert!(!region.contains(7.0 + s + 1e-6, 7.0 + s + 1e-6));
    }

    /// `to_piece` inverts `to_face`, along straight and circular directions alike.
    #[test]
    fn piece_parameters_map_to_the_face_and_back() {
        let region = std::sync::Arc::new(TrimRegion::new(vec![rounded_square(1.0, 0.5)]).unwrap());
        for arcs in [[None, None], [Some(std::f64::consts::FRAC_PI_4), Some(0.3)]] {
            let trim = PieceTrim {
                region: region.clone(),
                u: [0.2, 0.7],
                v: [-1.0, 0.5],
                arcs,
            };
            for (s, t) in [(0.0, 0.0), (0.3, 0.9), (1.0, 0.5), (0.77, 1.0)] {
                let [u, v] = trim.to_face(s, t);
                let back = trim.to_piece(u, v);
                // Round-off of tan/atan on values of order 1.
                assert!(
                    (back[0] - s).abs() < 1e-14 && (back[1] - t).abs() < 1e-14,
                    "{arcs:?}: ({s}, {t}) -> ({u}, {v}) -> {back:?}"
                );
            }
            assert!(trim.to_face(0.0, 1.0) == [0.2, 0.5] && trim.to_face(1.0, 0.0) == [0.7, -1.0]);
        }
    }

    #[test]
    fn open_loops_are_refused_and_rectangles_recognised() {
        let mut open = rounded_square(10.0, 3.0);
        open.pop();
        let err = TrimRegion::new(vec![open]).unwrap_err().to_string();
        assert!(
            err.contains("trimming loop 0 segment 6: gap to the next segment"),
            "{err}"
        );
        let rect = vec![
            TrimSegment::line([0.0, 0.0], [2.0, 0.0]),
            TrimSegment::line([2.0, 0.0], [2.0, 1.0]),
            TrimSegment::line([2.0, 1.0], [0.0, 1.0]),
            TrimSegment::line([0.0, 1.0], [0.0, 0.0]),
        ];
        let region = TrimRegion::new(vec![rect]).unwrap();
        assert!(region.is_rectangle([0.0, 2.0], [0.0, 1.0]));
        assert!(!region.is_rectangle([0.0, 3.0], [0.0, 1.0]));
        let round = TrimRegion::new(vec![rounded_square(1.0, 0.5)]).unwrap();
        assert!(!round.is_rectangle([-1.0, 1.0], [-1.0, 1.0]));
    }
}
