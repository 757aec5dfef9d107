//! Checkpoints: the complete committed state of a simulation as JSON, so that a run can be
//! continued (`tribo run SCRIPT --restart FILE`) or inspected.
//!
//! A checkpoint holds everything the next increment depends on: the unknowns (displacements
//! and multipliers), every integration point's history, every contact pair's history
//! (multiplier, slip reference point, projection hint, status, frictional work, slip, theta,
//! flips, mu), the time, the increment counter, the step controller (next increment size),
//! the energy balance and the forces of the trapezoidal energy rule, what the elements
//! remember of their last linearisation (where the solid-shell's next local solves start),
//! the loaded shape and springback measures of release steps (`simulation::springback`),
//! and the increment reports so far. The model itself (mesh, materials, tools, schedules, settings) is not
//! stored: the script builds it again, and [`Checkpoint::restore`] checks that it matches
//! (sizes, tool names and candidates, tool positions at the checkpoint's time, and FNV-1a
//! fingerprints of the mesh, the tools' surfaces, the material and each tool's friction law,
//! taken from their descriptions: a restart with another material or law is refused, naming
//! the field; checkpoints written before a fingerprint existed skip that comparison).
//!
//! Numbers are written by serde_json in shortest round-trip form and read back with its
//! `float_roundtrip` parser, so every f64 is restored bit for bit and a restarted run
//! repeats the uninterrupted one exactly.

use crate::contact::ContactNodeState;
use crate::material::PointState;
use crate::solver::simulation::energy::{EnergyBalance, EnergyMemory};
use crate::solver::simulation::step_control::StepController;
use crate::solver::simulation::{IncrementReport, Simulation};
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
    /// What the elements remembered at the committed state (the solid-shell's last
    /// linearisation; [`crate::solver::assembly::ElementMemory`]), so that a restarted run
    /// predicts its next local solves as the uninterrupted one does. Unset entries are NaN,
    /// written as JSON `null`. Absent from older checkpoints (read as empty: the next
    /// increment's first local solves start cold).
    #[serde(default, with = "nan_as_null")]
    pub element_memory: Vec<f64>,
    /// Steps ended early by their condition: (step index, time of the increment that met
    /// it); the tools' schedules are rebuilt from them (module `step_end`). Absent from
    /// older checkpoints (none).
    #[serde(default)]
    pub step_ends: Vec<(usize, f64)>,
    /// The tool-side fields of each tool (`None` for a tool without them); absent from
    /// older checkpoints (read as empty: every tool's fields restart from zero), and not
    /// written when no tool has fields, so that such checkpoints are what they were.
    #[serde(default, skip_serializing_if = "no_tool_fields")]
    pub tool_fields: Vec<Option<crate::tool::surface_fields::FieldValues>>,
    /// The stroke of a production run, from 0 (`model::strokes`); absent from older
    /// checkpoints and from runs of one stroke (0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stroke: usize,
    /// Per tool whose friction reads the tool's work: that work frozen at the stroke's
    /// start (module `simulation::strokes`); left out when no tool's friction reads it.
    #[serde(default, skip_serializing_if = "no_frozen_work")]
    pub tool_work_frozen: Vec<Option<Vec<f64>>>,
    /// Per tool worn by a geometry update of the strokes: the wear depth per cell its
    /// surface is offset by (`tool::worn`), the tool's wear field as the last update before
    /// this stroke took it; left out when no tool is worn (older checkpoints: none).
    #[serde(default, skip_serializing_if = "no_frozen_work")]
    pub tool_wear_applied: Vec<Option<Vec<f64>>>,
    /// The node positions where loading ended, once a release step has begun
    /// (`simulation::springback`), so that a run restarted after it measures springback
    /// as the uninterrupted one; left out before (older checkpoints: none, and a run
    /// restarted inside its release then reports no springback).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loaded_shape: Option<Vec<crate::geometry::Vec3>>,
    /// The springback of the release steps completed; left out when none (older
    /// checkpoints: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub springback: Vec<crate::solver::simulation::springback::Springback>,
}

fn is_zero(k: &usize) -> bool {
    *k == 0
}

fn no_frozen_work(frozen: &[Option<Vec<f64>>]) -> bool {
    frozen.iter().all(Option::is_none)
}

/// True when no tool has tool-side fields (the entry is then left out of the file).
fn no_tool_fields(fields: &[Option<crate::tool::surface_fields::FieldValues>]) -> bool {
    fields.iter().all(Option::is_none)
}

