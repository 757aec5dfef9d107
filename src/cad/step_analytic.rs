//! STEP's analytic surfaces (ISO 10303-42) made the exact rational NURBS they are, in
//! STEP's own parameters `(u, v)`, so that a face's pcurves are its trims as they stand and
//! its normal `S_u x S_v` is STEP's (the face's outward normal is it if the face's
//! `same_sense` is true, its opposite otherwise).
//!
//! With the placement `(c; x, y, z)` (an `AXIS2_PLACEMENT_3D`) and `r(u) = cos u x + sin u y`:
//!
//! | entity | `S(u, v)` | normal `S_u x S_v` points |
//! |---|---|---|
//! | `PLANE` | `c + u x + v y` | along `z` |
//! | `CYLINDRICAL_SURFACE(R)` | `c + R r(u) + v z` | away from the axis |
//! | `CONICAL_SURFACE(R, a)` | `c + (R + v tan a) r(u) + v z` (*) | away from the axis |
//! | `SPHERICAL_SURFACE(R)` | `c + R cos v r(u) + R sin v z` | out of the sphere |
//! | `TOROIDAL_SURFACE(R, r)` | `c + (R + r cos v) r(u) + r sin v z` | out of the tube |
//! | `SURFACE_OF_REVOLUTION(C, axis)` | `C(v)` turned by `u` about the axis | `dS/du x C'(v)` |
//! | `SURFACE_OF_LINEAR_EXTRUSION(C, V)` | `C(u) + v V` | `C'(u) x V` |
//! | `OFFSET_SURFACE(B, d)` | `B(u, v) + d n_B(u, v)` | as `B`'s |
//!
//! (*) ISO 10303-42's cone runs by the height `v`; OpenCascade writes its own cone,
//! `c + (R + v sin a) r(u) + v cos a z` (`v` the slant length), and pcurves in that `v`.
//! A cone face is read by the standard; if its line and circle pcurves do not then run
//! with their edges' 3-D curves, by OpenCascade's (whichever the face's own curves agree
//! with).
//!
//! The four surfaces with an axis are surfaces of revolution of a profile `P(v)` in the
//! half plane of `x` and `z`: a line (cylinder, cone: `c + (R + v tan a) x + v z`, linear
//! in `v`) or a circle (sphere: centre `c`; torus: centre `c + R x`, radius `r`, angle `v`).
//! The profile is made exact in `v` ([`Curve::nurbs`]), turned by
//! [`crate::geometry::analytic_nurbs::revolution`] (which puts the angle second) and the
//! result transposed, which gives exactly `S(u, v)`; the angle directions run by circular
//! arcs in normal form, whose half angles the face carries so that trims given in angles
//! are tested at the true angle. A spindle torus (`r > R`) is the same construction (its
//! profile crosses the axis; a turned control point is still the rotation of the point).
//! An offset of one of these, or of a plane, is the same kind with its profile moved by
//! `d` along the profile's unit normal: `R + d` (cylinder, sphere), `r + d` (torus),
//! `c + d z` (plane), and for the cone `P(v) + d (cos a x - sin a z)`, still linear in `v`,
//! so the parameters stay the basis's, as STEP defines. Offsets of offsets add. An offset
//! of a surface of revolution or extrusion (not rational in general) is refused.
//!
//! A face's extent in `(u, v)` is the box of its trimming loops' control points (which
//! holds the loops); along an angle it is at most one turn (`2 pi`), along a sphere's
//! latitude within `[-pi/2, pi/2]`. Angles are in radians (OpenCascade's
//! `PLANE_ANGLE_UNIT`); lengths in the file's unit, scaled to mm by the caller.

use super::step::{Step, Value};
use super::step_curves::{Curve, Frame};
use crate::geometry::analytic_nurbs::{extrusion_over, revolution, NurbsCurve};
use crate::geometry::nurbs::NurbsSurface;
use crate::geometry::trim::TrimSegment;
use crate::geometry::Vec3;
use crate::Result;
use std::f64::consts::{FRAC_PI_2, TAU};

