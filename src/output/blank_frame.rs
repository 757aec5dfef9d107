//! The blank's VTK frame at the committed state: points, cells and the fields listed in
//! docs/fields.md (names, units, signs and the categorical codes of `contact_status`).
//!
//! Points are those of the current configuration (reference + displacement) by default, so
//! that ParaView shows the deformed part without a Warp By Vector; `displacement` is written
//! alongside, so the reference configuration is `points - displacement`. The setting
//! `frame_points: "reference"` writes the reference coordinates instead (one mesh for every
//! frame, for Warp By Vector with a chosen scale). Cost: O(nodes + contact pairs + points).

use super::formability::FormabilityOptions;
use super::{Field, Frame};
use crate::contact::ContactStatus;
use crate::element::StrainTheory;
use crate::geometry::Vec3;
use crate::solver::Simulation;
use crate::{Error, Result};

/// Where the points of a frame or a chart are placed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Configuration {
    Reference,
    #[default]
    Current,
}

impl Configuration {
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "reference" => Ok(Configuration::Reference),
            "current" => Ok(Configuration::Current),
            other => Err(Error::input(
                "configuration",
                format!("\"{other}\""),
                "must be \"reference\" or \"current\"",
            )),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Configuration::Reference => "reference",
            Configuration::Current => "current",
        }
    }

    /// The position of a node at `reference` with displacement `u` in this configuration.
    pub fn place(self, reference: &Vec3, u: &[f64]) -> [f64; 3] {
        match self {
            Configuration::Reference => [reference.x, reference.y, reference.z],
            Configuration::Current => [reference.x + u[0], reference.y + u[1], reference.z + u[2]],
        }
    }
}

/// Per-node contact values: of all tools touching a node, the one pressing it hardest
/// (most negative lambda_n, then smallest gap) gives the status, gap, forces, pressure,
/// mu, theta and slip vector; work and flips add up over the tools, the accumulated slip
/// is the largest.
struct NodalContact {
    status: Vec<f64>,
    gap: Vec<f64>,
    lambda_n: Vec<f64>,
    lambda_t: Vec<f64>,
    tangential_force: Vec<[f64; 3]>,
    slip_increment: Vec<[f64; 3]>,
    pressure: Vec<f64>,
    work: Vec<f64>,
    slip: Vec<f64>,
    mu: Vec<f64>,
    theta: Vec<f64>,
    flips: Vec<f64>,
}

fn nodal_contact(sim: &Simulation, only: Option<usize>) -> NodalContact {
    let n = sim.model.mesh.nodes.len();
    let mut out = NodalContact {
        status: vec![0.0; n],
        gap: vec![f64::NAN; n],
        lambda_n: vec![0.0; n],
        lambda_t: vec![0.0; n],
        tangential_force: vec![[0.0; 3]; n],
        slip_increment: vec![[0.0; 3]; n],
        pressure: vec![0.0; n],
        work: vec![0.0; n],
        slip: vec![0.0; n],
        mu: vec![0.0; n],
        theta: vec![0.0; n],
        flips: vec![0.0; n],
    };
    for (c, contact) in sim.model.contacts.iter().enumerate() {
        if only.is_some_and(|o| o != c) {
            continue;
        }
        for (k, s) in sim.contact_states(c).iter().enumerate() {
            let node = contact.candidates[k];
            let ln = s.lambda_n();
            let first = out.gap[node].is_nan();
            if first
                || ln < out.lambda_n[node]
                || (ln == out.lambda_n[node] && s.gap < out.gap[node])
            {
                out.status[node] = s.status.code();
                out.gap[node] = s.gap;
                out.lambda_n[node] = ln;
                out.lambda_t[node] = s.lambda_t_norm();
                let t = s.lambda - s.normal * ln;
                out.tangential_force[node] = [t.x, t.y, t.z];
                let d = s.slip_increment;
                out.slip_increment[node] = [d.x, d.y, d.z];
                out.pressure[node] = if s.status == ContactStatus::Gap {
                    0.0
                } else {
                    -ln / contact.areas[k].max(f64::MIN_POSITIVE)
                };
                out.mu[node] = s.mu;
                out.theta[node] = s.theta;
            }
            out.flips[node] += s.flips as f64;
            out.work[node] += s.work;
            out.slip[node] = f64::max(out.slip[node], s.slip);
        }
    }
    for g in out.gap.iter_mut().filter(|g| g.is_nan()) {
        *g = 0.0;
    }
    out
}

