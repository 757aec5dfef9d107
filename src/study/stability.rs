//! Stability maps of the cylinder drag: for each method, a grid over the step size (drag
//! per increment), the augmentation (or penalty) parameter r (a multiple of the engine's
//! default, the column stiffness under each node) and the friction coefficient mu, marking
//! whether the run converged, cycled, stalled or diverged, and how many Newton iterations
//! it took.
//!
//! Every run has a fixed budget (25 iterations per increment) and no cutbacks, so a cell
//! says whether that step size works as it is; the solver classifies a failed increment
//! (status cycling named in its message, residual growth, or an exhausted budget).

use super::chart::{outcome_grid, Panel};
use super::scenes::{self, DRAG_DISTANCE};
use super::{seconds, write_file, Outcome, StudyOptions, Variant};
use crate::contact::Enforcement;
use crate::solver::AntiCycling;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::time::Instant;

/// Mesh of every run: 32 x 8 cells (0.5 mm), as in docs/history/benchmarks.md's drag.
const CELLS: usize = 32;
const MAX_ITERATIONS: usize = 25;

/// The grid axes.
pub struct Grid {
    /// Increments over [0, 3] (a third press, two thirds drag).
    pub increments: Vec<usize>,
    pub r_factors: Vec<f64>,
    pub mus: Vec<f64>,
    pub methods: Vec<Method>,
}

/// A method of the map: enforcement and Newton safeguards.
#[derive(Clone, Debug)]
pub struct Method {
    pub name: &'static str,
    pub enforcement: Enforcement,
    pub line_search: bool,
    pub anti_cycling: AntiCycling,
}

impl Grid {
    /// The full map: drag steps of 4, 2, 1, 0.5 mm (the contact is about 2 mm wide), r from
    /// 1/100 to 100 times the default, mu 0.1, 0.3, 0.6.
    pub fn full() -> Grid {
        let al = |name, line_search, anti_cycling| Method {
            name,
            enforcement: Enforcement::AugmentedLagrangian,
            line_search,
            anti_cycling,
        };
        Grid {
            increments: vec![3, 6, 12, 24],
            r_factors: vec![0.01, 0.1, 1.0, 10.0, 100.0],
            mus: vec![0.1, 0.3, 0.6],
            methods: vec![
                al("AL + line search + anti-cycling", true, AntiCycling::Freeze),
                al(
                    "AL, no line search, no anti-cycling",
                    false,
                    AntiCycling::Off,
                ),
                Method {
                    name: "penalty + line search + anti-cycling",
                    enforcement: Enforcement::Penalty,
                    line_search: true,
                    anti_cycling: AntiCycling::Freeze,
                },
            ],
        }
    }
}

/// Drag distance per increment for `increments` equal increments over [0, 3].
pub fn drag_step(increments: usize) -> f64 {
    DRAG_DISTANCE / (increments as f64 * 2.0 / 3.0)
}

/// One cell of the map.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Cell {
    pub method: String,
    pub mu: f64,
    pub r_factor: f64,
    pub increments: usize,
    pub drag_step_mm: f64,
    pub outcome: Outcome,
    /// Newton iterations of the converged increments.
    pub iterations: usize,
    pub increments_done: usize,
    pub wall_s: f64,
    pub failure: Option<String>,
}

/// Runs one cell.
pub fn run_cell(method: &Method, mu: f64, r_factor: f64, increments: usize) -> Result<Cell> {
    let mut v = Variant::new("", CELLS, increments);
    v.contact.enforcement = method.enforcement;
    v.r_factor = r_factor;
    v.line_search = method.line_search;
    v.anti_cycling = method.anti_cycling;
    let t = Instant::now();
    let mut sim = scenes::cylinder_drag(&v, mu, MAX_ITERATIONS, 0)?;
    let run = sim.run(|_, _| Ok(()));
    let cycled = sim.history.iter().any(|r| !r.cycling.is_empty());
    let (outcome, failure) = match run {
        Ok(()) if cycled => (Outcome::ConvergedCycling, None),
        Ok(()) => (Outcome::Converged, None),
        Err(e) => (Outcome::of_failure(&e), Some(e.to_string())),
    };
    Ok(Cell {
        method: method.name.into(),
        mu,
        r_factor,
        increments,
        drag_step_mm: drag_step(increments),
        outcome,
        iterations: sim.history.iter().map(|r| r.iterations).sum(),
        increments_done: sim.history.len(),
        wall_s: seconds(t),
        failure,
    })
}

