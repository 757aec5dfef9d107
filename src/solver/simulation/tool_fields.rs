//! The sheet's side of the tool-side fields (`crate::tool::surface_fields`): each contact
//! node's footprint on the tool, built after a converged increment and handed to the tool's
//! grids with the node's frictional dissipation, normal force and slip.
//!
//! Mathematics. A node's dual (tributary) area on the sheet is the union of its quarters of
//! the contact faces around it: for face `(x_a, x_b, x_c, x_d)` and corner `a`, the
//! quadrilateral `(x_a, (x_a + x_b)/2, centroid, (x_d + x_a)/2)`. The quarters of all nodes
//! tile the contact surface. Each quarter's corners, in the converged configuration, are
//! projected on the tool at its converged pose (closest point, warm-started at the node's
//! foot); the quarter becomes the polygon of their `(u, v)` on the node's patch. Shared
//! points (edge midpoints, centroids) get the same `(u, v)` from both sides, so the mapped
//! quarters tile the tool's contact zone too. A quarter whose corners do not all land on
//! the node's patch (a seam, a trim) is given to the cell of the node's foot, with its area
//! on the sheet as weight. The transfer's conservation does not depend on any of this
//! (`surface_fields.rs`): each node's quantities are split by fractions summing to 1.
//!
//! Runs once per converged increment, only for tools with fields; five projections per
//! face touching a loaded node.

use crate::contact::ContactNodeState;
use crate::geometry::Vec3;
use crate::mesh::Mesh;
use crate::solver::model::ToolContact;
use crate::tool::surface_fields::{NodeLoad, Piece};
use crate::tool::{Pose, ToolFields};
use crate::{Error, Result};

/// A tool's fields and the sheet faces whose quarters make its nodes' footprints.
#[derive(Clone, Debug)]
pub struct ContactFields {
    pub fields: ToolFields,
    /// Contact faces (all 4 nodes candidates), global node indices.
    faces: Vec<[usize; 4]>,
    /// Candidate index of each face corner.
    corners: Vec<[usize; 4]>,
}

impl ContactFields {
    /// The fields of `contact`'s tool if it asks for them (`Tool::fields`). Errors: a tool
    /// that is not a patch surface, a bad cell size.
    pub fn new(contact: &ToolContact, mesh: &Mesh) -> Result<Option<ContactFields>> {
        let Some(spec) = contact.tool.fields else {
            return Ok(None);
        };
        let name = &contact.tool.name;
        let Some(surface) = contact.tool.surface.as_patch_surface() else {
            return Err(Error::Input(format!(
                "tool '{name}': tool-side fields (tool.wear) need a surface of Bézier patches (flat_rectangle, cylinder_patch, patch_surface, round_die, ...), not {}",
                contact.tool.surface.describe()
            )));
        };
        let faces = mesh.faces_within(&contact.candidates)?;
        let mut index = vec![usize::MAX; mesh.nodes.len()];
        for (k, &n) in contact.candidates.iter().enumerate() {
            index[n] = k;
        }
        let corners = faces.iter().map(|f| f.map(|n| index[n])).collect();
        let cell = match spec.cell {
            Some(cell) => cell,
            None => {
                // A third of the sheet's mean element size under the tool.
                let area: f64 = contact.areas.iter().sum();
                if faces.is_empty() || !(area > 0.0) {
                    return Err(Error::Input(format!(
                        "tool '{name}': its node set holds no face of the sheet, so the cell size of the tool-side fields cannot be chosen; give one (tool.wear(law, cell))"
                    )));
                }
                (area / faces.len() as f64).sqrt() / 3.0
            }
        };
        Ok(Some(ContactFields {
            fields: ToolFields::new(name, surface, spec.wear, cell)?,
            faces,
            corners,
        }))
    }

    /// Adds one converged increment: `position(n)` the converged position of node `n`,
    /// `states` the committed contact states (hints at the converged feet), `loads` each
    /// candidate's quantities, `dt` the increment.
    pub fn accumulate(
        &mut self,
        contact: &ToolContact,
        pose: &Pose,
        position: impl Fn(usize) -> Vec3,
        states: &[ContactNodeState],
        loads: &[NodeLoad],
        dt: f64,
    ) {
        let loaded = |k: usize| loads[k].work != 0.0 || loads[k].normal_force > 0.0;
        let pieces = self.footprints(contact, pose, position, states, loaded);
        for (k, load) in loads.iter().enumerate() {
            if let (true, Some(h)) = (loaded(k), states[k].hint) {
                self.fields
                    .deposit(&pieces[k], (h.patch, [h.u, h.v]), *load);
            }
        }
        self.fields.finish_increment(dt);
    }

    /// The footprint pieces of every candidate for which `wanted(k)` (empty for the
    /// others): its quarters of the contact faces mapped to the tool (module doc).
    pub fn footprints(
        &self,
        contact: &ToolContact,
        pose: &Pose,
        position: impl Fn(usize) -> Vec3,
        states: &[ContactNodeState],
        wanted: impl Fn(usize) -> bool,
    ) -> Vec<Vec<Piece>> {
        let mut pieces: Vec<Vec<Piece>> = vec![Vec::new(); states.len()];
        for (face, corners) in self.faces.iter().zip(&self.corners) {
            if !corners.iter().any(|&k| wanted(k)) {
                continue;
            }
            let x = face.map(&position);
            let centre = (x[0] + x[1] + x[2] + x[3]) / 4.0;
            let hint = corners.iter().find_map(|&k| states[k].hint);
            let project = |p: &Vec3| {
                contact
                    .tool
                    .project(pose, p, hint.as_ref())
                    .map(|q| (q.hint.patch, [q.hint.u, q.hint.v]))
            };
            let mids: Vec<_> = (0..4)
                .map(|a| project(&((x[a] + x[(a + 1) % 4]) / 2.0)))
                .collect();
            let centre_uv = project(&centre);
            for a in 0..4 {
                let k = corners[a];
                let Some(h) = states[k].hint.filter(|_| wanted(k)) else {
                    continue;
                };
                let node = (h.patch, [h.u, h.v]);
                let quarter = [Some(node), mids[a], centre_uv, mids[(a + 3) % 4]];
                let same_patch = quarter.iter().all(|q| q.is_some_and(|q| q.0 == h.patch));
                pieces[k].push(if same_patch {
                    Piece::Polygon {
                        patch: h.patch,
                        uv: quarter.iter().map(|q| q.unwrap().1).collect(),
                    }
                } else {
                    let (m1, m2) = ((x[a] + x[(a + 1) % 4]) / 2.0, (x[a] + x[(a + 3) % 4]) / 2.0);
                    let area = 0.5
                        * ((m1 - x[a]).cross(&(centre - x[a])).norm()
                            + (centre - x[a]).cross(&(m2 - x[a])).norm());
                    Piece::Point {
                        patch: h.patch,
                        uv: node.1,
                        area,
                    }
                });
            }
        }
        pieces
    }
}
