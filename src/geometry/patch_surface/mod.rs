//! A rigid surface made of rational Bézier patches, and its closest-point projection.
//!
//! Projection of `x` on one patch minimises `F(u, v) = |S(u, v) - x|^2 / 2` over
//! `[0, 1]^2` by projected Newton: with `r = S - x`,
//!
//! ```text
//! grad F = [S_u . r, S_v . r],   H = [[S_u.S_u + S_uu.r, S_u.S_v + S_uv.r],
//!                                     [S_u.S_v + S_uv.r, S_v.S_v + S_vv.r]],
//! ```
//!
//! a coordinate sitting on a bound whose descent direction points out of the square is
//! held fixed, so once the foot leaves the patch the iteration becomes a 1-D Newton along
//! the edge curve (or stops at a corner). Where `H` is not positive definite (far on the
//! concave side) the Gauss-Newton metric `a = J^T J` replaces it, and a backtracking line
//! search keeps `F` decreasing.
//!
//! Normal gradient `G = dn/dx` at fixed surface, for the three kinds of foot point:
//!
//! - interior: differentiating `S_a . (x - S) = 0` gives `(a - d b) dxi = J^T dx` with the
//!   metric `a_ab = S_a . S_b`, the second form `b_ab = S_ab . n` and the gap `d`; Weingarten
//!   gives `n_a = -b_ab a^{bc} S_c`, so `G = -J a^{-1} b (a - d b)^{-1} J^T`
//!   (sphere: `(I - n n^T)/(R + d)`);
//! - edge, the foot on the curve `C(t)` (`C' = S_v` on `u = const`): the normal is
//!   `n = ±(x - C)/|x - C|`, and `C' . (x - C) = 0` gives `dt = C' . dx / (C'.C' - C''.(x-C))`,
//!   so `G = [(I - n n^T) - C' C'^T / (C'.C' - C''.(x - C))] / d` (straight edge: a cylinder);
//! - corner, the foot fixed: `G = (I - n n^T) / d` (a sphere of radius 0).
//!
//! On an edge or corner the sign of `n` (and of `d`) is that of the patch normal's side, so
//! `n` is continuous where the foot passes from the inside of the patch to its edge.

pub mod seams;

use super::bezier::{BezierPatch, PatchPoint};
use super::bvh::{box_distance, Bvh};
use super::kdop::Kdop;
use super::trim::PieceTrim;
use super::*;
use crate::{Error, Result};
use nalgebra::{Matrix2, Matrix3x2};
use seams::{seam_report, SeamReport};

/// Coarse samples per direction for a cold start (the grid has `(N + 1)^2` points).
const COLD_SAMPLES: usize = 8;
const MAX_NEWTON: usize = 60;

/// A tool surface: rational Bézier patches with a consistent outward orientation.
#[derive(Debug, Clone)]
pub struct PatchSurface {
    patches: Vec<BezierPatch>,
    /// Control-point bounding boxes, to skip patches that cannot hold a closer foot.
    boxes: Vec<(Vec3, Vec3)>,
    /// Tree over `boxes`: candidate patches nearest-first, pruned by the best distance.
    bvh: Bvh,
    /// Search with the tree (default) or by sorting all boxes (kept to cross-check it).
    use_bvh: bool,
    /// Control-point 26-DOPs: a tighter lower bound than `boxes` on the distance to a
    /// patch, checked before a patch the tree offers is projected on.
    hulls: Vec<Kdop>,
    /// Skip patches by `hulls` (default) or project on every patch the tree offers (kept
    /// to cross-check that the skipping changes no answer).
    use_hulls: bool,
    /// Diagonal of the whole surface's box: the length scale of tolerances.
    scale: f64,
    /// Worst gap and kink where patches meet, measured at construction.
    seams: SeamReport,
    /// Per patch, the trimmed face it belongs to (if any): a foot outside the trim is not a
    /// foot of that patch.
    trims: Vec<Option<PieceTrim>>,
    /// The cold-start grid of every patch, `S(i/N, j/N)` at `[k][i (N + 1) + j]`, evaluated
    /// once: a cold start then costs `(N + 1)^2` distances instead of as many patch
    /// evaluations (the same points, so the same start, bit for bit).
    cold_grid: Vec<[Vec3; COLD_GRID]>,
}

