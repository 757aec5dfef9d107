//! The verification scenes of the study, built with the library API (the same set-ups as
//! `tests/hertz.rs`, `tests/friction_work.rs` and `tests/cylinder_drag_newton.rs`), and the
//! quantities each run reports. Every builder takes a [`Variant`]: mesh, increments and the
//! method switches; the measures live in `work_precision`.

use super::Variant;
use crate::contact::{BernsteinLaw, FrictionLaw, WorkMeasure};
use crate::geometry::{Cylinder, Plane, RigidSurface, Vec3};
use crate::material::LinearElastic;
use crate::mesh::{End, Grading, Mesh};
use crate::solver::{Model, Simulation};
use crate::tool::{ScalarSchedule, Schedule, Tool};
use crate::{Error, Result};
use std::sync::Arc;

fn tool(
    name: &str,
    surface: impl RigidSurface + 'static,
    path: &[(f64, [f64; 3])],
) -> Result<Tool> {
    let mut t = Tool::new(name, Arc::new(surface));
    t.schedule = Schedule::new(
        path.iter()
            .map(|(t, d)| (*t, Vec3::new(d[0], d[1], d[2])))
            .collect(),
    )?;
    Ok(t)
}

/// Applies the variant's method switches, and its augmentation (or penalty) parameter as a
/// multiple `r_factor` of the engine's default r of every contact node.
/// Every run uses one element thread, so that wall times measure work and not how many
/// cores happened to be free.
fn apply(model: &mut Model, v: &Variant) {
    model.settings.threads = 1;
    model.settings.contact = v.contact;
    model.settings.stepping.line_search = v.line_search;
    model.settings.stepping.anti_cycling = v.anti_cycling;
    for c in &mut model.contacts {
        c.r.iter_mut().for_each(|r| *r *= v.r_factor);
    }
}

// ---- Hertz line contact ------------------------------------------------------------------

/// Young's modulus, Poisson's ratio, cylinder radius, block size and indentation of the
/// Hertz case (as in `tests/hertz.rs`: a/R = 0.003, block 25 half-widths wide and deep).
pub const HERTZ_E: f64 = 1000.0;
pub const HERTZ_NU: f64 = 0.3;
pub const HERTZ_R: f64 = 500.0;
const HERTZ_SIZE: f64 = 40.0;
const HERTZ_INDENT: f64 = 0.01;

/// What a Hertz run measured: the half-width a (least-squares fit of the elliptic profile)
/// and the peak pressure p0, each with its closed-form value for the computed load.
#[derive(Clone, Copy, Debug)]
pub struct HertzMeasure {
    pub a_fem: f64,
    pub a_exact: f64,
    pub p0_fem: f64,
    pub p0_exact: f64,
}

/// A rigid cylinder pressed into an elastic block in plane strain, half model, mesh graded
/// toward the contact (`v.cells` cells along x and z, smallest cell 1/40 of the largest).
pub fn hertz(v: &Variant) -> Result<(Simulation, HertzMeasure)> {
    let toward = |end| Grading::Toward { end, ratio: 40.0 };
    let mesh = Mesh::block_graded(
        Vec3::zeros(),
        Vec3::new(HERTZ_SIZE, 1.0, HERTZ_SIZE),
        [v.cells, 1, v.cells],
        [toward(End::Min), Grading::Uniform, toward(End::Max)],
    )?;
    let mut model = Model::new(mesh, Arc::new(LinearElastic::new(HERTZ_E, HERTZ_NU)?))?;
    let axis = Vec3::new(0.0, 0.0, HERTZ_SIZE + HERTZ_R);
    let cyl = Cylinder::new(axis, Vec3::y(), HERTZ_R)?;
    let path = [(0.0, [0.0; 3]), (1.0, [0.0, 0.0, -HERTZ_INDENT])];
    model.add_tool(tool("cylinder", cyl, &path)?, "z+", None)?;
    let zero = ScalarSchedule::constant(0.0);
    model.prescribe("z-", "xyz", zero.clone())?;
    model.prescribe("x-", "x", zero.clone())?;
    model.prescribe("y-", "y", zero.clone())?;
    model.prescribe("y+", "y", zero)?;
    model.settings.increments = v.increments;
    apply(&mut model, v);
    let mut sim = Simulation::new(model)?;
    sim.run(|_, _| Ok(()))?;
    let m = hertz_measure(&sim)?;
    Ok((sim, m))
}

