//! Strokes at run time (issue 53; what is asked: `model::strokes`): the next stroke started
//! on a new blank with the tools' state carried, the tool-side fields extrapolated after the
//! last simulated stroke, and friction laws of the tool's state.
//!
//! A new stroke. The committed state becomes the state `Simulation::new` built (kept as
//! `initial` when more than one stroke is simulated): displacements and multipliers 0,
//! virgin integration points, each candidate's contact history as at t = 0, energy 0,
//! step controller and predictor as at the start, the tools at their t = 0 poses (their
//! poses are functions of the time, which restarts at 0). Kept: the tool-side fields, the
//! increment counter (increment indices, history rows and checkpoint names run on over the
//! strokes) and the increment reports.
//!
//! Friction of the tool's state (`FrictionLaw::ToolWork`). mu of a node is
//! `B(min(w_tool(u, v) / w_cut, 1))` with `w_tool` the tool's frictional work per area in the
//! grid cell holding the node's foot, read from the tool's work field FROZEN AT THE START OF
//! THE STROKE (a copy taken when the stroke starts, part of the committed state and of
//! checkpoints). The foot is the committed one: mu is set after each converged increment
//! (like the explicit update of the sheet's laws) and when a stroke starts, and held fixed
//! during the next increment's Newton iterations. So mu is a constant of every increment
//! and the Jacobian needs no derivative of it: the operator's consistent Jacobian with a
//! fixed mu is exact. Freezing over the stroke keeps a stroke from reading the work it
//! deposits itself (the sheet's own law already follows that), so stroke 1 is the run
//! without strokes and stroke k sees the tool as the k - 1 strokes before left it.
//!
//! Geometry updated by the wear (`Strokes::update_geometry_every`). When a stroke starts
//! with an update (`Strokes::updates_geometry_at`), each tool with tool-side fields takes
//! a copy of its wear depth field as it is then, and its surface becomes the exact surface
//! worn by that depth (`tool::worn`: a normal offset, constant per cell, so the contact
//! Jacobian needs no derivative of the depth) until the next update. Without updates no
//! tool is worn and every projection is the exact one, bit for bit as before. Restart: the
//! copy is part of the committed state and of checkpoints (`state.tool_wear_applied`); it
//! cannot be recomputed from the checkpoint's fields, which hold the wear of the strokes
//! after the update too, so it is stored. A restore sets the tools' worn surfaces from it.

use crate::contact::FrictionLaw;
use crate::geometry::SurfaceHint;
use crate::solver::model::Model;
use crate::solver::simulation::Simulation;
use crate::tool::{ToolFields, WornSurface};
use crate::{Error, Result};
use std::sync::Arc;

/// Checks what strokes and tool-state laws need, before the run: a tool whose friction
/// reads its state has tool-side fields; extrapolation is refused when any law does.
pub(super) fn check(model: &Model) -> Result<()> {
    if model.strokes.update_geometry_every.is_some() {
        if !model.contacts.iter().any(|c| c.tool.fields.is_some()) {
            return Err(Error::Input(
                "sim.strokes: update_geometry_every updates the tools' geometry by their wear, but no tool accumulates wear; give a tool a wear law (tool.wear(archard(k, H)))".into(),
            ));
        }
        if model.strokes.extrapolated() {
            return Err(Error::Input(format!(
                "the strokes cannot be extrapolated ({} simulated of {}) when the tools' geometry is updated by their wear (update_geometry_every): each stroke differs; simulate every stroke (sim.strokes({}))",
                model.strokes.simulated, model.strokes.total, model.strokes.total
            )));
        }
    }
    for contact in &model.contacts {
        let name = &contact.tool.name;
        if let FrictionLaw::ToolWork(_) = contact.tool.friction {
            if contact.tool.fields.is_none() {
                return Err(Error::Input(format!(
                    "tool '{name}': its friction depends on the tool's work (friction_of_tool_work) but the tool accumulates no tool-side fields; give it a wear law (tool.wear(archard(k, H)))"
                )));
            }
            if model.strokes.extrapolated() {
                return Err(Error::Input(format!(
                    "the strokes cannot be extrapolated ({} simulated of {}): the friction of tool '{name}' depends on the tool's state, so each stroke differs; simulate every stroke (sim.strokes({}))",
                    model.strokes.simulated, model.strokes.total, model.strokes.total
                )));
            }
        }
    }
    Ok(())
}

/// mu of a node whose foot is `hint` under a tool-state law: the law at the frozen work per
/// area `frozen` of the cell holding the foot. `None` without a foot (the node keeps its mu).
pub(super) fn tool_state_mu(
    law: &crate::contact::BernsteinLaw,
    fields: &ToolFields,
    frozen: &[f64],
    hint: Option<&SurfaceHint>,
) -> Option<f64> {
    let h = hint?;
    let grid = fields.grids.get(h.patch)?;
    let cell = fields.offsets[h.patch] + grid.cell_of([h.u, h.v]);
    // The law's work is the tool's work per area, read directly (not divided by an area).
    Some(law.mu_of_theta((frozen[cell] / law.work_cut()).clamp(0.0, 1.0)))
}