/// An analytic STEP surface (see the module docs), offsets folded in.
#[derive(Debug, Clone)]
pub(super) enum Analytic {
    Plane(Frame),
    /// Cylinder (`semi_angle` 0) or cone; `offset` moves the profile along its normal;
    /// `slant`: `v` is the length along the generatrix (OpenCascade's cone), not the height.
    Cone {
        frame: Frame,
        radius: f64,
        semi_angle: f64,
        offset: f64,
        slant: bool,
    },
    Sphere {
        frame: Frame,
        radius: f64,
    },
    Torus {
        frame: Frame,
        major: f64,
        minor: f64,
    },
    Revolution {
        curve: Curve,
        origin: Vec3,
        axis: Vec3,
    },
    Extrusion {
        curve: Curve,
        vector: Vec3,
    },
}

/// The names of the surfaces this module reads, for messages.
pub(super) const READ: &str = "PLANE, CYLINDRICAL_SURFACE, CONICAL_SURFACE, \
     SPHERICAL_SURFACE, TOROIDAL_SURFACE, SURFACE_OF_REVOLUTION, SURFACE_OF_LINEAR_EXTRUSION, \
     OFFSET_SURFACE of these, B_SPLINE_SURFACE_WITH_KNOTS";

/// `v` rotated by `angle` about the unit `axis` (Rodrigues).
fn rotated(v: Vec3, axis: Vec3, angle: f64) -> Vec3 {
    let (s, c) = angle.sin_cos();
    v * c + axis.cross(&v) * s + axis * (axis.dot(&v) * (1.0 - c))
}

/// Radial and axial steps of a cone's generatrix per unit of `v`: `(tan a, 1)` by
/// ISO 10303-42 (`v` the height), `(sin a, cos a)` if `v` is the slant length.
fn generatrix(a: f64, slant: bool) -> [f64; 2] {
    if slant {
        [a.sin(), a.cos()]
    } else {
        [a.tan(), 1.0]
    }
}

impl Analytic {
    /// The same cone with `v` the slant length (OpenCascade writes its cones so, with
    /// pcurves in that parameter), or `None` if not a cone.
    pub fn slanted(&self) -> Option<Analytic> {
        match self {
            Analytic::Cone {
                semi_angle,
                slant: false,
                ..
            } if *semi_angle != 0.0 => {
                let mut c = self.clone();
                if let Analytic::Cone { slant, .. } = &mut c {
                    *slant = true;
                }
                Some(c)
            }
            _ => None,
        }
    }

    /// True along `u` (index 0) or `v` (1) if the parameter is an angle (one turn at most).
    fn angular(&self) -> [bool; 2] {
        match self {
            Analytic::Plane(_) => [false, false],
            Analytic::Cone { .. } => [true, false],
            Analytic::Sphere { .. } | Analytic::Torus { .. } => [true, true],
            Analytic::Revolution { curve, .. } => [true, curve.periodic()],
            Analytic::Extrusion { curve, .. } => [curve.periodic(), false],
        }
    }

    /// `S(u, v)` in closed form (the file's unit).
    pub fn point(&self, u: f64, v: f64) -> Vec3 {
        let radial = |f: &Frame, a: f64| f.x * a.cos() + f.y * a.sin();
        match self {
            Analytic::Plane(f) => f.origin + f.x * u + f.y * v,
            Analytic::Cone {
                frame: f,
                radius,
                semi_angle: a,
                offset: d,
                slant,
            } => {
                let [kr, kz] = generatrix(*a, *slant);
                let rho = radius + v * kr + d * a.cos();
                f.origin + radial(f, u) * rho + f.z * (v * kz - d * a.sin())
            }
            Analytic::Sphere { frame: f, radius } => {
                f.origin + radial(f, u) * (radius * v.cos()) + f.z * (radius * v.sin())
            }
            Analytic::Torus {
                frame: f,
                major,
                minor,
            } => f.origin + radial(f, u) * (major + minor * v.cos()) + f.z * (minor * v.sin()),
            Analytic::Revolution {
                curve,
                origin,
                axis,
            } => origin + rotated(curve.point(v) - origin, *axis, u),
            Analytic::Extrusion { curve, vector } => curve.point(u) + vector * v,
        }
    }

