//! Tool-side fields: frictional work per area, sliding distance, peak and time-integrated
//! contact pressure and Archard wear depth, accumulated on a grid of cells in each patch's
//! parameter square (`field_grid.rs`) after every converged increment.
//!
//! Mathematics (the transfer). In an increment each sheet contact node `k` brings
//!
//! - its frictional dissipation `W_k = f_T . delta_t` (the very term of the energy balance),
//! - its normal force `F_k = -lambda_n >= 0` and slip `s_k = |delta_t|`,
//! - so its Archard wear volume `V_k = c F_k s_k`, with `c = k / H` (dimensionless `k`,
//!   hardness `H`) or a dimensional coefficient `c` (mm^2/N).
//!
//! The node's quantities are spread uniformly over its footprint on the tool: the pieces
//! `P_kq` (its dual area on the sheet, quarter faces mapped to the tool's `(u, v)` by
//! closest-point projection, see the simulation's `tool_fields.rs`). With `a_kqC = ∫_{P_kq ∩
//! C} J_h` the physical overlap of piece `q` with cell `C` and `A_k = Σ_q,C a_kqC` the
//! footprint's area, cell `C` receives the fraction `a_kqC / A_k` of each quantity. The
//! fractions sum to 1, so the tool-side integrals `Σ_C |C| w_C` equal the sheet's sums
//! (work: the frictional dissipation) to round-off, whatever the grid. A piece that cannot
//! be mapped whole onto one patch (it straddles a seam or leaves a trimmed face) is a point
//! piece: its share (its area on the sheet) goes to the cell of the node's own foot point.
//!
//! Per increment, with `|C|` the cell's physical area:
//!
//! - pressure `p_C = Σ_k F_k a_kC / (A_k |C|)` (force per tool area: a uniform tool-side
//!   traction `F_k = p A_k` gives `p` in every fully covered cell);
//! - work per area `w_C += Σ_k W_k a_kC / (A_k |C|)`;
//! - wear depth `h_C += Σ_k c F_k s_k a_kC / (A_k |C|)`, which is `c p s` for uniform `p`
//!   and `s` in every fully covered cell (the footprints tile the cell);
//! - sliding distance `d_C += Σ_k s_k a_kC / |C|` (the slip averaged over the cell's area, a
//!   point not touched counting 0);
//! - peak pressure `max(peak_C, p_C)` and time-integrated pressure `P_C += p_C dt`.
//!
//! Only cells touched in an increment are visited, so the cost is proportional to the
//! contact zone, not to the grid.

use super::field_grid::PatchGrid;
use crate::geometry::PatchSurface;
use crate::{Error, Result};

/// Archard's wear law `dh = c p |ds|`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WearLaw {
    /// `c` (1 / pressure, mm^2/N): `k / H`, or a dimensional coefficient.
    pub coefficient: f64,
}

impl WearLaw {
    /// Dimensionless wear coefficient `k` and hardness `H` (pressure): `c = k / H`.
    pub fn archard(k: f64, hardness: f64) -> Result<WearLaw> {
        if !(k >= 0.0 && k.is_finite()) {
            return Err(Error::input(
                "Archard wear coefficient k",
                k,
                "must be >= 0 and finite",
            ));
        }
        if !(hardness > 0.0 && hardness.is_finite()) {
            return Err(Error::input(
                "Archard hardness H",
                hardness,
                "must be > 0 and finite",
            ));
        }
        Ok(WearLaw {
            coefficient: k / hardness,
        })
    }

    /// A dimensional wear coefficient `c` (mm^2/N, i.e. wear volume per force and length).
    pub fn dimensional(c: f64) -> Result<WearLaw> {
        if !(c >= 0.0 && c.is_finite()) {
            return Err(Error::input(
                "dimensional wear coefficient",
                c,
                "must be >= 0 and finite",
            ));
        }
        Ok(WearLaw { coefficient: c })
    }
}