/// Points of the cold-start grid.
const COLD_GRID: usize = (COLD_SAMPLES + 1) * (COLD_SAMPLES + 1);
/// Which bounds of `[0, 1]^2` hold the foot: the strictly active constraints.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Interior,
    /// On the edge `u = const` (`fixed_u`) or `v = const`.
    Edge {
        fixed_u: bool,
    },
    Corner,
}

impl Kind {
    /// Preference among feet at the same distance: a true interior minimum beats an edge
    /// foot of the neighbouring patch on a seam.
    fn rank(self) -> u8 {
        match self {
            Kind::Interior => 0,
            Kind::Edge { .. } => 1,
            Kind::Corner => 2,
        }
    }
}

/// Closest point of `x` on one patch.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Local {
    pub(crate) u: f64,
    pub(crate) v: f64,
    pub(crate) e: PatchPoint,
    pub(crate) dist: f64,
    kind: Kind,
}

impl PatchSurface {
    /// Errs if there is no patch, or if two patches meeting at a seam face opposite ways
    /// (see [`seam_report`]). The seam report is kept ([`PatchSurface::seams`]).
    pub fn new(patches: Vec<BezierPatch>) -> Result<PatchSurface> {
        let untrimmed = vec![None; patches.len()];
        PatchSurface::with_trims(patches, untrimmed)
    }

