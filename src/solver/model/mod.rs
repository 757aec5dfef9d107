//! The scene to simulate: body, boundary conditions, loads, tools and solver settings.
//! A `Model` holds no solution; see [`super::Simulation`] for the evolving state.

pub mod augmentation;
pub mod follower_load;
pub mod rigid_modes;
pub mod steps;
pub mod strokes;

use crate::geometry::Vec3;
use crate::material::Material;
use crate::mesh::Mesh;
use crate::solver::settings::SolverSettings;
use crate::tool::schedule::ScalarSchedule;
use crate::tool::Tool;
use crate::{Error, Result};
use follower_load::FollowerTraction;
use std::sync::Arc;

/// Prescribed value of one displacement component on a set of nodes.
#[derive(Clone, Debug)]
pub struct Dirichlet {
    pub label: String,
    pub nodes: Vec<usize>,
    /// 0, 1, 2 for x, y, z.
    pub component: usize,
    pub value: ScalarSchedule,
}

/// A total force distributed over a node set in proportion to the nodes' tributary areas.
#[derive(Clone, Debug)]
pub struct NodalLoad {
    pub label: String,
    pub nodes: Vec<usize>,
    /// Each node's share of the total (sums to 1).
    pub weights: Vec<f64>,
    /// Direction and magnitude at scale 1.
    pub total: Vec3,
    pub scale: ScalarSchedule,
}

/// Contact between a tool and the candidate nodes of the body.
#[derive(Clone, Debug)]
pub struct ToolContact {
    pub tool: Tool,
    /// Body nodes that may touch this tool.
    pub candidates: Vec<usize>,
    /// Tributary area of each candidate (for pressures and area-based measures).
    pub areas: Vec<f64>,
    /// Augmentation (or penalty) parameter r per candidate node, force/length.
    pub r: Vec<f64>,
    /// Whether `r` is the engine's default (the membrane stiffness under each node until the
    /// simulation starts, see `augmentation`), not the user's value.
    pub r_default: bool,
}

/// The whole scene.
#[derive(Clone, Debug)]
pub struct Model {
    pub mesh: Mesh,
    pub material: Arc<dyn Material>,
    pub dirichlet: Vec<Dirichlet>,
    pub loads: Vec<NodalLoad>,
    /// Loads that turn with the surface (`follower_load`).
    pub follower_loads: Vec<FollowerTraction>,
    pub contacts: Vec<ToolContact>,
    pub settings: SolverSettings,
    /// The process's named steps (`steps`); empty: one step over the whole run.
    pub steps: Vec<steps::Step>,
    /// A production run of several strokes (`strokes`); the default is one.
    pub strokes: strokes::Strokes,
}

impl Model {
    pub fn new(mesh: Mesh, material: Arc<dyn Material>) -> Result<Self> {
        mesh.validate()?;
        Ok(Model {
            mesh,
            material,
            dirichlet: Vec::new(),
            loads: Vec::new(),
            follower_loads: Vec::new(),
            contacts: Vec::new(),
            settings: SolverSettings::default(),
            steps: Vec::new(),
            strokes: strokes::Strokes::default(),
        })
    }

