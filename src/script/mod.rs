//! script (see DESIGN.md).
