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
//! The summary gives the tool-side frictional work `Σ_C |C| w_C`, the largest wear depth
//! and the largest peak pressure with where they are: the centre of the cell, in the tool's
//! own frame (the surface's coordinates, which do not move with the stroke).

use super::{Field, Frame};
use crate::geometry::PatchSurface;
use crate::tool::{Pose, ToolFields};

/// The VTU frame of `fields` on `surface`'s patches at `pose` (module doc).
pub fn frame(surface: &PatchSurface, fields: &ToolFields, pose: &Pose) -> Frame {
    let mut frame = Frame::default();
    let mut normals: Vec<[f64; 3]> = Vec::new();
    for (patch, grid) in surface.patches().iter().zip(&fields.grids) {
        super::tool_frame::add_patch_grid(&mut frame, &mut normals, patch, pose, grid.nu, grid.nv);
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
