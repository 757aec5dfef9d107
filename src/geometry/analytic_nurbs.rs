//! Exact NURBS forms of the analytic curves and surfaces CAD files carry: lines, circular
//! arcs, surfaces of revolution and tabulated cylinders (extrusions).
//!
//! A circular arc of sweep `phi` is cut into `n = ceil(phi / 90°)` equal pieces of half
//! angle `h = phi / 2n`, each the rational quadratic in normal form: end points on the
//! circle with weight 1, the middle control point where the end tangents meet (at
//! `r / cos h` from the centre) with weight `cos h`. Its knots are the angles of the piece
//! ends (each interior one twice), so the curve's parameter equals the angle at every
//! breakpoint; inside a piece the normal form runs by the half-angle tangent,
//! `angle = start + h + 2 atan((2 s - 1) tan(h / 2))` for the piece's `s` in `[0, 1]`
//! (what [`crate::geometry::trim::PieceTrim`] undoes to test a trim given in angles).
//!
//! A surface of revolution of a generatrix `C(t)` (control points `Q_k`, weights `w_k`)
//! about an axis through `O` along the unit `a`, from angle `a0` to `a1`: each `Q_k` is
//! rotated as a circle of centre `O_k` (its projection on the axis) by the same arc
//! construction (Piegl and Tiller, A8.1), weights multiplied. The result is the tensor
//! product, exact, of degree `(p, 2)`; a `Q_k` on the axis gives a collapsed (pole) row.
//! An extrusion `C(t) + v d`, `v` in `[0, 1]`, is degree `(p, 1)` with the same weights.
//! Cost: `O(n_t n_arc)` control points.

use super::nurbs::{check_knots, curve_segments, NurbsSurface};
use super::{Mat3, Vec3};
use crate::{Error, Result};

/// A rational B-spline curve in space, on the parameter range `range`.
#[derive(Debug, Clone)]
pub struct NurbsCurve {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<Vec3>,
    pub weights: Vec<f64>,
    pub range: [f64; 2],
    /// Half angle of every knot span if the curve is an arc in normal form (see the module
    /// docs), `None` for any other curve (the parameter is then the file's own).
    pub arc_half_angle: Option<f64>,
}

/// Control points (in the plane of `x`, `y`, unit and orthogonal, about `centre`) and knots of
/// an arc of radius `r` from angle `a0` to `a1 > a0`: `(points, weights, knots, half angle)`.
fn arc_net(
    centre: Vec3,
    x: Vec3,
    y: Vec3,
    r: f64,
    [a0, a1]: [f64; 2],
) -> (Vec<Vec3>, Vec<f64>, Vec<f64>, f64) {
    let sweep = a1 - a0;
    let n = (sweep / std::f64::consts::FRAC_PI_2 - 1e-9).ceil().max(1.0) as usize;
    let h = 0.5 * sweep / n as f64;
    let at = |a: f64, rho: f64| centre + (x * a.cos() + y * a.sin()) * rho;
    let mut points = vec![at(a0, r)];
    let mut weights = vec![1.0];
    let mut knots = vec![a0; 3];
    for k in 0..n {
        let start = a0 + 2.0 * h * k as f64;
        let end = if k + 1 == n { a1 } else { start + 2.0 * h };
        points.extend([at(start + h, r / h.cos()), at(end, r)]);
        weights.extend([h.cos(), 1.0]);
        knots.extend(if k + 1 == n {
            vec![a1; 3]
        } else {
            vec![end; 2]
        });
    }
    (points, weights, knots, h)
}