/// A vector of numbers, NaN among them, as JSON (which has no NaN): NaN as `null`.
mod nan_as_null {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        let opt: Vec<Option<f64>> = v.iter().map(|x| (!x.is_nan()).then_some(*x)).collect();
        opt.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        let opt = Vec::<Option<f64>>::deserialize(d)?;
        Ok(opt.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())
    }
}

/// Sizes and names that must agree between the checkpoint and the rebuilt model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    pub nodes: usize,
    pub elements: usize,
    pub unknowns: usize,
    /// (tool name, candidate nodes) per tool.
    pub tools: Vec<(String, Vec<usize>)>,
    /// FNV-1a hash of the node coordinates (bits) and the connectivity, as 16 hex digits.
    #[serde(default)]
    pub mesh_hash: String,
    /// FNV-1a hash of each tool's surface description, as 16 hex digits.
    #[serde(default)]
    pub tool_hashes: Vec<String>,
    /// FNV-1a hash of the material's description (its law and every parameter), so that a
    /// restart with another material is refused (a script function's body is not in it).
    #[serde(default)]
    pub material_hash: String,
    /// FNV-1a hash of each tool's friction law description (law and parameters).
    #[serde(default)]
    pub friction_hashes: Vec<String>,
}

/// 64-bit FNV-1a, written as 16 hex digits (JSON numbers would lose the high bits).
/// O(bytes).
pub fn fnv1a(bytes: impl IntoIterator<Item = u8>) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

impl Fingerprint {
    fn of(sim: &Simulation) -> Self {
        let mesh = &sim.model.mesh;
        let coordinates = mesh
            .nodes
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .flat_map(|v| v.to_bits().to_le_bytes());
        let connectivity = mesh
            .hexes
            .iter()
            .flatten()
            .flat_map(|&n| (n as u64).to_le_bytes());
        Fingerprint {
            nodes: mesh.nodes.len(),
            elements: mesh.hexes.len(),
            unknowns: sim.unknowns().len(),
            tools: sim
                .model
                .contacts
                .iter()
                .map(|c| (c.tool.name.clone(), c.candidates.clone()))
                .collect(),
            mesh_hash: fnv1a(coordinates.chain(connectivity)),
            tool_hashes: sim
                .model
                .contacts
                .iter()
                .map(|c| fnv1a(c.tool.surface.describe().into_bytes()))
                .collect(),
            material_hash: fnv1a(sim.model.material.describe().into_bytes()),
            friction_hashes: sim
                .model
                .contacts
                .iter()
                .map(|c| fnv1a(c.tool.friction.describe().into_bytes()))
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
    /// Values the script kept (`sim.keep`), restored with the state.
    #[serde(default)]
    pub script: serde_json::Map<String, serde_json::Value>,
    /// The evaluations and Newton steps up to the committed state, so that a restarted
    /// run's summary counts them as the uninterrupted run does (absent from older
    /// checkpoints: the restarted run counts its own only).
    #[serde(default)]
    pub evaluations: Option<crate::solver::assembly::EvaluationCounts>,
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
            script: serde_json::Map::new(),
            evaluations: Some(sim.committed_counts),
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
        let mut here = Fingerprint::of(sim);
        // Checkpoints of earlier versions have no hashes: sizes and names are checked.
        if self.model.mesh_hash.is_empty() {
            here.mesh_hash.clear();
        }
        if self.model.tool_hashes.is_empty() {
            here.tool_hashes.clear();
        }
        if self.model.material_hash.is_empty() {
            here.material_hash.clear();
        }
        if self.model.friction_hashes.is_empty() {
            here.friction_hashes.clear();
        }
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
            } else if here.mesh_hash != self.model.mesh_hash {
                format!(
                    "model.mesh_hash: {} in the checkpoint, {} for the script's mesh (node coordinates or connectivity differ)",
                    self.model.mesh_hash, here.mesh_hash
                )
            } else if here.tool_hashes != self.model.tool_hashes {
                let c = here
                    .tool_hashes
                    .iter()
                    .zip(&self.model.tool_hashes)
                    .position(|(a, b)| a != b)
                    .unwrap_or(0);
                format!(
                    "model.tool_hashes[{c}]: the surface of tool '{}' differs from the checkpoint's",
                    here.tools.get(c).map_or("", |t| t.0.as_str())
                )
            } else if here.material_hash != self.model.material_hash {
                format!(
                    "model.material_hash: the material differs from the checkpoint's (the script's: {})",
                    sim.model.material.describe()
                )
            } else if here.friction_hashes != self.model.friction_hashes {
                let c = (here.friction_hashes.iter())
                    .zip(&self.model.friction_hashes)
                    .position(|(a, b)| a != b)
                    .unwrap_or(0);
                format!(
                    "model.friction_hashes[{c}]: the friction law of tool '{}' differs from the checkpoint's (the script's: {})",
                    here.tools.get(c).map_or("", |t| t.0.as_str()),
                    sim.model.contacts.get(c).map_or(String::new(), |t| t.tool.friction.describe())
                )
            } else {
                "contact candidates or unknowns differ (enforcement, node sets)".to_string()
            };
            return Err(Error::Input(format!(
                "the checkpoint does not belong to this model: {what}"
            )));
        }
        let s = &self.state;
        let remembered = sim.model.element()?.memory_len();
        let shapes_ok = s.x.len() == here.unknowns
            && s.points.len() == sim.points().len()
            && s.contact.len() == here.tools.len()
            && s.contact
                .iter()
                .zip(&here.tools)
                .all(|(c, t)| c.len() == t.1.len())
            && s.history_len == self.history.len()
            && (s.element_memory.is_empty()
                || s.element_memory.len() == sim.model.mesh.hexes.len() * remembered);
        if !shapes_ok {
            return Err(Error::Input(
                "the checkpoint is inconsistent (array sizes do not match its model)".into(),
            ));
        }
        // The schedules of steps ended early, before the tools' poses are compared.
        sim.check_step_ends(&s.step_ends)?;
        sim.set_step_ends(s.step_ends.clone());
        check_tool_fields(sim, &s.tool_fields)?;
        check_strokes(sim, s)?;
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
        self.validate(sim)?;
        if s.time > sim.model.settings.end_time * (1.0 + 1e-12) {
            return Err(Error::Input(format!(
                "the checkpoint's time {} is past the script's end time {}",
                s.time, sim.model.settings.end_time
            )));
        }
        sim.history = self.history;
        sim.restore_state(self.state);
        if let Some(counts) = self.evaluations {
            sim.phase_times.set_counts(&counts);
            sim.committed_counts = counts;
        }
        sim.clear_rollback();
        Ok(())
    }
}

