//! Times the sparse LU on the Jacobian of the cylinder-drag case:
//! `cargo run --release --example bench_linear -- CELLS`.
use std::sync::Arc;
use std::time::Instant;
use tribo::contact::FrictionLaw;
use tribo::geometry::{Cylinder, Vec3};
use tribo::material::LinearElastic;
use tribo::mesh::Mesh;
use tribo::solver::linear::{FaerLu, LinearSolver, LuKernel};
use tribo::solver::{Model, Simulation};
use tribo::tool::{ScalarSchedule, Schedule, Tool};
fn main() {
    let cells: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(32);
    let mesh = Mesh::block(
        Vec3::zeros(),
        Vec3::new(16.0, 1.0, 4.0),
        [cells, 1, cells / 4],
    )
    .unwrap();
    let mut model = Model::new(mesh, Arc::new(LinearElastic::new(1000.0, 0.3).unwrap())).unwrap();
    let cyl = Cylinder::new(Vec3::new(4.0, 0.0, 9.02), Vec3::y(), 5.0).unwrap();
    let mut t = Tool::new("r", Arc::new(cyl));
    t.schedule = Schedule::new(vec![
        (0.0, Vec3::zeros()),
        (1.0, Vec3::new(0.0, 0.0, -0.12)),
    ])
    .unwrap();
    t.friction = FrictionLaw::coulomb(0.2).unwrap();
    model.add_tool(t, "z+", None).unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    if std::env::var("PENALTY").is_ok() {
        model.settings.contact.enforcement = tribo::contact::Enforcement::Penalty;
    }
    let sim = Simulation::new(model).unwrap();
    let e = sim.evaluate_at(0.5, sim.unknowns()).unwrap();
    println!(
        "n = {}, nnz = {}",
        e.jacobian.pattern.n,
        e.jacobian.pattern.nnz()
    );
    for kernel in [LuKernel::Auto, LuKernel::Simplicial, LuKernel::Supernodal] {
        let mut lu = FaerLu::with_kernel(kernel);
        let mut b = e.residual.clone();
        let t0 = Instant::now();
        lu.solve(&e.jacobian, &mut b).unwrap();
        let first = t0.elapsed().as_secs_f64() * 1e3;
        let reps = 10;
        let t1 = Instant::now();
        for _ in 0..reps {
            let mut b = e.residual.clone();
            lu.solve(&e.jacobian, &mut b).unwrap();
        }
        let each = t1.elapsed().as_secs_f64() * 1e3 / reps as f64;
        println!("{kernel:?}: first solve (symbolic + numeric) {first:.2} ms, then {each:.2} ms per factorization and solve");
    }
}
