//! mesh (see DESIGN.md).