    /// The parameters `(u, v)` of a point lying on the surface, in closed form (the
    /// inverse of [`Analytic::point`]): the frame coordinates on a plane; on the axial
    /// kinds `u = atan2(y, x)` in `(-pi, pi]` of the point's frame coordinates, and `v`
    /// the height (cylinder, cone; the slant length on OpenCascade's cone), the latitude
    /// `atan2(z, rho)` (sphere) or the tube angle `atan2(z, rho - R)` (torus), `rho` the
    /// distance from the axis. `None` for surfaces of revolution and extrusions, whose
    /// inverse needs a curve's.
    pub fn parameters(&self, p: Vec3) -> Option<[f64; 2]> {
        let local = |f: &Frame| {
            let d = p - f.origin;
            (d.dot(&f.x), d.dot(&f.y), d.dot(&f.z))
        };
        Some(match self {
            Analytic::Plane(f) => {
                let (x, y, _) = local(f);
                [x, y]
            }
            Analytic::Cone {
                frame,
                semi_angle: a,
                offset: d,
                slant,
                ..
            } => {
                let (x, y, z) = local(frame);
                let [_, kz] = generatrix(*a, *slant);
                [y.atan2(x), (z + d * a.sin()) / kz]
            }
            Analytic::Sphere { frame, .. } => {
                let (x, y, z) = local(frame);
                [y.atan2(x), z.atan2(x.hypot(y))]
            }
            Analytic::Torus { frame, major, .. } => {
                let (x, y, z) = local(frame);
                [y.atan2(x), z.atan2(x.hypot(y) - major)]
            }
            Analytic::Revolution { .. } | Analytic::Extrusion { .. } => return None,
        })
    }

    /// True along `u` (index 0) or `v` (1) if the parameter is an angle of period `2 pi`
    /// (a sphere's latitude is not: it stays within `[-pi/2, pi/2]`).
    pub fn periodic(&self) -> [bool; 2] {
        match self {
            Analytic::Sphere { .. } => [true, false],
            _ => self.angular(),
        }
    }

    /// The profile of an axial kind over `v` in `range`: a curve in the half plane of `x`
    /// and `z` whose turn about `z` is the surface.
    fn profile(&self, range: [f64; 2]) -> Option<Result<NurbsCurve>> {
        Some(match self {
            Analytic::Cone {
                frame: f,
                radius,
                semi_angle: a,
                offset: d,
                slant,
            } => {
                let [kr, kz] = generatrix(*a, *slant);
                let origin = f.origin + f.x * (radius + d * a.cos()) - f.z * (d * a.sin());
                NurbsCurve::ray(origin, f.x * kr + f.z * kz, range)
            }
            Analytic::Sphere { frame: f, radius } => {
                NurbsCurve::arc(f.origin, f.x, f.z, *radius, range)
            }
            Analytic::Torus {
                frame: f,
                major,
                minor,
            } => NurbsCurve::arc(f.origin + f.x * *major, f.x, f.z, *minor, range),
            _ => return None,
        })
    }

    /// The exact NURBS over `[u, v]` (see the module docs) and the arc half angles of its
    /// directions.
    pub fn nurbs(&self, [u, v]: [[f64; 2]; 2]) -> Result<(NurbsSurface, [Option<f64>; 2])> {
        if let Analytic::Plane(f) = self {
            let at = |a: f64, b: f64| f.origin + f.x * a + f.y * b;
            let s = NurbsSurface::new(
                [1, 1],
                [vec![u[0], u[0], u[1], u[1]], vec![v[0], v[0], v[1], v[1]]],
                vec![
                    vec![at(u[0], v[0]), at(u[0], v[1])],
                    vec![at(u[1], v[0]), at(u[1], v[1])],
                ],
                None,
            )?;
            return Ok((s, [None, None]));
        }
        if let Some(profile) = self.profile(v) {
            let profile = profile?;
            let f = match self {
                Analytic::Cone { frame, .. }
                | Analytic::Sphere { frame, .. }
                | Analytic::Torus { frame, .. } => frame,
                _ => unreachable!("only axial kinds have a profile"),
            };
            let (s, half) = revolution(&profile, f.origin, f.z, u)?;
            return Ok((s.transposed(), [Some(half), profile.arc_half_angle]));
        }
        match self {
            Analytic::Revolution {
                curve,
                origin,
                axis,
            } => {
                let c = curve.nurbs(v)?;
                let (s, half) = revolution(&c, *origin, *axis, u)?;
                Ok((s.transposed(), [Some(half), c.arc_half_angle]))
            }
            Analytic::Extrusion { curve, vector } => {
                let c = curve.nurbs(u)?;
                Ok((extrusion_over(&c, *vector, v)?, [c.arc_half_angle, None]))
            }
            _ => unreachable!("planes and axial kinds are made above"),
        }
    }

