//! IGES BRep (IGES 5.3 manifold solid B-rep objects, OpenCascade's
//! `write.iges.brep.mode = 1`) read into tool faces.
//!
//! The topology: a 186 manifold solid lists its shell (and void shells), each with an
//! orientation flag `SOF`; a 514 shell lists its 510 faces, each with a flag `OF` (1: the
//! face's normal is its surface's); a 510 face names its surface and its 508 loops; a 508
//! loop lists edge uses, each an index `NDX` into a 504 edge list (whose entry gives the
//! edge's model-space curve between two 502 vertices) with the parameter-space curves of
//! that use. A face's outward normal is `n = s o (S_u x S_v)`, `o = +1` if its shell's
//! `OF` is 1, `s = +1` if the shell's `SOF` in its solid is 1 (else `-1`): a face of a
//! solid then points out of it (tested on OpenCascade's punch and die). A 510 no shell
//! lists is a face with its surface's normal.
//!
//! The surfaces, made the exact NURBS they are by the STEP analytic constructors
//! ([`super::step_analytic`]; `L` the 116 location, `A` the 123 axis or normal, `X` the 123
//! reference direction made orthogonal to `A`, `Y = A x X`, `r(u) = cos u X + sin u Y`):
//!
//! | entity | `S(u, v)` | normal `S_u x S_v` |
//! |---|---|---|
//! | 190 plane surface | `L + u X + v Y` | `A` |
//! | 192 right circular cylinder (`R`) | `L + R r(u) + v A` | away from the axis |
//! | 194 right circular cone (`R`, semi-angle `a` in degrees) | `L + (R + v tan a) r(u) + v A` | away from the axis |
//! | 196 sphere (`R`) | `L + R cos v r(u) + R sin v A` | out of the sphere |
//! | 198 torus (`R`, `r`; spindle too) | `L + (R + r cos v) r(u) + r sin v A` | out of the tube |
//! | 128 rational B-spline surface | itself | its own |
//!
//! Without a reference direction (form 0) `X` is the coordinate axis least aligned with
//! `A`, made orthogonal to it. These `(u, v)` are this reader's: a writer's parameter
//! curves on an analytic surface are not read, because writers disagree on them
//! (OpenCascade writes angles in degrees, in its own surface's parameters, which on a
//! left-handed placement run against IGES's axis). Instead each edge's model-space curve
//! (110 line, 100 arc, 126 B-spline, with their 124 matrices) is inverted onto the
//! surface in closed form ([`Analytic::parameters`]): on a plane exactly (an affine map
//! of the control points), on the other kinds where the edge is a straight line of the
//! parameter plane (an isoparametric circle or line: every edge of a tool made of planes,
//! cylinders, cones, spheres and tori that meet tangentially or along their axes), checked
//! at 9 points to `1e-7` of the parameters' size, the other edges being refused naming
//! them. On a 128 the file's parameter-space curves are its trims (the B-spline's own
//! parameters are unambiguous). Edges are chained by continuity as STEP's
//! ([`super::step::chain`], with the turns of periodic parameters); a vertex use (a pole)
//! bounds nothing. Any other surface, a 510 that names no surface, a 508 edge use whose
//! list is not a 504, and an edge without a parameter-space curve on a 128 are refused
//! naming the entity, its type and D line, and what to do.

use super::iges::{Entry, Iges, Params};
use super::step::{chain, on_plane};
use super::step_analytic::{face_surface, Analytic};
use super::step_curves::Frame;
use super::Face;
use crate::geometry::analytic_nurbs::NurbsCurve;
use crate::geometry::nurbs::NurbsSurface;
use crate::geometry::trim::{TrimRegion, TrimSegment};
use crate::geometry::{Mat3, Vec3};
use crate::Result;
use std::collections::{HashMap, HashSet};
use std::f64::consts::TAU;

/// The surface of a 510 face.
enum BrepSurface {
    Analytic(Analytic),
    Spline(NurbsSurface),
}

/// Surfaces a 510 face may name.
const READ: &str = "128, 190, 192, 194, 196, 198";

