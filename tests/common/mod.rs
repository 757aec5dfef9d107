//! Shared set-up for the integration tests.
#![allow(dead_code)]

use std::sync::Arc;
use tribo::contact::FrictionLaw;
use tribo::geometry::{RigidSurface, Vec3};
use tribo::material::{LinearElastic, Material};
use tribo::tool::schedule::Schedule;
use tribo::tool::Tool;

pub fn elastic(young: f64, poisson: f64) -> Arc<dyn Material> {
    Arc::new(LinearElastic::new(young, poisson).unwrap())
}

pub fn tool(
    name: &str,
    surface: impl RigidSurface + 'static,
    path: &[(f64, [f64; 3])],
    mu: f64,
) -> Tool {
    let mut t = Tool::new(name, Arc::new(surface));
    t.schedule = Schedule::new(
        path.iter()
            .map(|(t, d)| (*t, Vec3::new(d[0], d[1], d[2])))
            .collect(),
    )
    .unwrap();
    t.friction = FrictionLaw::coulomb(mu).unwrap();
    t
}

/// Observed orders p_k = log(r_{k+1}/r_k) / log(r_k/r_{k-1}) over consecutive residuals,
/// keeping only triples above `floor` (below it round-off dominates).
pub fn convergence_orders(residuals: &[f64], floor: f64) -> Vec<f64> {
    let r: Vec<f64> = residuals.iter().copied().filter(|&x| x > floor).collect();
    r.windows(3)
        .filter(|w| w[0] != w[1])
        .map(|w| (w[2] / w[1]).ln() / (w[1] / w[0]).ln())
        .collect()
}

/// A rigid cylinder (radius 5, axis along y) over an elastic block `length` x 1 x `depth`
/// (E = 1000, nu = 0.3, plane strain, glued to the ground) with `cells` cells along x and
/// `cells * depth / length` through the depth; the cylinder starts 0.02 above the block at
/// x = length / 4, presses 0.1 into it over t in [0, 1] and is dragged by `drag` in x over
/// t in [1, 3], with Coulomb friction 0.2.
pub fn cylinder_drag_model(
    length: f64,
    depth: f64,
    cells: usize,
    drag: f64,
) -> tribo::solver::Model {
    use tribo::geometry::Cylinder;
    use tribo::tool::ScalarSchedule;
    let radius = 5.0;
    let size = Vec3::new(length, 1.0, depth);
    let mesh = tribo::mesh::Mesh::block(
        Vec3::zeros(),
        size,
        [cells, 1, (cells as f64 * depth / length) as usize],
    )
    .unwrap();
    let mut model = tribo::solver::Model::new(mesh, elastic(1000.0, 0.3)).unwrap();
    let axis = Vec3::new(length / 4.0, 0.0, depth + radius + 0.02);
    let cyl = Cylinder::new(axis, Vec3::y(), radius).unwrap();
    let path = [
        (0.0, [0.0; 3]),
        (1.0, [0.0, 0.0, -0.12]),
        (3.0, [drag, 0.0, -0.12]),
    ];
    model
        .add_tool(tool("roller", cyl, &path, 0.2), "z+", None)
        .unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe("y-", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe("y+", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.end_time = 3.0;
    model
}
