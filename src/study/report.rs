//! The markdown report (`README.md` of the output folder), made from every `results.json`
//! found there: per case its chart, the cheapest run reaching 1 % error, every run in a
//! table, the runs that failed; for the stability map the region where each method fails.

use super::cup_reference::ExtrapolatedReference;
use super::stability::StabilityResult;
use super::work_precision::{CaseResult, Point};
use super::{write_file, StudyOptions, STUDIES};
use crate::{Error, Result};
use std::fmt::Write as _;
use std::path::Path;

/// The error a run must reach to count as accurate.
pub const TARGET: f64 = 0.01;

fn read<T: serde::de::DeserializeOwned>(path: &Path) -> Result<Option<T>> {
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| Error::io(path, format!("not a study result: {e}")))
}

/// The cheapest converged run with error <= `TARGET` (by wall time).
pub fn cheapest_accurate(points: &[Point]) -> Option<&Point> {
    points
        .iter()
        .filter(|p| p.outcome.converged() && p.error.is_some_and(|e| e <= TARGET))
        .min_by(|a, b| a.cost.wall_s.total_cmp(&b.cost.wall_s))
}

/// Seconds with 3 significant digits below 1 s (the ODE's runs last milliseconds).
fn fmt_s(t: f64) -> String {
    if t < 1.0 {
        format!("{t:.3}")
    } else {
        format!("{t:.2}")
    }
}

fn fmt_err(e: Option<f64>) -> String {
    e.map(|e| format!("{e:.2e}")).unwrap_or_else(|| "-".into())
}

fn short(reason: &str) -> String {
    let s: String = reason.chars().take(160).collect();
    if s.len() < reason.len() {
        format!("{s}...")
    } else {
        s
    }
}

fn case_section(o: &mut String, c: &CaseResult) {
    let _ = writeln!(o, "## {}\n", c.title);
    let _ = writeln!(o, "Error: {}.\n", c.error_measure);
    if !c.notes.is_empty() {
        let _ = writeln!(o, "{}\n", c.notes);
    }
    let _ = writeln!(
        o,
        "![{0}](./{0}/work_precision.svg)\n\nPoints: [{0}/work_precision.csv](./{0}/work_precision.csv) (all runs: [{0}/results.json](./{0}/results.json)).\n",
        c.name
    );
    match cheapest_accurate(&c.points) {
        Some(p) => {
            let _ = writeln!(
                o,
                "**Cheapest run within 1 %:** {} ({}): error {}, {} s, {} Newton iterations.\n",
                p.label,
                p.family,
                fmt_err(p.error),
                fmt_s(p.cost.wall_s),
                p.cost.iterations
            );
        }
        None => {
            let best = c
                .points
                .iter()
                .filter(|p| p.error.is_some())
                .min_by(|a, b| {
                    a.error
                        .unwrap_or(f64::MAX)
                        .total_cmp(&b.error.unwrap_or(f64::MAX))
                });
            let _ = writeln!(
                o,
                "**No run reached 1 %.** Smallest error: {}.\n",
                best.map(|p| format!(
                    "{} ({}), {} in {} s",
                    p.label,
                    p.family,
                    fmt_err(p.error),
                    fmt_s(p.cost.wall_s)
                ))
                .unwrap_or_else(|| "none converged".into())
            );
        }
    }
    if let Some(x) = &c.extrapolated {
        extrapolation_section(o, x);
        if let Some(y) = &c.cross_reference {
            cross_reference_section(o, x, y);
        }
    } else if let Some(r) = &c.reference {
        let _ = writeln!(
            o,
            "Reference run: {}, {:.2} s, {} Newton iterations.\n",
            r.label, r.cost.wall_s, r.cost.iterations
        );
    }
    let _ = writeln!(o, "| family | run | wall time [s] | Newton iterations | increments (cutbacks) | error | outcome |");
    let _ = writeln!(o, "|---|---|---|---|---|---|---|");
    for p in &c.points {
        let _ = writeln!(
            o,
            "| {} | {} | {} | {} | {} ({}) | {} | {} |",
            p.family,
            p.label,
            fmt_s(p.cost.wall_s),
            p.cost.iterations,
            p.cost.increments,
            p.cost.cutbacks,
            fmt_err(p.error),
            p.outcome.name()
        );
    }
    let failed: Vec<&Point> = c.points.iter().filter(|p| !p.outcome.converged()).collect();
    if failed.is_empty() {
        let _ = writeln!(o, "\nEvery run of this case finished.\n");
    } else {
        let _ = writeln!(o, "\nRuns that failed:\n");
        for p in failed {
            let _ = writeln!(
                o,
                "- {} ({}): {}",
                p.label,
                p.family,
                short(p.failure.as_deref().unwrap_or(""))
            );
        }
        o.push('\n');
    }
}

