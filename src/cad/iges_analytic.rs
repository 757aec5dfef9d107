//! The analytic IGES surfaces a CAD exporter writes in faces mode, made exact NURBS
//! (see [`crate::geometry::analytic_nurbs`]), so that a file needs no B-spline conversion:
//!
//! - 120 surface of revolution: its generatrix (110 line, 100 circular arc or 126 B-spline,
//!   each with its own 124 matrix) rotated about its axis (a 110 line, positive sense from
//!   its start point to its end point) from `SA` to `TA`. Its parameters are IGES's: `u`
//!   the generatrix's own (0..1 on a line, the angle on an arc), `v` the angle, so the
//!   face's parameter-space trimming curves are read as they stand; along an arc, the
//!   Bézier pieces run by the half-angle tangent, which the trim test undoes exactly.
//! - 108 plane (`A x + B y + C z = D`): it has no parameters, so a plane face is
//!   trimmed by its 142 curves' model-space curves (110, 100, 126, 102 of those),
//!   projected on an orthonormal frame of the plane `(e1, e2, n)`. The face's surface is
//!   the rectangle of that frame bounding the loops, a bilinear patch whose `u, v` are the
//!   frame's coordinates (so the projected loops are its trim), its normal `e1 x e2` being
//!   the plane's `(A, B, C)`: the outward one in OpenCascade's files.
//!
//! - 190 plane surface: the same plane given by a 116 location point and a 123 normal
//!   direction (its reference direction, form 1, is not needed), read as a 108.
//!
//! - 122 tabulated cylinder: the exact extrusion of its directrix in the directrix's own
//!   parameter (see [`Iges::tabulated_cylinder`]); its trims' normalised `u` is mapped.
//!
//! A curve off its plane by more than `1e-6` of the face's size is refused (the file and
//! the curve entity named).

use super::iges::{bspline_curve, BsplineCurve, Entry, Iges, Params};
use super::Face;
use crate::geometry::analytic_nurbs::{extrusion, revolution, NurbsCurve};
use crate::geometry::nurbs::NurbsSurface;
use crate::geometry::trim::{TrimRegion, TrimSegment};
use crate::geometry::{Mat3, Vec3};
use crate::Result;

/// Homogeneous rational Bézier segments `(w x, w y, w z, w)` of one loop.
type Loop = Vec<Vec<[f64; 4]>>;

/// The segments moved by `x -> R x + t`, applied to homogeneous points.
fn moved(segments: &mut Loop, r: &Mat3, t: &Vec3) {
    for h in segments.iter_mut().flatten() {
        let x = r * Vec3::new(h[0], h[1], h[2]) + t * h[3];
        h[..3].copy_from_slice(x.as_slice());
    }
}

