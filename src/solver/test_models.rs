//! Small models the solver's unit tests share.

use super::Model;
use crate::contact::FrictionLaw;
use crate::element::StrainTheory;
use crate::geometry::{Cylinder, Vec3};
use crate::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};
use crate::mesh::Mesh;
use crate::tool::schedule::Schedule;
use crate::tool::{ForceControl, ScalarSchedule, Tool};
use std::sync::Arc;

/// A Hill48 strip (finite strain; 6 x 1 x 1 mm in 12 x 1 x 3 cells, clamped underneath,
/// Swift hardening of coefficient `swift_c`) under a rough (mu 0.2) cylinder of radius 5 mm
/// across it, its axis at `x = roller_x`, moved by `schedule`, and force-controlled by
/// `force_control` if given.
pub(crate) fn strip_under_roller(
    swift_c: f64,
    roller_x: f64,
    schedule: Schedule,
    force_control: Option<ForceControl>,
) -> Model {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(6.0, 1.0, 1.0), [12, 1, 3]).unwrap();
    let material = ElastoPlastic::new(
        LinearElastic::new(70e3, 0.33).unwrap(),
        Hill48::from_lankford(0.7, 1.3, 2.1).unwrap(),
        Hardening::swift(swift_c, 0.01, 0.22).unwrap(),
    );
    let mut model = Model::new(mesh, Arc::new(material)).unwrap();
    let cylinder = Cylinder::new(Vec3::new(roller_x, 0.0, 6.0), Vec3::y(), 5.0).unwrap();
    let mut tool = Tool::new("roller", Arc::new(cylinder));
    tool.schedule = schedule;
    tool.friction = FrictionLaw::coulomb(0.2).unwrap();
    tool.force_control = force_control;
    model.add_tool(tool, "z+", None).unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.kinematics = StrainTheory::Finite;
    model
}
