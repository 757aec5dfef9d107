//! Sparse assembly, linear solves, Newton iteration and incremental stepping.

pub mod linear;
pub mod sparse;
