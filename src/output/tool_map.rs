//! A tool's tool-side field (src/tool/surface_fields.rs) seen from above: a colour map drawn
//! by [`FieldMap`] (the sheet's field maps' drawing), with its own CSV of the drawn blocks.
//!
//! Mathematics. Each patch's grid of `nu x nv` cells is drawn in blocks of `b x b` cells
//! (`b = ceil(sqrt(cells / MAX_BLOCKS))`, 1 for grids of up to [`MAX_BLOCKS`] cells, the
//! last block of a row or column narrower), so the SVG stays well under 200 kB whatever the
//! grid. A block is the quadrilateral of its four parameter corners, evaluated exactly on
//! the patch, placed at the tool's pose and seen along -z (x right, y up). Its value is the
//! largest of its cells' (wear depth, work per area, pressure: the map shows the worst
//! spot, so the CSV's maximum is the field's maximum, summary.json's `max_wear_depth` for
//! `tool_wear_depth`). A block whose cells were never touched (no work, no pressure) has no
//! value and is drawn grey, which outlines the tool around the contact zone. The block's
//! four corners are its own points carrying its value, so the map's bilinear fill is
//! constant in the block.
//!
//! CSV: `patch,i,j,x,y,value`: the block's first cell `(i, j)` in the patch's grid, the
//! seen-from-above position of its centre, its value (empty for none).

use super::field_map::FieldMap;
use super::svg::write_pair;
use crate::geometry::PatchSurface;
use crate::tool::{Pose, ToolFields};
use crate::{Error, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Blocks per map at most (up to about 95 bytes of SVG path each, measured on the square
/// cup's die, so under 150 kB).
pub const MAX_BLOCKS: usize = 1_500;

/// The field names (those of the tool's VTU frames, docs/fields.md).
pub const FIELDS: [&str; 5] = [
    "tool_wear_depth",
    "tool_work_per_area",
    "tool_sliding_distance",
    "tool_peak_pressure",
    "tool_pressure_time",
];

/// One drawn block: where its first cell is, its centre seen from above, its value.
struct Block {
    patch: usize,
    cell: [usize; 2],
    centre: [f64; 2],
    value: f64,
}

/// A tool's field map and the CSV of its blocks.
pub struct ToolMap {
    pub map: FieldMap,
    blocks: Vec<Block>,
}

/// The cell values of field `name` of `fields`, or an error listing the known names.
fn values<'a>(fields: &'a ToolFields, tool: &str, name: &str) -> Result<&'a [f64]> {
    let v = &fields.values;
    Ok(match name {
        "tool_wear_depth" => &v.wear,
        "tool_work_per_area" => &v.work,
        "tool_sliding_distance" => &v.slip,
        "tool_peak_pressure" => &v.peak_pressure,
        "tool_pressure_time" => &v.pressure_time,
        _ => {
            return Err(Error::Input(format!(
                "tool '{tool}' has no tool-side field '{name}' (fields: {})",
                FIELDS.join(", ")
            )))
        }
    })
}