impl Iges<'_> {
    /// A 120 surface of revolution in mm (after its 124 matrix), with the arc half angles
    /// of its directions (`u`: if the generatrix is an arc; `v`: always).
    pub(super) fn revolution(&self, e: &Entry) -> Result<(NurbsSurface, [Option<f64>; 2])> {
        let p = self.params(e)?;
        let axis_entry = self.entry(p.int(1, "L, axis pointer")?, &p, "axis")?;
        if axis_entry.kind != 110 {
            return Err(p.fail(format!(
                "its axis pointer names {}, not a 110 line",
                Self::describe(axis_entry)
            )));
        }
        let axis = self.model_curve(axis_entry)?;
        let generatrix =
            self.model_curve(self.entry(p.int(2, "C, generatrix pointer")?, &p, "generatrix")?)?;
        let angles = [p.real(3, "SA, start angle")?, p.real(4, "TA, end angle")?];
        let (origin, end) = (axis.points[0], axis.points[1]);
        let (surface, half) = revolution(&generatrix, origin, end - origin, angles)
            .map_err(|err| p.fail(super::strip(err)))?;
        let (r, t) = self.matrix(e, 0)?;
        let surface = surface.transformed(&(r * self.to_mm), &(t * self.to_mm));
        Ok((surface, [generatrix.arc_half_angle, Some(half)]))
    }

    /// A 122 tabulated cylinder in mm (after its 124 matrix): IGES's `S(u, v) = C(t) +
    /// v (L - C(T0))`, `t = T0 + u (T1 - T0)`, made the exact extrusion of the directrix
    /// in the directrix's own parameter `t` (the angle on a 100 arc, whose half angle is
    /// returned). Returns the surface, the arc half angles, and `[T0, T1 - T0]`: a trim
    /// given in IGES's `u` maps to `t` by `u -> T0 + (T1 - T0) u`.
    pub(super) fn tabulated_cylinder(
        &self,
        e: &Entry,
    ) -> Result<(NurbsSurface, [Option<f64>; 2], [f64; 2])> {
        let p = self.params(e)?;
        let directrix =
            self.model_curve(self.entry(p.int(1, "DE, directrix pointer")?, &p, "directrix")?)?;
        let l = p.reals(2, 3, "LX, LY, LZ, generatrix end point")?;
        let [t0, t1] = directrix.range;
        let direction = Vec3::new(l[0], l[1], l[2]) - directrix.point(t0);
        let surface = extrusion(&directrix, direction).map_err(|err| p.fail(super::strip(err)))?;
        let (r, t) = self.matrix(e, 0)?;
        let surface = surface.transformed(&(r * self.to_mm), &(t * self.to_mm));
        Ok((surface, [directrix.arc_half_angle, None], [t0, t1 - t0]))
    }

    /// A curve entity in its parent's space (its own 124 matrix applied), not scaled to mm:
    /// 110 line (parameter 0..1), 100 circular arc (parameter: the angle, from the start
    /// point's in `[0, 2 pi)`), 126 rational B-spline.
    pub(super) fn model_curve(&self, e: &Entry) -> Result<NurbsCurve> {
        let p = self.params(e)?;
        let curve = match e.kind {
            110 => {
                let v = p.reals(1, 6, "end point coordinate")?;
                Ok(NurbsCurve::line(
                    Vec3::new(v[0], v[1], v[2]),
                    Vec3::new(v[3], v[4], v[5]),
                ))
            }
            100 => {
                let v = p.reals(1, 7, "arc parameter")?;
                let centre = Vec3::new(v[1], v[2], v[0]);
                let (s, f) = ([v[3] - v[1], v[4] - v[2]], [v[5] - v[1], v[6] - v[2]]);
                let tau = std::f64::consts::TAU;
                let a0 = s[1].atan2(s[0]).rem_euclid(tau);
                let mut sweep = (f[1].atan2(f[0]) - a0).rem_euclid(tau);
                if sweep <= 1e-14 {
                    sweep = tau;
                }
                NurbsCurve::arc(
                    centre,
                    Vec3::x(),
                    Vec3::y(),
                    s[0].hypot(s[1]),
                    [a0, a0 + sweep],
                )
            }
            126 => {
                let BsplineCurve {
                    degree,
                    knots,
                    weights,
                    xyz,
                    range,
                } = bspline_curve(&p)?;
                let points = xyz.chunks(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
                NurbsCurve::new(degree, knots, points, weights, range)
            }
            _ => {
                return Err(p.fail(format!(
                    "this entity (form {}) is not read as a model-space curve (read: 110, \
                     100, 126; 102 of those in a trimming loop)",
                    e.form
                )))
            }
        }
        .map_err(|err| p.fail(super::strip(err)))?;
        let (r, t) = self.matrix(e, 0)?;
        Ok(curve.transformed(&r, &t))
    }

    /// The segments of a model-space curve (102 composites of 110, 100, 126), in mm.
    fn model_segments(&self, e: &Entry, depth: usize) -> Result<Loop> {
        let mut out = Vec::new();
        if e.kind == 102 && depth < 8 {
            let p = self.params(e)?;
            for k in 0..p.count(1, "N, curve count")? {
                let c = self.entry(p.int(2 + k, "curve pointer")?, &p, "curve")?;
                out.extend(self.model_segments(c, depth + 1)?);
            }
            let (r, t) = self.matrix(e, 0)?;
            moved(&mut out, &r, &t);
        } else {
            out = self.model_curve(e)?.segments();
        }
        if depth == 0 {
            moved(&mut out, &(Mat3::identity() * self.to_mm), &Vec3::zeros());
        }
        Ok(out)
    }

    /// A 108 plane's, or a 190 plane surface's, point and unit normal in mm (after its 124
    /// matrix).
    fn plane(&self, s: &Entry) -> Result<(Vec3, Vec3)> {
        let p = self.params(s)?;
        let (point, n) = if s.kind == 190 {
            self.point_and_normal(&p)?
        } else {
            let v = p.reals(1, 4, "plane coefficient A, B, C, D")?;
            let n = Vec3::new(v[0], v[1], v[2]);
            (n * (v[3] / n.norm_squared()), n)
        };
        if !(n.norm() > 0.0) {
            return Err(p.fail("its normal is zero".to_string()));
        }
        let (r, t) = self.matrix(s, 0)?;
        let normal = r
            .try_inverse()
            .map(|inv| inv.transpose() * n)
            .and_then(|n| n.try_normalize(0.0))
            .ok_or_else(|| p.fail("its transformation matrix is singular".to_string()))?;
        Ok(((r * point + t) * self.to_mm, normal))
    }

    /// A 190 plane surface's location (a 116 point, after its matrix) and normal (a 123
    /// direction, after its matrix's rotation), in the 190's space, not scaled to mm.
    fn point_and_normal(&self, p: &Params) -> Result<(Vec3, Vec3)> {
        let at = |i: usize, kind: i64, what: &str| -> Result<(Vec3, Mat3, Vec3)> {
            let e = self.entry(p.int(i, what)?, p, what)?;
            let q = self.params(e)?;
            if e.kind != kind {
                return Err(p.fail(format!(
                    "its {what} names {}, not a {kind}",
                    Self::describe(e)
                )));
            }
            let v = q.reals(1, 3, "coordinate")?;
            let (r, t) = self.matrix(e, 0)?;
            Ok((Vec3::new(v[0], v[1], v[2]), r, t))
        };
        let (x, r, t) = at(1, 116, "location pointer")?;
        let (n, rn, _) = at(2, 123, "normal pointer")?;
        Ok((r * x + t, rn * n))
    }

    /// The model-space curve of the 142 at `pointer` (named from `face`).
    fn model_loop(&self, pointer: i64, face: &Params) -> Result<Loop> {
        let p = self.curve_on_surface(pointer, face)?;
        let curve = p.int(4, "CPTR, model-space curve pointer")?;
        if curve == 0 {
            return Err(p.fail(
                "it has no model-space curve, which a face on a plane needs (a plane has no \
                 parameters)"
                    .to_string(),
            ));
        }
        self.model_segments(self.entry(curve, &p, "model-space curve")?, 0)
    }

    /// A 144 on a 108 plane `s`: the plane trimmed by its model-space loops, then the
    /// 144's matrix.
    pub(super) fn trimmed_plane(&self, e: &Entry, p: &Params, s: &Entry) -> Result<Face> {
        if p.int(2, "N1, outer boundary flag")? == 0 {
            return Err(p.fail(format!(
                "its surface is {}, which has no extent without an outer boundary",
                Self::describe(s)
            )));
        }
        let holes = p.count(3, "N2, inner boundary count")?;
        let mut loops = vec![self.model_loop(p.int(4, "PTO, outer boundary pointer")?, p)?];
        for k in 0..holes {
            loops.push(self.model_loop(p.int(5 + k, "PTI, inner boundary pointer")?, p)?);
        }
        let mut face = self.plane_face(s, p, loops)?;
        let (r, t) = self.matrix(e, 0)?;
        face.surface = face.surface.transformed(&r, &(t * self.to_mm));
        face.origin = Self::describe(e);
        Ok(face)
    }

    /// A 108 plane not used by a 144: a face if it has a bounding curve (form 1); a 190
    /// plane surface has none.
    pub(super) fn bounded_plane(&self, s: &Entry) -> Result<Face> {
        let p = self.params(s)?;
        let curve = if s.kind == 190 {
            0
        } else {
            p.int(5, "PTR, bounding curve pointer")?
        };
        if curve == 0 {
            return Err(p.fail(
                "an unbounded plane is not a face: trim it (144), or write a 108 bounded by a \
                 curve (form 1)"
                    .to_string(),
            ));
        }
        let bound = self.model_segments(self.entry(curve, &p, "bounding curve")?, 0)?;
        self.plane_face(s, &p, vec![bound])
    }

    /// The plane of `s` as a bilinear patch over the frame rectangle bounding `loops`,
    /// trimmed by them (see the module docs).
    fn plane_face(&self, s: &Entry, p: &Params, loops: Vec<Loop>) -> Result<Face> {
        let (origin, n) = self.plane(s)?;
        // The axis least aligned with n, made orthogonal to it.
        let k = (0..3)
            .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
            .unwrap();
        let mut axis = Vec3::zeros();
        axis[k] = 1.0;
        let e1 = (axis - n * n.dot(&axis)).normalize();
        let e2 = n.cross(&e1);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut off = 0.0f64;
        let projected: Vec<Vec<TrimSegment>> = loops
            .iter()
            .map(|segments| {
                segments
                    .iter()
                    .map(|seg| {
                        TrimSegment::new(
                            seg.iter()
                                .map(|h| {
                                    let w = h[3];
                                    let x = Vec3::new(h[0], h[1], h[2]) / w - origin;
                                    let uv = [x.dot(&e1), x.dot(&e2)];
                                    for c in 0..2 {
                                        lo[c] = lo[c].min(uv[c]);
                                        hi[c] = hi[c].max(uv[c]);
                                    }
                                    off = off.max(x.dot(&n).abs());
                                    [uv[0] * w, uv[1] * w, w]
                                })
                                .collect(),
                        )
                    })
                    .collect()
            })
            .collect();
        let size = (hi[0] - lo[0]).hypot(hi[1] - lo[1]);
        if !(size > 0.0) || off > 1e-6 * size {
            return Err(p.fail(format!(
                "its trimming curves lie off the plane of {} by {off:e} mm (or enclose no area)",
                Self::describe(s)
            )));
        }
        let at = |u: f64, v: f64| origin + e1 * u + e2 * v;
        let surface = NurbsSurface::new(
            [1, 1],
            [
                vec![lo[0], lo[0], hi[0], hi[0]],
                vec![lo[1], lo[1], hi[1], hi[1]],
            ],
            vec![
                vec![at(lo[0], lo[1]), at(lo[0], hi[1])],
                vec![at(hi[0], lo[1]), at(hi[0], hi[1])],
            ],
            None,
        )
        .map_err(|err| p.fail(super::strip(err)))?;
        let trim = TrimRegion::new(projected).map_err(|err| p.fail(super::strip(err)))?;
        Ok(Face {
            surface,
            trim: Some(trim),
            origin: Self::describe(s),
            flip: false,
            arcs: [None, None],
            names: Vec::new(),
        })
    }
}
