//! What a forming engineer reads first: per node of the sheet, the thickness, thinning,
//! in-plane principal strains of the mid-surface, their ratio, the margin to the forming
//! limit curve and the formability zone; and the part's summary (largest thinning, smallest
//! margin, nodes per zone).
//!
//! # Mathematics
//!
//! Per through-thickness column ([`Mesh::columns`](crate::mesh::Mesh::columns)):
//! `major_strain` `ε1` and `minor_strain` `ε2` are the principal logarithmic strains of the
//! mid-surface (`mid_surface.rs`), `thickness` `t` the column's current length,
//! `thinning = 100 (1 - t / t0)` in percent, `strain_ratio = ε2 / ε1` (0 where `ε1 = 0`),
//! `flc_margin = ε1*(ε2) - ε1` against the curve of `flc.rs`, and `formability` the zone
//! code of `flc.rs`. Every node of a column carries its column's values. A mesh without
//! columns has none of these fields.
//!
//! The curve is the script's table (setting `flc`), else Keeler-Brazier from the material's
//! Swift exponent and the mean initial thickness of the columns, converted to mm from the
//! script's `units.length` (m, cm, mm, um, in; none set: mm); a model in a unit not listed
//! gives a table. Without a curve there is no `flc_margin` and no crack or risk zone, and
//! summary.json's `flc` says why.

mod flc;
mod mid_surface;

pub use flc::{zone, Flc, SheetPoint, Thresholds, Zone};
pub use mid_surface::{column_strains, mid_surface_quads, principal_strains, ColumnStrains};

use super::Field;
use crate::solver::Simulation;

/// The formability settings of a run: the script's curve (None: Keeler-Brazier when the
/// material has a Swift law) and the zone thresholds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FormabilityOptions {
    pub flc: Option<Flc>,
    pub thresholds: Thresholds,
    /// The script's length unit (`units.length`, "" when none was set: mm).
    pub length_unit: String,
}

/// The formability of every column and its nodes.
#[derive(Clone, Debug)]
pub struct Formability {
    /// The curve, or why there is none.
    pub flc: std::result::Result<Flc, String>,
    pub columns: ColumnStrains,
    /// Per column: margin (NaN without a curve) and zone.
    pub margin: Vec<f64>,
    pub zone: Vec<Zone>,
}

impl Formability {
    /// `100 (1 - t / t0)` of column `c`.
    pub fn thinning(&self, c: usize) -> f64 {
        100.0 * (1.0 - self.columns.thickness[c] / self.columns.initial_thickness[c])
    }

    /// `ε2 / ε1` of column `c` (0 where `ε1 = 0`).
    pub fn strain_ratio(&self, c: usize) -> f64 {
        let (e1, e2) = (self.columns.major[c], self.columns.minor[c]);
        if e1 == 0.0 {
            0.0
        } else {
            e2 / e1
        }
    }
}

/// The curve a run uses (module doc), or why there is none.
pub fn curve(sim: &Simulation, options: &FormabilityOptions) -> std::result::Result<Flc, String> {
    if let Some(flc) = &options.flc {
        return Ok(flc.clone());
    }
    let n = (sim.model.material.hardening_exponent()).ok_or_else(|| {
        "no curve: the material has no Swift law for Keeler-Brazier; give the setting flc"
            .to_string()
    })?;
    let mm = Flc::millimetres_per(&options.length_unit).ok_or_else(|| {
        format!(
            "no curve: Keeler-Brazier needs the thickness in mm and the length unit '{}' is \
             not one of m, cm, mm, um, in; give the setting flc",
            options.length_unit
        )
    })?;
    let mesh = &sim.model.mesh;
    let t0 = mesh.column_thicknesses(|_| crate::geometry::Vec3::zeros());
    if t0.is_empty() {
        return Err("no curve: the mesh has no through-thickness columns".into());
    }
    let mean = t0.iter().sum::<f64>() / t0.len() as f64;
    Flc::keeler_brazier(n, mean * mm).map_err(|e| format!("no curve: {e}"))
}

