//! A tool's tool-side fields (src/tool/surface_fields.rs) as output: its VTU frame and its
//! entry of summary.json.
//!
//! The frame is the tool's display surface drawn on the field grid itself: each patch is
//! sampled at the grid's `(nu + 1) x (nv + 1)` parameter nodes, exactly on the surface and
//! placed at the tool's pose, and each cell is one quadrilateral carrying the cell's values
//! as cell data (`tool_work_per_area`, `tool_sliding_distance`, `tool_peak_pressure`,
//! `tool_pressure_time`, `tool_wear_depth`; docs/fields.md). Points are not shared between
//! patches (seams are duplicated), as in `tool_frame.rs`.
//!
//! A tool worn by a geometry update of the strokes (`tool::worn`: the contact sees
//! `S - h_C n` on cell `C`, `h_C` the wear depth applied to the cell) is drawn worn: each
//! cell gets its own four corners, the grid nodes `S` moved by `-h_C n` (`n` the exact
//! surface's unit normal there), so the frame shows the surface the contact measures the
//! gap to. The depth is constant per cell, so neighbouring cells of different depths leave
//! steps at their common edge (the wear map's own resolution); the normals drawn are the
//! exact surface's, which are the worn one's. Without an applied update the frame is the
//! exact surface with shared grid nodes, as before.
//!
//! The samples (one patch evaluation per grid node) are the costly part of a frame and the
//! surface does not change during a run, so they are taken once, in the tool's own frame
//! ([`GridSamples`]), and each frame only places them at the pose: the same floating-point
//! operations as sampling at every frame, so the same points bit for bit.
//!
//! The summary gives the tool-side frictional work `Σ_C |C| w_C`, the largest wear depth
//! and the largest peak pressure with where they are: the centre of the cell, in the tool's
//! own frame (the surface's coordinates, which do not move with the stroke).

use super::{Field, Frame};
use crate::geometry::{PatchSurface, Vec3};
use crate::tool::{Pose, ToolFields};

/// A tool's field-grid nodes sampled in its own frame (module doc): per patch the
/// `(nu + 1) x (nv + 1)` points `S(i / nu, j / nv)`, node `(i, j)` the `i (nv + 1) + j`-th,
/// and their unit normals (`None` where the normal is undefined).
#[derive(Clone, Debug)]
pub struct GridSamples {
    /// Per patch: `(nu, nv, index of its first node)`.
    patches: Vec<(usize, usize, usize)>,
    points: Vec<Vec3>,
    normals: Vec<Option<Vec3>>,
}

impl GridSamples {
    /// The nodes of `fields`' grids on `surface`'s patches.
    pub fn new(surface: &PatchSurface, fields: &ToolFields) -> GridSamples {
        let mut samples = GridSamples {
            patches: Vec::new(),
            points: Vec::new(),
            normals: Vec::new(),
        };
        for (patch, grid) in surface.patches().iter().zip(&fields.grids) {
            let (nu, nv) = (grid.nu, grid.nv);
            samples.patches.push((nu, nv, samples.points.len()));
            for i in 0..=nu {
                for j in 0..=nv {
                    let e = patch.evaluate(i as f64 / nu as f64, j as f64 / nv as f64);
                    samples.points.push(e.point);
                    samples.normals.push(patch.normal(&e));
                }
            }
        }
        samples
    }

    /// True if these are the nodes of `fields`' grids (same patches, same cells).
    pub fn fits(&self, fields: &ToolFields) -> bool {
        self.patches.len() == fields.grids.len()
            && (self.patches.iter().zip(&fields.grids)).all(|(p, g)| (p.0, p.1) == (g.nu, g.nv))
    }
}

/// The VTU frame of `fields` on `surface`'s exact patches at `pose` (module doc), sampled
/// afresh (the run keeps its samples: [`frame_on`]).
#[cfg(test)]
pub fn frame(surface: &PatchSurface, fields: &ToolFields, pose: &Pose) -> Frame {
    frame_on(&GridSamples::new(surface, fields), fields, pose, None)
}

