//! The curves of a STEP file, in space (an edge's 3-D curve, a swept curve) and in a
//! surface's parameter plane (a pcurve): `LINE`, `CIRCLE`, `ELLIPSE`, `POLYLINE` (plane
//! only) and `B_SPLINE_CURVE_WITH_KNOTS` (rational or not). A 2-D curve is read as a 3-D one
//! with `z = 0`.
//!
//! Parameters are STEP's (ISO 10303-42): `LINE(p, VECTOR(d, m))` is `p + t m d`;
//! `CIRCLE(A, r)` is `c + r (cos t x + sin t y)` with `A` an `AXIS2_PLACEMENT_3D`
//! (`c`, `z`, `x`; `y = z x x`) or `_2D` (`c`, `x`; `y` the quarter turn of `x`);
//! `ELLIPSE(A, a, b)` is `c + a cos t x + b sin t y`; a B-spline runs by its knots.
//! [`Curve::nurbs`] makes each the exact NURBS in that same parameter over a range (a line
//! by two points at `t0`, `t1`; circles and ellipses by
//! [`crate::geometry::analytic_nurbs::NurbsCurve::arc`], the ellipse as the affine image
//! `x -> c + a x_1 x + b x_2 y` of the unit circle's net, weights unchanged, which is exact).
//! [`Curve::parameter`] inverts a point lying on the curve: closed form for lines
//! (projection), circles and ellipses (`atan2` of the scaled frame coordinates, in
//! `[0, 2 pi)`); for a B-spline the nearest of 512 samples refined by golden-section
//! search on the distance (a vertex lies on its curve, so the minimum is the point).

use super::step::Step;
use crate::geometry::analytic_nurbs::NurbsCurve;
use crate::geometry::{Mat3, Vec3};
use crate::Result;
use std::f64::consts::TAU;

/// An orthonormal frame: origin and axes `x`, `y`, `z = x x y`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame {
    pub origin: Vec3,
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
}

/// A STEP curve in its own parameter (see the module docs).
#[derive(Debug, Clone)]
pub(super) enum Curve {
    Line { origin: Vec3, step: Vec3 },
    Circle { frame: Frame, radius: f64 },
    Ellipse { frame: Frame, a: f64, b: f64 },
    Spline(NurbsCurve),
}

impl Curve {
    /// True for circles and ellipses: the parameter is an angle, of period `2 pi`.
    pub fn periodic(&self) -> bool {
        matches!(self, Curve::Circle { .. } | Curve::Ellipse { .. })
    }

    pub fn point(&self, t: f64) -> Vec3 {
        match self {
            Curve::Line { origin, step } => origin + step * t,
            Curve::Circle { frame, radius } => {
                frame.origin + (frame.x * t.cos() + frame.y * t.sin()) * *radius
            }
            Curve::Ellipse { frame, a, b } => {
                frame.origin + frame.x * (a * t.cos()) + frame.y * (b * t.sin())
            }
            Curve::Spline(c) => c.point(t),
        }
    }

    /// The exact NURBS over `range` (increasing; at most one turn on a periodic curve),
    /// in the curve's own parameter.
    pub fn nurbs(&self, range: [f64; 2]) -> Result<NurbsCurve> {
        match self {
            Curve::Line { origin, step } => NurbsCurve::ray(*origin, *step, range),
            Curve::Circle { frame, radius } => {
                NurbsCurve::arc(frame.origin, frame.x, frame.y, *radius, range)
            }
            Curve::Ellipse { frame, a, b } => {
                let mut unit = NurbsCurve::arc(Vec3::zeros(), Vec3::x(), Vec3::y(), 1.0, range)?;
                let map = Mat3::from_columns(&[frame.x * *a, frame.y * *b, frame.z]);
                unit = unit.transformed(&map, &frame.origin);
                Ok(unit)
            }
            Curve::Spline(c) => NurbsCurve::new(
                c.degree,
                c.knots.clone(),
                c.points.clone(),
                c.weights.clone(),
                range,
            ),
        }
    }