/// Short names of the extrapolated quantities, in the study's order.
fn quantity_name(key: &str) -> &str {
    match key {
        "draw_in_dx_mm" => "DX [mm]",
        "draw_in_dy_mm" => "DY [mm]",
        "draw_in_dd_mm" => "DD [mm]",
        "punch_force_n" => "F [N]",
        other => other,
    }
}

/// The extrapolated reference: per quantity the stored meshes' values, the observed order,
/// the verdict on the asymptotic range, the extrapolated value and its GCI band; then every
/// stored run with its cost and its distance to the reference.
fn extrapolation_section(o: &mut String, x: &ExtrapolatedReference) {
    let _ = writeln!(
        o,
        "**Reference ({} element):** Richardson extrapolation over {} ({} mm steps; runs at commit {}). Asymptotic when the convergence ratio R = (f2 - f1) / (f3 - f2) lies in (0, 1) and the observed order in [{}, {}]; then U = {} |f_ext - f1|, else order {} assumed from the two finest meshes and U = {} |f_ext - f1| (Roache's GCI; U is a band around the finest mesh's value that should hold the converged one).\n",
        x.element,
        x.sequence.join(", "),
        x.step_mm,
        x.commit.chars().take(7).collect::<String>(),
        x.rule.min,
        x.rule.max,
        super::richardson::SAFETY_ASYMPTOTIC,
        x.rule.assumed,
        super::richardson::SAFETY_ASSUMED,
    );
    let _ = writeln!(
        o,
        "| quantity | {} | observed order | R | verdict | reference | U | U / reference | finest mesh's error |",
        x.sequence.join(" | ")
    );
    let _ = writeln!(
        o,
        "|---|{}---|---|---|---|---|---|---|",
        "---|".repeat(x.sequence.len())
    );
    for (key, e) in &x.quantities {
        let values: Vec<String> = x
            .sequence
            .iter()
            .map(|label| {
                x.runs
                    .iter()
                    .find(|r| &r.label() == label)
                    .and_then(|r| r.values.get(key))
                    .map(|v| format!("{v:.5}"))
                    .unwrap_or_else(|| "-".into())
            })
            .collect();
        let _ = writeln!(
            o,
            "| {} | {} | {} | {:.3} | {} | {:.5} | {:.3e} | {:.2e} | {:.2e} |",
            quantity_name(key),
            values.join(" | "),
            e.observed_order
                .map(|p| format!("{p:.2}"))
                .unwrap_or_else(|| "-".into()),
            e.convergence_ratio,
            e.verdict,
            e.value,
            e.uncertainty,
            e.relative_uncertainty,
            e.finest_error
        );
    }
    let _ = writeln!(
        o,
        "\nStored runs (CPU seconds of the whole run, one element thread, niced on the shared machine; error as in the chart):\n"
    );
    let _ = writeln!(o, "| mesh | CPU [s] | wall [s] | Newton iterations | increments (cutbacks) | error against the reference | command |");
    let _ = writeln!(o, "|---|---|---|---|---|---|---|");
    let reference = x.values();
    for r in &x.runs {
        let error = reference
            .iter()
            .filter_map(|(k, v)| r.values.get(k).map(|m| (m - v).abs() / v.abs()))
            .fold(0.0, f64::max);
        let _ = writeln!(
            o,
            "| {} | {:.1} | {:.1} | {} | {} ({}) | {:.2e} | `{}` |",
            r.label(),
            r.cpu_s,
            r.wall_s,
            r.iterations,
            r.increments,
            r.cutbacks,
            error,
            r.command
        );
    }
    o.push('\n');
}

/// The second element family's extrapolation and, per quantity, whether the two references
/// agree within the sum of their bands.
fn cross_reference_section(o: &mut String, x: &ExtrapolatedReference, y: &ExtrapolatedReference) {
    let _ = writeln!(
        o,
        "**Independent check of the reference:** the same cup meshed with another element ({}), whose coarse meshes err on the other side, extrapolated alike. Two sound references differ by no more than the sum of their bands.\n",
        y.element
    );
    extrapolation_section(o, y);
    let _ = writeln!(
        o,
        "| quantity | {} reference | {} reference | difference | sum of the bands | agree |",
        x.element, y.element
    );
    let _ = writeln!(o, "|---|---|---|---|---|---|");
    for a in super::cup_reference::cross_check(x, y) {
        let _ = writeln!(
            o,
            "| {} | {:.5} | {:.5} | {:.2e} | {:.2e} | {} |",
            quantity_name(&a.quantity),
            a.first,
            a.second,
            a.relative_difference,
            a.relative_band,
            if a.agrees { "yes" } else { "**no**" }
        );
    }
    o.push('\n');
}