impl Simulation {
    /// The stroke the committed state belongs to, from 1.
    pub fn stroke(&self) -> usize {
        self.stroke + 1
    }

    /// Whether the current stroke has reached the end time.
    pub fn stroke_done(&self) -> bool {
        self.time >= self.model.settings.end_time * (1.0 - 1e-12)
    }

    /// Whether the current stroke is the last one simulated (frames are written only in it).
    pub fn is_last_stroke(&self) -> bool {
        self.stroke + 1 >= self.model.strokes.simulated
    }

    /// The tool's work per area frozen at the start of the stroke, for a tool whose
    /// friction reads it (`FrictionLaw::ToolWork`).
    pub fn frozen_tool_work(&self, c: usize) -> Option<&[f64]> {
        self.tool_work_frozen[c].as_deref()
    }

    /// The frozen work fields of the tools whose friction reads them, taken now.
    pub(super) fn freeze_tool_work(&self) -> Vec<Option<Vec<f64>>> {
        (self.model.contacts.iter().enumerate())
            .map(
                |(c, contact)| match (&contact.tool.friction, &self.tool_fields[c]) {
                    (FrictionLaw::ToolWork(_), Some(f)) => Some(f.fields.values.work.clone()),
                    _ => None,
                },
            )
            .collect()
    }

    /// Starts the next stroke (module doc). Only after the current stroke has ended and
    /// while strokes remain to simulate.
    pub(super) fn start_next_stroke(&mut self) -> Result<()> {
        if !self.stroke_done() || self.is_last_stroke() {
            return Err(Error::Input(format!(
                "stroke {} cannot be followed by another at t = {} ({} stroke(s) simulated)",
                self.stroke(),
                self.time,
                self.model.strokes.simulated
            )));
        }
        let mut state = self
            .initial
            .as_deref()
            .expect("the initial state is kept when several strokes are simulated")
            .clone();
        state.history_len = self.history.len();
        state.increments_done = self.increments_done;
        state.tool_fields = self.saved_state().tool_fields;
        state.tool_work_frozen = self.freeze_tool_work();
        state.stroke = self.stroke + 1;
        state.tool_wear_applied = if self.model.strokes.updates_geometry_at(state.stroke) {
            (self.tool_fields.iter())
                .map(|f| f.as_ref().map(|f| f.fields.values.wear.clone()))
                .collect()
        } else {
            self.tool_wear_applied.clone()
        };
        self.restore_state(state);
        self.set_tool_state_mu();
        Ok(())
    }

    /// The wear depth per cell tool `c`'s surface is worn by, if it is worn.
    pub fn applied_tool_wear(&self, c: usize) -> Option<&[f64]> {
        self.tool_wear_applied[c].as_deref()
    }

    /// Each tool's surface worn by its applied wear depth, or exact (module doc).
    pub(super) fn set_worn_tools(&mut self) {
        for (c, depth) in self.tool_wear_applied.iter().enumerate() {
            let worn = match (depth, &self.tool_fields[c]) {
                (Some(h), Some(f)) => Some(Arc::new(WornSurface::new(&f.fields, h.clone()))),
                _ => None,
            };
            self.model.contacts[c].tool.worn = worn;
        }
    }

    /// mu of every node under a tool-state law, from its committed foot and the frozen work.
    pub(super) fn set_tool_state_mu(&mut self) {
        for (c, contact) in self.model.contacts.iter().enumerate() {
            let (FrictionLaw::ToolWork(law), Some(fields), Some(frozen)) = (
                &contact.tool.friction,
                &self.tool_fields[c],
                &self.tool_work_frozen[c],
            ) else {
                continue;
            };
            for s in &mut self.contact[c] {
                if let Some(mu) = tool_state_mu(law, &fields.fields, frozen, s.hint.as_ref()) {
                    s.mu = mu;
                }
            }
        }
    }

    /// After the last simulated stroke of an extrapolated run: the additive fields scaled
    /// by N / m, the peak pressure kept (`model::strokes`).
    pub(super) fn extrapolate_tool_fields(&mut self) {
        let factor = self.model.strokes.extrapolation_factor();
        for fields in self.tool_fields.iter_mut().flatten() {
            let v = &mut fields.fields.values;
            for field in [&mut v.work, &mut v.slip, &mut v.pressure_time, &mut v.wear] {
                field.iter_mut().for_each(|x| *x *= factor);
            }
        }
    }
}