impl NurbsCurve {
    /// Checks knots (see [`check_knots`]), weights (> 0, finite), and that `range` is a
    /// non-empty interval of the knot domain.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<Vec3>,
        weights: Vec<f64>,
        range: [f64; 2],
    ) -> Result<NurbsCurve> {
        check_knots("curve", degree, points.len(), &knots)?;
        if weights.len() != points.len() {
            return Err(Error::input(
                "curve weight count",
                weights.len(),
                &format!("must equal the control point count {}", points.len()),
            ));
        }
        if let Some(k) = weights.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(Error::input(
                &format!("curve weight [{k}]"),
                weights[k],
                "must be > 0",
            ));
        }
        let (a, b) = (knots[degree], knots[points.len()]);
        if !(a <= range[0] && range[0] < range[1] && range[1] <= b) {
            return Err(Error::input(
                "curve parameter range",
                format!("[{}, {}]", range[0], range[1]),
                &format!("must be a non-empty interval inside the knot domain [{a}, {b}]"),
            ));
        }
        Ok(NurbsCurve {
            degree,
            knots,
            points,
            weights,
            range,
            arc_half_angle: None,
        })
    }

    /// The segment from `a` to `b`, parameter `t` in `[0, 1]` (`a + t (b - a)`).
    pub fn line(a: Vec3, b: Vec3) -> NurbsCurve {
        NurbsCurve {
            degree: 1,
            knots: vec![0.0, 0.0, 1.0, 1.0],
            points: vec![a, b],
            weights: vec![1.0, 1.0],
            range: [0.0, 1.0],
            arc_half_angle: None,
        }
    }

    /// The segment `origin + t direction` for `t` over `range` (increasing): a line in its
    /// own parameter, as STEP's `LINE` runs.
    pub fn ray(origin: Vec3, direction: Vec3, range: [f64; 2]) -> Result<NurbsCurve> {
        let [a, b] = range;
        NurbsCurve::new(
            1,
            vec![a, a, b, b],
            vec![origin + direction * a, origin + direction * b],
            vec![1.0, 1.0],
            range,
        )
    }

    /// The arc `centre + r (cos t x + sin t y)`, `t` from `angles[0]` to `angles[1]`
    /// (greater); `x`, `y` orthonormal. The parameter is the angle at every breakpoint.
    pub fn arc(centre: Vec3, x: Vec3, y: Vec3, r: f64, angles: [f64; 2]) -> Result<NurbsCurve> {
        if !(r.is_finite() && r > 0.0) {
            return Err(Error::input("arc radius", r, "must be > 0"));
        }
        let sweep = angles[1] - angles[0];
        if !(sweep > 0.0 && sweep <= std::f64::consts::TAU * (1.0 + 1e-12)) {
            return Err(Error::input(
                "arc sweep",
                sweep,
                "must be in (0, 2 pi] (end angle after the start)",
            ));
        }
        let (points, weights, knots, h) = arc_net(centre, x, y, r, angles);
        Ok(NurbsCurve {
            degree: 2,
            knots,
            points,
            weights,
            range: angles,
            arc_half_angle: Some(h),
        })
    }

    /// The curve moved by `x -> R x + t` (exact: control points map, weights stay).
    pub fn transformed(mut self, rotation: &Mat3, translation: &Vec3) -> NurbsCurve {
        for p in &mut self.points {
            *p = rotation * *p + translation;
        }
        self
    }

    /// The same curve with its parameter range mapped affinely onto `[0, 1]`.
    pub fn normalized(mut self) -> NurbsCurve {
        let [a, b] = self.range;
        for k in &mut self.knots {
            *k = (*k - a) / (b - a);
        }
        self.range = [0.0, 1.0];
        self
    }

    /// Rational Bézier segments over the range, homogeneous `(w x, w y, w z, w)`.
    pub fn segments(&self) -> Vec<Vec<[f64; 4]>> {
        let flat: Vec<f64> = self.points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        curve_segments(
            self.degree,
            &self.knots,
            &flat,
            &self.weights,
            3,
            self.range,
        )
        .into_iter()
        .map(|(h, _)| h.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect())
        .collect()
    }

    /// `C(t)` by the B-spline basis.
    pub fn point(&self, t: f64) -> Vec3 {
        let (k, n) = super::nurbs::basis(self.degree, &self.knots, self.points.len(), t);
        let (mut a, mut w) = (Vec3::zeros(), 0.0);
        for (i, b) in n.iter().enumerate() {
            let j = k - self.degree + i;
            a += self.points[j] * (self.weights[j] * b);
            w += self.weights[j] * b;
        }
        a / w
    }
}

/// Control points `[i][j]` and weights of a tensor product built row by row.
type Net = (Vec<Vec<Vec3>>, Vec<Vec<f64>>);