/// What a tool's fields are asked for: the wear law and the cell size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldSpec {
    pub wear: WearLaw,
    /// Cell size (length); `None`: a third of the sheet's mean element size under the tool.
    pub cell: Option<f64>,
}

/// Most cells one tool's grid may have (each holds about 80 bytes).
pub const MAX_CELLS: usize = 2_000_000;

/// Most cells along one direction of one patch.
const MAX_PER_DIRECTION: usize = 2000;

/// The accumulated fields, one value per cell, patches one after another.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FieldValues {
    /// Frictional work per area (force x length / area).
    pub work: Vec<f64>,
    /// Sliding distance (length): the slip averaged over each cell.
    pub slip: Vec<f64>,
    /// Peak contact pressure over the increments.
    pub peak_pressure: Vec<f64>,
    /// Time-integrated contact pressure, `Σ p dt`.
    pub pressure_time: Vec<f64>,
    /// Archard wear depth (length).
    pub wear: Vec<f64>,
}

/// What one node brings to the tool in one increment.
#[derive(Clone, Copy, Debug, Default)]
pub struct NodeLoad {
    /// Frictional dissipation `f_T . delta_t`.
    pub work: f64,
    /// Normal force `-lambda_n` (>= 0).
    pub normal_force: f64,
    /// Slip length `|delta_t|`.
    pub slip: f64,
}

/// A part of a node's footprint.
#[derive(Clone, Debug)]
pub enum Piece {
    /// A polygon in patch `patch`'s parameter square.
    Polygon { patch: usize, uv: Vec<[f64; 2]> },
    /// A share of weight `area` given to the cell holding `uv` on `patch`.
    Point {
        patch: usize,
        uv: [f64; 2],
        area: f64,
    },
}

/// A tool's grids and fields.
#[derive(Clone, Debug)]
pub struct ToolFields {
    pub grids: Vec<PatchGrid>,
    /// First cell of each patch in the flat arrays.
    pub offsets: Vec<usize>,
    pub wear: WearLaw,
    pub values: FieldValues,
    /// Per cell of the increment being accumulated: force, work, wear volume, slip x area.
    scratch: Vec<[f64; 4]>,
    touched: Vec<usize>,
}

impl ToolFields {
    /// Grids on every patch of `surface` with cells of about `cell` (length) along each
    /// direction. Errors: a cell size that is not > 0, a grid over [`MAX_CELLS`].
    pub fn new(tool: &str, surface: &PatchSurface, wear: WearLaw, cell: f64) -> Result<ToolFields> {
        if !(cell > 0.0 && cell.is_finite()) {
            return Err(Error::input(
                &format!("tool '{tool}': cell size of the tool-side fields"),
                cell,
                "must be > 0",
            ));
        }
        let mut grids = Vec::new();
        let mut offsets = Vec::new();
        let mut total = 0usize;
        for patch in surface.patches() {
            let (lu, lv) = side_lengths(patch);
            let n = |l: f64| ((l / cell).ceil() as usize).clamp(1, MAX_PER_DIRECTION);
            let (nu, nv) = (n(lu), n(lv));
            offsets.push(total);
            total += nu * nv;
            if total > MAX_CELLS {
                return Err(Error::Input(format!(
                    "tool '{tool}': the tool-side fields with cells of {cell} would need more than {MAX_CELLS} cells; choose a larger cell size (tool.wear(law, cell))"
                )));
            }
            grids.push(PatchGrid::new(patch, nu, nv));
        }
        let zeros = vec![0.0; total];
        Ok(ToolFields {
            grids,
            offsets,
            wear,
            values: FieldValues {
                work: zeros.clone(),
                slip: zeros.clone(),
                peak_pressure: zeros.clone(),
                pressure_time: zeros.clone(),
                wear: zeros,
            },
            scratch: vec![[0.0; 4]; total],
            touched: Vec::new(),
        })
    }

