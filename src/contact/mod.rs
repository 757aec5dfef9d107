//! Frictional contact: the nodal Alart-Curnier operator, friction laws and per-node state.

pub mod operator;

pub use operator::{alart_curnier, ContactStatus, NodalContact, OperatorParams};