    /// As [`PatchSurface::new`], with patch `k` restricted to the trimmed face `trims[k]`
    /// (`None`: the whole patch). The projection returns no foot of a patch outside its
    /// trim; the neighbouring face across the trimming curve answers instead. The seam
    /// report samples the untrimmed patches' edges.
    pub fn with_trims(
        patches: Vec<BezierPatch>,
        trims: Vec<Option<PieceTrim>>,
    ) -> Result<PatchSurface> {
        if trims.len() != patches.len() {
            return Err(Error::input(
                "patch surface trim count",
                trims.len(),
                &format!("must equal the patch count {}", patches.len()),
            ));
        }
        if patches.is_empty() {
            return Err(Error::input("patch surface patch count", 0, "must be >= 1"));
        }
        for (k, p) in patches.iter().enumerate() {
            if let Some((u, v)) = p.fold() {
                return Err(Error::Input(format!(
                    "patch {k} folds over itself: its Jacobian S_u x S_v reverses near \
                     (u, v) = ({u:.3}, {v:.3}) (check the order of its control points)"
                )));
            }
        }
        let boxes: Vec<_> = patches.iter().map(|p| p.bounding_box()).collect();
        let (lo, hi) = boxes.iter().fold(
            (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
            |(lo, hi), (l, h)| (lo.inf(l), hi.sup(h)),
        );
        let n = COLD_SAMPLES as f64;
        let cold_grid = patches
            .iter()
            .map(|p| {
                std::array::from_fn(|ij| {
                    let (i, j) = (ij / (COLD_SAMPLES + 1), ij % (COLD_SAMPLES + 1));
                    p.point(i as f64 / n, j as f64 / n)
                })
            })
            .collect();
        let mut surface = PatchSurface {
            cold_grid,
            bvh: Bvh::new(&boxes),
            hulls: patches.iter().map(|p| Kdop::around(p.points())).collect(),
            patches,
            boxes,
            use_bvh: true,
            use_hulls: true,
            scale: (hi - lo).norm(),
            seams: SeamReport::default(),
            trims,
        };
        surface.seams = seam_report(&surface)?;
        Ok(surface)
    }

    /// As [`PatchSurface::new`], and `outside` (a point the user knows to be outside the
    /// tool) must lie on the outer side: a positive gap. Otherwise the patches face inward
    /// and the error says so.
    pub fn with_outside_point(patches: Vec<BezierPatch>, outside: Vec3) -> Result<PatchSurface> {
        let outside = finite_vec3("patch surface outside point", &outside)?;
        let surface = PatchSurface::new(patches)?;
        match surface.project(&outside, None) {
            Some(p) if p.gap > 0.0 => Ok(surface),
            Some(p) => Err(Error::input(
                "patch surface outside point",
                fmt_vec3(&outside),
                &format!(
                    "is on the inner side of patch {} (signed gap {:.6e}): the patches face \
                     inward; flip them or give a point outside the tool",
                    p.hint.patch, p.gap
                ),
            )),
            None => Err(Error::input(
                "patch surface outside point",
                fmt_vec3(&outside),
                "has no defined projection on the surface",
            )),
        }
    }

    pub fn patches(&self) -> &[BezierPatch] {
        &self.patches
    }

    /// Per patch, its trimmed face (`None`: the whole patch).
    pub fn trims(&self) -> &[Option<PieceTrim>] {
        &self.trims
    }

    /// True if the foot `loc` of patch `k` lies on the patch's trimmed face.
    fn on_face(&self, k: usize, loc: &Local) -> bool {
        self.trims[k]
            .as_ref()
            .is_none_or(|t| t.admits(loc.u, loc.v))
    }

    /// Worst position gap and normal kink across the seams, from construction.
    pub fn seams(&self) -> &SeamReport {
        &self.seams
    }

    /// Diagonal of the surface's bounding box.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The same surface searched by sorting every patch box instead of the tree: slower,
    /// kept to check the tree gives the same answers.
    pub fn without_bvh(mut self) -> PatchSurface {
        self.use_bvh = false;
        self
    }

    /// The same surface projecting on every patch whose box is near enough, without the
    /// tighter 26-DOP test: slower, kept to check that test changes no answer.
    pub fn without_hulls(mut self) -> PatchSurface {
        self.use_hulls = false;
        self
    }

    /// Lower bound of the distance from `x` to patch `k` (its box).
    fn box_distance(&self, k: usize, x: &Vec3) -> f64 {
        let (lo, hi) = &self.boxes[k];
        box_distance(lo, hi, x)
    }

    /// Patches in non-decreasing box distance from `x`, while `visit` (which returns the
    /// current pruning bound) accepts them.
    pub(crate) fn nearest_patches(
        &self,
        x: &Vec3,
        bound: f64,
        mut visit: impl FnMut(usize, f64) -> f64,
    ) {
        if self.use_bvh {
            self.bvh.nearest_first(x, bound, visit);
            return;
        }
        let mut order: Vec<(f64, usize)> = (0..self.patches.len())
            .map(|k| (self.box_distance(k, x), k))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut bound = bound;
        for (d, k) in order {
            if d > bound {
                break;
            }
            bound = visit(k, d);
        }
    }

    /// Closest point on patch `k`, from `start` (warm) or from the best of a coarse grid.
    pub(crate) fn closest_on_patch(&self, k: usize, x: &Vec3, start: Option<(f64, f64)>) -> Local {
        let patch = &self.patches[k];
        let (mut u, mut v) = match start {
            Some((u, v)) => (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)),
            None => {
                // The grid point nearest to x (the first of equals, in grid order).
                let n = COLD_SAMPLES as f64;
                let (_, u, v) = self.cold_grid[k].iter().enumerate().fold(
                    (f64::INFINITY, 0.5, 0.5),
                    |b, (ij, p)| {
                        let d = (p - x).norm_squared();
                        if d < b.0 {
                            let (i, j) = (ij / (COLD_SAMPLES + 1), ij % (COLD_SAMPLES + 1));
                            (d, i as f64 / n, j as f64 / n)
                        } else {
                            b
                        }
                    },
                );
                (u, v)
            }
        };
        let mut e = patch.evaluate(u, v);
        let mut f = (e.point - x).norm_squared();
        for _ in 0..MAX_NEWTON {
            let r = e.point - x;
            let g = [e.su.dot(&r), e.sv.dot(&r)];
            let fixed = [pushes_out(u, g[0], 0.0), pushes_out(v, g[1], 0.0)];
            let step = newton_step(&e, &r, g, fixed);
            if step == [0.0, 0.0] {
                break;
            }
            // Backtracking on the clamped trial point: F must not increase. A small full
            // step is taken as it is: near the minimum the decrease of F (quadratic in the
            // step) falls below its rounding error while the step still matters.
            let local = step[0].abs() + step[1].abs() < 1e-6;
            let mut t = 1.0;
            let mut accepted = None;
            for _ in 0..40 {
                let (un, vn) = (
                    (u + t * step[0]).clamp(0.0, 1.0),
                    (v + t * step[1]).clamp(0.0, 1.0),
                );
                let en = patch.evaluate(un, vn);
                let fnew = (en.point - x).norm_squared();
                if fnew <= f || (local && t == 1.0) {
                    accepted = Some((un, vn, en, fnew));
                    break;
                }
                t *= 0.5;
            }
            let Some((un, vn, en, fnew)) = accepted else {
                break; // no decrease left at rounding level: converged
            };
            let moved = (un - u).abs() + (vn - v).abs();
            (u, v, e, f) = (un, vn, en, fnew);
            if moved < 1e-15 {
                break;
            }
        }
        // Strictly active bounds only: a foot on a seam with vanishing outward gradient is an
        // interior minimum (of the union of patches). The threshold corresponds to a foot
        // offset of about 1e-13 of the patch size, above the rounding of the gradient.
        let r = e.point - x;
        let size = patch.extent();
        let scale = 1e-13 * (size + r.norm());
        let active_u = pushes_out(u, e.su.dot(&r), scale * e.su.norm());
        let active_v = pushes_out(v, e.sv.dot(&r), scale * e.sv.norm());
        let kind = match (active_u, active_v) {
            (false, false) => Kind::Interior,
            (true, false) => Kind::Edge { fixed_u: true },
            (false, true) => Kind::Edge { fixed_u: false },
            (true, true) => Kind::Corner,
        };
        Local {
            u,
            v,
            e,
            dist: f.sqrt(),
            kind,
        }
    }

