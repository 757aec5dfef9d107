//! The scene to simulate: body, boundary conditions, loads, tools and solver settings.
//! A `Model` holds no solution; see [`super::Simulation`] for the evolving state.

use crate::contact::ContactSettings;
use crate::geometry::Vec3;
use crate::material::Material;
use crate::mesh::Mesh;
use crate::tool::schedule::ScalarSchedule;
use crate::tool::Tool;
use crate::{Error, Result};
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

/// Status-prediction re-solves per Newton step by default: 8. They take 42-50 % fewer
/// iterations over the whole 25 x 25 x 1 square cups (on the paper cup's first 3 mm: 43
/// against 129), which then meet issue 14's cup targets under the default budget (the plain
/// Newton does not finish the paper cup under it), at 0.86-0.87 times the plain Newton's
/// CPU (docs/convergence.md). The blocker of earlier sessions, a frictional first contact
/// converging to another of its states (the cylindrical cup's first increment), came from
/// pivoting solves of nearly singular predicted systems, which re-solves no longer do. Cost
/// where prediction fails: an attempt that does not converge with it is tried again
/// plainly before a cutback (the U-channel scene takes 2.6-2.9 times the plain CPU, and
/// stays under 25 iterations per increment where the plain Newton took 26 and 30).
pub const DEFAULT_STATUS_PREDICTION: usize = 8;

/// Newton and stepping settings.
#[derive(Clone, Debug)]
pub struct SolverSettings {
    pub max_iterations: usize,
    /// Force residual tolerance relative to the norm of internal forces and reactions.
    pub force_rel_tol: f64,
    /// Absolute floor for the force residual (force units).
    pub force_abs_tol: f64,
    /// Contact residual tolerance (length units: constraint violation).
    pub contact_tol: f64,
    /// End of pseudo-time.
    pub end_time: f64,
    /// Number of equal increments to reach `end_time`.
    pub increments: usize,
    /// How many times an increment may be halved after a failed Newton solve.
    pub max_cutbacks: usize,
    pub contact: ContactSettings,
    /// Eliminate the multipliers of single-pair, unconstrained contact nodes before the
    /// linear solve (same Newton iterates, smaller factorization; see `condense`).
    pub eliminate_multipliers: bool,
    /// The sparse factorization of each Newton step (see `linear`).
    pub linear_solver: super::linear::LinearSolverKind,
    /// Small strain (B-bar hexahedra, the default) or finite strain (total-Lagrangian
    /// F-bar hexahedra, Lagrangian log-strain material update).
    pub kinematics: crate::element::StrainTheory,
    /// F-bar volumetric treatment of the finite-strain hexahedron (default on; off gives
    /// the fully integrated element, which locks: for verification only).
    pub fbar: bool,
    /// The hexahedron of the strain theory or the solid-shell (`element::solid_shell`).
    pub element: crate::element::ElementKind,
    /// Gauss points through the thickness of the solid-shell.
    pub thickness_points: usize,
    /// Increment control, line search, anti-cycling and rollback depth.
    pub stepping: super::step_control::StepSettings,
    /// Start each increment's Newton iteration from the last increment's change of the
    /// displacements, scaled to the new step (off: from the committed state).
    pub extrapolate: bool,
    /// Re-solves of each Newton step with the contact nodes that the step carries across a
    /// status boundary linearised on the status they are heading into (0: off; see
    /// `status_prediction`).
    pub status_prediction: usize,
    /// Threads evaluating elements and factorizing (0: as many as the machine has cores).
    /// The results do not depend on it: elements are scattered into the global system in
    /// element order, and each supernode of the factorization is computed by the same
    /// operations whatever thread runs it (`symmetric_lu`, "Threads").
    pub threads: usize,
}

/// Newton iterations an attempt may take before it fails (and the increment is retried or
/// cut back): 25. With the default r a tenth of the membrane stiffness (`augmentation`), an
/// increment that has not converged in 25 iterations does better halved: on the U-channel
/// (tests/scenes) a budget of 30 let two increments take 26 iterations and changed nothing
/// else that matters (8 and 7 cutbacks either way, about the same CPU), and the 25 x 25 x 1
/// cups never take more than 22 (docs/convergence.md).
pub const DEFAULT_MAX_ITERATIONS: usize = 25;

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            max_iterations: DEFAULT_MAX_ITERATIONS,
            force_rel_tol: 1e-9,
            force_abs_tol: 1e-9,
            contact_tol: 1e-9,
            end_time: 1.0,
            increments: 10,
            max_cutbacks: 4,
            contact: ContactSettings::default(),
            eliminate_multipliers: true,
            linear_solver: Default::default(),
            kinematics: crate::element::StrainTheory::Small,
            fbar: true,
            element: crate::element::ElementKind::Hexahedron,
            thickness_points: crate::element::solid_shell::DEFAULT_THICKNESS_POINTS,
            stepping: Default::default(),
            extrapolate: true,
            status_prediction: DEFAULT_STATUS_PREDICTION,
            threads: 0,
        }
    }
}

/// The whole scene.
#[derive(Clone, Debug)]
pub struct Model {
    pub mesh: Mesh,
    pub material: Arc<dyn Material>,
    pub dirichlet: Vec<Dirichlet>,
    pub loads: Vec<NodalLoad>,
    /// Loads that turn with the surface (`solver::follower_load`).
    pub follower_loads: Vec<super::follower_load::FollowerTraction>,
    pub contacts: Vec<ToolContact>,
    pub settings: SolverSettings,
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
            None => super::augmentation::membrane_stiffness(
                &self.mesh,
                super::augmentation::young_modulus(&self.material.elastic_tangent()),
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
