//! Sparse assembly, linear solves, Newton iteration and incremental stepping.

pub mod assembly;
pub mod augmentation;
pub mod checkpoint;
pub mod condense;
pub mod cycling;
pub mod energy;
pub mod follower_load;
pub mod force_control;
pub mod kinematics_check;
pub mod line_search;
pub mod linear;
pub mod model;
pub mod newton;
pub mod predictor;
pub mod pseudo_transient;
pub mod simulation;
pub mod slots;
pub mod sparse;
pub mod status_prediction;
pub mod step_control;
pub mod stepping;
pub mod subtree_split;
pub mod symmetric_lu;
pub mod system_dump;
#[cfg(test)]
pub(crate) mod test_models;

pub use energy::EnergyBalance;
pub use model::{Model, SolverSettings};
pub use newton::IterationRecord;
pub use simulation::{IncrementReport, Simulation};
pub use step_control::{AntiCycling, StepMode, StepSettings};
