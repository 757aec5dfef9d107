//! tool (see DESIGN.md).