    /// The face's parameter box from the box of its loops (see the module docs); `None`
    /// for a face with no loop whose surface is unbounded.
    pub fn extent(&self, loops: Option<[[f64; 2]; 2]>) -> Option<[[f64; 2]; 2]> {
        let angular = self.angular();
        let whole = |d: usize| match (self, d) {
            (Analytic::Sphere { .. }, 1) => Some([-FRAC_PI_2, FRAC_PI_2]),
            _ if angular[d] => Some([0.0, TAU]),
            _ => None,
        };
        let mut out = [[0.0; 2]; 2];
        for d in 0..2 {
            out[d] = match loops {
                Some(b) => b[d],
                None => whole(d)?,
            };
            if angular[d] {
                out[d][1] = out[d][1].min(out[d][0] + TAU);
            }
            if let (Analytic::Sphere { .. }, 1) = (self, d) {
                out[d] = [out[d][0].max(-FRAC_PI_2), out[d][1].min(FRAC_PI_2)];
            }
            // A swept B-spline ends where its knots do (the loops reach it to rounding).
            match (self, d) {
                (
                    Analytic::Revolution {
                        curve: Curve::Spline(c),
                        ..
                    },
                    1,
                )
                | (
                    Analytic::Extrusion {
                        curve: Curve::Spline(c),
                        ..
                    },
                    0,
                ) => {
                    out[d] = [out[d][0].max(c.range[0]), out[d][1].min(c.range[1])];
                }
                _ => {}
            }
        }
        Some(out)
    }
}

/// The exact NURBS of a face on `a` over the box of its trimming `loops` (in the surface's
/// own unit), with its arc half angles; errs for a face on an unbounded surface with no
/// loop. Shared by the STEP and IGES BRep readers.
pub(super) fn face_surface(
    a: &Analytic,
    loops: &[Vec<TrimSegment>],
) -> Result<(NurbsSurface, [Option<f64>; 2])> {
    let boxed = loops
        .iter()
        .flatten()
        .map(|s| s.hull_box())
        .reduce(|a, b| [0, 1].map(|d| [a[d][0].min(b[d][0]), a[d][1].max(b[d][1])]));
    let extent = a.extent(boxed).ok_or_else(|| {
        crate::Error::Input("a face on an unbounded surface with no bounding loop".into())
    })?;
    a.nurbs(extent)
}

