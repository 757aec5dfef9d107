//! Frictional contact: the nodal Alart-Curnier operator, friction laws and per-node state.

pub mod friction;
pub mod operator;
pub mod state;

pub use friction::{BernsteinLaw, FrictionInput, FrictionLaw, FrictionUpdate, WorkMeasure};
pub use operator::{alart_curnier, ContactStatus, NodalContact, OperatorParams, SigmaModel};
pub use state::ContactNodeState;

/// How contact constraints are enforced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Enforcement {
    /// Mixed (u, lambda) augmented-Lagrangian formulation (Alart-Curnier): exact constraints.
    #[default]
    AugmentedLagrangian,
    /// Plain penalty: normal force r d_n, tangential force r delta_t added to the committed
    /// tangential force; no multiplier unknowns, the constraint is violated by force/r.
    Penalty,
}

/// Where the contact frame (foot point, normal) is evaluated during Newton iterations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrameUpdate {
    /// Projected anew at every iteration (the paper's choice: exact on curved tools).
    #[default]
    EveryIteration,
    /// Projected once at the start of the increment and kept (the tool is replaced by its
    /// tangent plane for the increment).
    Frozen,
}