/// The checkpoint's tool-side fields against the model's: the same tools have them, on
/// grids of the same size, with finite values >= 0. An older checkpoint without them (empty)
/// passes: the fields restart from zero.
fn check_tool_fields(
    sim: &Simulation,
    saved: &[Option<crate::tool::surface_fields::FieldValues>],
) -> Result<()> {
    if saved.is_empty() {
        return Ok(());
    }
    let n_tools = sim.model.contacts.len();
    if saved.len() != n_tools {
        return Err(Error::Input(format!(
            "the checkpoint's state.tool_fields has {} entries for {n_tools} tools (the file was edited or is damaged)",
            saved.len()
        )));
    }
    for (c, values) in saved.iter().enumerate() {
        let name = &sim.model.contacts[c].tool.name;
        match (sim.tool_fields(c), values) {
            (None, None) => {}
            (Some(fields), Some(values)) => {
                let mut check = fields.clone();
                check.set_values(name, values.clone())?;
                let all = [&values.work, &values.slip, &values.peak_pressure, &values.pressure_time, &values.wear];
                if let Some(v) = all.iter().flat_map(|f| f.iter()).find(|v| !(**v >= 0.0 && v.is_finite())) {
                    return Err(Error::Input(format!(
                        "the checkpoint's state.tool_fields[{c}] (tool '{name}') holds {v}, but its values are finite and >= 0 (the file was edited or is damaged)"
                    )));
                }
            }
            (Some(_), None) => {
                return Err(Error::Input(format!(
                    "tool '{name}' accumulates tool-side fields (tool.wear) but the checkpoint has none for it: it was written without them"
                )))
            }
            (None, Some(_)) => {
                return Err(Error::Input(format!(
                    "the checkpoint has tool-side fields for tool '{name}', which the script does not ask for (tool.wear)"
                )))
            }
        }
    }
    Ok(())
}

