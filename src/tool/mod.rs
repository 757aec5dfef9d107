//! Rigid tools: a surface, its pose, and how the pose moves with pseudo-time (see docs/architecture.md).

pub mod field_grid;
pub mod force_control;
pub mod pose;
pub mod schedule;

pub use pose::{project_posed, Pose};
pub use schedule::{ScalarSchedule, Schedule};
pub mod rigid_tool;
pub mod surface_fields;
pub mod worn;

pub use force_control::ForceControl;
pub use rigid_tool::Tool;
pub use surface_fields::{FieldSpec, ToolFields, WearLaw};
pub use worn::WornSurface;
