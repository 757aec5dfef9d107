//! material (see DESIGN.md).
