//! Work-precision of the NUMISHEET'93 square cup (paper variant), run through
//! `scripts/square_cup.rhai` itself with `--set`-style overrides (cells, layers, step,
//! travel, r_contact) and, for the method switches the script does not declare, settings
//! given to its simulation before the script's own (`HostOptions::base_settings`).
//!
//! The travel is cut to 15 mm (the first travel at which the script records the draw-in)
//! to keep the study cheap. Error against the converged reference, a Richardson
//! extrapolation over a stored sequence of refined meshes (`cup_reference`):
//!
//! ```text
//! e = max over q in (DX, DY, DD, F) of |q - q_ref| / |q_ref|
//! ```
//!
//! with DX, DY the inward travels of the blank's edge midpoints, DD that of its corner along
//! the diagonal, and F the punch force at 15 mm (its peak so far, full cup).

use super::cup_reference::{self, ExtrapolatedReference, QUANTITIES};
use super::work_precision::{
    run_families, write_case, CaseResult, Family, Labelled, Measured, Point, Values,
};
use super::{Cost, Outcome, StudyOptions};
use crate::script::{self, HostOptions};
use crate::{Error, Result};
use rhai::Dynamic;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Punch travel of every run [mm].
pub const TRAVEL: f64 = 15.0;

/// One square-cup run: the script's own parameters and extra solver settings.
#[derive(Clone, Debug)]
pub struct CupVariant {
    pub label: String,
    pub cells: i64,
    pub layers: i64,
    /// Nominal increment of punch travel [mm].
    pub step: f64,
    /// The script's `r_contact` (< 0: E t, 0: the engine's default per node).
    pub r_contact: f64,
    /// Settings given before the script's own, e.g. ("friction_update", "implicit").
    pub settings: Vec<(&'static str, Dynamic)>,
}

impl Labelled for CupVariant {
    fn label(&self) -> &str {
        &self.label
    }
}

impl CupVariant {
    pub fn new(label: impl Into<String>, cells: i64, step: f64) -> Self {
        CupVariant {
            label: label.into(),
            cells,
            layers: 1,
            step,
            r_contact: -1.0,
            settings: Vec::new(),
        }
    }