/// The checkpoint's stroke within the script's strokes, the frozen work of every tool
/// whose friction reads it and the wear depth of every worn tool: one finite value >= 0
/// per cell.
fn check_strokes(sim: &Simulation, s: &SavedState) -> Result<()> {
    let simulated = sim.model.strokes.simulated;
    if s.stroke >= simulated {
        return Err(Error::Input(format!(
            "the checkpoint is in stroke {} but the script simulates {simulated} stroke(s) (sim.strokes)",
            s.stroke + 1
        )));
    }
    for (c, contact) in sim.model.contacts.iter().enumerate() {
        let Some(fields) = sim.tool_fields(c) else {
            continue;
        };
        if !matches!(
            contact.tool.friction,
            crate::contact::FrictionLaw::ToolWork(_)
        ) {
            continue;
        }
        check_per_cell(
            &contact.tool.name,
            c,
            "tool_work_frozen",
            &s.tool_work_frozen,
            fields.len(),
        )?;
    }
    // Worn tools exactly when the script's strokes have updated the geometry by this one.
    let worn = s.tool_wear_applied.iter().any(Option::is_some);
    let updated = matches!(sim.model.strokes.update_geometry_every, Some(k) if s.stroke >= k);
    if worn != updated {
        return Err(Error::Input(format!(
            "the checkpoint (stroke {}) has {} worn tool geometry, but the script's strokes (update_geometry_every {:?}) {} updated it by then",
            s.stroke + 1,
            if worn { "a" } else { "no" },
            sim.model.strokes.update_geometry_every,
            if updated { "have" } else { "have not" },
        )));
    }
    for (c, contact) in sim.model.contacts.iter().enumerate() {
        let Some(Some(_)) = s.tool_wear_applied.get(c) else {
            continue;
        };
        let name = &contact.tool.name;
        let Some(fields) = sim.tool_fields(c) else {
            return Err(Error::Input(format!(
                "the checkpoint's state.tool_wear_applied[{c}] wears tool '{name}', but the tool has no tool-side fields (no wear law)"
            )));
        };
        check_per_cell(
            name,
            c,
            "tool_wear_applied",
            &s.tool_wear_applied,
            fields.len(),
        )?;
    }
    Ok(())
}

/// `state.<what>[c]` of tool `name`: present, one finite value >= 0 per cell of its grid.
fn check_per_cell(
    name: &str,
    c: usize,
    what: &str,
    values: &[Option<Vec<f64>>],
    cells: usize,
) -> Result<()> {
    let frozen = values.get(c).and_then(Option::as_ref);
    let Some(frozen) = frozen else {
        return Err(Error::Input(format!(
            "tool '{name}': its friction reads the tool's work, but the checkpoint holds no state.{what} for it (written by a script without friction_of_tool_work)"
        )));
    };
    if frozen.len() != cells {
        return Err(Error::Input(format!(
            "the checkpoint's state.{what}[{c}] (tool '{name}') has {} values, the grid {cells} cells",
            frozen.len(),
        )));
    }
    if let Some(v) = frozen.iter().find(|v| !(**v >= 0.0 && v.is_finite())) {
        return Err(Error::Input(format!(
            "the checkpoint's state.{what}[{c}] (tool '{name}') holds {v}, but its values are finite and >= 0 (the file was edited or is damaged)"
        )));
    }
    Ok(())
}