/// The VTU frame of `fields` on the grid nodes `samples` at `pose` (module doc): the exact
/// surface, or with `worn` (the wear depth per cell applied to the tool's geometry, in the
/// flat order of `fields`' values) the worn one.
pub fn frame_on(
    samples: &GridSamples,
    fields: &ToolFields,
    pose: &Pose,
    worn: Option<&[f64]>,
) -> Frame {
    debug_assert!(samples.fits(fields));
    let mut frame = Frame::default();
    let mut normals: Vec<[f64; 3]> = Vec::new();
    // The node `node` moved by `-h n` and placed at the pose, with its normal.
    let mut push = |frame: &mut Frame, node: usize, h: f64| {
        let n = samples.normals[node];
        let mut x = samples.points[node];
        if let (Some(n), true) = (n, h != 0.0) {
            x -= n * h;
        }
        let x = pose.to_global_point(&x);
        let n = n.map_or(Vec3::zeros(), |n| pose.to_global_vector(&n));
        frame.points.push([x.x, x.y, x.z]);
        normals.push([n.x, n.y, n.z]);
    };
    for (k, &(nu, nv, first_node)) in samples.patches.iter().enumerate() {
        let node = |i: usize, j: usize| first_node + i * (nv + 1) + j;
        match worn {
            None => {
                let first = frame.points.len();
                for i in 0..=nu {
                    for j in 0..=nv {
                        push(&mut frame, node(i, j), 0.0);
                    }
                }
                let id = |i: usize, j: usize| first + i * (nv + 1) + j;
                for i in 0..nu {
                    for j in 0..nv {
                        (frame.quads).push([
                            id(i, j),
                            id(i + 1, j),
                            id(i + 1, j + 1),
                            id(i, j + 1),
                        ]);
                    }
                }
            }
            Some(depth) => {
                // Each cell its own corners, all moved by the cell's depth (module doc).
                for i in 0..nu {
                    for j in 0..nv {
                        let h = depth[fields.offsets[k] + i * nv + j];
                        let corner = frame.points.len();
                        for (a, b) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                            push(&mut frame, node(i + a, j + b), h);
                        }
                        frame.quads.push(std::array::from_fn(|q| corner + q));
                    }
                }
            }
        }
    }
    frame.point_data.push(Field::vector("normal", &normals));
    let v = &fields.values;
    for (name, values) in [
        ("tool_work_per_area", &v.work),
        ("tool_sliding_distance", &v.slip),
        ("tool_peak_pressure", &v.peak_pressure),
        ("tool_pressure_time", &v.pressure_time),
        ("tool_wear_depth", &v.wear),
    ] {
        frame.cell_data.push(Field::scalar(name, values.clone()));
    }
    frame
}