    /// Number of cells over all patches.
    pub fn len(&self) -> usize {
        self.values.work.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Physical area of every cell, in the flat order of the values.
    pub fn cell_areas(&self) -> impl Iterator<Item = f64> + '_ {
        self.grids.iter().flat_map(|g| g.cell_area.iter().copied())
    }

    /// (patch, cell of that patch) of a flat cell index.
    pub fn locate(&self, flat: usize) -> (usize, usize) {
        let patch = self.offsets.partition_point(|&o| o <= flat) - 1;
        (patch, flat - self.offsets[patch])
    }

    /// The area of a footprint (`A_k` of the module doc): its polygons' physical areas on
    /// the grid plus its point pieces' weights.
    pub fn footprint_area(&self, pieces: &[Piece]) -> f64 {
        pieces
            .iter()
            .map(|piece| match piece {
                Piece::Polygon { patch, uv } => self.grids[*patch].overlaps(uv, |_, _| ()),
                Piece::Point { area, .. } => area.max(0.0),
            })
            .sum()
    }

    /// Adds one node's increment quantities, spread over its footprint `pieces` (see the
    /// module doc). `foot` (patch, uv) takes everything if the pieces have no area.
    /// Returns the footprint's area `A_k`.
    pub fn deposit(&mut self, pieces: &[Piece], foot: (usize, [f64; 2]), load: NodeLoad) -> f64 {
        let mut overlaps: Vec<(usize, f64)> = Vec::new();
        for piece in pieces {
            match piece {
                Piece::Polygon { patch, uv } => {
                    let offset = self.offsets[*patch];
                    self.grids[*patch].overlaps(uv, |c, a| overlaps.push((offset + c, a)));
                }
                Piece::Point { patch, uv, area } => {
                    if *area > 0.0 {
                        overlaps.push((
                            self.offsets[*patch] + self.grids[*patch].cell_of(*uv),
                            *area,
                        ));
                    }
                }
            }
        }
        let total: f64 = overlaps.iter().map(|o| o.1).sum();
        if !(total > 0.0) {
            overlaps.clear();
            overlaps.push((
                self.offsets[foot.0] + self.grids[foot.0].cell_of(foot.1),
                1.0,
            ));
        }
        let total = total.max(0.0);
        let norm: f64 = overlaps.iter().map(|o| o.1).sum();
        let wear = self.wear.coefficient * load.normal_force * load.slip;
        for (c, a) in overlaps {
            let fraction = a / norm;
            if self.scratch[c] == [0.0; 4] {
                self.touched.push(c);
            }
            let s = &mut self.scratch[c];
            s[0] += load.normal_force * fraction;
            s[1] += load.work * fraction;
            s[2] += wear * fraction;
            if total > 0.0 {
                s[3] += load.slip * a;
            }
        }
        total
    }

    /// Turns the increment's deposits into the fields (per area) and clears them; `dt` is
    /// the increment's length of pseudo-time.
    pub fn finish_increment(&mut self, dt: f64) {
        let mut touched = std::mem::take(&mut self.touched);
        // Cells in ascending order: the result does not depend on the order of deposit.
        touched.sort_unstable();
        touched.dedup();
        for &c in &touched {
            let (patch, local) = self.locate(c);
            let area = self.grids[patch].cell_area[local];
            let s = std::mem::take(&mut self.scratch[c]);
            if !(area > 0.0) {
                continue; // a degenerate cell (collapsed edge) holds no area and no density
            }
            let p = s[0] / area;
            let v = &mut self.values;
            v.work[c] += s[1] / area;
            v.wear[c] += s[2] / area;
            v.slip[c] += s[3] / area;
            v.peak_pressure[c] = v.peak_pressure[c].max(p);
            v.pressure_time[c] += p * dt;
        }
        touched.clear();
        self.touched = touched;
    }

