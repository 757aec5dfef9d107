//! A tool's display surface for a VTK frame: its exact Bezier patches sampled on a grid and
//! placed at the tool's pose. For viewing only; contact always uses the exact patches.
//!
//! Each patch of degree (p, q) is sampled at `(s_u + 1) x (s_v + 1)` parameter points, with
//! `s = 1` along a straight (degree-1) direction and [`SAMPLES_CURVED`] along a curved one,
//! giving `s_u s_v` quadrilaterals; patches do not share points (seams are duplicated).
//! Cost: O(patches x samples x (p + 1)(q + 1)). A tool that is not a patch surface (plane,
//! cylinder, sphere: unbounded or analytic) has no display surface.

use super::{Field, Frame};
use crate::geometry::{BezierPatch, Vec3};
use crate::tool::{Pose, Tool};

/// Quadrilaterals along a curved patch direction: a 90 degree arc in 8 chords of 11.25
/// degrees, within 0.5 % of the radius.
pub const SAMPLES_CURVED: usize = 8;

/// The display surface of `tool` at `pose`, with the point field `normal` (the outward unit
/// normal of the exact patch at each sample, for smooth shading); `None` when the tool's
/// surface is not made of patches.
pub fn tool_frame(tool: &Tool, pose: &Pose) -> Option<Frame> {
    let surface = tool.surface.as_patch_surface()?;
    let mut frame = Frame::default();
    let mut normals: Vec<[f64; 3]> = Vec::new();
    for patch in surface.patches() {
        add_patch(&mut frame, &mut normals, patch, pose);
    }
    frame.point_data.push(Field::vector("normal", &normals));
    Some(frame)
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
    let (su, sv) = (samples(p), samples(q));
    let first = frame.points.len();
    for i in 0..=su {
        for j in 0..=sv {
            let (u, v) = (i as f64 / su as f64, j as f64 / sv as f64);
            let e = patch.evaluate(u, v);
            let x = pose.to_global_point(&e.point);
            let n = patch
                .normal(&e)
                .map_or(Vec3::zeros(), |n| pose.to_global_vector(&n));
            frame.points.push([x.x, x.y, x.z]);
            normals.push([n.x, n.y, n.z]);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PatchSurface;
    use std::sync::Arc;

    /// A flat square gives one quad whose corners are the exact patch's moved by the pose;
    /// an analytic plane has no display surface.
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
        let f = tool_frame(&tool, &pose).unwrap();
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
        let plane = Tool::new(
            "plane",
            Arc::new(crate::geometry::Plane::new(Vec3::zeros(), Vec3::new(0.0, 0.0, 1.0)).unwrap()),
        );
        assert!(tool_frame(&plane, &pose).is_none());
    }
}
