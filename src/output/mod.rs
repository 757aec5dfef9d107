//! output (see DESIGN.md).
