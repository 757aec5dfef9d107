//! contact (see DESIGN.md).