    fn with(&self, label: &str, change: impl FnOnce(&mut CupVariant)) -> Self {
        let mut v = self.clone();
        v.label = label.into();
        change(&mut v);
        v
    }
}

/// The script: `scripts/square_cup.rhai` under the working directory, else in the source
/// tree this binary was built from.
fn script_path() -> Result<PathBuf> {
    let local = PathBuf::from("scripts/square_cup.rhai");
    if local.is_file() {
        return Ok(local);
    }
    let built = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scripts/square_cup.rhai");
    if built.is_file() {
        return Ok(built);
    }
    Err(Error::Input(format!(
        "the square-cup study needs scripts/square_cup.rhai (looked in the working directory and in {})",
        env!("CARGO_MANIFEST_DIR")
    )))
}

/// Runs the script into a scratch folder under `scratch` and reads its summary.json.
fn measure(v: &CupVariant, scratch: &std::path::Path) -> Result<Measured> {
    let path = script_path()?;
    let out = scratch.join(v.label.replace(|c: char| !c.is_ascii_alphanumeric(), "_"));
    let _ = std::fs::remove_dir_all(&out);
    let overrides = vec![
        ("cells".to_string(), Dynamic::from(v.cells)),
        ("layers".to_string(), Dynamic::from(v.layers)),
        ("step".to_string(), Dynamic::from(v.step)),
        ("travel".to_string(), Dynamic::from(TRAVEL)),
        ("r_contact".to_string(), Dynamic::from(v.r_contact)),
        ("charts".to_string(), Dynamic::from(false)),
        // The script's default for one layer is the solid-shell; the study's families are
        // F-bar hexahedra (docs/studies/square_cup).
        (
            "element".to_string(),
            Dynamic::from(cup_reference::HEXAHEDRON.to_string()),
        ),
    ];
    let mut base = rhai::Map::new();
    // One frame at the start and one at the end: the study needs the summary only.
    base.insert("output_every".into(), Dynamic::from(1_000_000_i64));
    // One element thread: wall times measure work, not free cores.
    base.insert("threads".into(), Dynamic::from(1_i64));
    for (k, val) in &v.settings {
        base.insert((*k).into(), val.clone());
    }
    let host = HostOptions {
        out_dir: out.clone(),
        progress: false,
        warnings: false,
        base_settings: base,
        script_print: false,
        ..HostOptions::default()
    };
    let run = script::run_file(&path, &overrides, &host);
    let summary_path = out.join(crate::output::SUMMARY_FILE);
    let summary: Option<serde_json::Value> = std::fs::read_to_string(&summary_path)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let _ = std::fs::remove_dir_all(&out);
    run?;
    let s = summary.ok_or_else(|| Error::io(&summary_path, "no readable summary after the run"))?;
    let num = |v: &serde_json::Value, what: &str| {
        v.as_f64().ok_or_else(|| {
            Error::Input(format!(
                "square cup summary: '{what}' missing or not a number"
            ))
        })
    };
    if s["status"] != "finished" {
        return Err(Error::no_convergence(
            crate::error::Failure::Unrecoverable,
            format!(
                "square cup stopped: {}",
                s["error"].as_str().unwrap_or("no reason given")
            ),
        ));
    }
    let draw = &s["draw_in"][0];
    let cost = Cost {
        wall_s: 0.0,
        iterations: num(&s["newton_iterations"], "newton_iterations")? as usize,
        increments: num(&s["increments"], "increments")? as usize,
        cutbacks: num(&s["cutbacks"], "cutbacks")? as usize,
    };
    let mut values = BTreeMap::new();
    values.insert("draw_in_dx_mm".into(), num(&draw["dx"], "draw_in dx")?);
    values.insert("draw_in_dy_mm".into(), num(&draw["dy"], "draw_in dy")?);
    values.insert("draw_in_dd_mm".into(), num(&draw["dd"], "draw_in dd")?);
    values.insert(
        "punch_force_n".into(),
        num(&s["punch_force_peak_n"], "punch_force_peak_n")?,
    );
    Ok((cost, values))
}

/// Largest relative difference of DX, DY, DD and the punch force from the reference's.
pub fn error(m: &Values, reference: &Values) -> f64 {
    QUANTITIES
        .iter()
        .map(|k| {
            let (a, b) = (m[*k], reference[*k]);
            (a - b).abs() / b.abs()
        })
        .fold(0.0, f64::max)
}

fn families() -> Vec<Family<CupVariant>> {
    let s = |v: &str| Dynamic::from(v.to_string());
    let base = CupVariant::new("16 cells", 16, 0.5);
    let fine = CupVariant::new("25 cells", 25, 0.5);
    vec![
        Family {
            name: "mesh (0.5 mm steps)",
            variants: [8, 12, 16, 20, 25]
                .map(|c| CupVariant::new(format!("{c}x{c}"), c, 0.5))
                .to_vec(),
        },
        Family {
            name: "step (25 x 25)",
            variants: [3.0, 1.5, 1.0]
                .map(|st| CupVariant::new(format!("{st} mm"), 25, st))
                .to_vec(),
        },
        Family {
            name: "layers (12 x 12, 0.5 mm)",
            variants: [1, 2, 4]
                .map(|l| {
                    let mut v = CupVariant::new(format!("{l} layer(s)"), 12, 0.5);
                    v.layers = l;
                    v
                })
                .to_vec(),
        },
        Family {
            name: "methods (16 x 16, 0.5 mm)",
            variants: vec![
                base.with("implicit friction", |v| {
                    v.settings.push(("friction_update", s("implicit")))
                }),
                base.with("curvature off", |v| {
                    v.settings.push(("curvature", Dynamic::from(false)))
                }),
                base.with("frame frozen", |v| v.settings.push(("frame", s("frozen")))),
                base.with("AL r = engine default", |v| v.r_contact = 0.0),
                base.with("AL r = 10 E t", |v| v.r_contact = 10.0 * E_T),
                base.with("penalty r = E t", |v| {
                    v.settings.push(("enforcement", s("penalty")))
                }),
                base.with("penalty r = 10 E t", |v| {
                    v.r_contact = 10.0 * E_T;
                    v.settings.push(("enforcement", s("penalty")))
                }),
            ],
        },
        // On the reference's mesh, where the error is the method's own (and the step's).
        Family {
            name: "methods (25 x 25, 0.5 mm)",
            variants: vec![
                fine.with("25: implicit friction", |v| {
                    v.settings.push(("friction_update", s("implicit")))
                }),
                fine.with("25: frame frozen", |v| {
                    v.settings.push(("frame", s("frozen")))
                }),
                fine.with("25: penalty r = E t", |v| {
                    v.settings.push(("enforcement", s("penalty")))
                }),
            ],
        },
    ]
}

/// E t of the script's aluminium blank (71 GPa x 0.81 mm), N/mm: its default r.
const E_T: f64 = 71_000.0 * 0.81;

/// What the report says about the reference and the families, from the extrapolation.
fn notes(r: &ExtrapolatedReference) -> String {
    let checks: Vec<String> = r
        .runs
        .iter()
        .filter(|run| !r.sequence.contains(&run.label()))
        .map(|run| run.label())
        .collect();
    format!(
        "The reference is no run of the study: it is a Richardson extrapolation, per quantity, over the stored meshes {} (0.5 mm steps; refinement ratio {:.3} and {:.3}, {}), made by runs committed with their commands in [square_cup/reference/meshes.json](./square_cup/reference/meshes.json) and not rerun by the study (table below). Its uncertainty U (a GCI band; the largest over the quantities is the dashed line 'reference uncertainty' on the chart) bounds how small an error here can be trusted: an error below it is not resolved.{} The layers family changes the through-thickness model as well as the mesh. The 16 x 16 methods family compares costs; its mesh error (the mesh family's 16 x 16 point) dominates its errors: compare each method's values with that point (in the CSV); switches that change only the Newton path (r of the augmented Lagrangian, curvature terms) give the same result on the same mesh. The step family and the 25 x 25 methods family run on 25 x 25 x 1, whose own mesh error (the mesh family's 25 x 25 point) is most of theirs.",
        r.sequence.join(", "),
        r.ratios[0],
        r.ratios[1],
        if r.similar {
            "in-plane and through the thickness alike, so the cells stay similar"
        } else {
            "not the same in-plane and through the thickness: the cells do not stay similar"
        },
        if checks.is_empty() {
            String::new()
        } else {
            format!(
                " The other stored meshes ({}) check the extrapolation: their distance to it is in the table.",
                checks.join(", ")
            )
        }
    )
}

/// The stored mesh sequence (see `cup_reference::locate`), extrapolated.
fn extrapolated_reference(opts: &StudyOptions) -> Result<ExtrapolatedReference> {
    stored_reference(opts, cup_reference::STORED_FILE)
}

fn stored_reference(opts: &StudyOptions, file: &str) -> Result<ExtrapolatedReference> {
    let stored_path = cup_reference::locate(&opts.out, file)?;
    let reference = cup_reference::load(&stored_path)?.extrapolate()?;
    opts.note(&format!(
        "  reference ({}): Richardson extrapolation over {} from {}",
        reference.element,
        reference.sequence.join(", "),
        stored_path.display()
    ));
    Ok(reference)
}

/// The solid-shell sequence's extrapolation, the independent check of the reference.
fn cross_reference(opts: &StudyOptions) -> Result<ExtrapolatedReference> {
    stored_reference(opts, cup_reference::SOLID_SHELL_FILE)
}

/// The case's result, every converged point's error measured against `reference`.
fn scored(
    mut points: Vec<Point>,
    reference: ExtrapolatedReference,
    cross_reference: Option<ExtrapolatedReference>,
    opts: &StudyOptions,
) -> Result<CaseResult> {
    let values = reference.values();
    for p in points.iter_mut().filter(|p| p.outcome.converged()) {
        if let Some(missing) = QUANTITIES.iter().find(|q| !p.values.contains_key(**q)) {
            return Err(Error::Input(format!(
                "square-cup run '{}' ({}) has no value '{missing}': run the study again rather than rescoring it",
                p.label, p.family
            )));
        }
        p.error = Some(error(&p.values, &values));
    }
    Ok(CaseResult {
        name: "square_cup".into(),
        title: format!("NUMISHEET'93 square cup, paper variant, punch to {TRAVEL} mm"),
        error_measure: format!(
            "max over q in (DX, DY, DD, F) of |q - q_ref| / |q_ref|: draw-in of the edge midpoints (DX, DY) and of the corner (DD), punch force at {TRAVEL} mm (F), against the Richardson extrapolation over {}",
            reference.sequence.join(", ")
        ),
        // The extrapolated values as the reference row of the CSV (no run: no cost).
        reference: Some(Point {
            family: "reference".into(),
            label: format!("Richardson extrapolation over {}", reference.sequence.join(", ")),
            cost: Cost::default(),
            outcome: Outcome::Converged,
            failure: None,
            values: reference.values(),
            error: None,
        }),
        notes: notes(&reference),
        points,
        command: opts.command.clone(),
        extrapolated: Some(reference),
        cross_reference,
    })
}

/// Runs every family and measures it against the extrapolated reference.
pub fn run(opts: &StudyOptions) -> Result<()> {
    let reference = extrapolated_reference(opts)?;
    let dir = opts.folder("square_cup")?;
    let scratch = dir.join("scratch");
    let measure = |v: &CupVariant| measure(v, &scratch);
    // Errors are set by `scored`, once, against the extrapolation.
    let no_error = |_: &Values, _: Option<&Values>| f64::NAN;
    let (_, points) = run_families(&families(), None, &measure, &no_error, Some(opts))?;
    let _ = std::fs::remove_dir_all(&scratch);
    write_case(
        &scored(points, reference, Some(cross_reference(opts)?), opts)?,
        opts,
    )
}

/// Measures the runs of an existing `square_cup/results.json` against the stored reference
/// again, without running them (after the stored mesh sequence changed).
pub fn rescore(opts: &StudyOptions) -> Result<()> {
    let path = opts.out.join("square_cup").join("results.json");
    let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    let old: CaseResult = serde_json::from_str(&text)
        .map_err(|e| Error::io(&path, format!("not a study result: {e}")))?;
    let reference = extrapolated_reference(opts)?;
    let mut result = scored(old.points, reference, Some(cross_reference(opts)?), opts)?;
    result.command = old.command;
    write_case(&result, opts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(dx: f64, dy: f64, dd: f64, f: f64) -> Values {
        QUANTITIES
            .iter()
            .zip([dx, dy, dd, f])
            .map(|(k, v)| (k.to_string(), v))
            .collect()
    }

    #[test]
    fn error_is_the_largest_relative_difference_over_all_four_quantities() {
        let reference = values(5.0, 5.0, 3.0, 30_000.0);
        // DY alone is 4 % off; the others 1 % or less.
        let e = error(&values(5.05, 5.2, 3.0, 30_300.0), &reference);
        assert!((e - 0.04).abs() < 1e-12, "{e}");
    }

    #[test]
    fn scoring_a_run_without_dy_names_it() {
        let mut v = values(5.0, 5.0, 3.0, 30_000.0);
        v.remove("draw_in_dy_mm");
        let point = Point {
            family: "mesh".into(),
            label: "8x8".into(),
            cost: Cost::default(),
            outcome: Outcome::Converged,
            failure: None,
            values: v,
            error: None,
        };
        let reference = ExtrapolatedReference {
            element: cup_reference::HEXAHEDRON.into(),
            sequence: Vec::new(),
            ratios: [2.0, 2.0],
            similar: true,
            rule: crate::study::richardson::OrderRule {
                min: 0.5,
                max: 3.0,
                assumed: 1.0,
            },
            quantities: BTreeMap::new(),
            runs: Vec::new(),
            commit: String::new(),
            step_mm: 0.5,
        };
        let opts = StudyOptions::new("unused", "test");
        let err = scored(vec![point], reference, None, &opts)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("8x8") && err.contains("draw_in_dy_mm"),
            "{err}"
        );
    }
}