/// summary.json's `tool_fields` entry of a tool (module doc).
pub fn summary(surface: &PatchSurface, fields: &ToolFields) -> serde_json::Value {
    let v = &fields.values;
    let largest = |values: &[f64]| {
        let (c, max) =
            values.iter().enumerate().fold(
                (0, 0.0),
                |best, (c, &x)| if x > best.1 { (c, x) } else { best },
            );
        let at = (max > 0.0).then(|| {
            let (patch, cell) = fields.locate(c);
            let grid = &fields.grids[patch];
            let [u, w] = grid.cell_centre(cell);
            let p = surface.patches()[patch].point(u, w);
            [p.x, p.y, p.z]
        });
        (max, at)
    };
    let (wear, wear_at) = largest(&v.wear);
    let (pressure, pressure_at) = largest(&v.peak_pressure);
    serde_json::json!({
        "wear_coefficient": fields.wear.coefficient,
        "cells": fields.len(),
        "total_work": fields.total_work(),
        "max_wear_depth": wear,
        "max_wear_at": wear_at,
        "peak_pressure": pressure,
        "peak_pressure_at": pressure_at,
        "max_sliding_distance": largest(&v.slip).0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::BezierPatch;
    use crate::geometry::Vec3;
    use crate::tool::WearLaw;

    /// A 2 x 1 flat patch with cells of 0.5: 4 x 2 quads at the pose, one value per cell
    /// per field, and the summary's maximum where the value was put.
    #[test]
    fn frame_and_summary_follow_the_grid() {
        let patch = BezierPatch::parallelogram(
            Vec3::zeros(),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        )
        .unwrap();
        let surface = PatchSurface::new(vec![patch.clone()]).unwrap();
        let mut fields =
            ToolFields::new("die", &surface, WearLaw::archard(1e-3, 1e3).unwrap(), 0.5).unwrap();
        fields.values.wear[5] = 2e-6;
        let pose = Pose::from_translation(Vec3::new(0.0, 0.0, 3.0));
        let f = frame(&surface, &fields, &pose);
        assert_eq!((f.points.len(), f.quads.len()), (15, 8));
        assert_eq!(f.cell_data.len(), 5);
        assert!(f.cell_data.iter().all(|d| d.values.len() == 8));
        let p = patch.point(1.0, 1.0) + Vec3::new(0.0, 0.0, 3.0);
        assert_eq!(Vec3::from(*f.points.last().unwrap()), p);
        f.validate().unwrap();
        let s = summary(&surface, &fields);
        assert_eq!(s["max_wear_depth"], 2e-6);
        // Cell 5 = (i = 2, j = 1): centre (1.25, 0.75) in the tool's frame.
        assert_eq!(s["max_wear_at"], serde_json::json!([1.25, 0.75, 0.0]));
        assert_eq!(s["peak_pressure_at"], serde_json::Value::Null);
    }
}

#[cfg(test)]
mod worn_tests {
    use super::*;
    use crate::geometry::{BezierPatch, RigidSurface};
    use crate::tool::WearLaw;

    /// Two quarter-cylinder patches (radius 5, axis y) with cells of 0.5, a pose turning
    /// and moving the tool.
    fn roller() -> (PatchSurface, ToolFields, Pose) {
        let patches = (0..2)
            .map(|k| {
                BezierPatch::cylinder_patch(
                    Vec3::zeros(),
                    Vec3::new(0.0, 1.0, 0.0),
                    Vec3::new(0.0, 0.0, 1.0),
                    -0.7 + 0.7 * k as f64,
                    0.7,
                    5.0,
                    2.0,
                )
                .unwrap()
            })
            .collect();
        let surface = PatchSurface::new(patches).unwrap();
        let law = WearLaw::archard(1e-4, 1000.0).unwrap();
        let fields = ToolFields::new("roller", &surface, law, 0.5).unwrap();
        let pose = Pose::about_axis(
            &Vec3::new(1.0, 0.0, 0.0),
            &Vec3::new(0.3, 1.0, 0.2),
            0.6,
            &Vec3::new(0.5, -2.0, 3.0),
        );
        (surface, fields, pose)
    }

    /// Without an applied wear the frame is the exact surface sampled as every tool frame
    /// is (`tool_frame::add_patch_grid`, the frames' sampling before the samples were kept):
    /// the same points, normals and quads bit for bit.
    #[test]
    fn an_unworn_frame_is_the_exact_grid_bit_for_bit() {
        let (surface, fields, pose) = roller();
        let f = frame_on(&GridSamples::new(&surface, &fields), &fields, &pose, None);
        let mut exact = Frame::default();
        let mut normals = Vec::new();
        for (patch, grid) in surface.patches().iter().zip(&fields.grids) {
            let (nu, nv) = (grid.nu, grid.nv);
            super::super::tool_frame::add_patch_grid(
                &mut exact,
                &mut normals,
                patch,
                &pose,
                nu,
                nv,
            );
        }
        assert_eq!(f.points, exact.points);
        assert_eq!(f.quads, exact.quads);
        assert_eq!(
            f.point_data[0].values,
            Field::vector("normal", &normals).values
        );
        assert_eq!(f.quads.len(), fields.len());
    }

    /// A roller worn by a depth different in every cell: every corner of every quad lies at
    /// the depth of the quad's cell inside the exact roller (distance to the exact surface,
    /// by its closest-point projection, to 1e-10: the projection converges to round-off of
    /// the radius 5, and the depths are 1e-3 to 1e-1, far above it), the normal is the
    /// exact one, and the cell data keep their order.
    #[test]
    fn a_worn_frame_draws_each_cell_moved_in_by_its_depth() {
        let (surface, mut fields, pose) = roller();
        let depth: Vec<f64> = (0..fields.len())
            .map(|c| 1e-3 * (1.0 + (c % 97) as f64))
            .collect();
        fields.values.wear = depth.iter().map(|h| 2.0 * h).collect();
        let samples = GridSamples::new(&surface, &fields);
        let f = frame_on(&samples, &fields, &pose, Some(&depth));
        f.validate().unwrap();
        assert_eq!(f.quads.len(), fields.len());
        assert_eq!(f.points.len(), 4 * fields.len());
        assert_eq!(f.cell_data[4].values, fields.values.wear);
        let normals = &f.point_data[0].values;
        for (c, quad) in f.quads.iter().enumerate() {
            for &p in quad {
                let local = pose.to_local(&Vec3::from(f.points[p]));
                let proj = surface.project(&local, None).unwrap();
                assert!(
                    (proj.gap + depth[c]).abs() < 1e-10,
                    "cell {c}: gap {:e}, depth {:e}",
                    proj.gap,
                    depth[c]
                );
                let radial = (local.x * local.x + local.z * local.z).sqrt();
                assert!((radial - (5.0 - depth[c])).abs() < 1e-10, "cell {c}");
                let n = Vec3::new(normals[3 * p], normals[3 * p + 1], normals[3 * p + 2]);
                assert!(
                    (n - pose.to_global_vector(&proj.normal)).norm() < 1e-12,
                    "cell {c}"
                );
            }
        }
        // Neighbouring cells of different depths: the shared grid node is drawn twice, a
        // step of the depths' difference apart.
        let (a, b) = (f.quads[0][1], f.quads[fields.grids[0].nv][0]);
        let step = (Vec3::from(f.points[a]) - Vec3::from(f.points[b])).norm();
        let expected = (depth[0] - depth[fields.grids[0].nv]).abs();
        assert!(
            expected > 0.0 && (step - expected).abs() < 1e-12,
            "{step} {expected}"
        );
    }
}