impl Step<'_> {
    /// The analytic surface `id` (a face's geometry, `face` named in messages), or `None`
    /// if it is a B-spline surface (read by [`Step::surface`]).
    pub(super) fn analytic(&self, id: usize, face: usize) -> Result<Option<Analytic>> {
        self.analytic_offset(id, face, 0.0, 0)
    }

    fn analytic_offset(
        &self,
        id: usize,
        face: usize,
        d: f64,
        depth: usize,
    ) -> Result<Option<Analytic>> {
        let inst = self.instance(id, face, "surface")?;
        let (name, p) = &inst.parts[0];
        let frame = || self.frame(self.reference(id, p.get(1), "position")?, id);
        let length = |k: usize, what: &str| -> Result<f64> {
            let x = self.number(id, p.get(k), what)?;
            if x >= 0.0 {
                Ok(x)
            } else {
                Err(self.fail(id, format!("its {what} {x} is negative")))
            }
        };
        let positive = |x: f64, what: &str| -> Result<f64> {
            if x > 0.0 {
                Ok(x)
            } else {
                Err(self.fail(
                    id,
                    format!("its {what} {x} (with the offset {d}) is not > 0"),
                ))
            }
        };
        let out = match name.as_str() {
            "PLANE" => {
                let f = frame()?;
                Analytic::Plane(Frame {
                    origin: f.origin + f.z * d,
                    ..f
                })
            }
            "CYLINDRICAL_SURFACE" | "CONICAL_SURFACE" => {
                let radius = length(2, "radius")?;
                let semi_angle = if name == "CONICAL_SURFACE" {
                    self.number(id, p.get(3), "semi-angle")?
                } else {
                    0.0
                };
                if semi_angle.abs() >= FRAC_PI_2 {
                    return Err(self.fail(
                        id,
                        format!("its semi-angle {semi_angle} is not below pi/2 (radians)"),
                    ));
                }
                if semi_angle == 0.0 {
                    positive(radius + d, "radius")?;
                }
                Analytic::Cone {
                    frame: frame()?,
                    radius,
                    semi_angle,
                    offset: d,
                    slant: false,
                }
            }
            "SPHERICAL_SURFACE" => Analytic::Sphere {
                frame: frame()?,
                radius: positive(length(2, "radius")? + d, "radius")?,
            },
            "TOROIDAL_SURFACE" => Analytic::Torus {
                frame: frame()?,
                major: length(2, "major radius")?,
                minor: positive(length(3, "minor radius")? + d, "minor radius")?,
            },
            "SURFACE_OF_REVOLUTION" | "SURFACE_OF_LINEAR_EXTRUSION" if d != 0.0 => {
                return Err(self.fail(
                    id,
                    format!(
                        "an OFFSET_SURFACE of a {name} is not read (its offset is not rational); \
                     export the face as a B-spline surface"
                    ),
                ))
            }
            "SURFACE_OF_REVOLUTION" => {
                let curve = self.curve(self.reference(id, p.get(1), "swept curve")?, id)?;
                let a = self.reference(id, p.get(2), "axis position")?;
                let q = self.part(a, "AXIS1_PLACEMENT").ok_or_else(|| {
                    self.fail(id, format!("its axis #{a} is not an AXIS1_PLACEMENT"))
                })?;
                let origin = self.vec3(self.reference(a, q.get(1), "location")?, a)?;
                let axis = match q.get(2) {
                    Some(Value::Ref(r)) => self.direction(*r, a)?,
                    _ => Vec3::z(),
                };
                Analytic::Revolution {
                    curve,
                    origin,
                    axis,
                }
            }
            "SURFACE_OF_LINEAR_EXTRUSION" => {
                let curve = self.curve(self.reference(id, p.get(1), "swept curve")?, id)?;
                let v = self.reference(id, p.get(2), "extrusion axis")?;
                let q = self.part(v, "VECTOR").ok_or_else(|| {
                    self.fail(id, format!("its extrusion axis #{v} is not a VECTOR"))
                })?;
                let dir = self.direction(self.reference(v, q.get(1), "orientation")?, v)?;
                let vector = dir * self.number(v, q.get(2), "magnitude")?;
                Analytic::Extrusion { curve, vector }
            }
            "OFFSET_SURFACE" if depth < 8 => {
                let basis = self.reference(id, p.get(1), "basis surface")?;
                let distance = self.number(id, p.get(2), "distance")?;
                return match self.analytic_offset(basis, face, d + distance, depth + 1)? {
                    Some(a) => Ok(Some(a)),
                    None => Err(self.fail(
                        id,
                        format!(
                            "an OFFSET_SURFACE of the B-spline surface #{basis} is not read; \
                         export the face as a B-spline surface"
                        ),
                    )),
                };
            }
            _ if inst
                .parts
                .iter()
                .any(|(n, _)| n == "B_SPLINE_SURFACE_WITH_KNOTS") =>
            {
                return if d == 0.0 {
                    Ok(None)
                } else {
                    Err(self.fail(id, "an offset B-spline surface is not read".into()))
                };
            }
            _ => {
                return Err(self.fail(
                    face,
                    format!(
                        "its surface #{id} is a {}, which is not read (read: {READ})",
                        self.kind(id)
                    ),
                ))
            }
        };
        Ok(Some(out))
    }
}
