//! A rigid tool: a surface, where it is at each time, and its friction law.

use super::pose::{project_posed, Pose};
use super::schedule::Schedule;
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
}

impl Tool {
    pub fn new(name: &str, surface: Arc<dyn RigidSurface>) -> Self {
        Tool {
            name: name.to_string(),
            surface,
            schedule: Schedule::fixed(),
            friction: FrictionLaw::frictionless(),
        }
    }

    /// The tool's pose at (pseudo-)time `t`.
    pub fn pose(&self, t: f64) -> Pose {
        self.schedule.pose(t)
    }

    /// Closest-point projection of a global point on the tool at pose `pose`.
    pub fn project(&self, pose: &Pose, x: &Vec3, hint: Option<&SurfaceHint>) -> Option<Projection> {
        project_posed(self.surface.as_ref(), pose, x, hint)
    }
}