    /// The projection's normal, gap and normal gradient at the closest point `loc` of patch
    /// `k`; `None` where they are undefined (`x` at a centre of curvature of the foot).
    fn finish(&self, k: usize, loc: &Local, x: &Vec3) -> Option<Projection> {
        let patch = &self.patches[k];
        let e = &loc.e;
        let r = x - e.point;
        let dist = r.norm();
        let surface_normal = patch.normal(e);
        let hint = SurfaceHint {
            patch: k,
            u: loc.u,
            v: loc.v,
        };
        let on_surface = dist <= 1e-14 * self.scale;
        let point_like = |n: Vec3, gap: f64, extra: Mat3| -> Option<Projection> {
            Some(Projection {
                foot: e.point,
                normal: n,
                gap,
                normal_gradient: (Mat3::identity() - n * n.transpose() - extra) / gap,
                hint,
            })
        };
        if loc.kind == Kind::Interior || on_surface || surface_normal.is_none() {
            let Some(n) = surface_normal else {
                // Degenerate foot (a collapsed edge): only the direction to x is defined; it is
                // treated like a corner (an approximation: the foot may still slide).
                return if on_surface {
                    None
                } else {
                    point_like(r / dist, dist, Mat3::zeros())
                };
            };
            let gap = n.dot(&r);
            let j = Matrix3x2::from_columns(&[e.su, e.sv]);
            let a = j.transpose() * j;
            let (buu, buv, bvv) = (e.suu.dot(&n), e.suv.dot(&n), e.svv.dot(&n));
            let b = Matrix2::new(buu, buv, buv, bvv);
            let a_inv = a.try_inverse()?;
            let m_inv = (a - b * gap).try_inverse()?;
            let g = -(j * a_inv * b * m_inv * j.transpose());
            return g.iter().all(|c| c.is_finite()).then_some(Projection {
                foot: e.point,
                normal: n,
                gap,
                normal_gradient: g,
                hint,
            });
        }
        let side = if surface_normal.unwrap().dot(&r) < 0.0 {
            -1.0
        } else {
            1.0
        };
        let n = r * (side / dist);
        let gap = side * dist;
        match loc.kind {
            Kind::Edge { fixed_u } => {
                let (c1, c2) = if fixed_u {
                    (e.sv, e.svv)
                } else {
                    (e.su, e.suu)
                };
                let stiffness = c1.dot(&c1) - c2.dot(&r);
                if stiffness.is_nan() || stiffness <= 0.0 {
                    return None;
                }
                point_like(n, gap, c1 * c1.transpose() / stiffness)
            }
            _ => point_like(n, gap, Mat3::zeros()),
        }
    }
}

/// True if parameter `t` sits on a bound of `[0, 1]` and the descent direction `-g`
/// points out of the interval by more than `threshold`.
fn pushes_out(t: f64, g: f64, threshold: f64) -> bool {
    (t <= 0.0 && g > threshold) || (t >= 1.0 && g < -threshold)
}

