//! tribo: implicit quasi-static finite-element simulation of frictional contact between a
//! deformable sheet and rigid curved tools, scripted in Rhai.
//!
//! Layers, each knowing only those below it:
//! `geometry` -> `contact` -> `tool` -> `mesh`/`material`/`element` -> `solver` -> `output` -> `script`
//! -> `study` (families of runs, charted speed against accuracy) and `sweep` (a user's table of
//! runs as child processes or cluster jobs). See docs/architecture.md.

// `!(x > 0.0)` is how inputs are refused when they are not positive *or are NaN*; the
// `partial_cmp` spelling clippy suggests hides that intent.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Index loops over several arrays of the same element (nodes, components, Gauss points)
// read like the formulas they implement.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod cad;
pub mod contact;
pub mod element;
pub mod error;
pub mod geometry;
pub mod interrupt;
pub mod material;
pub mod mesh;
pub mod output;
pub mod paths;
pub mod script;
pub mod solver;
pub mod study;
pub mod sweep;
pub mod tool;

pub use error::{Error, Result};
