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