impl Iges<'_> {
    /// The faces of the file's shells (in directory order of the 514s, each's faces in
    /// its order), then the 510 faces no shell lists.
    pub(super) fn brep_faces(&self) -> Result<Vec<Face>> {
        let pointer = |i: usize| (2 * i + 1) as i64;
        let mut shell_sense: HashMap<i64, bool> = HashMap::new();
        for e in self.entries().iter().filter(|e| e.kind == 186) {
            let p = self.params(e)?;
            shell_sense.insert(
                p.int(1, "SHELL, shell pointer")?,
                p.int(2, "SOF, shell orientation flag")? != 0,
            );
            for k in 0..p.count(3, "N, void shell count")? {
                shell_sense.insert(
                    p.int(4 + 2 * k, "VOID, void shell pointer")?,
                    p.int(5 + 2 * k, "VOF, void shell orientation flag")? != 0,
                );
            }
        }
        let mut listed = HashSet::new();
        let mut faces = Vec::new();
        for (i, e) in self.entries().iter().enumerate() {
            if e.kind != 514 {
                continue;
            }
            let sense = shell_sense.get(&pointer(i)).copied().unwrap_or(true);
            let p = self.params(e)?;
            for k in 0..p.count(1, "N, face count")? {
                let f = p.int(2 + 2 * k, "FACE, face pointer")?;
                let agrees = p.int(3 + 2 * k, "OF, face orientation flag")? != 0;
                let face = self.entry(f, &p, "face")?;
                if face.kind != 510 {
                    return Err(p.fail(format!(
                        "its face pointer names {}, not a 510 face",
                        Self::describe(face)
                    )));
                }
                listed.insert(f);
                // n = s o (S_u x S_v): flipped when exactly one of the flags is 0.
                faces.push(self.brep_face(face, agrees != sense)?);
            }
        }
        for (i, e) in self.entries().iter().enumerate() {
            if e.kind == 510 && !listed.contains(&pointer(i)) {
                faces.push(self.brep_face(e, false)?);
            }
        }
        Ok(faces)
    }

    /// A 510 face: its surface, trimmed by its loops; `flip`: its outward side is that of
    /// `-S_u x S_v`.
    fn brep_face(&self, e: &Entry, flip: bool) -> Result<Face> {
        let p = self.params(e)?;
        let s = self.entry(p.int(1, "SURF, surface pointer")?, &p, "surface")?;
        let surface = self.brep_surface(s, &p)?;
        let mut loops = Vec::new();
        for k in 0..p.count(2, "N, loop count")? {
            let l = self.entry(p.int(4 + k, "LOOP, loop pointer")?, &p, "loop")?;
            if l.kind != 508 {
                return Err(p.fail(format!(
                    "its loop pointer names {}, not a 508 loop",
                    Self::describe(l)
                )));
            }
            let segments = self.brep_loop(l, &surface)?;
            if !segments.is_empty() {
                loops.push(segments);
            }
        }
        let (nurbs, arcs) = match &surface {
            BrepSurface::Analytic(a) => {
                face_surface(a, &loops).map_err(|x| p.fail(super::strip(x)))?
            }
            BrepSurface::Spline(s) => (s.clone(), [None, None]),
        };
        let trim = if loops.is_empty() {
            None
        } else {
            Some(TrimRegion::new(loops).map_err(|x| p.fail(super::strip(x)))?)
        };
        Ok(Face {
            surface: nurbs,
            trim,
            origin: Self::describe(e),
            flip,
            arcs,
            names: Vec::new(),
        })
    }

    /// The surface of a 510 (see the module docs), in mm.
    fn brep_surface(&self, s: &Entry, face: &Params) -> Result<BrepSurface> {
        if s.kind == 128 {
            return Ok(BrepSurface::Spline(self.surface(s)?));
        }
        if !matches!(s.kind, 190 | 192 | 194 | 196 | 198) {
            return Err(face.fail(format!(
                "its surface is {}, which is not read as the surface of a BRep face (read: \
                 {READ}); convert the faces to B-splines before writing (OpenCascade: \
                 BRepBuilderAPI_NurbsConvert), or export STEP",
                Self::describe(s)
            )));
        }
        let p = self.params(s)?;
        let (r, t) = self.matrix(s, 0)?;
        let mm = self.to_mm;
        let point = |i: usize| -> Result<Vec3> {
            Ok((r * self.pointed(&p, i, 116, "LOCATION, point pointer")? + t) * mm)
        };
        let direction = |i: usize, what: &str| -> Result<Vec3> {
            (r * self.pointed(&p, i, 123, what)?)
                .try_normalize(1e-300)
                .ok_or_else(|| p.fail(format!("its {what} names a direction of length zero")))
        };
        let length = |i: usize, what: &str, zero: bool| -> Result<f64> {
            let x = p.real(i, what)?;
            if x > 0.0 || (zero && x == 0.0) {
                Ok(x * mm)
            } else {
                Err(p.fail(format!("its {what} = {x} must be > 0")))
            }
        };
        // The reference direction, parameter `i` of form 1 (form 0 has none).
        let reference = |i: usize| -> Result<Option<Vec3>> {
            if s.form == 1 {
                direction(i, "REFDIR, reference direction pointer").map(Some)
            } else {
                Ok(None)
            }
        };
        let frame = |origin: Vec3, z: Vec3, x: Option<Vec3>| -> Result<Frame> {
            brep_frame(origin, z, x)
                .ok_or_else(|| p.fail("its reference direction is along its axis".to_string()))
        };
        let axis = "AXIS, axis direction pointer";
        let a = match s.kind {
            190 => Analytic::Plane(frame(
                point(1)?,
                direction(2, "NORMAL, normal direction pointer")?,
                reference(3)?,
            )?),
            192 => Analytic::Cone {
                frame: frame(point(1)?, direction(2, axis)?, reference(4)?)?,
                radius: length(3, "RADIUS", false)?,
                semi_angle: 0.0,
                offset: 0.0,
                slant: false,
            },
            194 => {
                let degrees = p.real(4, "SANGLE, semi-angle")?;
                if !(degrees > 0.0 && degrees < 90.0) {
                    return Err(p.fail(format!(
                        "its semi-angle {degrees} must be in (0, 90) degrees"
                    )));
                }
                Analytic::Cone {
                    frame: frame(point(1)?, direction(2, axis)?, reference(5)?)?,
                    radius: length(3, "RADIUS", true)?,
                    semi_angle: degrees.to_radians(),
                    offset: 0.0,
                    slant: false,
                }
            }
            196 => {
                let z = if s.form == 1 {
                    direction(3, axis)?
                } else {
                    Vec3::z()
                };
                Analytic::Sphere {
                    frame: frame(point(1)?, z, reference(4)?)?,
                    radius: length(2, "RADIUS", false)?,
                }
            }
            _ => Analytic::Torus {
                frame: frame(point(1)?, direction(2, axis)?, reference(5)?)?,
                major: length(3, "MAJRAD, major radius", true)?,
                minor: length(4, "MINRAD, minor radius", false)?,
            },
        };
        Ok(BrepSurface::Analytic(a))
    }

    /// The coordinates of the 116 point (`kind` 116: after its matrix) or 123 direction
    /// (123: after its matrix's rotation) parameter `i` of `p` points at.
    fn pointed(&self, p: &Params, i: usize, kind: i64, what: &str) -> Result<Vec3> {
        let e = self.entry(p.int(i, what)?, p, what)?;
        if e.kind != kind {
            return Err(p.fail(format!(
                "its {what} names {}, not a {kind}",
                Self::describe(e)
            )));
        }
        let q = self.params(e)?;
        let v = q.reals(1, 3, "coordinate")?;
        let (r, t) = self.matrix(e, 0)?;
        let x = r * Vec3::new(v[0], v[1], v[2]);
        Ok(if kind == 116 { x + t } else { x })
    }

    /// A 508 loop's segments in the parameter plane of `surface`, its edge uses chained.
    fn brep_loop(&self, l: &Entry, surface: &BrepSurface) -> Result<Vec<TrimSegment>> {
        let p = self.params(l)?;
        let mut at = 2;
        let mut edges = Vec::new();
        for _ in 0..p.count(1, "N, edge count")? {
            let vertex = p.int(at, "TYPE, edge (0) or vertex (1)")? == 1;
            let list = p.int(at + 1, "EDGE, edge list pointer")?;
            let index = p.count(at + 2, "NDX, edge index")?;
            let k = p.count(at + 4, "K, parameter-space curve count")?;
            let curves: Vec<i64> = (0..k)
                .map(|j| p.int(at + 6 + 2 * j, "CURV, parameter-space curve pointer"))
                .collect::<Result<_>>()?;
            at += 5 + 2 * k;
            if vertex {
                continue; // a vertex use (a pole) bounds nothing
            }
            let edge = format!(
                "its edge {index} of {}",
                Self::describe(self.entry(list, &p, "edge list")?)
            );
            let chains = match surface {
                BrepSurface::Analytic(a) => {
                    let curve = self.edge_curve(list, index, &p)?;
                    self.edge_on_surface(a, &curve, &edge, &p)?
                }
                BrepSurface::Spline(_) => {
                    if curves.is_empty() {
                        return Err(p.fail(format!(
                            "{edge} has no parameter-space curve on the face's 128 B-spline \
                             surface, which is not read; write the file with parameter-space \
                             curves"
                        )));
                    }
                    let mut segments = Vec::new();
                    for c in curves {
                        let c = self.entry(c, &p, "parameter-space curve")?;
                        self.param_curve(c, &mut segments, 0)?;
                    }
                    vec![segments]
                }
            };
            let mut options = Vec::new();
            for c in chains {
                let reversed: Vec<TrimSegment> = c.iter().rev().map(|s| s.reversed()).collect();
                options.push(c);
                options.push(reversed);
            }
            edges.push(options);
        }
        let segments = chain(&edges);
        Ok(match surface {
            BrepSurface::Analytic(Analytic::Plane(_)) | BrepSurface::Spline(_) => segments,
            BrepSurface::Analytic(_) => closed_lines(&segments),
        })
    }

    /// The model-space curve of edge `index` (from 1) of the 504 edge list at `list`, in mm.
    fn edge_curve(&self, list: i64, index: usize, from: &Params) -> Result<NurbsCurve> {
        let e = self.entry(list, from, "edge list")?;
        if e.kind != 504 {
            return Err(from.fail(format!(
                "its edge list pointer names {}, not a 504 edge list",
                Self::describe(e)
            )));
        }
        let p = self.params(e)?;
        let n = p.count(1, "N, edge count")?;
        if index == 0 || index > n {
            return Err(from.fail(format!(
                "its edge index {index} is not in 1..{n} of {}",
                Self::describe(e)
            )));
        }
        let c = p.int(2 + 5 * (index - 1), "CURV, model-space curve pointer")?;
        let curve = self.model_curve(self.entry(c, &p, "model-space curve")?)?;
        Ok(curve.transformed(&(Mat3::identity() * self.to_mm), &Vec3::zeros()))
    }

    /// An edge's segments in the parameter plane of the analytic surface `a` (see the
    /// module docs): each way of placing it on the periodic parameters' turns; `edge`
    /// names it in messages.
    fn edge_on_surface(
        &self,
        a: &Analytic,
        curve: &NurbsCurve,
        edge: &str,
        p: &Params,
    ) -> Result<Vec<Vec<TrimSegment>>> {
        let off = || {
            p.fail(format!(
                "{edge} does not lie on the face's surface (off by more than 1e-6 of its size)"
            ))
        };
        if let Analytic::Plane(f) = a {
            let [t0, t1] = curve.range;
            let x = curve.point(0.5 * (t0 + t1));
            if (x - f.origin).dot(&f.z).abs() > 1e-6 * (1.0 + (x - f.origin).norm()) {
                return Err(off());
            }
            return Ok(vec![on_plane(curve, f)]);
        }
        let uv = isoparametric(a, curve).map_err(|e| match e {
            Unmapped::Off => off(),
            Unmapped::Curved => p.fail(format!(
                "{edge} is not a straight line of the face's parameter plane (an isoparametric circle or line), which is not read on \
                 a {}: convert the faces to B-splines (OpenCascade: BRepBuilderAPI_NurbsConvert) \
                 or export STEP",
                match a {
                    Analytic::Cone { semi_angle, .. } if *semi_angle == 0.0 => "cylinder",
                    Analytic::Cone { .. } => "cone",
                    Analytic::Sphere { .. } => "sphere",
                    _ => "torus",
                }
            )),
        })?;
        let periodic = a.periodic();
        // The unshifted image first: the chain keeps it where it closes.
        let turns = |d: usize| {
            if periodic[d] {
                vec![0.0, -1.0, 1.0]
            } else {
                vec![0.0]
            }
        };
        let line = TrimSegment::line(uv[0], uv[1]);
        let mut out = Vec::new();
        for du in turns(0) {
            for dv in turns(1) {
                out.push(vec![line.shifted(du * TAU, dv * TAU)]);
            }
        }
        Ok(out)
    }
}

