//! Checkpoints: the complete committed state of a simulation as JSON, so that a run can be
//! continued (`tribo run SCRIPT --restart FILE`) or inspected.
//!
//! A checkpoint holds everything the next increment depends on: the unknowns (displacements
//! and multipliers), every integration point's history, every contact pair's history
//! (multiplier, slip reference point, projection hint, status, frictional work, slip, theta,
//! flips, mu), the time, the increment counter, the step controller (next increment size),
//! the energy balance and the forces of the trapezoidal energy rule, and the increment
//! reports so far. The model itself (mesh, materials, tools, schedules, settings) is not
//! stored: the script builds it again, and [`Checkpoint::restore`] checks that it matches
//! (sizes, tool names and candidates, tool positions at the checkpoint's time).
//!
//! Numbers are written by serde_json in shortest round-trip form and read back with its
//! `float_roundtrip` parser, so every f64 is restored bit for bit and a restarted run
//! repeats the uninterrupted one exactly.

use super::energy::{EnergyBalance, EnergyMemory};
use super::simulation::{IncrementReport, Simulation};
use super::step_control::StepController;
use crate::contact::ContactNodeState;
use crate::material::PointState;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// Format tag and version of the JSON file.
const FORMAT: &str = "tribo-checkpoint";
const VERSION: u32 = 1;

/// The committed state of a simulation (also what `rollback` keeps).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SavedState {
    /// Unknowns [u, lambda].
    pub x: Vec<f64>,
    pub points: Vec<PointState>,
    pub contact: Vec<Vec<ContactNodeState>>,
    pub time: f64,
    pub increments_done: usize,
    /// Number of increment reports at this state.
    pub history_len: usize,
    pub energy: EnergyBalance,
    pub energy_memory: EnergyMemory,
    pub controller: StepController,
    /// The last increment's (dt, change of the displacements), for the extrapolating predictor.
    #[serde(default)]
    pub last_step: Option<(f64, Vec<f64>)>,
}

/// Sizes and names that must agree between the checkpoint and the rebuilt model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    pub nodes: usize,
    pub elements: usize,
    pub unknowns: usize,
    /// (tool name, candidate nodes) per tool.
    pub tools: Vec<(String, Vec<usize>)>,
}

impl Fingerprint {
    fn of(sim: &Simulation) -> Self {
        Fingerprint {
            nodes: sim.model.mesh.nodes.len(),
            elements: sim.model.mesh.hexes.len(),
            unknowns: sim.unknowns().len(),
            tools: sim
                .model
                .contacts
                .iter()
                .map(|c| (c.tool.name.clone(), c.candidates.clone()))
                .collect(),
        }
    }
}

/// A checkpoint file's content.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    pub format: String,
    pub version: u32,
    pub model: Fingerprint,
    /// Each tool's pose at the checkpoint's time, as the images of the origin and of the
    /// three unit points of the tool's frame (a check on the schedules).
    pub tool_poses: Vec<[[f64; 3]; 4]>,
    pub state: SavedState,
    pub history: Vec<IncrementReport>,
    /// Times of the VTK frames the run had written when the checkpoint was taken.
    pub frame_times: Vec<f64>,
}

impl Checkpoint {
    /// The committed state of `sim`.
    pub fn of(sim: &Simulation, frame_times: Vec<f64>) -> Self {
        let state = sim.saved_state();
        Checkpoint {
            format: FORMAT.into(),
            version: VERSION,
            model: Fingerprint::of(sim),
            tool_poses: sim
                .model
                .contacts
                .iter()
                .map(|c| pose_points(&c.tool.pose(state.time)))
                .collect(),
            history: sim.history.clone(),
            state,
            frame_times,
        }
    }

    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self)
            .map_err(|e| Error::Input(format!("cannot write the checkpoint as JSON: {e}")))
    }

    /// Parses a checkpoint; `source` names the file in errors.
    pub fn from_json(text: &str, source: &str) -> Result<Self> {
        let ck: Checkpoint = serde_json::from_str(text)
            .map_err(|e| Error::Input(format!("{source} is not a tribo checkpoint: {e}")))?;
        if ck.format != FORMAT || ck.version != VERSION {
            return Err(Error::Input(format!(
                "{source}: checkpoint format '{}' version {} (this tribo reads '{FORMAT}' version {VERSION})",
                ck.format, ck.version
            )));
        }
        Ok(ck)
    }

    /// Makes the checkpoint's state the committed state of `sim`, after checking that
    /// `sim`'s model is the one the checkpoint was taken from.
    pub fn restore(self, sim: &mut Simulation) -> Result<()> {
        let here = Fingerprint::of(sim);
        if here != self.model {
            let what = if here.nodes != self.model.nodes || here.elements != self.model.elements {
                format!(
                    "mesh: {} nodes / {} elements in the checkpoint, {} / {} in the script",
                    self.model.nodes, self.model.elements, here.nodes, here.elements
                )
            } else if here.tools.len() != self.model.tools.len()
                || here
                    .tools
                    .iter()
                    .zip(&self.model.tools)
                    .any(|(a, b)| a.0 != b.0)
            {
                format!(
                    "tools: {:?} in the checkpoint, {:?} in the script",
                    self.model.tools.iter().map(|t| &t.0).collect::<Vec<_>>(),
                    here.tools.iter().map(|t| &t.0).collect::<Vec<_>>()
                )
            } else {
                "contact candidates or unknowns differ (enforcement, node sets)".to_string()
            };
            return Err(Error::Input(format!(
                "the checkpoint does not belong to this model: {what}"
            )));
        }
        let s = &self.state;
        let shapes_ok = s.x.len() == here.unknowns
            && s.points.len() == sim.points().len()
            && s.contact.len() == here.tools.len()
            && s.contact
                .iter()
                .zip(&here.tools)
                .all(|(c, t)| c.len() == t.1.len())
            && s.history_len == self.history.len();
        if !shapes_ok {
            return Err(Error::Input(
                "the checkpoint is inconsistent (array sizes do not match its model)".into(),
            ));
        }
        for (c, (contact, stored)) in sim.model.contacts.iter().zip(&self.tool_poses).enumerate() {
            let here = pose_points(&contact.tool.pose(s.time));
            let d = here
                .iter()
                .zip(stored)
                .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max);
            let scale = 1.0 + here.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            if d > 1e-12 * scale {
                return Err(Error::Input(format!(
                    "tool {c} '{}' is placed differently at t = {} in the script than in the checkpoint (origin at {:?}, was {:?}): the schedules changed",
                    contact.tool.name, s.time, here[0], stored[0]
                )));
            }
        }
        if s.time > sim.model.settings.end_time * (1.0 + 1e-12) {
            return Err(Error::Input(format!(
                "the checkpoint's time {} is past the script's end time {}",
                s.time, sim.model.settings.end_time
            )));
        }
        sim.history = self.history;
        sim.restore_state(self.state);
        sim.clear_rollback();
        Ok(())
    }
}

/// The images of the origin and of the unit points of a tool's frame.
fn pose_points(pose: &crate::tool::pose::Pose) -> [[f64; 3]; 4] {
    use crate::geometry::Vec3;
    [Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::z()].map(|p| {
        let g = pose.to_global_point(&p);
        [g.x, g.y, g.z]
    })
}
