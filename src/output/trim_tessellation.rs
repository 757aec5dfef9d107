//! A trimmed Bézier piece tessellated within its trims, for display: the triangles of the
//! part of the piece's parameter square `[0, 1]^2` that lies on its trimmed face.
//!
//! The face is the region of its `(u, v)` plane inside its trimming loops (even-odd rule,
//! [`crate::geometry::trim::TrimRegion`]); the piece covers the rectangle
//! `[u0, u1] x [v0, v1]` of it, its own `(s, t)` mapped to `(u, v)` by
//! [`PieceTrim::to_face`] (affine, or the half-angle law along a circular direction).
//!
//! 1. **Boundary.** Each trimming segment `c(τ) = (u(τ), v(τ))`, `τ ∈ [0, 1]`, is cut where
//!    it crosses the lines `u = u0`, `u = u1`, `v = v0`, `v = v1` (sign changes of
//!    `u(τ) - u0` ... on 32 samples, then bisection to machine precision), and its
//!    intervals whose midpoint lies in the rectangle are kept. A kept interval is flattened
//!    by halving: the chord between the surface points `S(c(τa))` and `S(c(τb))` is kept
//!    when the surface points at `τ = τa + (τb - τa) k / 4`, `k = 1, 2, 3`, lie within the
//!    tolerance `δ` (a length) of it, else the interval is halved (at most 2^16 chords a
//!    segment). Every boundary vertex is thus an exact point of the trimming curve (its
//!    `(s, t)` from [`PieceTrim::to_piece`]), and each drawn boundary edge is a chord of the
//!    curve's image on the surface, within `δ` of it at the checked points.
//! 2. **Triangulation.** The constrained Delaunay triangulation (spade) in the `(s, t)`
//!    square of the display grid's points `(i / su, j / sv)` that lie on the face and the
//!    boundary vertices, with the boundary chords as constraint edges. Its triangles never
//!    cross a chord, so each connected set of triangles (through edges that are not
//!    chords) lies wholly on the face or wholly off it (up to the chords' sagitta `δ`). A set
//!    is kept when most of its area (triangle centroids tested with the exact
//!    [`PieceTrim::admits`]) is on the face.
//!
//! Grid points off the face are left out, so no drawn vertex lies off the face; a
//! triangle's points can lie off the face only within the sagitta `δ` of a chord across a
//! concave part of the boundary (the rim of a hole), so the drawn area differs from the
//! face's by at most about `(2/3) δ L`, `L` the length of the curved trims (a circular cap
//! of chord `c` and height `δ` has area `(2/3) c δ` to leading order).
//!
//! A piece no boundary enters is wholly on or off the face ([`Cover::Whole`],
//! [`Cover::Empty`]), decided at its centre. Cost: the boundary's chords plus the grid's
//! points, `O(n log n)` for the triangulation.

use crate::geometry::trim::{PieceTrim, TrimSegment};
use crate::geometry::{BezierPatch, Vec3};
use spade::handles::FixedVertexHandle;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

/// Samples along a trimming segment on which the crossings of the piece's edges are sought.
const CROSSING_SAMPLES: usize = 32;
/// Distance (in the piece's unit square) within which a boundary point is put on a side.
const SNAP: f64 = 1e-12;
/// Triangles of less area (in the unit square) are round-off slivers, left out.
const SLIVER: f64 = 1e-18;
/// Halvings of a boundary interval at most (2^16 chords a segment).
const MAX_DEPTH: usize = 16;

/// The part of a piece on its trimmed face.
#[derive(Debug, Clone, PartialEq)]
pub enum Cover {
    /// No trimming curve enters the piece and its centre is on the face: all of it.
    Whole,
    /// No trimming curve enters the piece and its centre is off the face: none of it.
    Empty,
    /// Triangles of `(s, t)` points, counter-clockwise in the `(s, t)` plane (as the
    /// display grid's quadrilaterals).
    Triangles {
        points: Vec<[f64; 2]>,
        triangles: Vec<[usize; 3]>,
    },
}

/// The cover of `patch`, restricted to `trim`, on the display grid of `su x sv` cells,
/// with boundary chords within `tolerance` (a length) of the trimming curves (see the
/// module docs).
pub fn cover(patch: &BezierPatch, trim: &PieceTrim, su: usize, sv: usize, tolerance: f64) -> Cover {
    let chains = boundary_chains(patch, trim, tolerance);
    if chains.is_empty() {
        return if trim.admits(0.5, 0.5) {
            Cover::Whole
        } else {
            Cover::Empty
        };
    }
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> = Default::default();
    for i in 0..=su {
        for j in 0..=sv {
            let (s, t) = (i as f64 / su as f64, j as f64 / sv as f64);
            if trim.admits(s, t) {
                // Coordinates in [0, 1] are always accepted by spade.
                let _ = cdt.insert(Point2::new(s, t));
            }
        }
    }
    for chain in &chains {
        let handles: Vec<FixedVertexHandle> = (chain.iter())
            .filter_map(|p| cdt.insert(Point2::new(p[0], p[1])).ok())
            .collect();
        for w in handles.windows(2) {
            // A chord crossing another (two trimming curves closer than the tolerance)
            // is left out rather than split: the display loses a sliver there.
            let _ = cdt.try_add_constraint(w[0], w[1]);
        }
    }
    kept_triangles(&cdt, trim)
}