    /// `Σ_C |C| w_C`: the tool-side frictional work.
    pub fn total_work(&self) -> f64 {
        self.cell_areas()
            .zip(&self.values.work)
            .map(|(a, w)| a * w)
            .sum()
    }

    /// Restores accumulated values (a checkpoint or rollback); errors if the shape differs.
    pub fn set_values(&mut self, tool: &str, values: FieldValues) -> Result<()> {
        let n = self.len();
        let lens = [
            values.work.len(),
            values.slip.len(),
            values.peak_pressure.len(),
            values.pressure_time.len(),
            values.wear.len(),
        ];
        if lens.iter().any(|&l| l != n) {
            return Err(Error::Input(format!(
                "tool '{tool}': the saved tool-side fields have {lens:?} values per field, the grid has {n} cells (a different surface or cell size)"
            )));
        }
        self.values = values;
        Ok(())
    }
}

/// Longest length of the patch's iso-lines along u and along v (v, u = 0, 1/2, 1), each by
/// a 32-segment polyline.
fn side_lengths(patch: &crate::geometry::BezierPatch) -> (f64, f64) {
    const N: usize = 32;
    let line = |f: &dyn Fn(f64) -> crate::geometry::Vec3| {
        (0..N)
            .map(|k| (f((k + 1) as f64 / N as f64) - f(k as f64 / N as f64)).norm())
            .sum::<f64>()
    };
    let mut lu: f64 = 0.0;
    let mut lv: f64 = 0.0;
    for t in [0.0, 0.5, 1.0] {
        lu = lu.max(line(&|u| patch.point(u, t)));
        lv = lv.max(line(&|v| patch.point(t, v)));
    }
    (lu, lv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{BezierPatch, Vec3};

    fn flat() -> PatchSurface {
        let p = BezierPatch::parallelogram(
            Vec3::zeros(),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        )
        .unwrap();
        PatchSurface::new(vec![p]).unwrap()
    }

    /// Cell size 0.5 on a 3 x 3 patch: 6 x 6 cells of 0.25; one node's deposit over 1 x 1
    /// footprint at (1, 1) and a point share: work and wear conserved, pressure peak p.
    #[test]
    fn deposit_conserves_and_fills_covered_cells() {
        let law = WearLaw::archard(1e-3, 2000.0).unwrap();
        let mut f = ToolFields::new("die", &flat(), law, 0.5).unwrap();
        assert_eq!(f.len(), 36);
        let s = 1.0 / 3.0;
        let square = vec![[s, s], [2.0 * s, s], [2.0 * s, 2.0 * s], [s, 2.0 * s]];
        let load = NodeLoad {
            work: 0.7,
            normal_force: 4.0,
            slip: 0.2,
        };
        let a = f.deposit(
            &[Piece::Polygon {
                patch: 0,
                uv: square,
            }],
            (0, [0.5, 0.5]),
            load,
        );
        assert!((a - 1.0).abs() < 1e-14);
        f.finish_increment(0.5);
        assert!((f.total_work() - 0.7).abs() < 1e-15);
        let p = 4.0; // force 4 over area 1
        let covered = f.grids[0].cell_of([0.5, 0.5]);
        assert!((f.values.peak_pressure[covered] - p).abs() < 1e-13);
        assert!((f.values.pressure_time[covered] - 0.5 * p).abs() < 1e-13);
        assert!((f.values.wear[covered] - 1e-3 / 2000.0 * p * 0.2).abs() < 1e-18);
        assert!((f.values.slip[covered] - 0.2).abs() < 1e-14);
        // Cells outside the footprint are untouched.
        assert_eq!(f.values.work[0], 0.0);
        assert!(WearLaw::archard(-1.0, 1.0).is_err());
        assert!(ToolFields::new("die", &flat(), law, 0.0).is_err());
        assert!(ToolFields::new("die", &flat(), law, 1e-4).is_err());
    }
}
