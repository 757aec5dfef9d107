//! A tool's display surface for a VTK frame: its exact Bezier patches sampled on a grid and
//! placed at the tool's pose. For viewing only; contact always uses the exact surfaces.
//!
//! Each patch of degree (p, q) is sampled at `(s_u + 1) x (s_v + 1)` parameter points, with
//! `s = 1` along a straight (degree-1) direction and [`SAMPLES_CURVED`] along a curved one,
//! giving `s_u s_v` quadrilaterals; patches do not share points (seams are duplicated).
//! Cost: O(patches x samples x (p + 1)(q + 1)).
//!
//! An analytic tool is shown through exact patches of its surface
//! ([`crate::geometry::analytic_nurbs`]): a sphere whole (a half circle revolved, but for
//! holes of `1e-4 R` at its poles); a plane as the square of half side `half` about the foot of `centre`, and a
//! cylinder as its length `2 half` about the foot of `centre` on the axis, where
//! [`DisplayRegion`] is the blank's reference box (fixed, so that the display moves only
//! with the tool's pose).

use super::trim_tessellation::{self, Cover};
use super::{Field, Frame};
use crate::geometry::analytic_nurbs::{revolution, NurbsCurve};
use crate::geometry::trim::PieceTrim;
use crate::geometry::{AnalyticShape, BezierPatch, Vec3};
use crate::tool::{Pose, Tool};

/// Quadrilaterals along a curved patch direction: a 90 degree arc in 8 chords of 11.25
/// degrees, within 0.5 % of the radius.
pub const SAMPLES_CURVED: usize = 8;

/// Default chord tolerance of drawn trimming curves, relative to the size (bounding-box
/// diagonal) of the patch they cut: 0.25 mm on the 180 mm die's top face.
pub const TRIM_TOLERANCE: f64 = 1e-3;

/// Angle (rad) by which a sphere's display stops short of its poles.
const POLE_GAP: f64 = 1e-4;

/// Where an unbounded tool is shown (in the tool's own frame): about `centre`, `half` on
/// each side.
#[derive(Debug, Clone, Copy)]
pub struct DisplayRegion {
    pub centre: Vec3,
    pub half: f64,
}

impl DisplayRegion {
    /// The box of `points` (the blank's reference nodes): its centre and half diagonal.
    pub fn around(points: &[Vec3]) -> DisplayRegion {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for p in points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        if points.is_empty() {
            return DisplayRegion {
                centre: Vec3::zeros(),
                half: 1.0,
            };
        }
        DisplayRegion {
            centre: (lo + hi) * 0.5,
            half: (0.5 * (hi - lo).norm()).max(1e-3),
        }
    }
}

/// The display surface of `tool` at `pose`, with the point field `normal` (the outward unit
/// normal of the exact surface at each sample, for smooth shading); `None` for a surface
/// that is neither patches nor analytic. A trimmed patch is drawn within its trims with
/// boundary chords within `trim_tolerance` (a length; `None`: [`TRIM_TOLERANCE`] of the
/// patch's size) of its trimming curves.
pub fn tool_frame(
    tool: &Tool,
    pose: &Pose,
    region: &DisplayRegion,
    trim_tolerance: Option<f64>,
) -> Option<Frame> {
    let analytic;
    let (patches, trims): (&[BezierPatch], &[Option<PieceTrim>]) =
        match tool.surface.as_patch_surface() {
            Some(surface) => (surface.patches(), surface.trims()),
            None => {
                analytic = analytic_patches(&tool.surface.analytic_shape()?, region);
                (&analytic, &[])
            }
        };
    let mut frame = Frame::default();
    let mut normals: Vec<[f64; 3]> = Vec::new();
    for (k, patch) in patches.iter().enumerate() {
        match trims.get(k).and_then(Option::as_ref) {
            None => add_patch(&mut frame, &mut normals, patch, pose),
            Some(trim) => {
                add_trimmed_patch(&mut frame, &mut normals, patch, trim, pose, trim_tolerance)
            }
        }
    }
    frame.point_data.push(Field::vector("normal", &normals));
    Some(frame)
}