/// The frame `(origin; x, y = z x x, z)` of an IGES surface: `x` the reference direction
/// made orthogonal to the unit axis `z`, or without one the coordinate axis least aligned
/// with `z`; `None` if the reference direction is along the axis.
fn brep_frame(origin: Vec3, z: Vec3, x: Option<Vec3>) -> Option<Frame> {
    let x = x.unwrap_or_else(|| {
        let k = (0..3)
            .min_by(|&a, &b| z[a].abs().total_cmp(&z[b].abs()))
            .unwrap_or(0);
        let mut axis = Vec3::zeros();
        axis[k] = 1.0;
        axis
    });
    let x = (x - z * x.dot(&z)).try_normalize(1e-9)?;
    Some(Frame {
        origin,
        x,
        y: z.cross(&x),
        z,
    })
}

/// Why an edge has no straight image in a surface's parameter plane.
#[derive(Debug, PartialEq)]
enum Unmapped {
    /// A point of the edge is not on the surface.
    Off,
    /// Its image is not a straight line.
    Curved,
}

/// The ends `(u, v)` of the straight image of `curve` on `a`: the closed-form parameters
/// of 9 points equally spaced in the curve's parameter, the angles unwrapped along the
/// curve (each within half a turn of the previous), each point on the surface to `1e-6`
/// of its size (the file's digits), and all on the line of the ends to `1e-7` of the
/// parameters' size (the file's ten digits through the inverse; a curved image, as an
/// oblique circle on a cylinder, is off by a fraction of the face's size). A coordinate
/// that the ends share to that tolerance is made equal (the edge is isoparametric).
fn isoparametric(a: &Analytic, curve: &NurbsCurve) -> std::result::Result<[[f64; 2]; 2], Unmapped> {
    let n = 8;
    let [t0, t1] = curve.range;
    let periodic = a.periodic();
    let mut uv: Vec<[f64; 2]> = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let x = curve.point(t0 + (t1 - t0) * k as f64 / n as f64);
        let mut q = a.parameters(x).ok_or(Unmapped::Curved)?;
        if let Some(prev) = uv.last() {
            for d in 0..2 {
                if periodic[d] {
                    q[d] += TAU * ((prev[d] - q[d]) / TAU).round();
                }
            }
        }
        if (a.point(q[0], q[1]) - x).norm() > 1e-6 * (1.0 + x.norm()) {
            return Err(Unmapped::Off);
        }
        uv.push(q);
    }
    let (mut s, mut e) = (uv[0], uv[n]);
    let size = uv.iter().flatten().fold(1.0f64, |m, c| m.max(c.abs()));
    let tol = 1e-7 * size;
    let d = [e[0] - s[0], e[1] - s[1]];
    let length = d[0].hypot(d[1]);
    if length <= tol {
        return Err(Unmapped::Curved);
    }
    let off_line = |q: &[f64; 2]| ((q[0] - s[0]) * d[1] - (q[1] - s[1]) * d[0]).abs() / length;
    if uv.iter().any(|q| off_line(q) > tol) {
        return Err(Unmapped::Curved);
    }
    for c in 0..2 {
        if (e[c] - s[c]).abs() <= tol {
            let m = 0.5 * (s[c] + e[c]);
            (s[c], e[c]) = (m, m);
        }
    }
    Ok([s, e])
}

