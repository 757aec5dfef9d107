//! Work-precision studies: each case runs families of variants (mesh refinement, step
//! refinement, method switches) and charts the error of each run against its wall time.
//!
//! Error measures (all relative, dimensionless):
//!
//! - Hertz line contact, against the closed form for the computed load:
//!   `e = max(|a_h - a| / a, |p0_h - p0| / p0)`, a the contact half-width (least-squares
//!   fit of the elliptic pressure profile to the nodal pressures), p0 the peak pressure.
//! - Frictional-work ODE, against dPsi/ds = mu(Psi) N_node integrated by RK4 to round-off:
//!   `e = |Psi_h(S) - Psi(S)| / Psi(S)` for the corner node's work after the whole slide S.
//! - Cylinder drag (slip of four contact widths), against the reference run (finer mesh
//!   and step than any of the families): `e = max(|D - D_ref| / D_ref, |Fz - Fz_ref| /
//!   |Fz_ref|)`, D the frictional dissipation over the run and Fz the mean normal force
//!   over the drag (trapezoidal over the increments).
//! - Square cup (`square_cup.rs`): against the reference run, the largest relative
//!   difference of the draw-ins DX and DD and of the punch force at the end.
//!
//! A run that stops (no convergence) is kept with its outcome and no error.

use super::chart::{log_log, LogSeries};
use super::cup_reference::ExtrapolatedReference;
use super::scenes;
use super::{seconds, write_file, Cost, Outcome, StudyOptions, Variant};
use crate::contact::{Enforcement, FrameUpdate, FrictionUpdate};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::Instant;

/// A named set of variants charted as one line.
pub struct Family<V = Variant> {
    pub name: &'static str,
    pub variants: Vec<V>,
}

/// What a run is called in charts and tables.
pub trait Labelled {
    fn label(&self) -> &str;
}

impl Labelled for Variant {
    fn label(&self) -> &str {
        &self.label
    }
}

/// One run of a case.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Point {
    pub family: String,
    pub label: String,
    pub cost: Cost,
    pub outcome: Outcome,
    /// Why a run stopped.
    pub failure: Option<String>,
    /// The measured values the error is made of.
    pub values: BTreeMap<String, f64>,
    pub error: Option<f64>,
}

/// Everything one case's study produced (`results.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseResult {
    pub name: String,
    pub title: String,
    /// How the error is measured (for the report).
    pub error_measure: String,
    /// The run the others are compared with (None: an analytic solution).
    pub reference: Option<Point>,
    /// What a reader must know to read the chart (known effects behind its shape).
    #[serde(default)]
    pub notes: String,
    pub points: Vec<Point>,
    pub command: String,
    /// The extrapolated reference the errors are measured against, when there is one
    /// (the square cup's).
    #[serde(default)]
    pub extrapolated: Option<ExtrapolatedReference>,
    /// A second extrapolated reference, from another element family, that checks the
    /// first (the square cup's solid-shell sequence).
    #[serde(default)]
    pub cross_reference: Option<ExtrapolatedReference>,
}

/// Runs shorter than this many seconds are repeated and timed by their mean.
pub const MIN_TIMED: f64 = 0.5;
const MAX_REPEATS: usize = 100;

/// Named measured values of a run.
pub type Values = BTreeMap<String, f64>;

/// Measured values of one finished run and its cost (wall time set by the caller).
pub type Measured = (Cost, Values);