/// Appends the part of `patch` on its trimmed face (see [`super::trim_tessellation`]): the
/// whole grid where no trimming curve enters the patch, nothing where the patch is off the
/// face, else triangles.
fn add_trimmed_patch(
    frame: &mut Frame,
    normals: &mut Vec<[f64; 3]>,
    patch: &BezierPatch,
    trim: &PieceTrim,
    pose: &Pose,
    tolerance: Option<f64>,
) {
    let (p, q) = patch.degrees();
    let (su, sv) = (samples(p), samples(q));
    let tolerance = tolerance.unwrap_or_else(|| {
        let (lo, hi) = patch.bounding_box();
        TRIM_TOLERANCE * (hi - lo).norm()
    });
    match trim_tessellation::cover(patch, trim, su, sv, tolerance) {
        Cover::Whole => add_patch_grid(frame, normals, patch, pose, su, sv),
        Cover::Empty => {}
        Cover::Triangles { points, triangles } => {
            let first = frame.points.len();
            for [s, t] in points {
                push_sample(frame, normals, patch, pose, s, t);
            }
            (frame.triangles).extend(triangles.iter().map(|c| c.map(|i| first + i)));
        }
    }
}

/// Exact patches of an analytic surface's displayed part (see the module docs), normals
/// outward.
fn analytic_patches(shape: &AnalyticShape, region: &DisplayRegion) -> Vec<BezierPatch> {
    let (c, h) = (region.centre, region.half);
    // A unit vector across `n` (the axis least aligned with it, made orthogonal).
    let across = |n: &Vec3| {
        let k = n.iamin();
        let mut e = Vec3::zeros();
        e[k] = 1.0;
        (e - n * n.dot(&e)).normalize()
    };
    let revolved = |generatrix: NurbsCurve, origin: Vec3, axis: Vec3| {
        revolution(&generatrix, origin, axis, [0.0, std::f64::consts::TAU])
            .and_then(|(s, _)| s.to_bezier())
            .map(|pieces| pieces.into_iter().map(|p| p.patch).collect())
            .unwrap_or_default()
    };
    match *shape {
        AnalyticShape::Plane { point, normal } => {
            let foot = c - normal * normal.dot(&(c - point));
            let e1 = across(&normal);
            let e2 = normal.cross(&e1);
            BezierPatch::parallelogram(foot - (e1 + e2) * h, e1 * (2.0 * h), e2 * (2.0 * h))
                .into_iter()
                .collect()
        }
        AnalyticShape::Cylinder {
            axis_point,
            axis,
            radius,
        } => {
            let foot = axis_point + axis * axis.dot(&(c - axis_point));
            let side = across(&axis) * radius;
            // Down the axis, so that S_t x S_angle points away from it.
            let line = NurbsCurve::line(foot + axis * h + side, foot - axis * h + side);
            revolved(line, foot, axis)
        }
        AnalyticShape::Sphere { centre, radius } => {
            // From the north pole to the south one in the plane of (x, z), stopping
            // POLE_GAP short of each pole: a collapsed row would be refused by the fold
            // check, and a hole of 1e-4 R is not seen.
            let end = std::f64::consts::FRAC_PI_2 - POLE_GAP;
            let arc = NurbsCurve::arc(centre, Vec3::x(), -Vec3::z(), radius, [-end, end]);
            arc.map(|a| revolved(a, centre, Vec3::z()))
                .unwrap_or_default()
        }
    }
}

fn samples(degree: usize) -> usize {
    if degree <= 1 {
        1
    } else {
        SAMPLES_CURVED
    }
}

fn add_patch(frame: &mut Frame, normals: &mut Vec<[f64; 3]>, patch: &BezierPatch, pose: &Pose) {
    let (p, q) = patch.degrees();
    add_patch_grid(frame, normals, patch, pose, samples(p), samples(q));
}