/// A closed chain of straight segments with each junction at the middle of the two ends
/// that meet there (they differ by the file's rounding through the inverse), so that the
/// loop closes exactly; an isoparametric segment stays so when its neighbours share the
/// coordinate, which they do where the ends agree to the rounding.
fn closed_lines(segments: &[TrimSegment]) -> Vec<TrimSegment> {
    let n = segments.len();
    let joint = |k: usize| {
        let (a, b) = (segments[(k + n - 1) % n].end(), segments[k].start());
        [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
    };
    (0..n)
        .map(|k| TrimSegment::line(joint(k), joint((k + 1) % n)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn torus() -> Analytic {
        Analytic::Torus {
            frame: brep_frame(
                Vec3::new(1.0, 2.0, 3.0),
                Vec3::new(0.6, 0.0, 0.8),
                Some(Vec3::y()),
            )
            .unwrap(),
            major: 2.0,
            minor: 8.0,
        }
    }

    /// A meridian (a tube circle at fixed `u`) and a parallel (fixed `v`) of a spindle
    /// torus, made exact NURBS in space, come back as the lines of the parameter plane
    /// they are; an oblique circle does not.
    #[test]
    fn isoparametric_circles_invert_to_their_lines() {
        let a = torus();
        let Analytic::Torus { frame: f, .. } = &a else {
            unreachable!()
        };
        let (u, v): (f64, f64) = (0.7, -1.2);
        let radial = f.x * u.cos() + f.y * u.sin();
        let meridian =
            NurbsCurve::arc(f.origin + radial * 2.0, radial, f.z, 8.0, [v, 0.3]).unwrap();
        let [s, e] = isoparametric(&a, &meridian).unwrap();
        for (got, want) in [(s, [u, v]), (e, [u, 0.3])] {
            assert!((got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12);
        }
        let rho = 2.0 + 8.0 * v.cos();
        let parallel = NurbsCurve::arc(
            f.origin + f.z * (8.0 * v.sin()),
            f.x,
            f.y,
            rho,
            [u, u + 2.0],
        )
        .unwrap();
        let [s, e] = isoparametric(&a, &parallel).unwrap();
        assert!(
            (s[1] - v).abs() < 1e-12 && (e[1] - v).abs() < 1e-12,
            "{s:?} {e:?}"
        );
        assert!((e[0] - s[0] - 2.0).abs() < 1e-12);
        // A circle off the torus is refused as off it.
        let off = NurbsCurve::arc(f.origin, f.x, f.z, 5.0, [0.0, 1.0]).unwrap();
        assert_eq!(isoparametric(&a, &off), Err(Unmapped::Off));
    }

    /// The ellipse where the plane `z = x / 2` cuts a cylinder of radius 3 lies on it but
    /// is the curve `v = cos(u) 3 / 2` of its parameter plane: refused, not bent into a line.
    #[test]
    fn an_oblique_section_of_a_cylinder_is_refused() {
        let frame = brep_frame(Vec3::zeros(), Vec3::z(), Some(Vec3::x())).unwrap();
        let cylinder = Analytic::Cone {
            frame,
            radius: 3.0,
            semi_angle: 0.0,
            offset: 0.0,
            slant: false,
        };
        let squash = Mat3::new(3.0, 0.0, 0.0, 0.0, 3.0, 0.0, 1.5, 0.0, 0.0);
        let ellipse = NurbsCurve::arc(Vec3::zeros(), Vec3::x(), Vec3::y(), 1.0, [0.2, 1.4])
            .unwrap()
            .transformed(&squash, &Vec3::zeros());
        let x = ellipse.point(0.8);
        assert!((x.x.hypot(x.y) - 3.0).abs() < 1e-12 && (x.z - x.x / 2.0).abs() < 1e-12);
        assert_eq!(isoparametric(&cylinder, &ellipse), Err(Unmapped::Curved));
    }
}