/// The surface swept by rotating `generatrix` about the axis through `origin` along
/// `axis` (normalised here) from angle `angles[0]` to `angles[1]` (greater, right-handed
/// about `axis`): `u` is the generatrix's parameter, `v` the angle (see the module docs).
/// Returns the surface and the arc half angle of its `v` spans.
pub fn revolution(
    generatrix: &NurbsCurve,
    origin: Vec3,
    axis: Vec3,
    angles: [f64; 2],
) -> Result<(NurbsSurface, f64)> {
    let a = axis
        .try_normalize(1e-300)
        .ok_or_else(|| Error::input("revolution axis length", axis.norm(), "must be > 0"))?;
    let sweep = angles[1] - angles[0];
    if !(sweep > 0.0 && sweep <= std::f64::consts::TAU * (1.0 + 1e-12)) {
        return Err(Error::input(
            "revolution sweep",
            sweep,
            "must be in (0, 2 pi] (end angle after the start)",
        ));
    }
    let mut net: Net = (Vec::new(), Vec::new());
    let mut v_knots = Vec::new();
    let mut half = 0.0;
    for (q, w) in generatrix.points.iter().zip(&generatrix.weights) {
        let centre = origin + a * (q - origin).dot(&a);
        let radial = q - centre;
        let r = radial.norm();
        let (points, weights, knots, h) = if r > 1e-14 * (1.0 + q.norm()) {
            let x = radial / r;
            arc_net(centre, x, a.cross(&x), r, angles)
        } else {
            // On the axis: the whole row is the point (a pole), weights as any row's.
            let (p, wt, k, h) = arc_net(centre, Vec3::x(), Vec3::y(), 1.0, angles);
            (vec![*q; p.len()], wt, k, h)
        };
        net.0.push(points);
        net.1.push(weights.iter().map(|c| c * w).collect());
        v_knots = knots;
        half = h;
    }
    let surface = NurbsSurface::new(
        [generatrix.degree, 2],
        [generatrix.knots.clone(), v_knots],
        net.0,
        Some(net.1),
    )?
    .restricted(generatrix.range, angles)?;
    Ok((surface, half))
}

/// The surface `C(u) + v d`, `v` in `[0, 1]`: a tabulated cylinder.
pub fn extrusion(directrix: &NurbsCurve, direction: Vec3) -> Result<NurbsSurface> {
    extrusion_over(directrix, direction, [0.0, 1.0])
}