/// Appends `patch` at `pose` sampled at the `(su + 1) x (sv + 1)` parameter nodes
/// `(i / su, j / sv)`: the points, their unit normals (zero where the normal is undefined)
/// and the `su x sv` quadrilaterals between them, cell `(i, j)` the `i * sv + j`-th.
pub(super) fn add_patch_grid(
    frame: &mut Frame,
    normals: &mut Vec<[f64; 3]>,
    patch: &BezierPatch,
    pose: &Pose,
    su: usize,
    sv: usize,
) {
    let first = frame.points.len();
    for i in 0..=su {
        for j in 0..=sv {
            push_sample(
                frame,
                normals,
                patch,
                pose,
                i as f64 / su as f64,
                j as f64 / sv as f64,
            );
        }
    }
    let id = |i: usize, j: usize| first + i * (sv + 1) + j;
    for i in 0..su {
        for j in 0..sv {
            frame
                .quads
                .push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
}

/// Appends the point of `patch` at `(u, v)` placed at `pose`, and its unit normal (zero
/// where the normal is undefined).
fn push_sample(
    frame: &mut Frame,
    normals: &mut Vec<[f64; 3]>,
    patch: &BezierPatch,
    pose: &Pose,
    u: f64,
    v: f64,
) {
    let e = patch.evaluate(u, v);
    let x = pose.to_global_point(&e.point);
    let n = patch
        .normal(&e)
        .map_or(Vec3::zeros(), |n| pose.to_global_vector(&n));
    frame.points.push([x.x, x.y, x.z]);
    normals.push([n.x, n.y, n.z]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PatchSurface;
    use std::sync::Arc;

    /// A flat square gives one quad whose corners are the exact patch's moved by the pose.
    #[test]
    fn patches_are_sampled_on_the_exact_surface_at_the_pose() {
        let flat = BezierPatch::parallelogram(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        )
        .unwrap();
        let surface = PatchSurface::new(vec![flat.clone()]).unwrap();
        let tool = Tool::new("flat", Arc::new(surface));
        let pose = Pose::about_axis(
            &Vec3::new(1.0, 0.0, 0.0),
            &Vec3::new(0.0, 0.0, 1.0),
            0.5,
            &Vec3::new(0.0, 0.0, -3.0),
        );
        let region = DisplayRegion::around(&[]);
        let f = tool_frame(&tool, &pose, &region, None).unwrap();
        assert_eq!((f.points.len(), f.quads.len()), (4, 1));
        for (k, (u, v)) in [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0)]
            .into_iter()
            .enumerate()
        {
            let exact = pose.to_global_point(&flat.point(u, v));
            let got = Vec3::from(f.points[k]);
            assert!((got - exact).norm() < 1e-14, "{got} vs {exact}");
        }
        f.validate().unwrap();
    }

    /// Plane, cylinder and sphere tools are shown by samples on their exact surface at the
    /// pose, with its outward normal, over the display region.
    #[test]
    fn analytic_tools_are_shown_on_their_exact_surface() {
        use crate::geometry::{Cylinder, Plane, RigidSurface, Sphere};
        let region = DisplayRegion::around(&[Vec3::new(0.0, 0.0, 0.0), Vec3::new(8.0, 6.0, 0.0)]);
        assert_eq!(
            (region.centre, region.half),
            (Vec3::new(4.0, 3.0, 0.0), 5.0)
        );
        let pose = Pose::about_axis(
            &Vec3::new(1.0, 0.0, 0.0),
            &Vec3::new(0.3, 0.0, 1.0),
            0.4,
            &Vec3::new(0.5, 0.0, -3.0),
        );
        let surfaces: Vec<Arc<dyn RigidSurface>> = vec![
            Arc::new(Plane::new(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 1.0, 1.0)).unwrap()),
            Arc::new(
                Cylinder::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 1.0, 0.0), 2.5).unwrap(),
            ),
            Arc::new(Sphere::new(Vec3::new(-1.0, 0.0, 4.0), 1.5).unwrap()),
        ];
        for surface in surfaces {
            let tool = Tool::new("analytic", surface.clone());
            let f = tool_frame(&tool, &pose, &region, None).unwrap();
            f.validate().unwrap();
            let normals = &f.point_data[0].values;
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for (k, x) in f.points.iter().enumerate() {
                let local = pose.to_local(&Vec3::from(*x));
                let p = surface.project(&local, None).unwrap();
                assert!(
                    p.gap.abs() < 1e-12,
                    "{}: {x:?} off by {}",
                    surface.describe(),
                    p.gap
                );
                let n = Vec3::new(normals[3 * k], normals[3 * k + 1], normals[3 * k + 2]);
                if n.norm() > 0.0 {
                    let exact = pose.to_global_vector(&p.normal);
                    // 1e-9: by the sphere's poles one tangent is 1e-4 times the other, which
                    // amplifies the round-off of their cross product.
                    assert!(
                        (n - exact).norm() < 1e-9,
                        "{}: {n} vs {exact}",
                        surface.describe()
                    );
                }
                let along = (local - region.centre).dot(&Vec3::y());
                lo = lo.min(along);
                hi = hi.max(along);
            }
            // Plane and cylinder: over the region's extent along y (the cylinder's axis).
            if surface.describe().starts_with("cylinder") {
                assert!(
                    (lo + 5.0).abs() < 1e-12 && (hi - 5.0).abs() < 1e-12,
                    "{lo} {hi}"
                );
            }
            assert!(!f.quads.is_empty() && hi > lo, "{}", surface.describe());
        }
    }
}