/// Newton step in the free coordinates (Gauss-Newton where the Hessian is not positive
/// definite); zero in the fixed ones and where even the metric is singular.
fn newton_step(e: &PatchPoint, r: &Vec3, g: [f64; 2], fixed: [bool; 2]) -> [f64; 2] {
    let metric = [
        [e.su.dot(&e.su), e.su.dot(&e.sv)],
        [e.su.dot(&e.sv), e.sv.dot(&e.sv)],
    ];
    let second = [[e.suu.dot(r), e.suv.dot(r)], [e.suv.dot(r), e.svv.dot(r)]];
    let hessian = [
        [metric[0][0] + second[0][0], metric[0][1] + second[0][1]],
        [metric[1][0] + second[1][0], metric[1][1] + second[1][1]],
    ];
    let solve2 = |h: [[f64; 2]; 2]| -> Option<[f64; 2]> {
        let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
        (h[0][0] > 0.0 && det > 1e-14 * h[0][0] * h[1][1]).then(|| {
            [
                -(h[1][1] * g[0] - h[0][1] * g[1]) / det,
                -(h[0][0] * g[1] - h[1][0] * g[0]) / det,
            ]
        })
    };
    match fixed {
        [false, false] => solve2(hessian)
            .or_else(|| solve2(metric))
            .unwrap_or([0.0, 0.0]),
        [true, true] => [0.0, 0.0],
        _ => {
            let k = if fixed[0] { 1 } else { 0 };
            let h = if hessian[k][k] > 0.0 {
                hessian[k][k]
            } else {
                metric[k][k]
            };
            let mut step = [0.0, 0.0];
            if h > 0.0 {
                step[k] = -g[k] / h;
            }
            step
        }
    }
}

impl RigidSurface for PatchSurface {
    /// Closest point over all patches. The hinted patch is tried first from the hinted
    /// `(u, v)` and kept unless another patch is closer by more than `1e-10` of the surface
    /// size (hysteresis: a node on a seam does not flip-flop), or equally close with a true
    /// interior foot where the hinted one is on an edge. Patches whose bounding box is
    /// farther than the best distance are skipped.
    fn project(&self, x: &Vec3, hint: Option<&SurfaceHint>) -> Option<Projection> {
        if !x.iter().all(|c| c.is_finite()) {
            return None;
        }
        let tol = 1e-10 * self.scale;
        let hinted =
            hint.filter(|h| h.patch < self.patches.len() && h.u.is_finite() && h.v.is_finite());
        let mut best: Option<(usize, Local)> = hinted
            .map(|h| (h.patch, self.closest_on_patch(h.patch, x, Some((h.u, h.v)))))
            .filter(|(k, loc)| self.on_face(*k, loc));
        let hinted_patch = hinted.map(|h| h.patch);
        // The hysteresis margin a candidate must beat the best by: only the hinted patch
        // has one (a node on a seam keeps its patch).
        let margin = |kb: usize| if Some(kb) == hinted_patch { tol } else { 0.0 };
        // The distance a candidate must beat to replace the best (the rules below): closer
        // than an interior best by its margin (an interior foot cannot be out-ranked), or
        // within tol of an edge or corner best with a better-ranked foot.
        let to_beat = |best: &Option<(usize, Local)>| match best {
            None => f64::INFINITY,
            Some((kb, b)) if b.kind == Kind::Interior => b.dist - margin(*kb),
            Some((_, b)) => b.dist + tol,
        };
        // Pruning bound of the boxes: no box farther than that distance can hold a winner
        // (less 1e-14 of the size below an interior best, so that a flat patch's box,
        // exactly at the distance, is skipped despite the rounding of the foot's distance).
        let bound_of = |best: &Option<(usize, Local)>| match best {
            Some((_, b)) if b.kind == Kind::Interior => to_beat(best) - 1e-14 * self.scale,
            _ => to_beat(best),
        };
        let bound = bound_of(&best);
        // A patch whose hull is farther than the distance to beat is not projected on; the
        // margin (1e-12 of the size) covers the rounding of the bound and of the foot's
        // distance.
        self.nearest_patches(x, bound, |k, _| {
            let hopeless = self.use_hulls
                && self.hulls[k].distance_lower_bound(x) > to_beat(&best) + 1e-12 * self.scale;
            if Some(k) != hinted_patch && !hopeless {
                let c = self.closest_on_patch(k, x, None);
                let replace = match &best {
                    _ if !self.on_face(k, &c) => false,
                    None => true,
                    Some((kb, b)) => {
                        if c.kind.rank() != b.kind.rank() && (c.dist - b.dist).abs() <= tol {
                            c.kind.rank() < b.kind.rank()
                        } else {
                            c.dist < b.dist - margin(*kb)
                        }
                    }
                };
                if replace {
                    best = Some((k, c));
                }
            }
            bound_of(&best)
        });
        let (k, loc) = best?;
        self.finish(k, &loc, x)
    }

