//! A rigid tool: a surface (exact, or worn by a normal offset: `worn.rs`), where it is at
//! each time, and its friction law.

use super::force_control::ForceControl;
use super::pose::{project_posed, Pose};
use super::schedule::Schedule;
use super::surface_fields::FieldSpec;
use super::worn::WornSurface;
use crate::contact::FrictionLaw;
use crate::geometry::{Projection, RigidSurface, SurfaceHint, Vec3};
use std::sync::Arc;

/// A rigid tool moving on a kinematic schedule.
#[derive(Clone, Debug)]
pub struct Tool {
    pub name: String,
    pub surface: Arc<dyn RigidSurface>,
    pub schedule: Schedule,
    pub friction: FrictionLaw,
    /// When set, the tool's position along an axis is an unknown fixed by a force schedule.
    pub force_control: Option<ForceControl>,
    /// When set, the tool accumulates tool-side fields (work, pressure, Archard wear) on
    /// its patches (`surface_fields.rs`).
    pub fields: Option<FieldSpec>,
    /// When set, the surface is worn by a wear depth per field cell (`worn.rs`): set by
    /// the simulation between strokes when the strokes update the geometry, never by a
    /// script.
    pub worn: Option<Arc<WornSurface>>,
}

impl Tool {
    pub fn new(name: &str, surface: Arc<dyn RigidSurface>) -> Self {
        Tool {
            name: name.to_string(),
            surface,
            schedule: Schedule::fixed(),
            friction: FrictionLaw::frictionless(),
            force_control: None,
            fields: None,
            worn: None,
        }
    }

    /// The tool's scheduled pose at (pseudo-)time `t` (without a force-control offset).
    pub fn pose(&self, t: f64) -> Pose {
        self.schedule.pose(t)
    }

    /// Closest-point projection of a global point on the tool at pose `pose`: on the
    /// worn surface when the tool is worn (`worn.rs`), else on the exact one.
    pub fn project(&self, pose: &Pose, x: &Vec3, hint: Option<&SurfaceHint>) -> Option<Projection> {
        let exact = project_posed(self.surface.as_ref(), pose, x, hint)?;
        Some(match &self.worn {
            Some(w) => w.apply(exact),
            None => exact,
        })
    }
}