/// Runs one variant, timing it; a failed run gives its outcome and reason.
pub fn run_point<V: Labelled>(
    family: &str,
    v: &V,
    measure: &dyn Fn(&V) -> Result<Measured>,
    opts: Option<&StudyOptions>,
) -> Point {
    let t = Instant::now();
    let mut result = measure(v);
    let mut wall = seconds(t);
    // A run of a few milliseconds is timed as the mean of repeats filling `MIN_TIMED`
    // seconds: one such run is at the mercy of the clock and the other core's load.
    if result.is_ok() && wall < MIN_TIMED {
        let mut runs = 1;
        while seconds(t) < MIN_TIMED && runs < MAX_REPEATS {
            result = measure(v);
            runs += 1;
        }
        wall = seconds(t) / runs as f64;
    }
    let point = match result {
        Ok((mut cost, values)) => {
            cost.wall_s = wall;
            Point {
                family: family.into(),
                label: v.label().to_string(),
                cost,
                outcome: Outcome::Converged,
                failure: None,
                values,
                error: None,
            }
        }
        Err(e) => Point {
            family: family.into(),
            label: v.label().to_string(),
            cost: Cost {
                wall_s: wall,
                ..Cost::default()
            },
            outcome: Outcome::of_failure(&e),
            failure: Some(e.to_string()),
            values: BTreeMap::new(),
            error: None,
        },
    };
    if let Some(o) = opts {
        o.note(&format!(
            "  {family} / {}: {:.2} s, {} iterations, {}",
            v.label(),
            point.cost.wall_s,
            point.cost.iterations,
            point.outcome.name()
        ));
    }
    point
}

/// Runs every family, then sets each converged point's error with `error(values, reference)`.
pub fn run_families<V: Labelled>(
    families: &[Family<V>],
    reference: Option<&V>,
    measure: &dyn Fn(&V) -> Result<Measured>,
    error: &dyn Fn(&Values, Option<&Values>) -> f64,
    opts: Option<&StudyOptions>,
) -> Result<(Option<Point>, Vec<Point>)> {
    let reference = match reference {
        Some(v) => {
            let p = run_point("reference", v, measure, opts);
            if !p.outcome.converged() {
                return Err(Error::no_convergence(
                    crate::error::Failure::Unrecoverable,
                    format!(
                        "the reference run '{}' did not finish: {}",
                        v.label(),
                        p.failure.unwrap_or_default()
                    ),
                ));
            }
            Some(p)
        }
        None => None,
    };
    let mut points = Vec::new();
    for f in families {
        for v in &f.variants {
            let mut p = run_point(f.name, v, measure, opts);
            if p.outcome.converged() {
                p.error = Some(error(&p.values, reference.as_ref().map(|r| &r.values)));
            }
            points.push(p);
        }
    }
    Ok((reference, points))
}