    fn describe(&self) -> String {
        format!(
            "bezier surface of {} patches, size {:.6}",
            self.patches.len(),
            self.scale
        )
    }

    fn as_patch_surface(&self) -> Option<&PatchSurface> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::bezier::random_patch;
    use crate::geometry::testutil::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// Orthonormal `(f1, f2)` across `a`, as the patch constructors build it from `reference`.
    fn across(a: &Vec3, reference: &Vec3) -> (Vec3, Vec3) {
        let f1 = (reference - a * a.dot(reference)).normalize();
        (f1, a.cross(&f1))
    }

    /// An angle in `[lo, hi]`, half of the time within `1e-12..1e-2` of a multiple of 90°
    /// (a seam), on either side.
    fn angle(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
        if rng.uniform(0.0, 1.0) < 0.5 {
            return rng.uniform(lo, hi);
        }
        let k = (rng.uniform(lo, hi) / FRAC_PI_2).round();
        let offset = 10f64.powf(-rng.uniform(2.0, 12.0)) * rng.uniform(-1.0, 1.0).signum();
        (k * FRAC_PI_2 + offset).clamp(lo, hi)
    }

    struct CylinderCase {
        surface: PatchSurface,
        analytic: Cylinder,
        a: Vec3,
        f: (Vec3, Vec3),
        c: Vec3,
    }

    const R_CYL: f64 = 2.0;
    const L_CYL: f64 = 6.0;

    fn bezier_cylinder() -> CylinderCase {
        let c = Vec3::new(0.5, -1.0, 2.0);
        let a = Vec3::new(0.2, 1.0, -0.3).normalize();
        let reference = Vec3::new(1.0, 0.0, 0.3);
        let patches = (0..4)
            .map(|k| {
                let start = k as f64 * FRAC_PI_2;
                BezierPatch::quarter_cylinder(c, a, reference, start, R_CYL, L_CYL).unwrap()
            })
            .collect();
        CylinderCase {
            surface: PatchSurface::new(patches).unwrap(),
            analytic: Cylinder::new(c, a, R_CYL).unwrap(),
            a,
            f: across(&a, &reference),
            c,
        }
    }

    /// A point around the cylinder, away from its ends, gap in `[-0.8 R, 2 R]`.
    fn cylinder_point(case: &CylinderCase, rng: &mut Rng) -> Vec3 {
        let theta = angle(rng, 0.0, 2.0 * PI);
        let rho = R_CYL + rng.uniform(-0.8 * R_CYL, 2.0 * R_CYL);
        let t = rng.uniform(0.05 * L_CYL, 0.95 * L_CYL);
        case.c + case.a * t + (case.f.0 * theta.cos() + case.f.1 * theta.sin()) * rho
    }

    fn assert_same(p: &Projection, q: &Projection, x: &Vec3) {
        let ok = (p.foot - q.foot).norm() < 1e-10
            && (p.normal - q.normal).norm() < 1e-10
            && (p.gap - q.gap).abs() < 1e-10;
        assert!(ok, "x = {x:?}:\n bezier   {p:?}\n analytic {q:?}");
    }

    #[test]
    fn cylinder_of_quarter_patches_matches_analytic_cylinder() {
        let case = bezier_cylinder();
        let mut rng = Rng::new(51);
        let mut previous: Option<SurfaceHint> = None;
        for _ in 0..10_000 {
            let x = cylinder_point(&case, &mut rng);
            let exact = case.analytic.project(&x, None).unwrap();
            let cold = case.surface.project(&x, None).unwrap();
            assert_projection_consistent(&cold, &x);
            assert_same(&cold, &exact, &x);
            // Warm start from an unrelated point's foot (often another patch) and from the
            // point's own foot.
            let warm = case.surface.project(&x, previous.as_ref()).unwrap();
            assert_same(&warm, &exact, &x);
            let again = case.surface.project(&x, Some(&cold.hint)).unwrap();
            assert_same(&again, &exact, &x);
            assert_eq!(again.hint.patch, cold.hint.patch);
            previous = Some(cold.hint);
        }
    }

    const R_MAJOR: f64 = 3.0;
    const R_MINOR: f64 = 1.0;