impl ToolMap {
    /// The map of field `name` of tool `tool`'s `fields` on `surface` at `pose` (module
    /// doc), titled with the time `t`.
    pub fn new(
        tool: &str,
        surface: &PatchSurface,
        fields: &ToolFields,
        pose: &Pose,
        name: &str,
        t: f64,
    ) -> Result<ToolMap> {
        let cell_values = values(fields, tool, name)?;
        let v = &fields.values;
        let b = ((fields.len() as f64 / MAX_BLOCKS as f64).sqrt().ceil() as usize).max(1);
        let mut map = FieldMap {
            title: format!("{name} on {tool}, t = {}", super::significant(t, 6)),
            label: name.to_string(),
            ..FieldMap::default()
        };
        let mut blocks = Vec::new();
        let mut first = 0;
        for (k, (patch, grid)) in surface.patches().iter().zip(&fields.grids).enumerate() {
            let (nu, nv) = (grid.nu, grid.nv);
            let seen = |u: f64, w: f64| {
                let x = pose.to_global_point(&patch.point(u, w));
                [x.x, x.y]
            };
            for i0 in (0..nu).step_by(b) {
                for j0 in (0..nv).step_by(b) {
                    let (i1, j1) = ((i0 + b).min(nu), (j0 + b).min(nv));
                    let (mut value, mut touched) = (0.0f64, false);
                    for i in i0..i1 {
                        for j in j0..j1 {
                            let c = first + i * nv + j;
                            value = value.max(cell_values[c]);
                            touched |= v.work[c] > 0.0 || v.peak_pressure[c] > 0.0;
                        }
                    }
                    let value = if touched { value } else { f64::NAN };
                    let (u0, u1) = (i0 as f64 / nu as f64, i1 as f64 / nu as f64);
                    let (w0, w1) = (j0 as f64 / nv as f64, j1 as f64 / nv as f64);
                    let n = map.points.len();
                    map.points
                        .extend([seen(u0, w0), seen(u1, w0), seen(u1, w1), seen(u0, w1)]);
                    map.values.extend([value; 4]);
                    map.quads.push([n, n + 1, n + 2, n + 3]);
                    blocks.push(Block {
                        patch: k,
                        cell: [i0, j0],
                        centre: seen(0.5 * (u0 + u1), 0.5 * (w0 + w1)),
                        value,
                    });
                }
            }
            first += grid.len();
        }
        Ok(ToolMap { map, blocks })
    }

    /// The blocks as CSV (module doc).
    pub fn to_csv(&self) -> String {
        let mut out = String::from("patch,i,j,x,y,value\n");
        for b in &self.blocks {
            let value = if b.value.is_finite() {
                super::fmt_f64(b.value)
            } else {
                String::new()
            };
            let _ = writeln!(
                out,
                "{},{},{},{},{},{value}",
                b.patch,
                b.cell[0],
                b.cell[1],
                super::fmt_f64(b.centre[0]),
                super::fmt_f64(b.centre[1]),
            );
        }
        out
    }

    /// Writes `path` (the SVG) and the CSV beside it; returns the CSV's path.
    pub fn write(&self, path: &Path) -> Result<PathBuf> {
        write_pair(path, &self.map.to_svg()?, &self.to_csv())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{BezierPatch, Vec3};
    use crate::tool::WearLaw;

    /// A 2 x 1 flat patch with cells of 0.5 (8 cells, one block each): the touched cell's
    /// value on its block at the pose, the others grey, an unknown field named.
    #[test]
    fn blocks_carry_the_cells_values_at_the_pose() {
        let patch = BezierPatch::parallelogram(
            Vec3::zeros(),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        )
        .unwrap();
        let surface = PatchSurface::new(vec![patch]).unwrap();
        let mut fields =
            ToolFields::new("die", &surface, WearLaw::archard(1e-3, 1e3).unwrap(), 0.5).unwrap();
        fields.values.wear[5] = 2e-6;
        fields.values.work[5] = 1.0;
        let pose = Pose::from_translation(Vec3::new(10.0, 0.0, 3.0));
        let m = ToolMap::new("die", &surface, &fields, &pose, "tool_wear_depth", 1.0).unwrap();
        assert_eq!((m.map.quads.len(), m.blocks.len()), (8, 8));
        // Cell 5 = (i = 2, j = 1): [1, 1.5] x [0.5, 1] moved by 10 in x.
        assert_eq!(m.map.points[20], [11.0, 0.5]);
        assert_eq!(m.map.values[20..24], [2e-6; 4]);
        assert!(m.map.values[..20].iter().all(|v| v.is_nan()));
        let csv = m.to_csv();
        assert!(csv.contains("\n0,2,1,11.25,0.75,2e-6\n"), "{csv}");
        let err = ToolMap::new("die", &surface, &fields, &pose, "wear", 1.0)
            .err()
            .unwrap();
        assert!(err.to_string().contains("'wear'"), "{err}");
    }
}