impl Checkpoint {
    /// Checks every value of the state against what a converged state can hold: finite
    /// numbers, displacements within 1000 times the mesh's size, multipliers (contact
    /// forces) within 1000 times the largest elastic stiffness times the size squared,
    /// stresses finite, mu, frictional work, slip, equivalent plastic strain >= 0, det F > 0, a
    /// positive next increment. The error names the field (`state.contact[0][12].mu`) and
    /// its value. A checkpoint is JSON that a person can edit: this keeps an edited or
    /// damaged file from starting a run from a state no increment could have produced.
    /// O(size of the state).
    fn validate(&self, sim: &Simulation) -> Result<()> {
        let s = &self.state;
        let refuse = |field: String, value: f64, requirement: &str| {
            Err(Error::Input(format!(
                "the checkpoint's {field} = {value} {requirement} (the file was edited or is damaged)"
            )))
        };
        let finite = |field: &dyn Fn() -> String, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                refuse(field(), v, "must be finite")
            }
        };
        let non_negative = |field: &dyn Fn() -> String, v: f64| {
            if v >= 0.0 && v.is_finite() {
                Ok(())
            } else {
                refuse(field(), v, "must be finite and >= 0")
            }
        };
        let mesh = &sim.model.mesh;
        let (lo, hi) = mesh.nodes.iter().fold(
            (
                crate::geometry::Vec3::repeat(f64::INFINITY),
                crate::geometry::Vec3::repeat(f64::NEG_INFINITY),
            ),
            |(lo, hi), p| (lo.inf(p), hi.sup(p)),
        );
        let size = (hi - lo).norm().max(f64::MIN_POSITIVE);
        let bound = 1e3 * size;
        // A multiplier is a nodal contact force: a stress times an area. Displacements are
        // bounded by 1000 sizes (so strains by about 1000), stresses then by 1000 times the
        // largest elastic stiffness, areas by size^2: a force past that bound is not one a
        // converged state of this model holds (1e300 in an edited file, say).
        let stiffness = sim.model.material.elastic_tangent().abs().max();
        let force_bound = (1e3 * stiffness * size * size).max(f64::MIN_POSITIVE);
        let force = |field: &dyn Fn() -> String, v: f64| {
            if v.abs() <= force_bound {
                Ok(())
            } else {
                refuse(
                    field(),
                    v,
                    &format!(
                        "must be finite and within +-{force_bound:e} (1000 times the largest \
                         elastic stiffness times the mesh's size squared)"
                    ),
                )
            }
        };
        non_negative(&|| "state.time".into(), s.time)?;
        let n_u = 3 * mesh.nodes.len();
        for (i, &v) in s.x.iter().enumerate() {
            if i < n_u {
                if !(v.abs() <= bound) {
                    return refuse(
                        format!(
                            "state.x[{i}] (displacement {} of node {})",
                            ["x", "y", "z"][i % 3],
                            i / 3
                        ),
                        v,
                        &format!(
                            "must be finite and within +-{bound:e} (1000 times the mesh's size)"
                        ),
                    );
                }
            } else {
                force(&|| format!("state.x[{i}] (a multiplier)"), v)?;
            }
        }
        for (p, point) in s.points.iter().enumerate() {
            let field = |name: &str| format!("state.points[{p}].{name}");
            for (name, values) in [
                ("stress", point.stress.as_slice()),
                ("strain", point.strain.as_slice()),
                ("plastic_strain", point.plastic_strain.as_slice()),
                ("log_stress", point.log_stress.as_slice()),
                (
                    "deformation_gradient",
                    point.deformation_gradient.as_slice(),
                ),
                ("enhanced", point.enhanced.as_slice()),
            ] {
                for (i, &v) in values.iter().enumerate() {
                    finite(&|| format!("{}[{i}]", field(name)), v)?;
                }
            }
            non_negative(&|| field("eq_plastic_strain"), point.eq_plastic_strain)?;
            finite(&|| field("plastic_dissipation"), point.plastic_dissipation)?;
            let det = point.deformation_gradient.determinant();
            if !(det > 0.0) {
                return refuse(
                    format!("determinant of {}", field("deformation_gradient")),
                    det,
                    "must be > 0",
                );
            }
        }
        for (c, nodes) in s.contact.iter().enumerate() {
            for (k, n) in nodes.iter().enumerate() {
                let field = |name: &str| format!("state.contact[{c}][{k}].{name}");
                for (i, &x) in n.lambda.iter().enumerate() {
                    force(&|| format!("{}[{i}]", field("lambda")), x)?;
                }
                for (name, v) in [
                    ("x_ref_local", n.x_ref_local),
                    ("normal", n.normal),
                    ("slip_increment", n.slip_increment),
                ] {
                    for (i, &x) in v.iter().enumerate() {
                        finite(&|| format!("{}[{i}]", field(name)), x)?;
                    }
                }
                finite(&|| field("gap"), n.gap)?;
                finite(&|| field("theta"), n.theta)?;
                non_negative(&|| field("mu"), n.mu)?;
                non_negative(&|| field("work"), n.work)?;
                non_negative(&|| field("slip"), n.slip)?;
                if let Some(h) = n.hint {
                    finite(&|| field("hint.u"), h.u)?;
                    finite(&|| field("hint.v"), h.v)?;
                }
            }
        }
        let e = &s.energy;
        for (name, v) in [
            ("tool_work", e.tool_work),
            ("load_work", e.load_work),
            ("support_work", e.support_work),
            ("elastic_energy", e.elastic_energy),
            ("plastic_dissipation", e.plastic_dissipation),
        ] {
            finite(&|| format!("state.energy.{name}"), v)?;
        }
        for (c, &v) in e.frictional_dissipation.iter().enumerate() {
            finite(&|| format!("state.energy.frictional_dissipation[{c}]"), v)?;
        }
        if !(s.controller.dt > 0.0 && s.controller.dt.is_finite()) {
            return refuse(
                "state.controller.dt".into(),
                s.controller.dt,
                "must be finite and > 0",
            );
        }
        if let Some((dt, du)) = &s.last_step {
            finite(&|| "state.last_step.dt".into(), *dt)?;
            if du.len() != n_u {
                return Err(Error::Input(format!(
                    "the checkpoint's state.last_step holds {} values, the model has {n_u} displacements",
                    du.len()
                )));
            }
            for (i, &v) in du.iter().enumerate() {
                finite(&|| format!("state.last_step[{i}]"), v)?;
            }
        }
        for (i, &t) in self.frame_times.iter().enumerate() {
            non_negative(&|| format!("frame_times[{i}]"), t)?;
        }
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