    /// Half a torus (major angle 0..180°) in 2 x 4 quarter patches.
    fn bezier_torus() -> (PatchSurface, Vec3, Vec3, (Vec3, Vec3)) {
        let c = Vec3::new(-1.0, 0.5, 0.25);
        let a = Vec3::new(0.1, -0.2, 1.0).normalize();
        let reference = Vec3::new(0.0, 1.0, 0.0);
        let mut patches = Vec::new();
        for i in 0..2 {
            for j in 0..4 {
                let (major, minor) = (i as f64 * FRAC_PI_2, j as f64 * FRAC_PI_2);
                patches.push(
                    BezierPatch::quarter_torus(c, a, reference, major, minor, R_MAJOR, R_MINOR)
                        .unwrap(),
                );
            }
        }
        (
            PatchSurface::new(patches).unwrap(),
            c,
            a,
            across(&a, &reference),
        )
    }

    #[test]
    fn torus_of_quarter_patches_matches_analytic_torus() {
        let (surface, c, a, (f1, f2)) = bezier_torus();
        let mut rng = Rng::new(52);
        let mut previous: Option<SurfaceHint> = None;
        for _ in 0..10_000 {
            let psi = angle(&mut rng, 0.1, PI - 0.1);
            let phi = angle(&mut rng, 0.0, 2.0 * PI);
            let s = rng.uniform(0.2, 2.0) * R_MINOR;
            let radial = f1 * psi.cos() + f2 * psi.sin();
            let n = radial * phi.cos() + a * phi.sin();
            let tube_centre = c + radial * R_MAJOR;
            let x = tube_centre + n * s;
            let exact = Projection {
                foot: tube_centre + n * R_MINOR,
                normal: n,
                gap: s - R_MINOR,
                normal_gradient: Mat3::zeros(),
                hint: SurfaceHint::default(),
            };
            let cold = surface.project(&x, None).unwrap();
            assert_projection_consistent(&cold, &x);
            assert_same(&cold, &exact, &x);
            let warm = surface.project(&x, previous.as_ref()).unwrap();
            assert_same(&warm, &exact, &x);
            previous = Some(cold.hint);
        }
    }

    #[test]
    fn normal_gradient_matches_finite_differences_on_cylinder_and_torus() {
        let case = bezier_cylinder();
        let mut rng = Rng::new(53);
        for _ in 0..300 {
            let x = cylinder_point(&case, &mut rng);
            let p = case.surface.project(&x, None).unwrap();
            assert!(
                (p.normal_gradient - case.analytic.project(&x, None).unwrap().normal_gradient)
                    .norm()
                    < 1e-9
            );
            assert_gradient_matches_fd(&|y| case.surface.project(y, None), &x);
        }
        let (surface, c, a, (f1, f2)) = bezier_torus();
        for _ in 0..300 {
            let psi = angle(&mut rng, 0.1, PI - 0.1);
            let phi = angle(&mut rng, 0.0, 2.0 * PI);
            let s = rng.uniform(0.2, 2.0) * R_MINOR;
            let radial = f1 * psi.cos() + f2 * psi.sin();
            let x = c + radial * R_MAJOR + (radial * phi.cos() + a * phi.sin()) * s;
            assert_gradient_matches_fd(&|y| surface.project(y, None), &x);
        }
    }

    /// Dual basis of the tangent plane: `e^u . S_u = 1, e^u . S_v = 0`, and likewise `e^v`.
    fn dual_basis(e: &PatchPoint) -> (Vec3, Vec3) {
        let j = Matrix3x2::from_columns(&[e.su, e.sv]);
        let dual = j * (j.transpose() * j).try_inverse().unwrap();
        (dual.column(0).into(), dual.column(1).into())
    }

