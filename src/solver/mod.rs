//! solver (see DESIGN.md).