    /// The parameter of a point on the curve (see the module docs).
    pub fn parameter(&self, p: Vec3) -> f64 {
        match self {
            Curve::Line { origin, step } => (p - origin).dot(step) / step.norm_squared(),
            Curve::Circle { frame, .. } => {
                let d = p - frame.origin;
                turn(d.dot(&frame.y).atan2(d.dot(&frame.x)))
            }
            Curve::Ellipse { frame, a, b } => {
                let d = p - frame.origin;
                turn((d.dot(&frame.y) / b).atan2(d.dot(&frame.x) / a))
            }
            Curve::Spline(c) => nearest_parameter(c, p),
        }
    }
}

/// An angle from `atan2` in `[0, 2 pi)`; within `1e-12` below `2 pi` (the rounding of a
/// point at angle 0 seen slightly below the axis) it is 0.
fn turn(a: f64) -> f64 {
    let t = if a < 0.0 { a + TAU } else { a };
    if t >= TAU - 1e-12 {
        0.0
    } else {
        t
    }
}

/// The parameter of `c` nearest to `p`: best of 512 samples, then golden-section search on
/// the bracketing sample interval.
fn nearest_parameter(c: &NurbsCurve, p: Vec3) -> f64 {
    let [a, b] = c.range;
    let n = 512;
    let at = |k: usize| a + (b - a) * k as f64 / n as f64;
    let dist = |t: f64| (c.point(t) - p).norm_squared();
    let k = (0..=n)
        .min_by(|&i, &j| dist(at(i)).total_cmp(&dist(at(j))))
        .unwrap_or(0);
    let (mut lo, mut hi) = (at(k.saturating_sub(1)), at((k + 1).min(n)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..80 {
        let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if dist(m1) < dist(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    0.5 * (lo + hi)
}

impl Step<'_> {
    /// A `DIRECTION` (2 or 3 components, padded with 0), normalised.
    pub(super) fn direction(&self, id: usize, from: usize) -> Result<Vec3> {
        let p = self
            .part(id, "DIRECTION")
            .ok_or_else(|| self.fail(from, format!("its direction #{id} is not a DIRECTION")))?;
        let c = self.list(id, p.get(1), "direction ratios")?;
        let c: Vec<f64> = c
            .iter()
            .map(|x| self.number(id, Some(x), "direction ratio"))
            .collect::<Result<_>>()?;
        let v = Vec3::new(c[0], *c.get(1).unwrap_or(&0.0), *c.get(2).unwrap_or(&0.0));
        v.try_normalize(1e-300)
            .ok_or_else(|| self.fail(id, "a direction of length zero".into()))
    }

    /// A point (2 or 3 coordinates, padded with 0), in the file's unit.
    pub(super) fn vec3(&self, id: usize, from: usize) -> Result<Vec3> {
        let c = self.point(id, from)?;
        if c.len() < 2 {
            return Err(self.fail(id, "a point with fewer than 2 coordinates".into()));
        }
        Ok(Vec3::new(c[0], c[1], *c.get(2).unwrap_or(&0.0)))
    }

    /// An `AXIS2_PLACEMENT_3D` or `_2D` as a frame (missing axes default as STEP says:
    /// `z` along +z, `x` along +x made orthogonal to `z`).
    pub(super) fn frame(&self, id: usize, from: usize) -> Result<Frame> {
        let (origin, z, x) = if let Some(p) = self.part(id, "AXIS2_PLACEMENT_3D") {
            let origin = self.vec3(self.reference(id, p.get(1), "location")?, id)?;
            let axis = |k: usize, default: Vec3| match p.get(k) {
                Some(crate::cad::step::Value::Ref(r)) => self.direction(*r, id),
                _ => Ok(default),
            };
            (origin, axis(2, Vec3::z())?, axis(3, Vec3::x())?)
        } else if let Some(p) = self.part(id, "AXIS2_PLACEMENT_2D") {
            let origin = self.vec3(self.reference(id, p.get(1), "location")?, id)?;
            let x = match p.get(2) {
                Some(crate::cad::step::Value::Ref(r)) => self.direction(*r, id)?,
                _ => Vec3::x(),
            };
            (origin, Vec3::z(), x)
        } else {
            return Err(self.fail(
                from,
                format!("its placement #{id} is not an AXIS2_PLACEMENT"),
            ));
        };
        let x = (x - z * x.dot(&z))
            .try_normalize(1e-12)
            .ok_or_else(|| self.fail(id, "its reference direction is along its axis".into()))?;
        Ok(Frame {
            origin,
            x,
            y: z.cross(&x),
            z,
        })
    }

    /// A curve instance (see the module docs), in the file's unit.
    pub(super) fn curve(&self, id: usize, from: usize) -> Result<Curve> {
        self.instance(id, from, "curve")?;
        let positive = |v, what: &str| -> Result<f64> {
            let x = self.number(id, v, what)?;
            if x > 0.0 {
                Ok(x)
            } else {
                Err(self.fail(id, format!("its {what} {x} is not > 0")))
            }
        };
        if let Some(p) = self.part(id, "LINE") {
            let origin = self.vec3(self.reference(id, p.get(1), "point")?, id)?;
            let v = self.reference(id, p.get(2), "vector")?;
            let q = self
                .part(v, "VECTOR")
                .ok_or_else(|| self.fail(id, format!("its direction #{v} is not a VECTOR")))?;
            let d = self.direction(self.reference(v, q.get(1), "orientation")?, v)?;
            let m = self.number(v, q.get(2), "magnitude")?;
            if m == 0.0 {
                return Err(self.fail(v, "a vector of magnitude zero".into()));
            }
            return Ok(Curve::Line {
                origin,
                step: d * m,
            });
        }
        if let Some(p) = self.part(id, "CIRCLE") {
            let frame = self.frame(self.reference(id, p.get(1), "position")?, id)?;
            return Ok(Curve::Circle {
                frame,
                radius: positive(p.get(2), "radius")?,
            });
        }
        if let Some(p) = self.part(id, "ELLIPSE") {
            let frame = self.frame(self.reference(id, p.get(1), "position")?, id)?;
            let (a, b) = (
                positive(p.get(2), "semi axis 1")?,
                positive(p.get(3), "semi axis 2")?,
            );
            return Ok(Curve::Ellipse { frame, a, b });
        }
        if self.part(id, "B_SPLINE_CURVE_WITH_KNOTS").is_some() {
            return self.spline_curve(id).map(Curve::Spline);
        }
        Err(self.fail(
            from,
            format!(
                "its curve #{id} is a {}, which is not read (read: LINE, CIRCLE, ELLIPSE, \
                 B_SPLINE_CURVE_WITH_KNOTS)",
                self.kind(id)
            ),
        ))
    }

    /// A `B_SPLINE_CURVE_WITH_KNOTS` (simple, or complex with `RATIONAL_B_SPLINE_CURVE`)
    /// over its whole knot domain.
    pub(super) fn spline_curve(&self, id: usize) -> Result<NurbsCurve> {
        let (head, knots, weights) = if let Some(p) = self
            .part(id, "B_SPLINE_CURVE_WITH_KNOTS")
            .filter(|p| p.len() == 9)
        {
            (&p[1..3], &p[6..8], None)
        } else if let (Some(b), Some(k)) = (
            self.part(id, "B_SPLINE_CURVE"),
            self.part(id, "B_SPLINE_CURVE_WITH_KNOTS"),
        ) {
            if b.len() < 2 || k.len() < 2 {
                return Err(self.fail(id, "too few parameters for a B-spline curve".into()));
            }
            (&b[0..2], &k[0..2], self.part(id, "RATIONAL_B_SPLINE_CURVE"))
        } else {
            return Err(self.fail(id, "not a B-spline curve".into()));
        };
        let p = self.degree(id, head.first())?;
        let points: Vec<Vec3> = self
            .list(id, head.get(1), "control points")?
            .iter()
            .map(|q| self.vec3(self.reference(id, Some(q), "control point")?, id))
            .collect::<Result<_>>()?;
        let n = points.len();
        let knots = self.knots(id, knots.first(), knots.get(1))?;
        let w = match weights {
            None => vec![1.0; n],
            Some(w) => self
                .list(id, w.first(), "weights")?
                .iter()
                .map(|x| self.number(id, Some(x), "weight"))
                .collect::<Result<_>>()?,
        };
        crate::geometry::nurbs::check_knots("curve", p, n, &knots)
            .map_err(|e| self.fail(id, super::strip(e)))?;
        let range = [knots[p], knots[n]];
        NurbsCurve::new(p, knots, points, w, range).map_err(|e| self.fail(id, super::strip(e)))
    }
}