/// The formability of the committed state, None for a mesh without columns.
pub fn evaluate(sim: &Simulation, options: &FormabilityOptions) -> Option<Formability> {
    let mesh = &sim.model.mesh;
    if mesh.columns().is_empty() {
        return None;
    }
    let flc = curve(sim, options);
    let columns = column_strains(mesh, sim.displacements());
    let mut out = Formability {
        flc,
        margin: Vec::with_capacity(columns.major.len()),
        zone: Vec::with_capacity(columns.major.len()),
        columns,
    };
    for c in 0..out.columns.major.len() {
        let (major, minor) = (out.columns.major[c], out.columns.minor[c]);
        let margin = out.flc.as_ref().ok().map(|f| f.margin(major, minor));
        let point = SheetPoint {
            major,
            minor,
            thickness_strain: (out.columns.thickness[c] / out.columns.initial_thickness[c]).ln(),
            thinning_pct: out.thinning(c),
        };
        out.zone.push(zone(&point, margin, &options.thresholds));
        out.margin.push(margin.unwrap_or(f64::NAN));
    }
    Some(out)
}

/// The frame's point fields (names of docs/fields.md), each node carrying its column's
/// values (0 at a node in no column).
pub fn fields(f: &Formability, node_count: usize, columns: &[Vec<usize>]) -> Vec<Field> {
    let per_node = |value: &dyn Fn(usize) -> f64| {
        let mut v = vec![0.0; node_count];
        for (c, col) in columns.iter().enumerate() {
            for &n in col {
                v[n] = value(c);
            }
        }
        v
    };
    let mut out = vec![
        Field::scalar("thinning", per_node(&|c| f.thinning(c))),
        Field::scalar("major_strain", per_node(&|c| f.columns.major[c])),
        Field::scalar("minor_strain", per_node(&|c| f.columns.minor[c])),
        Field::scalar("strain_ratio", per_node(&|c| f.strain_ratio(c))),
    ];
    if f.flc.is_ok() {
        out.push(Field::scalar("flc_margin", per_node(&|c| f.margin[c])));
    }
    out.push(Field::scalar(
        "formability",
        per_node(&|c| f.zone[c].code() as f64),
    ));
    out
}

/// summary.json's `formability`: the largest thinning and the smallest margin with where
/// (the column's middle node, the top one of a one-layer column, with its reference and
/// current coordinates), the nodes per zone, the worst zone and the curve.
pub fn summary(sim: &Simulation, f: &Formability) -> serde_json::Value {
    let mesh = &sim.model.mesh;
    let u = sim.displacements();
    let place = |c: usize| {
        let col = &mesh.columns()[c];
        let n = col[col.len() / 2];
        let x = mesh.nodes[n];
        serde_json::json!({
            "node": n,
            "reference": [x.x, x.y, x.z],
            "current": [x.x + u[3 * n], x.y + u[3 * n + 1], x.z + u[3 * n + 2]],
        })
    };
    let columns = 0..f.zone.len();
    let thinnest = columns
        .clone()
        .max_by(|&a, &b| f.thinning(a).total_cmp(&f.thinning(b)));
    let tightest = (columns.clone())
        .filter(|&c| f.margin[c].is_finite())
        .min_by(|&a, &b| f.margin[a].total_cmp(&f.margin[b]));
    let mut counts = serde_json::Map::new();
    for z in Zone::ALL {
        let nodes: usize = (columns.clone())
            .filter(|&c| f.zone[c] == z)
            .map(|c| mesh.columns()[c].len())
            .sum();
        counts.insert(z.name().into(), nodes.into());
    }
    let worst = f.zone.iter().max().copied().unwrap_or(Zone::Safe);
    serde_json::json!({
        "max_thinning_pct": thinnest.map(|c| f.thinning(c)),
        "max_thinning_at": thinnest.map(place),
        "min_flc_margin": tightest.map(|c| f.margin[c]),
        "min_flc_margin_at": tightest.map(place),
        "nodes_per_zone": counts,
        "worst_zone": worst.name(),
        "flc": match &f.flc {
            Ok(flc) => flc.describe(),
            Err(why) => serde_json::json!({ "kind": "none", "reason": why }),
        },
    })
}

/// The end-of-run terminal lines: the largest thinning and the worst zone reached.
pub fn terminal_lines(f: &Formability) -> Vec<String> {
    let columns = 0..f.zone.len();
    let max_thinning = columns
        .map(|c| f.thinning(c))
        .fold(f64::NEG_INFINITY, f64::max);
    let worst = f.zone.iter().max().copied().unwrap_or(Zone::Safe);
    let count = f.zone.iter().filter(|&&z| z == worst).count();
    vec![
        format!("max thinning: {:.2} %", max_thinning),
        format!(
            "worst formability zone: {} ({count} of {} sheet columns)",
            worst.name().replace('_', " "),
            f.zone.len()
        ),
    ]
}