/// Closed form for the computed load P per unit length (twice the half model's):
/// a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a), E* = E / (1 - nu^2). The FE half-width is
/// the least-squares fit of p^2 = p0^2 (1 - x^2/a^2) to the nodal pressures lambda_n / A of
/// the active nodes of the y = 0 row, leaving out the outermost one (its tributary strip
/// straddles the edge); the FE peak pressure is the pressure at x = 0. For the Hertz
/// scene's constants (any mesh of it, analytic or Bezier cylinder).
pub fn hertz_measure(sim: &Simulation) -> Result<HertzMeasure> {
    let p = 2.0 * sim.tool_force(0).z;
    let e_star = HERTZ_E / (1.0 - HERTZ_NU * HERTZ_NU);
    let a_exact = (4.0 * p * HERTZ_R / (std::f64::consts::PI * e_star)).sqrt();
    let p0_exact = 2.0 * p / (std::f64::consts::PI * a_exact);
    let contact = &sim.model.contacts[0];
    let mut profile: Vec<(f64, f64, bool)> = contact
        .candidates
        .iter()
        .zip(sim.contact_states(0))
        .zip(&contact.areas)
        .filter(|((&n, _), _)| sim.model.mesh.nodes[n].y == 0.0)
        .map(|((&n, s), &area)| {
            (
                sim.model.mesh.nodes[n].x,
                -s.lambda_n() / area,
                s.status.is_active(),
            )
        })
        .collect();
    profile.sort_by(|a, b| a.0.total_cmp(&b.0));
    let active: Vec<(f64, f64)> = profile
        .iter()
        .filter(|q| q.2 && q.1 > 0.0)
        .map(|q| (q.0, q.1))
        .collect();
    if active.len() < 4 {
        return Err(Error::no_convergence(
            crate::error::Failure::Unrecoverable,
            format!(
                "Hertz: only {} node(s) in contact, too few to fit the pressure profile",
                active.len()
            ),
        ));
    }
    let fit = &active[..active.len() - 1];
    let (mut sx, mut sy, mut sxx, mut sxy) = (0.0, 0.0, 0.0, 0.0);
    for &(x, pr) in fit {
        let (u, w) = (x * x, pr * pr);
        sx += u;
        sy += w;
        sxx += u * u;
        sxy += u * w;
    }
    let m = fit.len() as f64;
    let slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
    let intercept = (sy - slope * sx) / m;
    Ok(HertzMeasure {
        a_fem: (-intercept / slope).sqrt(),
        a_exact,
        p0_fem: profile[0].1,
        p0_exact,
    })
}

// ---- the frictional-work ODE --------------------------------------------------------------

/// Total normal force, slide distance, the paper's Bernstein control points and the cut-off
/// work of the frictional-work case (as in `tests/friction_work.rs`).
pub const ODE_N: f64 = 100.0;
pub const ODE_SLIDE: f64 = 10.0;
pub const ODE_POINTS: [f64; 4] = [0.16, 0.16, 0.01, 0.01];
pub const ODE_WORK_CUT: f64 = 50.0;

pub fn ode_law() -> Result<BernsteinLaw> {
    BernsteinLaw::new(ODE_POINTS.to_vec(), ODE_WORK_CUT, WorkMeasure::PerNode)
}

/// A 2 x 2 x 1 column whose nodes all follow a rigid slide along x, pressed on a rigid plane
/// by `ODE_N` over t in [0, 1] and slid `ODE_SLIDE` over t in [1, 2] in `v.increments`
/// increments (plus as many for the press): every bottom node slips exactly by the slide and
/// carries N A_node / A, so its work obeys dPsi/ds = mu(Psi) N_node. Returns the work of the
/// corner node at the origin (force [`corner_force`]).
pub fn friction_work(v: &Variant) -> Result<(Simulation, f64)> {
    let mesh = Mesh::block(
        Vec3::zeros(),
        Vec3::new(2.0, 2.0, 1.0),
        [v.cells, v.cells, 1],
    )?;
    let mut model = Model::new(mesh, Arc::new(LinearElastic::new(10000.0, 0.0)?))?;
    let mut floor = Tool::new("floor", Arc::new(Plane::new(Vec3::zeros(), Vec3::z())?));
    floor.friction = FrictionLaw::Bernstein(ode_law()?);
    model.add_tool(floor, "z-", None)?;
    let ramp = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 1.0)])?;
    model.add_load("z+", Vec3::new(0.0, 0.0, -ODE_N), ramp)?;
    let everything = model.mesh.select_nodes(|_| true);
    model.mesh.add_node_set("all", everything)?;
    let slide = ScalarSchedule::new(vec![(0.0, 0.0), (1.0, 0.0), (2.0, ODE_SLIDE)])?;
    model.prescribe("all", "x", slide)?;
    model.prescribe("all", "y", ScalarSchedule::constant(0.0))?;
    model.settings.end_time = 2.0;
    model.settings.increments = 2 * v.increments;
    model.settings.force_rel_tol = 1e-13;
    model.settings.contact_tol = 1e-13;
    apply(&mut model, v);
    let mut sim = Simulation::new(model)?;
    sim.run(|_, _| Ok(()))?;
    let contact = &sim.model.contacts[0];
    let corner = contact
        .candidates
        .iter()
        .position(|&n| sim.model.mesh.nodes[n].norm() < 1e-12)
        .ok_or_else(|| {
            Error::Input("friction-work column: no contact node at the origin".into())
        })?;
    let work = sim.contact_states(0)[corner].work;
    Ok((sim, work))
}