/// The committed state as a VTK frame, points in `configuration`: displacement and contact
/// fields on the nodes (and, for sheet meshes with through-thickness columns, the current
/// thickness, the thickness strain ln(t/t0) and the formability fields of each column on
/// its nodes, with the default curve and thresholds),
/// element-averaged Cauchy stress (components named xx, yy, zz, xy, yz, xz), von Mises
/// stress (of that mean), the mean of the points' equivalent stress of the material's
/// yield function (Hill48's `φ` of the stress the material works in, which plastic points
/// keep at the yield stress;
/// [`Material::equivalent_stress`](crate::material::Material::equivalent_stress)) and equivalent plastic
/// strain on the cells; for solid-shell models also the values
/// at the faces and the mid-surface (`shell_layers`).
pub fn frame(sim: &Simulation, configuration: Configuration) -> Frame {
    frame_against(sim, configuration, None, &FormabilityOptions::default())
}

/// As [`frame`], with the contact fields of tool `only` alone when given (a chart of the
/// punch side shows the punch's work, not the holder's), and the formability fields
/// (`thinning`, `major_strain`, ..., formability/) of `formability`'s curve and thresholds.
pub fn frame_against(
    sim: &Simulation,
    configuration: Configuration,
    only: Option<usize>,
    formability: &FormabilityOptions,
) -> Frame {
    let mesh = &sim.model.mesh;
    let n = mesh.nodes.len();
    let u = sim.displacements();
    let contact = nodal_contact(sim, only);
    let per = sim.points().len() / mesh.hexes.len().max(1);
    let mut stress = vec![0.0; 6 * mesh.hexes.len()];
    let mut von_mises = vec![0.0; mesh.hexes.len()];
    let mut eq_plastic = vec![0.0; mesh.hexes.len()];
    let mut equivalent = vec![0.0; mesh.hexes.len()];
    let finite = sim.model.settings.kinematics == StrainTheory::Finite;
    let material = &sim.model.material;
    for e in 0..mesh.hexes.len() {
        let pts = &sim.points()[e * per..(e + 1) * per];
        for p in pts {
            for i in 0..6 {
                stress[6 * e + i] += p.stress[i] / per as f64;
            }
            eq_plastic[e] += p.eq_plastic_strain / per as f64;
            equivalent[e] += material.equivalent_stress(p, finite) / per as f64;
        }
        let s = &stress[6 * e..6 * e + 6];
        von_mises[e] = (0.5
            * ((s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2))
            + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))
            .sqrt();
    }
    // Sheet thickness per through-thickness column, on the column's nodes, and the
    // formability fields (formability/).
    let mut sheet_fields = Vec::new();
    if let Some(f) = super::formability::evaluate(sim, formability) {
        let mut thickness = vec![0.0; n];
        let mut thickness_strain = vec![0.0; n];
        for (k, col) in mesh.columns().iter().enumerate() {
            for &node in col {
                thickness[node] = f.columns.thickness[k];
                thickness_strain[node] =
                    (f.columns.thickness[k] / f.columns.initial_thickness[k]).ln();
            }
        }
        sheet_fields.push(Field::scalar("thickness", thickness));
        sheet_fields.push(Field::scalar("thickness_strain", thickness_strain));
        sheet_fields.extend(super::formability::fields(&f, n, mesh.columns()));
    }
    Frame {
        points: (mesh.nodes.iter().enumerate())
            .map(|(i, p)| configuration.place(p, &u[3 * i..3 * i + 3]))
            .collect(),
        hexes: mesh.hexes.clone(),
        quads: Vec::new(),
        triangles: Vec::new(),
        point_data: vec![
            Field::new("displacement", 3, u.to_vec()),
            Field::scalar("contact_status", contact.status),
            Field::scalar("gap", contact.gap),
            Field::scalar("lambda_n", contact.lambda_n),
            Field::scalar("lambda_t_norm", contact.lambda_t),
            Field::vector("tangential_force", &contact.tangential_force),
            Field::vector("slip_increment", &contact.slip_increment),
            Field::scalar("contact_pressure", contact.pressure),
            Field::scalar("frictional_work", contact.work),
            Field::scalar("accumulated_slip", contact.slip),
            Field::scalar("mu", contact.mu),
            Field::scalar("theta", contact.theta),
            Field::scalar("stick_slip_flips", contact.flips),
        ]
        .into_iter()
        .chain(sheet_fields)
        .collect(),
        cell_data: vec![
            Field::symmetric_tensor("stress", stress),
            Field::scalar("von_mises", von_mises),
            Field::scalar("equivalent_stress", equivalent),
            Field::scalar("equivalent_plastic_strain", eq_plastic),
        ]
        .into_iter()
        .chain(super::shell_layers::cell_fields(sim))
        .collect(),
    }
}