fn stability_section(o: &mut String, s: &StabilityResult) {
    let _ = writeln!(o, "## Stability map: {}\n", s.title);
    let _ = writeln!(
        o,
        "![stability map](./stability/stability_map.svg)\n\nCells: [stability/stability_map.csv](./stability/stability_map.csv). Rows: r as a multiple of the engine's default (the column stiffness under each node); columns: drag of the cylinder per increment (the contact zone is about 2 mm wide); colour: outcome; number: Newton iterations of the whole run, or `iN` for the increment that failed.\n"
    );
    let mut methods: Vec<&str> = Vec::new();
    for c in &s.cells {
        if !methods.contains(&c.method.as_str()) {
            methods.push(&c.method);
        }
    }
    let _ = writeln!(
        o,
        "Methods: the augmented Lagrangian (AL) or penalty enforcement; line search: backtracking on the residual norm; anti-cycling: a node whose contact status changes 3 times within an increment has its status frozen (slip if slip took part, else stick) until Newton settles, then released, so that every accepted increment satisfies the free friction law. No run may cut its step back, so a cell says whether its step size works as it is.\n"
    );
    let mut summary: Vec<String> = Vec::new();
    let _ = writeln!(
        o,
        "Where each method fails (every failing cell, by mu and r):\n"
    );
    let _ = writeln!(o, "| method | converged | failed | failing cells: mu, r / default: drag steps [mm] (outcome) |");
    let _ = writeln!(o, "|---|---|---|---|");
    for m in methods {
        let cells: Vec<_> = s.cells.iter().filter(|c| c.method == m).collect();
        let ok = cells.iter().filter(|c| c.outcome.converged()).count();
        let mut groups: Vec<String> = Vec::new();
        let mut keys: Vec<(f64, f64)> = Vec::new();
        for c in cells.iter().filter(|c| !c.outcome.converged()) {
            if !keys.contains(&(c.mu, c.r_factor)) {
                keys.push((c.mu, c.r_factor));
            }
        }
        for (mu, r) in keys {
            let steps: Vec<String> = cells
                .iter()
                .filter(|c| c.mu == mu && c.r_factor == r && !c.outcome.converged())
                .map(|c| format!("{:.2} ({})", c.drag_step_mm, c.outcome.name()))
                .collect();
            groups.push(format!("mu {mu}, r x {r}: {}", steps.join(", ")));
        }
        let _ = writeln!(
            o,
            "| {m} | {ok} of {} | {} | {} |",
            cells.len(),
            cells.len() - ok,
            if groups.is_empty() {
                "none".to_string()
            } else {
                groups.join("; ")
            }
        );
        // Per r: in how many cells the method fails.
        let mut rs: Vec<f64> = cells.iter().map(|c| c.r_factor).collect();
        rs.sort_by(f64::total_cmp);
        rs.dedup();
        let (mut safe, mut failing) = (Vec::new(), Vec::new());
        for r in rs {
            let at_r: Vec<_> = cells.iter().filter(|c| c.r_factor == r).collect();
            let bad = at_r.iter().filter(|c| !c.outcome.converged()).count();
            if bad == 0 {
                safe.push(format!("{r}"));
            } else {
                failing.push(format!("r x {r}: {bad} of {}", at_r.len()));
            }
        }
        summary.push(format!(
            "- {m}: converges at every step size and mu for r x {}; fails in {}.",
            if safe.is_empty() {
                "none".to_string()
            } else {
                safe.join(", ")
            },
            if failing.is_empty() {
                "no cell".to_string()
            } else {
                failing.join(", ")
            }
        ));
    }
    let _ = writeln!(o, "\nIn short:\n\n{}", summary.join("\n"));
    let frozen = s
        .cells
        .iter()
        .filter(|c| c.outcome == super::Outcome::ConvergedCycling)
        .count();
    let _ = writeln!(
        o,
        "\n{frozen} converged cell(s) needed the anti-cycling treatment in some increment.\n"
    );
}

/// Rewrites `opts.out/README.md` from the results found there.
pub fn write(opts: &StudyOptions) -> Result<()> {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "# Speed against accuracy\n\nGenerated by `tribo study` from the `results.json` files in this folder; do not edit by hand. Reproduce everything with\n\n```sh\ncargo run --release -- study all --out {}\n```\n\n(one study alone: `study NAME`, NAME one of {}; `study report` rewrites this page). Wall times are whole runs on one thread of a shared 2-core machine (about 10 % run-to-run scatter). Error charts are log-log: error against wall time, one line per family, the dashed line at 1 %. A run that stopped has no error and is listed under its case.\n",
        opts.out.display(),
        STUDIES.join(", ")
    );
    let mut found = false;
    for name in STUDIES {
        let path = opts.out.join(name).join("results.json");
        if name == "stability" {
            if let Some(s) = read::<StabilityResult>(&path)? {
                stability_section(&mut o, &s);
                found = true;
            }
        } else if let Some(c) = read::<CaseResult>(&path)? {
            case_section(&mut o, &c);
            found = true;
        }
    }
    if !found {
        let _ = writeln!(o, "No study results yet in this folder.");
    }
    write_file(&opts.out.join("README.md"), &o)
}
