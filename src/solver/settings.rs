//! Every setting of the solver in one place: Newton and its tolerances
//! ([`SolverSettings`]), increment control and Newton's safeguards ([`StepSettings`]), the
//! contact treatment ([`ContactSettings`]) and the linear solver ([`LinearSolverKind`]).
//!
//! These are plain values: the script layer fills them from `sim.settings(#{...})`, the
//! solver's wings read them, and nothing here computes. They live apart from the code that
//! reads them so that a setting is found in one file, and so that the lower layers
//! (contact/) need not reach up into the solver for their defaults.
//!
//! Where a default was chosen by measurement, its doc says what was measured.

use crate::contact::{Enforcement, FrameUpdate, FrictionUpdate};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

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
    pub linear_solver: LinearSolverKind,
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
    pub stepping: StepSettings,
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

/// How the increment size is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StepMode {
    /// `end_time / increments`, halved on failure (the default).
    Fixed,
    /// Bounded by increment limits and Newton effort, cut on failure (see the module doc).
    Adaptive,
}

/// What to do when the contact status of some nodes cycles during one increment's Newton
/// iterations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum AntiCycling {
    /// Freeze the cycling nodes' status until the frozen problem converges, then release.
    Freeze,
    /// Halve the Newton update while some node cycles.
    Damp,
    /// Detect and report only (the default: on the square cup freezing cost 24 cutbacks
    /// on 15 mm of the coarse benchmark variant, and none were needed without it; see
    /// docs/convergence.md).
    Off,
}

/// Settings of the increment control and of the Newton safeguards.
#[derive(Clone, Debug)]
pub struct StepSettings {
    pub mode: StepMode,
    /// Smallest increment (pseudo-time); `None`: end_time * 1e-6.
    pub dt_min: Option<f64>,
    /// Largest increment; `None`: no bound besides the end time.
    pub dt_max: Option<f64>,
    /// First increment in adaptive mode; `None`: end_time / increments.
    pub dt_initial: Option<f64>,
    pub max_plastic_strain_increment: f64,
    /// Radians.
    pub max_rotation_increment: f64,
    /// Length units.
    pub max_slip_increment: f64,
    pub target_iterations: usize,
    /// Largest growth factor of the increment after an easy one.
    pub growth: f64,
    /// Backtracking line search on the residual merit function.
    pub line_search: bool,
    pub anti_cycling: AntiCycling,
    /// Status changes of one node within an increment that count as cycling.
    pub cycle_flips: usize,
    /// How many committed states are kept for `rollback`.
    pub rollback_depth: usize,
    /// Where Newton fails at the smallest part, the last resorts before the run stops
    /// (module `stepping`).
    pub last_resort: bool,
}

impl Default for StepSettings {
    fn default() -> Self {
        StepSettings {
            mode: StepMode::Fixed,
            dt_min: None,
            dt_max: None,
            dt_initial: None,
            max_plastic_strain_increment: 0.05,
            max_rotation_increment: 0.1,
            max_slip_increment: f64::INFINITY,
            target_iterations: 6,
            growth: 2.0,
            line_search: true,
            anti_cycling: AntiCycling::Off,
            cycle_flips: 3,
            rollback_depth: 3,
            last_resort: true,
        }
    }
}

impl StepSettings {
    pub fn dt_min(&self, end_time: f64) -> f64 {
        self.dt_min.unwrap_or(end_time * 1e-6)
    }

    pub fn dt_max(&self, end_time: f64) -> f64 {
        self.dt_max.unwrap_or(end_time)
    }

    /// Checks the values a script may set; the message names the setting.
    pub fn validate(&self, end_time: f64) -> Result<()> {
        let positive = [
            ("dt_min", self.dt_min(end_time)),
            ("dt_max", self.dt_max(end_time)),
            ("dt_initial", self.dt_initial.unwrap_or(1.0)),
            (
                "max_plastic_strain_increment",
                self.max_plastic_strain_increment,
            ),
            ("max_rotation_increment", self.max_rotation_increment),
            ("max_slip_increment", self.max_slip_increment),
            ("target_iterations", self.target_iterations as f64),
        ];
        for (what, v) in positive {
            if v.is_nan() || v <= 0.0 {
                return Err(Error::input(what, v, "must be > 0"));
            }
        }
        if !(self.growth >= 1.0 && self.growth.is_finite()) {
            return Err(Error::input("step_growth", self.growth, "must be >= 1"));
        }
        if self.dt_min(end_time) > self.dt_max(end_time) {
            return Err(Error::Input(format!(
                "dt_min = {} is larger than dt_max = {}",
                self.dt_min(end_time),
                self.dt_max(end_time)
            )));
        }
        if self.cycle_flips < 2 {
            return Err(Error::input(
                "cycle_flips",
                self.cycle_flips,
                "must be >= 2 (a node must leave a status and come back)",
            ));
        }
        Ok(())
    }
}

/// The fraction of the membrane stiffness under a node that is its default r under the
/// augmented Lagrangian (setting `r_fraction`; why a tenth: `model::augmentation`).
pub const MEMBRANE_FRACTION: f64 = 0.1;

/// Switches of the contact treatment that studies compare.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactSettings {
    pub enforcement: Enforcement,
    pub frame: FrameUpdate,
    /// Include curvature (normal gradient) terms in the Jacobian.
    pub curvature: bool,
    /// Explicit (paper) or implicit (trapezoidal, in the Newton loop) friction update.
    pub friction_update: FrictionUpdate,
    /// The default augmentation parameter under the augmented Lagrangian as a fraction of
    /// the membrane stiffness under each node (`solver::model::augmentation`).
    pub r_fraction: f64,
}

impl Default for ContactSettings {
    fn default() -> Self {
        ContactSettings {
            enforcement: Enforcement::AugmentedLagrangian,
            frame: FrameUpdate::EveryIteration,
            curvature: true,
            friction_update: FrictionUpdate::Explicit,
            r_fraction: MEMBRANE_FRACTION,
        }
    }
}

/// Which sparse factorization the Newton solver uses (solver setting `linear_solver`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearSolverKind {
    /// [`SymmetricLu`](crate::solver::linear::SymmetricLu): no pivoting on the symmetric structure, the pivoting LU as fallback.
    #[default]
    SymmetricLu,
    /// [`FaerLu`](crate::solver::linear::FaerLu): faer's LU with partial pivoting (COLAMD).
    Lu,
}

impl LinearSolverKind {
    pub fn from_name(name: &str) -> std::result::Result<Self, String> {
        match name {
            "symmetric_lu" => Ok(LinearSolverKind::SymmetricLu),
            "lu" => Ok(LinearSolverKind::Lu),
            other => Err(format!(
                "linear_solver must be \"symmetric_lu\" or \"lu\", got \"{other}\""
            )),
        }
    }
}