    #[test]
    fn open_patch_interior_edges_and_corners() {
        let mut rng = Rng::new(54);
        let (mut interior, mut edges, mut corners) = (0, 0, 0);
        for _ in 0..100 {
            let patch = random_patch(&mut rng);
            let surface = PatchSurface::new(vec![patch.clone()]).unwrap();
            let project = |y: &Vec3| surface.project(y, None);
            let (u, v) = (rng.uniform(0.15, 0.85), rng.uniform(0.15, 0.85));
            let which = rng.uniform(0.0, 3.0) as usize;
            // Foot parameters and the point: inside, beyond one of the 4 edges, or beyond
            // one of the 4 corners, on either side of the patch.
            let (fu, fv, x) = match which {
                0 => {
                    let e = patch.evaluate(u, v);
                    let x = e.point + patch.normal(&e).unwrap() * rng.uniform(-0.2, 0.4);
                    interior += 1;
                    (u, v, x)
                }
                1 => {
                    let side = rng.uniform(0.0, 4.0) as usize;
                    let (fu, fv) = match side {
                        0 => (0.0, v),
                        1 => (1.0, v),
                        2 => (u, 0.0),
                        _ => (u, 1.0),
                    };
                    let e = patch.evaluate(fu, fv);
                    let (du, dv) = dual_basis(&e);
                    let out = match side {
                        0 => -du,
                        1 => du,
                        2 => -dv,
                        _ => dv,
                    }
                    .normalize();
                    let theta = rng.uniform(0.4, 2.7);
                    let m = patch.normal(&e).unwrap() * theta.cos() + out * theta.sin();
                    edges += 1;
                    (fu, fv, e.point + m * rng.uniform(0.05, 0.3))
                }
                _ => {
                    let (fu, fv) = (rng.uniform(0.0, 2.0).floor(), rng.uniform(0.0, 2.0).floor());
                    let e = patch.evaluate(fu, fv);
                    let (du, dv) = dual_basis(&e);
                    let (su, sv) = (2.0 * fu - 1.0, 2.0 * fv - 1.0);
                    let m = du.normalize() * (su * rng.uniform(0.3, 1.0))
                        + dv.normalize() * (sv * rng.uniform(0.3, 1.0))
                        + patch.normal(&e).unwrap() * rng.uniform(-1.0, 1.0);
                    corners += 1;
                    (fu, fv, e.point + m.normalize() * rng.uniform(0.05, 0.3))
                }
            };
            let p = project(&x).unwrap();
            assert_projection_consistent(&p, &x);
            let expected = patch.evaluate(fu, fv).point;
            assert!(
                (p.foot - expected).norm() < 1e-10,
                "case {which}: {p:?}, expected foot {expected:?}"
            );
            assert_gradient_matches_fd(&project, &x);
        }
        assert!(interior > 20 && edges > 20 && corners > 20);
    }

    #[test]
    fn node_on_a_seam_keeps_its_patch() {
        let case = bezier_cylinder();
        // Exactly on the seam between patches 0 and 1 (angle 90°), outside the cylinder.
        let x = case.c + case.a * 3.0 + case.f.1 * 3.0;
        for k in [0, 1] {
            let hint = SurfaceHint {
                patch: k,
                u: 0.5,
                v: 0.5,
            };
            let p = case.surface.project(&x, Some(&hint)).unwrap();
            assert_eq!(p.hint.patch, k);
            assert!((p.foot - (case.c + case.a * 3.0 + case.f.1 * R_CYL)).norm() < 1e-12);
        }
        // Walking across the seam with warm starts switches patch once, on the far side.
        let mut hint = SurfaceHint {
            patch: 0,
            u: 0.9,
            v: 0.5,
        };
        let mut switches = 0;
        for i in 0..=200 {
            let theta = FRAC_PI_2 + (i as f64 - 100.0) * 1e-3;
            let x = case.c + case.a * 3.0 + (case.f.0 * theta.cos() + case.f.1 * theta.sin()) * 3.0;
            let p = case.surface.project(&x, Some(&hint)).unwrap();
            if p.hint.patch != hint.patch {
                switches += 1;
                assert!(theta > FRAC_PI_2);
            }
            hint = p.hint;
        }
        assert_eq!(switches, 1);
    }

    #[test]
    fn degenerate_foot_and_bad_input_give_no_nan_and_no_panic() {
        let apex = Vec3::new(0.0, 0.0, 1.0);
        let points = vec![
            apex,
            apex,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let surface =
            PatchSurface::new(vec![BezierPatch::new(1, 1, points, vec![1.0; 4]).unwrap()]).unwrap();
        let mut rng = Rng::new(55);
        for _ in 0..200 {
            let x = apex + rng.vec3(0.5);
            if let Some(p) = surface.project(&x, None) {
                assert!(p.normal_gradient.iter().all(|c| c.is_finite()));
                assert_projection_consistent(&p, &x);
            }
        }
        assert!(surface
            .project(&Vec3::new(f64::NAN, 0.0, 0.0), None)
            .is_none());
        let bad_hint = SurfaceHint {
            patch: 7,
            u: f64::NAN,
            v: 2.0,
        };
        assert!(surface
            .project(&Vec3::new(0.5, 0.5, 1.0), Some(&bad_hint))
            .is_some());
        let err = PatchSurface::new(vec![]).unwrap_err().to_string();
        assert!(
            err.contains("patch surface patch count = 0 must be >= 1"),
            "{err}"
        );
    }
}