/// The triangles of the components on the face (see the module docs, step 2).
fn kept_triangles(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>, trim: &PieceTrim) -> Cover {
    let faces: Vec<_> = cdt.inner_faces().collect();
    let mut component = vec![usize::MAX; cdt.num_all_faces()];
    let mut votes: Vec<[f64; 2]> = Vec::new();
    for start in &faces {
        if component[start.fix().index()] != usize::MAX {
            continue;
        }
        let id = votes.len();
        votes.push([0.0; 2]);
        let mut stack = vec![*start];
        component[start.fix().index()] = id;
        while let Some(face) = stack.pop() {
            let [a, b, c] = face.positions();
            let area = 0.5 * ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
            let on = trim.admits((a.x + b.x + c.x) / 3.0, (a.y + b.y + c.y) / 3.0);
            votes[id][usize::from(on)] += area;
            for edge in face.adjacent_edges() {
                if cdt.is_constraint_edge(edge.as_undirected().fix()) {
                    continue;
                }
                if let Some(next) = edge.rev().face().as_inner() {
                    if component[next.fix().index()] == usize::MAX {
                        component[next.fix().index()] = id;
                        stack.push(next);
                    }
                }
            }
        }
    }
    let mut index = vec![usize::MAX; cdt.num_vertices()];
    let mut points = Vec::new();
    let mut triangles = Vec::new();
    for face in faces {
        let [off, on] = votes[component[face.fix().index()]];
        if on <= off || face.area() < SLIVER {
            continue;
        }
        let corners = face.vertices().map(|v| {
            let k = v.fix().index();
            if index[k] == usize::MAX {
                index[k] = points.len();
                let p = v.position();
                points.push([p.x, p.y]);
            }
            index[k]
        });
        triangles.push(corners);
    }
    Cover::Triangles { points, triangles }
}

/// The trimming curves inside the piece, as chains of `(s, t)` points (step 1 of the module
/// docs).
fn boundary_chains(patch: &BezierPatch, trim: &PieceTrim, tolerance: f64) -> Vec<Vec<[f64; 2]>> {
    let (u, v) = (sorted(trim.u), sorted(trim.v));
    let eps = [1e-9 * (u[1] - u[0]), 1e-9 * (v[1] - v[0])];
    let inside = |p: [f64; 2]| {
        p[0] >= u[0] - eps[0]
            && p[0] <= u[1] + eps[0]
            && p[1] >= v[0] - eps[1]
            && p[1] <= v[1] + eps[1]
    };
    let mut chains = Vec::new();
    for segment in trim.region.loops().iter().flatten() {
        let cuts = crossings(segment, [u, v]);
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b - a <= 0.0 || !inside(segment.point(0.5 * (a + b))) {
                continue;
            }
            let flat = Flattening {
                segment,
                trim,
                patch,
                tolerance,
            };
            let start = flat.at(a);
            let mut chain = vec![start.0];
            flat.refine((a, start), (b, flat.at(b)), 0, &mut chain);
            chains.push(chain);
        }
    }
    chains
}

fn sorted(x: [f64; 2]) -> [f64; 2] {
    [x[0].min(x[1]), x[0].max(x[1])]
}

/// The parameters `0`, `1` and those where `segment` crosses a side line of the box
/// `[u, v]`, in increasing order.
fn crossings(segment: &TrimSegment, [u, v]: [[f64; 2]; 2]) -> Vec<f64> {
    let lines = [(0, u[0]), (0, u[1]), (1, v[0]), (1, v[1])];
    let n = CROSSING_SAMPLES;
    let samples: Vec<[f64; 2]> = (0..=n)
        .map(|k| segment.point(k as f64 / n as f64))
        .collect();
    let mut cuts = vec![0.0, 1.0];
    for (axis, c) in lines {
        let g = |t: f64| segment.point(t)[axis] - c;
        for k in 0..n {
            let (ga, gb) = (samples[k][axis] - c, samples[k + 1][axis] - c);
            if ga == 0.0 {
                cuts.push(k as f64 / n as f64);
            } else if ga * gb < 0.0 {
                let (mut lo, mut hi) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if (g(mid) < 0.0) == (ga < 0.0) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                cuts.push(0.5 * (lo + hi));
            }
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    cuts
}

/// One trimming segment drawn on one piece.
struct Flattening<'a> {
    segment: &'a TrimSegment,
    trim: &'a PieceTrim,
    patch: &'a BezierPatch,
    tolerance: f64,
}

impl Flattening<'_> {
    /// The piece's `(s, t)` (clamped to its square) and the surface point at the segment's
    /// parameter `tau`.
    fn at(&self, tau: f64) -> ([f64; 2], Vec3) {
        let [u, v] = self.segment.point(tau);
        // Snapped onto the square's sides within round-off, so that points of a trim along
        // a side are exactly collinear there (no sliver triangles of round-off width).
        let st = self.trim.to_piece(u, v).map(|x| {
            if x < SNAP {
                0.0
            } else if x > 1.0 - SNAP {
                1.0
            } else {
                x
            }
        });
        (st, self.patch.point(st[0], st[1]))
    }

    /// Appends the chain's points after `a` up to `b` (see the module docs, step 1).
    fn refine(
        &self,
        a: (f64, ([f64; 2], Vec3)),
        b: (f64, ([f64; 2], Vec3)),
        depth: usize,
        out: &mut Vec<[f64; 2]>,
    ) {
        let ((ta, (_, pa)), (tb, (_, pb))) = (a, b);
        let far = [0.25, 0.5, 0.75].iter().any(|f| {
            let q = self.at(ta + f * (tb - ta)).1;
            distance_to_segment(&q, &pa, &pb) > self.tolerance
        });
        if far && depth < MAX_DEPTH {
            let tm = 0.5 * (ta + tb);
            let m = (tm, self.at(tm));
            self.refine(a, m, depth + 1, out);
            self.refine(m, b, depth + 1, out);
        } else {
            out.push(b.1 .0);
        }
    }
}

/// Distance from `q` to the segment from `a` to `b`.
fn distance_to_segment(q: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    let t = if len2 > 0.0 {
        ((q - a).dot(&d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (q - (a + d * t)).norm()
}