/// Nodal force of the corner node of a `cells` x `cells` column (its quarter-cell share).
pub fn corner_force(cells: usize) -> f64 {
    let n = cells as f64;
    ODE_N / (4.0 * n * n)
}

/// Psi(s) of dPsi/ds = mu(Psi) n_node over the slide by classical RK4, sampled at
/// `samples` + 1 equally spaced points, `steps` RK4 steps between samples.
pub fn ode_work(n_node: f64, samples: usize, steps: usize) -> Result<Vec<f64>> {
    let law = ode_law()?;
    let f = |psi: f64| law.mu(psi, 1.0) * n_node;
    let h = ODE_SLIDE / (samples * steps) as f64;
    let mut psi = 0.0;
    let mut out = vec![0.0];
    for _ in 0..samples {
        for _ in 0..steps {
            let k1 = f(psi);
            let k2 = f(psi + 0.5 * h * k1);
            let k3 = f(psi + 0.5 * h * k2);
            let k4 = f(psi + h * k3);
            psi += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        out.push(psi);
    }
    Ok(out)
}

/// Psi(ODE_SLIDE) with 10^5 RK4 steps (error ~ h^4 ~ 1e-20 relative: exact for the study).
pub fn ode_exact(n_node: f64) -> Result<f64> {
    Ok(ode_work(n_node, 1, 100_000)?[1])
}

// ---- cylinder drag --------------------------------------------------------------------------

/// Length, depth, cylinder radius and drag distance of the drag case (as
/// `scripts/cylinder_drag.rhai` and `tests/cylinder_drag_newton.rs`).
const DRAG_LENGTH: f64 = 16.0;
const DRAG_DEPTH: f64 = 4.0;
const DRAG_RADIUS: f64 = 5.0;
pub const DRAG_DISTANCE: f64 = 8.0;

/// A rigid cylinder (R = 5) pressed 0.1 into an elastic block 16 x 1 x 4 (E = 1000,
/// nu = 0.3, plane strain, glued to the ground) over t in [0, 1] and dragged 8 (four
/// contact widths) over t in [1, 3] with Coulomb friction `mu`; `v.increments` equal
/// increments over [0, 3], `v.cells` cells along x (a quarter of them through the depth).
/// `max_iterations` and `max_cutbacks` as given (the stability map uses no cutbacks, so
/// that a step size either works or fails).
pub fn cylinder_drag(
    v: &Variant,
    mu: f64,
    max_iterations: usize,
    max_cutbacks: usize,
) -> Result<Simulation> {
    let mesh = Mesh::block(
        Vec3::zeros(),
        Vec3::new(DRAG_LENGTH, 1.0, DRAG_DEPTH),
        [v.cells, 1, (v.cells / 4).max(1)],
    )?;
    let mut model = Model::new(mesh, Arc::new(LinearElastic::new(1000.0, 0.3)?))?;
    let axis = Vec3::new(DRAG_LENGTH / 4.0, 0.0, DRAG_DEPTH + DRAG_RADIUS + 0.02);
    let cyl = Cylinder::new(axis, Vec3::y(), DRAG_RADIUS)?;
    let path = [
        (0.0, [0.0; 3]),
        (1.0, [0.0, 0.0, -0.12]),
        (3.0, [DRAG_DISTANCE, 0.0, -0.12]),
    ];
    let mut roller = tool("roller", cyl, &path)?;
    roller.friction = FrictionLaw::coulomb(mu)?;
    model.add_tool(roller, "z+", None)?;
    let zero = ScalarSchedule::constant(0.0);
    model.prescribe("z-", "xyz", zero.clone())?;
    model.prescribe("y-", "y", zero.clone())?;
    model.prescribe("y+", "y", zero)?;
    model.settings.end_time = 3.0;
    model.settings.increments = v.increments;
    model.settings.max_iterations = max_iterations;
    model.settings.max_cutbacks = max_cutbacks;
    apply(&mut model, v);
    Simulation::new(model)
}
