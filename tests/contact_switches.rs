//! The switches that studies compare: plain penalty instead of the augmented Lagrangian,
//! and a contact frame frozen at the start of each increment instead of updated every
//! iteration. Each gives what it should and no more.

mod common;

use tribo::contact::{ContactStatus, Enforcement, FrameUpdate};
use tribo::geometry::{Plane, Vec3};
use tribo::mesh::Mesh;
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

const N: f64 = 100.0;
const MU: f64 = 0.3;
const R_PENALTY: f64 = 2000.0;

fn pressed_block(enforcement: Enforcement, frame: FrameUpdate) -> Simulation {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(10.0, 10.0, 2.0), [4, 4, 2]).unwrap();
    let mut model = Model::new(mesh, common::elastic(1000.0, 0.3)).unwrap();
    let plane = Plane::new(Vec3::zeros(), Vec3::z()).unwrap();
    let r = (enforcement == Enforcement::Penalty).then_some(R_PENALTY);
    model
        .add_tool(
            common::tool("floor", plane, &[(0.0, [0.0; 3])], MU),
            "z-",
            r,
        )
        .unwrap();
    let ramp = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 1.0)]).unwrap();
    model.add_load("z+", Vec3::new(0.0, 0.0, -N), ramp).unwrap();
    let drag = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 0.0), (2.0, 0.5)]).unwrap();
    model.prescribe("z+", "x", drag).unwrap();
    model
        .prescribe("z+", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.end_time = 2.0;
    model.settings.increments = 8;
    model.settings.force_rel_tol = 1e-12;
    model.settings.contact_tol = 1e-12;
    model.settings.contact.enforcement = enforcement;
    model.settings.contact.frame = frame;
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    sim
}

#[test]
fn penalty_violates_the_constraint_by_force_over_r() {
    let sim = pressed_block(Enforcement::Penalty, FrameUpdate::EveryIteration);
    let f = sim.tool_force(0);
    // Coulomb's law still holds exactly in full slip, and so does equilibrium.
    assert!((-f.z - N).abs() < 1e-8 * N);
    assert!(
        (f.x - MU * N).abs() < 1e-7 * MU * N,
        "friction force {}",
        f.x
    );
    // Every contact node penetrates by its own normal force over r.
    for s in sim.contact_states(0) {
        assert_eq!(s.status, ContactStatus::Slip);
        assert!(
            (s.gap - s.lambda_n() / R_PENALTY).abs() < 1e-10,
            "gap {} force {}",
            s.gap,
            s.lambda_n()
        );
        assert!(s.gap < 0.0);
    }
    // The augmented Lagrangian leaves no penetration at all.
    let exact = pressed_block(
        Enforcement::AugmentedLagrangian,
        FrameUpdate::EveryIteration,
    );
    for s in exact.contact_states(0) {
        assert!(s.gap.abs() < 1e-11, "augmented Lagrangian gap {}", s.gap);
    }
}

#[test]
fn frozen_frame_is_exact_on_a_plane() {
    let a = pressed_block(
        Enforcement::AugmentedLagrangian,
        FrameUpdate::EveryIteration,
    );
    let b = pressed_block(Enforcement::AugmentedLagrangian, FrameUpdate::Frozen);
    let d = a
        .displacements()
        .iter()
        .zip(b.displacements())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(
        d < 1e-10,
        "a plane is its own tangent plane: max difference {d}"
    );
}