fn values(pairs: &[(&str, f64)]) -> BTreeMap<String, f64> {
    pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

fn get(m: &BTreeMap<String, f64>, k: &str) -> f64 {
    m.get(k).copied().unwrap_or(f64::NAN)
}

// ---- Hertz -----------------------------------------------------------------------------------

pub fn hertz_measure(v: &Variant) -> Result<Measured> {
    let (sim, m) = scenes::hertz(v)?;
    Ok((
        Cost::of(&sim, 0.0),
        values(&[
            ("a_fem", m.a_fem),
            ("a_exact", m.a_exact),
            ("p0_fem", m.p0_fem),
            ("p0_exact", m.p0_exact),
        ]),
    ))
}

/// `max(|a_h - a| / a, |p0_h - p0| / p0)`.
pub fn hertz_error(m: &BTreeMap<String, f64>, _: Option<&BTreeMap<String, f64>>) -> f64 {
    rel(get(m, "a_fem"), get(m, "a_exact")).max(rel(get(m, "p0_fem"), get(m, "p0_exact")))
}

/// Penalty variants `r_factor` times the default r (the column stiffness under each node).
pub fn penalty(base: &Variant, factor: f64) -> Variant {
    base.with(format!("penalty r x {factor}"), |v| {
        v.contact.enforcement = Enforcement::Penalty;
        v.r_factor = factor;
    })
}

fn hertz_families() -> Vec<Family> {
    let base = Variant::new("24 cells", 24, 4);
    vec![
        Family {
            name: "mesh (4 increments)",
            variants: [12, 16, 24, 32, 48, 64]
                .map(|c| Variant::new(format!("{c} cells"), c, 4))
                .to_vec(),
        },
        Family {
            name: "increments (24 cells)",
            variants: [1, 2, 4, 8]
                .map(|n| Variant::new(format!("{n} incr."), 24, n))
                .to_vec(),
        },
        Family {
            name: "penalty (24 cells)",
            variants: [100.0, 10.0, 1.0, 0.1, 0.01]
                .map(|f| penalty(&base, f))
                .to_vec(),
        },
        Family {
            name: "augmented Lagrangian r (24 cells)",
            variants: [100.0, 1.0, 0.01]
                .map(|f| base.with(format!("AL r x {f}"), |v| v.r_factor = f))
                .to_vec(),
        },
        Family {
            name: "switches (24 cells)",
            variants: vec![
                base.with("curvature off", |v| v.contact.curvature = false),
                base.with("frame frozen", |v| v.contact.frame = FrameUpdate::Frozen),
            ],
        },
    ]
}

// ---- frictional-work ODE -----------------------------------------------------------------------

pub fn friction_work_measure(v: &Variant) -> Result<Measured> {
    let (sim, work) = scenes::friction_work(v)?;
    Ok((
        Cost::of(&sim, 0.0),
        values(&[
            ("work", work),
            ("node_force", scenes::corner_force(v.cells)),
        ]),
    ))
}

/// `|Psi_h - Psi| / Psi`, the exact work integrated here (outside the timed run).
pub fn friction_work_error(m: &BTreeMap<String, f64>, _: Option<&BTreeMap<String, f64>>) -> f64 {
    match scenes::ode_exact(get(m, "node_force")) {
        Ok(exact) => rel(get(m, "work"), exact),
        Err(_) => f64::NAN,
    }
}

fn friction_work_families() -> Vec<Family> {
    let update = |name: &'static str, u: FrictionUpdate| Family {
        name,
        variants: [5, 10, 20, 40, 80]
            .map(|n| {
                let mut v = Variant::new(format!("{n} incr."), 1, n);
                v.contact.friction_update = u;
                v
            })
            .to_vec(),
    };
    let base = Variant::new("20 incr.", 1, 20);
    vec![
        update("explicit update", FrictionUpdate::Explicit),
        update("implicit update", FrictionUpdate::Implicit),
        Family {
            name: "penalty (explicit, 20 incr.)",
            variants: [1.0, 0.01].map(|f| penalty(&base, f)).to_vec(),
        },
    ]
}

// ---- cylinder drag ------------------------------------------------------------------------------

pub fn drag_measure(v: &Variant) -> Result<Measured> {
    let mut sim = scenes::cylinder_drag(v, 0.2, 30, 4)?;
    sim.run(|_, _| Ok(()))?;
    let f = sim.tool_force(0);
    // Mean normal force over the drag (t in [1, 3]), trapezoidal over the increments.
    let history: Vec<(f64, f64)> = sim
        .history
        .iter()
        .map(|r| (r.time, r.tool_forces[0][2]))
        .collect();
    let mut mean_fz = 0.0;
    for w in history.windows(2).filter(|w| w[0].0 >= 1.0 - 1e-12) {
        mean_fz += 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0);
    }
    mean_fz /= 2.0;
    Ok((
        Cost::of(&sim, 0.0),
        values(&[
            ("dissipation", sim.energy().frictional_dissipation[0]),
            ("mean_force_z", mean_fz),
            ("final_force_x", f.x),
            ("final_force_z", f.z),
        ]),
    ))
}

/// `max(|D - D_ref| / D_ref, |Fz - Fz_ref| / |Fz_ref|)`: frictional dissipation D over the
/// whole run and mean normal force over the drag. Both integrate over the path, so they see
/// the step size, and they average out the ripple of the force as the cylinder passes over
/// the nodes (the final force alone swings by a few per cent with where the drag ends
/// relative to the mesh).
pub fn drag_error(m: &BTreeMap<String, f64>, r: Option<&BTreeMap<String, f64>>) -> f64 {
    let r = r.expect("the drag is measured against its reference run");
    rel(get(m, "dissipation"), get(r, "dissipation"))
        .max(rel(get(m, "mean_force_z"), get(r, "mean_force_z")))
}