/// Runs the whole grid.
pub fn run_grid(grid: &Grid, opts: Option<&StudyOptions>) -> Result<Vec<Cell>> {
    let mut cells = Vec::new();
    let total = grid.methods.len() * grid.mus.len() * grid.r_factors.len() * grid.increments.len();
    for m in &grid.methods {
        for &mu in &grid.mus {
            for &r in &grid.r_factors {
                for &n in &grid.increments {
                    let c = run_cell(m, mu, r, n)?;
                    if let Some(o) = opts {
                        o.note(&format!(
                            "  [{}/{total}] {}, mu {mu}, r x {r}, drag step {:.2} mm: {}, {} iterations, {:.2} s",
                            cells.len() + 1,
                            m.name,
                            c.drag_step_mm,
                            c.outcome.name(),
                            c.iterations,
                            c.wall_s
                        ));
                    }
                    cells.push(c);
                }
            }
        }
    }
    Ok(cells)
}

/// Results of the map (`results.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StabilityResult {
    pub title: String,
    pub command: String,
    pub cells: Vec<Cell>,
}

pub fn run(opts: &StudyOptions) -> Result<()> {
    let grid = Grid::full();
    let cells = run_grid(&grid, Some(opts))?;
    let result = StabilityResult {
        title: format!(
            "Cylinder drag, {CELLS} x {} cells, no cutbacks, {MAX_ITERATIONS} iterations per increment",
            CELLS / 4
        ),
        command: opts.command.clone(),
        cells,
    };
    write(&grid, &result, opts)
}

fn write(grid: &Grid, result: &StabilityResult, opts: &StudyOptions) -> Result<()> {
    let dir = opts.folder("stability")?;
    let json = serde_json::to_string_pretty(result)
        .map_err(|e| Error::Input(format!("stability results: {e}")))?;
    write_file(&dir.join("results.json"), &json)?;
    let mut panels = Vec::new();
    for m in &grid.methods {
        for &mu in &grid.mus {
            let cells = grid
                .r_factors
                .iter()
                .rev()
                .map(|&r| {
                    grid.increments
                        .iter()
                        .map(|&n| {
                            let c = result.cells.iter().find(|c| {
                                c.method == m.name
                                    && c.mu == mu
                                    && c.r_factor == r
                                    && c.increments == n
                            });
                            match c {
                                Some(c) if c.outcome.converged() => {
                                    (c.outcome, c.iterations.to_string())
                                }
                                Some(c) => (c.outcome, format!("i{}", c.increments_done + 1)),
                                None => (Outcome::Diverged, "?".into()),
                            }
                        })
                        .collect()
                })
                .collect();
            panels.push(Panel {
                title: format!("{}\nmu = {mu}", m.name),
                rows: grid
                    .r_factors
                    .iter()
                    .rev()
                    .map(|r| format!("x {r}"))
                    .collect(),
                cols: grid
                    .increments
                    .iter()
                    .map(|&n| format!("{:.2}", drag_step(n)))
                    .collect(),
                cells,
            });
        }
    }
    let svg = outcome_grid(
        &format!("Stability map: {}", result.title),
        "r / default r",
        "drag per increment [mm]",
        &panels,
        grid.mus.len(),
    );
    write_file(&dir.join("stability_map.svg"), &svg)?;
    let mut csv = format!(
        "# stability map: {} -- made by: {}\nmethod,mu,r_factor,increments,drag_step_mm,outcome,iterations,increments_done,wall_s,failure\n",
        result.title, result.command
    );
    let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    for c in &result.cells {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{:.4},{}",
            quote(&c.method),
            c.mu,
            c.r_factor,
            c.increments,
            c.drag_step_mm,
            quote(c.outcome.name()),
            c.iterations,
            c.increments_done,
            c.wall_s,
            quote(c.failure.as_deref().unwrap_or(""))
        );
    }
    write_file(&dir.join("stability_map.csv"), &csv)
}
