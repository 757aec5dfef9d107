//! The solver: from a [`Model`] (what is solved) to a [`Simulation`] (its committed
//! solution, advanced one increment of pseudo-time at a time).
//!
//! # Wings
//!
//! Each folder owns one part of an increment's work and may use only the wings listed
//! before it here (tests/architecture.rs checks this):
//!
//! | wing | owns | may use |
//! |---|---|---|
//! | [`settings`] | every setting type and its default (solver, stepping, contact, linear solver) | nothing of the solver |
//! | [`sparse`] | the sparse pattern and matrix storage | nothing of the solver |
//! | [`model`] | the scene: mesh, material, tools with candidates, boundary conditions, loads (follower loads), the default augmentation parameter | settings |
//! | [`assembly`] | the unknowns' layout ([`assembly::DofMap`]), residual and Jacobian of a trial state (`IncrementContext`), entry slots, force-controlled tools' rows | settings, sparse, model |
//! | [`linear`] | the linear solvers behind one trait: the symmetric LU and its subtree split, faer's LU, the multipliers' condensation, system dumps | settings, sparse, model, assembly |
//! | [`newton`] | one increment's generalised Newton method as a value that borrows the committed state ([`newton::Newton`]): line search, status prediction, anti-cycling, predictor, pseudo-transient continuation | all above |
//! | [`simulation`] | the committed state and its history: [`Simulation`], stepping with cutbacks and last resorts, step control, commit, rollback, checkpoints, energy balance | all above |
//!
//! Invariants: the solver writes no file and prints nothing (the system dump of
//! `TRIBO_DUMP_SYSTEM` excepted); a trial never touches committed state (Newton borrows it
//! immutably); results do not depend on the thread count.

pub mod assembly;
pub mod linear;
pub mod model;
pub mod newton;
pub mod settings;
pub mod simulation;
pub mod sparse;
#[cfg(test)]
pub(crate) mod test_models;

pub use assembly::DofMap;
pub use model::Model;
pub use newton::IterationRecord;
pub use settings::{
    AntiCycling, ContactSettings, LinearSolverKind, SolverSettings, StepMode, StepSettings,
};
pub use simulation::energy::EnergyBalance;
pub use simulation::{IncrementReport, Simulation};