fn drag_families() -> Vec<Family> {
    let base = Variant::new("32 cells, 30 incr.", 32, 30);
    vec![
        Family {
            name: "mesh (30 increments)",
            variants: [16, 24, 32, 48]
                .map(|c| Variant::new(format!("{c} cells"), c, 30))
                .to_vec(),
        },
        Family {
            name: "increments (32 cells)",
            variants: [6, 12, 24, 48]
                .map(|n| Variant::new(format!("{n} incr."), 32, n))
                .to_vec(),
        },
        Family {
            name: "penalty (32 cells, 30 incr.)",
            variants: [10.0, 1.0, 0.1, 0.01].map(|f| penalty(&base, f)).to_vec(),
        },
        Family {
            name: "augmented Lagrangian r (32 cells, 30 incr.)",
            variants: [10.0, 0.1]
                .map(|f| base.with(format!("AL r x {f}"), |v| v.r_factor = f))
                .to_vec(),
        },
        Family {
            name: "switches (32 cells, 30 incr.)",
            variants: vec![
                base.with("curvature off", |v| v.contact.curvature = false),
                base.with("frame frozen", |v| v.contact.frame = FrameUpdate::Frozen),
            ],
        },
    ]
}

/// The drag's reference: finer than the finest mesh (48) and step (48 increments) of the
/// families. Against it, the error of the 48-cell run is underestimated (the reference has
/// an error of its own), which the report says.
fn drag_reference() -> Variant {
    Variant::new("reference: 64 cells, 96 incr.", 64, 96)
}

// ---- running and writing -------------------------------------------------------------------------

/// Runs case `name` (`hertz`, `friction_work` or `cylinder_drag`) and writes its output.
pub fn run(name: &str, opts: &StudyOptions) -> Result<()> {
    let result = match name {
        "hertz" => CaseResult {
            name: name.into(),
            title: "Hertz line contact (rigid cylinder on an elastic block, plane strain)".into(),
            error_measure: "max(|a_h - a| / a, |p0_h - p0| / p0) against the closed form (half-width a, peak pressure p0)".into(),
            reference: None,
            notes: "The problem is linear up to the contact zone, so the number of increments changes the cost only. Penalty at and above the default r gives errors of the size of the mesh error with either sign (the penetration widens the contact and offsets part of the coarse mesh's error); below it the penetration dominates.".into(),
            points: run_families(&hertz_families(), None, &hertz_measure, &hertz_error, Some(opts))?.1,
            command: opts.command.clone(),
            extrapolated: None,
            cross_reference: None,
        },
        "friction_work" => CaseResult {
            name: name.into(),
            title: "Frictional-work ODE (column sliding 10 mm, Bernstein mu(work))".into(),
            error_measure: "|Psi_h - Psi| / Psi, corner node's frictional work after the slide, against RK4 of dPsi/ds = mu(Psi) N_node".into(),
            reference: None,
            notes: "Every node slips exactly the prescribed distance, so the only error is the time discretisation of the friction update: first order explicit, second order implicit (tests/friction_work.rs). These runs last milliseconds; their wall time is the mean of repeats and mostly fixed set-up cost.".into(),
            points: run_families(&friction_work_families(), None, &friction_work_measure, &friction_work_error, Some(opts))?.1,
            command: opts.command.clone(),
            extrapolated: None,
            cross_reference: None,
        },
        "cylinder_drag" => {
            let reference = drag_reference();
            let (reference, points) =
                run_families(&drag_families(), Some(&reference), &drag_measure, &drag_error, Some(opts))?;
            CaseResult {
                name: name.into(),
                title: "Cylinder drag, slip of four contact widths (mu = 0.2)".into(),
                error_measure: "max(|D - D_ref| / D_ref, |Fz - Fz_ref| / |Fz_ref|), D the frictional dissipation over the run, Fz the mean normal force over the drag, against the reference run (64 cells, 96 increments)".into(),
                reference,
                notes: "The contact force ripples as the cylinder passes over the nodes (node-to-surface contact: on 32 cells the normal force is 68.4 with the cylinder over a node and 64.4 between two, in steady sliding); the increments sample that ripple, and an increment that is a multiple of the cell size samples it at one phase only, so the error need not fall monotonically under step refinement on a fixed mesh, nor under mesh refinement at a fixed number of increments. The reference has an error of its own, so the errors of the finest runs are underestimated.".into(),
                points,
                command: opts.command.clone(),
            extrapolated: None,
            cross_reference: None,
            }
        }
        other => return Err(Error::Input(format!("no work-precision case named '{other}'"))),
    };
    write_case(&result, opts)
}