/// The surface `C(u) + v d` for `v` over `range` (increasing): STEP's
/// `SURFACE_OF_LINEAR_EXTRUSION`, in its own parameters.
pub fn extrusion_over(
    directrix: &NurbsCurve,
    direction: Vec3,
    range: [f64; 2],
) -> Result<NurbsSurface> {
    let [a, b] = range;
    let points = directrix
        .points
        .iter()
        .map(|p| vec![p + direction * a, p + direction * b])
        .collect();
    let weights = directrix.weights.iter().map(|w| vec![*w, *w]).collect();
    NurbsSurface::new(
        [directrix.degree, 1],
        [directrix.knots.clone(), vec![a, a, b, b]],
        points,
        Some(weights),
    )?
    .restricted(directrix.range, range)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Arc pieces: points on the circle, and the normal form's parameter law (the angle
    /// at piece parameter `s` is `start + h + 2 atan((2 s - 1) tan(h / 2))`).
    #[test]
    fn arcs_are_exact_and_run_by_the_half_angle_tangent() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        let (x, y) = (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
        let arc = NurbsCurve::arc(c, x, y, 2.5, [0.3, 0.3 + 4.0]).unwrap();
        let h = arc.arc_half_angle.unwrap();
        assert!((h - 4.0 / 6.0).abs() < 1e-15);
        for k in 0..=400 {
            let t = 0.3 + 4.0 * k as f64 / 400.0;
            let p = arc.point(t) - c;
            assert!((p.norm() - 2.5).abs() < 1e-14, "{t}");
            assert!(p.dot(&Vec3::x()).abs() < 1e-15);
        }
        // A piece [t0, t0 + 2h]: the point at knot parameter t0 + s 2h has angle law above.
        let t0 = 0.3 + 2.0 * h;
        for k in 0..=20 {
            let s = k as f64 / 20.0;
            let p = arc.point(t0 + s * 2.0 * h) - c;
            let angle = p.dot(&y).atan2(p.dot(&x));
            let law = t0 + h + 2.0 * ((2.0 * s - 1.0) * (0.5 * h).tan()).atan();
            assert!(
                (angle - law).abs() < 1e-13,
                "s = {s}: {angle} against {law}"
            );
        }
    }

    /// A torus quarter of revolution (an arc generatrix) lies on the torus, at the angle
    /// the knots say at breakpoints.
    #[test]
    fn revolution_of_an_arc_is_a_torus() {
        let gen = NurbsCurve::arc(
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::x(),
            Vec3::z(),
            3.0,
            [0.0, PI],
        )
        .unwrap();
        let (s, h) = revolution(&gen, Vec3::zeros(), Vec3::z(), [0.5, 0.5 + 1.5 * PI]).unwrap();
        assert!((h - 1.5 * PI / 6.0).abs() < 1e-15);
        let [u, v] = s.domain();
        for i in 0..=30 {
            for j in 0..=30 {
                let p = s.point(
                    u[0] + (u[1] - u[0]) * i as f64 / 30.0,
                    v[0] + (v[1] - v[0]) * j as f64 / 30.0,
                );
                let rho = p.x.hypot(p.y);
                assert!(((rho - 10.0).hypot(p.z) - 3.0).abs() < 1e-13, "{p:?}");
            }
        }
        // Breakpoint angles are exact, and a pole-free right-handed sense about +z.
        let p = s.point(0.5 * PI, 0.5 + 2.0 * h);
        assert!((p.y.atan2(p.x) - (0.5 + 2.0 * h)).abs() < 1e-14);
        assert!((p.z - 3.0).abs() < 1e-14 && (p.x.hypot(p.y) - 10.0).abs() < 1e-13);
        for piece in s.to_bezier().unwrap() {
            assert_eq!(piece.patch.degrees(), (2, 2));
        }
    }

    /// A cylinder of revolution trimmed by a loop that is no iso-line in `(t, angle)`: the
    /// pieces' trim test, undoing the half-angle law, classifies every point as the exact
    /// angle of its surface point does.
    #[test]
    fn trims_given_in_angles_are_tested_at_the_true_angle() {
        use crate::geometry::testutil::Rng;
        use crate::geometry::trim::{PieceTrim, TrimRegion, TrimSegment};
        use std::sync::Arc;
        let gen = NurbsCurve::line(Vec3::new(5.0, 0.0, 0.0), Vec3::new(5.0, 0.0, 10.0));
        let (s, h) = revolution(&gen, Vec3::zeros(), Vec3::z(), [0.2, 0.2 + 5.0]).unwrap();
        // A triangle with slanted sides in (t, angle).
        let corners = [[0.1, 0.4], [0.9, 1.5], [0.3, 4.9]];
        let region = Arc::new(
            TrimRegion::new(vec![(0..3)
                .map(|k| TrimSegment::line(corners[k], corners[(k + 1) % 3]))
                .collect()])
            .unwrap(),
        );
        let mut rng = Rng::new(7);
        let mut inside = [0; 2];
        for piece in s.to_bezier().unwrap() {
            let trim = PieceTrim {
                region: region.clone(),
                u: piece.u,
                v: piece.v,
                arcs: [None, Some(h)],
            };
            for _ in 0..2000 {
                let (a, b) = (rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
                let p = piece.patch.point(a, b);
                let angle = (p.y.atan2(p.x) - 0.2).rem_euclid(std::f64::consts::TAU) + 0.2;
                let t = p.z / 10.0;
                let expected = region.contains(t, angle);
                // Away from the boundary, where rounding could decide.
                let near = [(1e-9, 0.0), (-1e-9, 0.0), (0.0, 1e-9), (0.0, -1e-9)]
                    .iter()
                    .any(|(dt, da)| region.contains(t + dt, angle + da) != expected);
                if near {
                    continue;
                }
                assert_eq!(trim.admits(a, b), expected, "t = {t}, angle = {angle}");
                inside[expected as usize] += 1;
            }
        }
        assert!(inside[0] > 2000 && inside[1] > 2000, "{inside:?}");
    }

    #[test]
    fn extrusion_of_an_arc_is_a_cylinder() {
        let arc = NurbsCurve::arc(Vec3::zeros(), Vec3::x(), Vec3::y(), 4.0, [0.0, 2.0])
            .unwrap()
            .normalized();
        let s = extrusion(&arc, Vec3::new(0.0, 0.0, 7.0)).unwrap();
        assert_eq!(s.domain(), [[0.0, 1.0], [0.0, 1.0]]);
        let p = s.point(1.0, 1.0);
        assert!((p - Vec3::new(4.0 * 2f64.cos(), 4.0 * 2f64.sin(), 7.0)).norm() < 1e-14);
        let q = s.point(0.37, 0.2);
        assert!((q.x.hypot(q.y) - 4.0).abs() < 1e-14 && (q.z - 1.4).abs() < 1e-14);
    }
}
