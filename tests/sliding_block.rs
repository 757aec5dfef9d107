//! An elastic block pressed on a rigid plane by a total force N and dragged along it.
//! Coulomb's law with the augmented Lagrangian is exact at convergence: once every contact
//! node slips, the tangential reaction is mu N to solver precision; well below the slip
//! threshold every node sticks.

mod common;

use tribo::contact::ContactStatus;
use tribo::geometry::{Plane, Vec3};
use tribo::mesh::Mesh;
use tribo::solver::{Model, Simulation};
use tribo::tool::schedule::ScalarSchedule;

const N: f64 = 100.0;
const MU: f64 = 0.3;

fn block_on_plane(drag: &[(f64, f64)], increments: usize, poisson: f64) -> Simulation {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(10.0, 10.0, 2.0), [4, 4, 2]).unwrap();
    let mut model = Model::new(mesh, common::elastic(1000.0, poisson)).unwrap();
    let plane = Plane::new(Vec3::zeros(), Vec3::z()).unwrap();
    model
        .add_tool(
            common::tool("floor", plane, &[(0.0, [0.0; 3])], MU),
            "z-",
            None,
        )
        .unwrap();
    model
        .add_load(
            "z+",
            Vec3::new(0.0, 0.0, -N),
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 1.0)]).unwrap(),
        )
        .unwrap();
    model
        .prescribe("z+", "x", ScalarSchedule::new(drag.to_vec()).unwrap())
        .unwrap();
    model
        .prescribe("z+", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.end_time = drag.last().unwrap().0;
    model.settings.increments = increments;
    model.settings.force_rel_tol = 1e-12;
    model.settings.contact_tol = 1e-12;
    Simulation::new(model).unwrap()
}

#[test]
fn full_slip_gives_tangential_reaction_mu_n() {
    // Load to N over t in [0, 1] without drag, then drag 0.5 mm, some 300 times the slip
    // onset displacement mu N h / (G A) ~ 1.6e-3 mm, so that the transverse slip left over
    // from the Poisson expansion under load has died out.
    let mut sim = block_on_plane(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.5)], 8, 0.3);
    sim.run(|_, _| Ok(())).unwrap();
    let f = sim.tool_force(0);
    let states = sim.contact_states(0);
    assert!(
        states.iter().all(|s| s.status == ContactStatus::Slip),
        "every contact node slips"
    );
    assert!(
        (-f.z - N).abs() <= 1e-8 * N,
        "normal reaction {} against N = {N}",
        -f.z
    );
    assert!(
        (f.x - MU * N).abs() <= 1e-8 * MU * N,
        "tangential reaction {} against mu N = {}",
        f.x,
        MU * N
    );
    println!(
        "normal {:.12e}  tangential {:.12e}  ratio {:.12e}",
        -f.z,
        f.x,
        f.x / -f.z
    );
}

#[test]
fn below_the_slip_threshold_every_node_sticks() {
    // A drag of 1e-4 mm loads the interface to about 6% of mu N. With nu = 0 the block
    // does not expand sideways under the normal load (with nu = 0.3 the corner nodes slip
    // outward while the load comes on: partial slip, physically right but not this check).
    let mut sim = block_on_plane(&[(0.0, 0.0), (1.0, 0.0), (2.0, 1e-4)], 4, 0.0);
    sim.run(|_, _| Ok(())).unwrap();
    let f = sim.tool_force(0);
    assert!(
        f.x > 0.0 && f.x < 0.2 * MU * N,
        "tangential reaction {} well below mu N",
        f.x
    );
    let states = sim.contact_states(0);
    assert!(
        states.iter().all(|s| s.status == ContactStatus::Stick),
        "every contact node sticks"
    );
    // Every node's own friction criterion holds strictly.
    for s in states {
        assert!(s.lambda_t_norm() < -MU * s.lambda_n());
    }
}