/// `results.json`, `work_precision.svg` and `work_precision.csv` of a case.
pub fn write_case(result: &CaseResult, opts: &StudyOptions) -> Result<()> {
    let dir = opts.folder(&result.name)?;
    let json = serde_json::to_string_pretty(result)
        .map_err(|e| Error::Input(format!("results of '{}': {e}", result.name)))?;
    write_file(&dir.join("results.json"), &json)?;
    let mut families: Vec<String> = Vec::new();
    for p in &result.points {
        if !families.contains(&p.family) {
            families.push(p.family.clone());
        }
    }
    let series: Vec<LogSeries> = families
        .iter()
        .map(|f| LogSeries {
            name: f.clone(),
            points: result
                .points
                .iter()
                .filter(|p| &p.family == f)
                .filter_map(|p| p.error.map(|e| (p.cost.wall_s, e, p.label.clone())))
                .collect(),
        })
        .collect();
    let uncertainty = result
        .extrapolated
        .as_ref()
        .map(|r| (r.worst_relative_uncertainty(), "reference uncertainty"));
    let hlines: Vec<(f64, &str)> = [Some((0.01, "1 %")), uncertainty]
        .into_iter()
        .flatten()
        .collect();
    let svg = log_log(
        &format!("{}: error against wall time", result.title),
        "wall time of the whole run [s]",
        "relative error",
        &series,
        &hlines,
    );
    write_file(&dir.join("work_precision.svg"), &svg)?;
    write_file(&dir.join("work_precision.csv"), &points_csv(result))?;
    Ok(())
}

/// One row per run (the reference first), the command in a leading comment line.
pub fn points_csv(result: &CaseResult) -> String {
    let mut keys: Vec<String> = Vec::new();
    for p in result.reference.iter().chain(&result.points) {
        for k in p.values.keys() {
            if !keys.contains(k) {
                keys.push(k.clone());
            }
        }
    }
    let mut o = format!(
        "# {} -- made by: {}\n# error: {}\nfamily,label,outcome,wall_s,iterations,increments,cutbacks,error",
        result.title, result.command, result.error_measure
    );
    for k in &keys {
        let _ = write!(o, ",{k}");
    }
    o.push('\n');
    let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    for p in result.reference.iter().chain(&result.points) {
        let _ = write!(
            o,
            "{},{},{},{:.4},{},{},{},{}",
            quote(&p.family),
            quote(&p.label),
            quote(p.outcome.name()),
            p.cost.wall_s,
            p.cost.iterations,
            p.cost.increments,
            p.cost.cutbacks,
            p.error.map(|e| format!("{e:e}")).unwrap_or_default()
        );
        for k in &keys {
            let _ = write!(
                o,
                ",{}",
                p.values
                    .get(k)
                    .map(|v| format!("{v:e}"))
                    .unwrap_or_default()
            );
        }
        o.push('\n');
    }
    o
}
