//! Sparse assembly, linear solves, Newton iteration and incremental stepping.

pub mod assembly;
pub mod augmentation;
pub mod checkpoint;
pub mod condense;
pub mod cycling;
pub mod force_control;
pub mod linear;
pub mod model;
pub mod simulation;
pub mod sparse;
pub mod step_control;
pub mod symmetric_lu;
pub mod system_dump;

pub use model::{Model, SolverSettings};
pub use simulation::{IncrementReport, IterationRecord, Simulation};
pub use step_control::{AntiCycling, StepMode, StepSettings};