    /// The element the settings select (see `element::solid_shell::select`).
    pub fn element(
        &self,
    ) -> Result<&'static dyn crate::element::Element<{ crate::element::hex8::DOFS }>> {
        let s = &self.settings;
        crate::element::solid_shell::select(s.element, s.kinematics, s.fbar, s.thickness_points)
    }

    /// Node set by name (a face "x-", ..., or one the script defined).
    pub fn nodes(&self, set: &str) -> Result<Vec<usize>> {
        Ok(self.mesh.node_set(set)?.to_vec())
    }

    /// Adds a follower bending moment `moment · scale(t)` on the boundary faces of the node
    /// set `set` (an end face of a beam or strip), about `direction` (the thickness
    /// direction): see [`FollowerTraction::end_moment`].
    pub fn add_end_moment(
        &mut self,
        set: &str,
        moment: f64,
        direction: Vec3,
        scale: ScalarSchedule,
    ) -> Result<()> {
        let nodes = self.nodes(set)?;
        let load = FollowerTraction::end_moment(&self.mesh, set, &nodes, moment, direction, scale)?;
        self.follower_loads.push(load);
        Ok(())
    }

    /// Prescribes `components` (subset of "xyz") of the nodes of `set` to follow `value`.
    pub fn prescribe(&mut self, set: &str, components: &str, value: ScalarSchedule) -> Result<()> {
        let nodes = self.nodes(set)?;
        let comps = parse_components(components)?;
        // A node component held twice with different values would silently take the last.
        let held: std::collections::HashSet<usize> = nodes.iter().copied().collect();
        for &c in &comps {
            if let Some(d) = self.dirichlet.iter().find(|d| {
                d.component == c && d.value != value && d.nodes.iter().any(|n| held.contains(n))
            }) {
                return Err(Error::Input(format!(
                    "prescribing '{set}' {} conflicts with the earlier constraint '{}' on the \
                     same nodes (a node component is held once; remove one of them)",
                    ['x', 'y', 'z'][c],
                    d.label
                )));
            }
        }
        for c in comps {
            self.dirichlet.push(Dirichlet {
                label: format!("{set}.{}", ['x', 'y', 'z'][c]),
                nodes: nodes.clone(),
                component: c,
                value: value.clone(),
            });
        }
        Ok(())
    }

    /// Distributes the total force `total` (scaled by `scale(t)`) over the face set `set`.
    pub fn add_load(&mut self, set: &str, total: Vec3, scale: ScalarSchedule) -> Result<()> {
        let nodes = self.nodes(set)?;
        let areas = self.mesh.tributary_areas(&nodes)?;
        let sum: f64 = areas.iter().sum();
        if !(sum > 0.0) {
            return Err(Error::input(
                &format!("load on node set '{set}': tributary area"),
                sum,
                "must be > 0 (is the set a boundary face?)",
            ));
        }
        if !total.iter().all(|v| v.is_finite()) {
            return Err(Error::input(
                "load total force",
                format!("{total:?}"),
                "must be finite",
            ));
        }
        self.loads.push(NodalLoad {
            label: set.to_string(),
            nodes,
            weights: areas.iter().map(|a| a / sum).collect(),
            total,
            scale,
        });
        Ok(())
    }

    /// Adds a tool in contact with the nodes of `set`. `r = None` picks a default
    /// augmentation parameter from the material stiffness and the local element size.
    pub fn add_tool(&mut self, tool: Tool, set: &str, r: Option<f64>) -> Result<()> {
        if self.contacts.iter().any(|c| c.tool.name == tool.name) {
            return Err(Error::Input(format!(
                "a tool named '{}' already exists",
                tool.name
            )));
        }
        if let Some(r) = r {
            if !(r.is_finite() && r > 0.0) {
                return Err(Error::input(
                    &format!("augmentation parameter r of tool '{}'", tool.name),
                    r,
                    "must be > 0",
                ));
            }
        }
        let candidates = self.nodes(set)?;
        let areas = self.mesh.tributary_areas(&candidates)?;
        let r_default = r.is_none();
        let r = match r {
            Some(r) => vec![r; candidates.len()],
            // The membrane stiffness of the layer under each node, scaled to the enforcement
            // when the simulation starts (`settle_default_r`; the settings may still change).
            None => crate::solver::model::augmentation::membrane_stiffness(
                &self.mesh,
                crate::solver::model::augmentation::young_modulus(&self.material.elastic_tangent()),
                &candidates,
            )?,
        };
        self.contacts.push(ToolContact {
            tool,
            candidates,
            areas,
            r,
            r_default,
        });
        Ok(())
    }

    /// Turns the default r of every tool (the membrane stiffness under each node, see
    /// `augmentation`) into the value for the enforcement in the settings: the fraction
    /// `settings.contact.r_fraction` of it (a tenth by default) under the augmented
    /// Lagrangian, itself under penalty. Called once, when the simulation starts; a value the
    /// user gave is kept.
    pub fn settle_default_r(&mut self) {
        let fraction = match self.settings.contact.enforcement {
            crate::contact::Enforcement::AugmentedLagrangian => self.settings.contact.r_fraction,
            crate::contact::Enforcement::Penalty => 1.0,
        };
        for c in self.contacts.iter_mut().filter(|c| c.r_default) {
            c.r.iter_mut().for_each(|r| *r *= fraction);
            c.r_default = false;
        }
    }

    /// Nodal external forces at time `t` (3 per node): every load's total spread by its
    /// weights.
    pub fn external_forces(&self, t: f64) -> Vec<f64> {
        let mut f = vec![0.0; 3 * self.mesh.nodes.len()];
        for load in &self.loads {
            let total = load.total * load.scale.value(t);
            for (&node, &w) in load.nodes.iter().zip(&load.weights) {
                for i in 0..3 {
                    f[3 * node + i] += w * total[i];
                }
            }
        }
        f
    }

    pub fn tool_index(&self, name: &str) -> Result<usize> {
        self.contacts
            .iter()
            .position(|c| c.tool.name == name)
            .ok_or_else(|| {
                let known: Vec<_> = self.contacts.iter().map(|c| c.tool.name.as_str()).collect();
                Error::Input(format!("no tool named '{name}' (tools: {known:?})"))
            })
    }
}

/// "xz" -> [0, 2]; anything but x, y, z is an error naming the letter.
pub fn parse_components(s: &str) -> Result<Vec<usize>> {
    let mut out = Vec::new();
    for ch in s.chars() {
        let c = match ch {
            'x' | 'X' => 0,
            'y' | 'Y' => 1,
            'z' | 'Z' => 2,
            _ => {
                return Err(Error::input(
                    "displacement component",
                    format!("'{ch}' in \"{s}\""),
                    "must be x, y or z",
                ))
            }
        };
        if !out.contains(&c) {
            out.push(c);
        }
    }
    if out.is_empty() {
        return Err(Error::input(
            "displacement components",
            "\"\"",
            "must name at least one of x, y, z",
        ));
    }
    Ok(out)
}