#[test]
fn frozen_frame_on_a_cylinder_leaves_a_gap_error_of_the_order_of_the_curvature() {
    let run = |frame| {
        let mut model = common::cylinder_drag_model(16.0, 4.0, 32, 8.0);
        model.settings.increments = 12;
        model.settings.contact.frame = frame;
        let mut sim = Simulation::new(model).unwrap();
        sim.run(|_, _| Ok(())).unwrap();
        sim
    };
    let exact = run(FrameUpdate::EveryIteration);
    let frozen = run(FrameUpdate::Frozen);
    // True gaps (projected anew at commit) of the active nodes.
    let worst = |s: &Simulation| {
        s.contact_states(0)
            .iter()
            .filter(|c| c.status.is_active())
            .fold(0.0f64, |m, c| m.max(c.gap.abs()))
    };
    println!(
        "largest |gap| of active nodes: updated frame {:.2e}, frozen frame {:.2e}",
        worst(&exact),
        worst(&frozen)
    );
    assert!(worst(&exact) < 1e-9);
    // The frozen frame is the tangent plane at the projection of the increment's start
    // position on the tool at its end pose, so the tool's own travel is accounted for; what
    // remains is the node's displacement within the increment, d ~ 0.01-0.03 mm, moving it
    // along the tangent plane and off the circle by about d^2 / (2R) ~ 1e-5-1e-4 mm.
    assert!(
        worst(&frozen) > 1e-6 && worst(&frozen) < 1e-3,
        "frozen-frame gap {}",
        worst(&frozen)
    );
    assert!(
        exact.symbolic_analyses() == 1,
        "one symbolic analysis for the whole run"
    );
}

/// The default r of a tool added without one: a tenth (`r_fraction`) of the membrane
/// stiffness under each node under the augmented Lagrangian, the membrane stiffness itself
/// under penalty (where r sets the penetration), another fraction when the setting asks;
/// a value the user gave is kept whatever the enforcement. The block's cubes have side
/// 2.5 x 2.5 x 1 (4 x 4 x 2 cells of 10 x 10 x 2): membrane stiffness E h = 1000 at
/// interior face nodes of its bottom (h = 1), half on edges, a quarter at corners.
#[test]
fn default_r_is_a_fraction_of_the_membrane_stiffness_under_the_augmented_lagrangian() {
    let with = |enforcement: Enforcement, fraction: Option<f64>, r: Option<f64>| -> Vec<f64> {
        let mesh = Mesh::block(Vec3::zeros(), Vec3::new(10.0, 10.0, 2.0), [4, 4, 2]).unwrap();
        let mut model = Model::new(mesh, common::elastic(1000.0, 0.3)).unwrap();
        let plane = Plane::new(Vec3::zeros(), Vec3::z()).unwrap();
        model
            .add_tool(
                common::tool("floor", plane, &[(0.0, [0.0; 3])], MU),
                "z-",
                r,
            )
            .unwrap();
        model.settings.contact.enforcement = enforcement;
        if let Some(f) = fraction {
            model.settings.contact.r_fraction = f;
        }
        Simulation::new(model).unwrap().model.contacts[0].r.clone()
    };
    let largest = |r: &[f64]| r.iter().cloned().fold(0.0, f64::max);
    let smallest = |r: &[f64]| r.iter().cloned().fold(f64::INFINITY, f64::min);
    let al = with(Enforcement::AugmentedLagrangian, None, None);
    assert!((largest(&al) - 100.0).abs() < 1e-9, "{al:?}");
    assert!((smallest(&al) - 25.0).abs() < 1e-9, "{al:?}");
    let penalty = with(Enforcement::Penalty, None, None);
    assert!((largest(&penalty) - 1000.0).abs() < 1e-9, "{penalty:?}");
    let half = with(Enforcement::AugmentedLagrangian, Some(0.5), None);
    assert!((largest(&half) - 500.0).abs() < 1e-9, "{half:?}");
    for enforcement in [Enforcement::AugmentedLagrangian, Enforcement::Penalty] {
        let given = with(enforcement, Some(0.5), Some(7.0));
        assert!(given.iter().all(|&r| r == 7.0), "{given:?}");
    }
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
    let mut model = Model::new(mesh, common::elastic(1000.0, 0.3)).unwrap();
    model.settings.contact.r_fraction = 0.0;
    let err = Simulation::new(model)
        .err()
        .expect("r_fraction 0 is refused");
    assert!(err.to_string().contains("r_fraction"), "{err}");
}
