//! A tool's surface worn by its accumulated Archard wear depth (issue 53): the exact rigid
//! surface offset inwards, along its outward normal, by a depth that is constant on each
//! cell of the tool-side field grid.
//!
//! Mathematics. Wear removes tool material, so the worn surface is
//!
//! ```text
//! S_w(u, v) = S(u, v) - h(u, v) n(u, v)
//! ```
//!
//! with `n` the tool's outward normal and `h` the wear depth. `h` is taken PIECEWISE
//! CONSTANT: on cell `c` of the grid (`field_grid.rs`) it is the wear depth accumulated
//! in that cell, `h_c`. On one cell the worn surface is then an exact parallel (offset)
//! surface of the exact tool surface, and for a point `x` outside the tool with
//! closest point `p = S(u, v)` on the exact surface, signed distance `d = n.(x - p)`:
//!
//! ```text
//! foot_w = p - h_c n,   n_w = n,   d_w = d + h_c,   G_w = dn/dx = G
//! ```
//!
//! (the closest point of an offset surface lies on the same normal line, as long as
//! `h_c` is smaller than the tool's smallest concave radius of curvature — wear depths are
//! micrometres, tool radii millimetres). The foot's parameters `(u, v)` and the normal are
//! those of the exact surface, so warm starts, the cell a foot lies in and the normal
//! gradient are unchanged, and the contact operator's consistent Jacobian
//! (`contact::operator`, `dd/dx = n^T`) stays exact inside a cell: `h` has zero
//! derivative almost everywhere, and no `dh/du` term exists. Across a cell edge the gap
//! jumps by the difference of the two cells' depths (the cells resolve the contact spots,
//! so those jumps are what the wear map is made of).
//!
//! When the depths are set is the strokes' business (`solver::simulation::strokes`):
//! between strokes only, so that `h` is a constant of every stroke.
//!
//! Cost: one cell lookup and a scaled vector per projection.

use super::field_grid::PatchGrid;
use super::surface_fields::ToolFields;
use crate::geometry::Projection;

/// The wear depth per cell that offsets a tool's surface.
#[derive(Clone, Debug)]
pub struct WornSurface {
    grids: Vec<PatchGrid>,
    offsets: Vec<usize>,
    /// Wear depth per cell (length), patches one after another as in `ToolFields`.
    depth: Vec<f64>,
}

impl WornSurface {
    /// The surface worn by `depth` (one value per cell of `fields`' grids).
    pub fn new(fields: &ToolFields, depth: Vec<f64>) -> WornSurface {
        debug_assert_eq!(depth.len(), fields.len());
        WornSurface {
            grids: fields.grids.clone(),
            offsets: fields.offsets.clone(),
            depth,
        }
    }

    /// The wear depth per cell.
    pub fn depth(&self) -> &[f64] {
        &self.depth
    }

    /// The depth of the cell holding the foot of `proj` (0 off the grids).
    pub fn depth_at(&self, proj: &Projection) -> f64 {
        let h = &proj.hint;
        match self.grids.get(h.patch) {
            Some(grid) => self.depth[self.offsets[h.patch] + grid.cell_of([h.u, h.v])],
            None => 0.0,
        }
    }

    /// The projection on the worn surface from the projection on the exact one.
    pub fn apply(&self, mut proj: Projection) -> Projection {
        let h = self.depth_at(&proj);
        proj.gap += h;
        proj.foot -= proj.normal * h;
        proj
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{BezierPatch, PatchSurface, RigidSurface, Vec3};
    use crate::tool::WearLaw;

    fn worn(surface: &PatchSurface, depth: impl Fn(usize) -> f64) -> WornSurface {
        let law = WearLaw::archard(1e-4, 1000.0).unwrap();
        let fields = ToolFields::new("t", surface, law, 0.5).unwrap();
        WornSurface::new(&fields, (0..fields.len()).map(depth).collect())
    }

    #[test]
    fn a_cylinder_worn_by_h_moves_every_foot_in_by_h_along_the_same_normal() {
        // Quarter cylinder, radius 5, axis y; a depth different in every cell.
        let patch = BezierPatch::cylinder_patch(
            Vec3::zeros(),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            -0.7,
            1.4,
            5.0,
            2.0,
        )
        .unwrap();
        let surface = PatchSurface::new(vec![patch]).unwrap();
        let w = worn(&surface, |c| 1e-3 * (1.0 + c as f64));
        let mut seen = std::collections::HashSet::new();
        for k in 0..200 {
            let a = -0.6 + 1.2 * (k as f64 * 0.618).fract();
            let y = 0.1 + 1.8 * (k as f64 * 0.377).fract();
            let r = 5.0 + 0.3 * (k as f64 * 0.271).fract();
            let x = Vec3::new(r * a.sin(), y, r * a.cos());
            let exact = surface.project(&x, None).unwrap();
            let h = w.depth_at(&exact);
            seen.insert(h.to_bits());
            let p = w.apply(exact);
            // The worn cylinder of that cell has radius 5 - h: the gap is |x| - (5 - h)
            // in the plane normal to the axis, the foot on radius 5 - h.
            let radial = (x[0] * x[0] + x[2] * x[2]).sqrt();
            assert!((p.gap - (radial - (5.0 - h))).abs() < 1e-10, "{k}");
            let foot_r = (p.foot[0].powi(2) + p.foot[2].powi(2)).sqrt();
            assert!((foot_r - (5.0 - h)).abs() < 1e-10, "{k}");
            assert_eq!(p.normal, exact.normal);
            assert_eq!(p.normal_gradient, exact.normal_gradient);
        }
        // The points fell in many cells, so the per-cell lookup was exercised.
        assert!(seen.len() > 10, "{}", seen.len());
    }
}
