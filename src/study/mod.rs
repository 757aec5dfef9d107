//! Speed against accuracy: families of runs of the verification cases, charted as error
//! against wall time (work-precision), and maps of where Newton converges, cycles or
//! diverges over step size x augmentation parameter x friction coefficient.
//!
//! `tribo study NAME --out DIR` runs one study (`hertz`, `friction_work`, `cylinder_drag`,
//! `square_cup`, `stability`), `all` runs every one, `report` only rewrites the report,
//! `square_cup_rescore` measures the stored square-cup runs against the stored reference again.
//! Each study writes `DIR/NAME/results.json` (every run: its settings, wall time, Newton
//! iterations, measured values, error or reason of failure), its charts as SVG with a CSV
//! of their points whose first line is the command that made them, and then
//! `DIR/README.md` is regenerated from every `results.json` found in `DIR`.
//!
//! Wall time is the whole run (model set-up, every increment, and for the square cup the
//! script and its output): the cost a user pays. It is measured on one thread; on a shared
//! machine it varies by some 10 % (see BENCHMARKS.md), which the charts' log scale absorbs.
//! Runs shorter than half a second are repeated and timed by their mean.

pub mod chart;
pub mod cup_reference;
pub mod extrapolate;
pub mod report;
pub mod richardson;
pub mod scenes;
pub mod square_cup;
pub mod stability;
pub mod work_precision;

use crate::solver::AntiCycling;
use crate::solver::ContactSettings;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The studies `tribo study` knows, in the order `all` runs them.
pub const STUDIES: [&str; 5] = [
    "hertz",
    "friction_work",
    "cylinder_drag",
    "square_cup",
    "stability",
];

/// One run's settings: mesh, increments and method switches. What `cells`, `increments`
/// and `layers` mean is the scene's (see `scenes`); `r_factor` multiplies the engine's
/// default augmentation (or penalty) parameter of every contact node.
#[derive(Clone, Debug)]
pub struct Variant {
    pub label: String,
    pub cells: usize,
    pub increments: usize,
    pub layers: usize,
    pub contact: ContactSettings,
    pub r_factor: f64,
    pub line_search: bool,
    pub anti_cycling: AntiCycling,
}

impl Variant {
    /// The engine's default methods on `cells` cells in `increments` increments.
    pub fn new(label: impl Into<String>, cells: usize, increments: usize) -> Self {
        Variant {
            label: label.into(),
            cells,
            increments,
            layers: 1,
            contact: ContactSettings::default(),
            r_factor: 1.0,
            line_search: true,
            anti_cycling: AntiCycling::Freeze,
        }
    }

    /// Renamed copy with a change applied: `v.with("penalty", |v| ...)`.
    pub fn with(&self, label: impl Into<String>, change: impl FnOnce(&mut Variant)) -> Self {
        let mut v = self.clone();
        v.label = label.into();
        change(&mut v);
        v
    }
}

/// Where the output goes and how the study was started (written beside every chart).
#[derive(Clone, Debug)]
pub struct StudyOptions {
    pub out: PathBuf,
    /// The command line that reproduces the output, e.g. `tribo study all --out docs/studies`.
    pub command: String,
    /// Print one progress line per run on stderr.
    pub progress: bool,
}

impl StudyOptions {
    pub fn new(out: impl Into<PathBuf>, command: impl Into<String>) -> Self {
        StudyOptions {
            out: out.into(),
            command: command.into(),
            progress: true,
        }
    }

    pub(crate) fn note(&self, line: &str) {
        if self.progress {
            eprintln!("{line}");
        }
    }

    /// `out/name`, created.
    pub(crate) fn folder(&self, name: &str) -> Result<PathBuf> {
        let dir = self.out.join(name);
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        Ok(dir)
    }
}

/// Runs study `name` (or `all`, or only the `report`) into `opts.out`.
pub fn run(name: &str, opts: &StudyOptions) -> Result<()> {
    let names: Vec<&str> = match name {
        "all" => STUDIES.to_vec(),
        "report" => Vec::new(),
        "square_cup_rescore" => vec!["square_cup_rescore"],
        n if STUDIES.contains(&n) => vec![n],
        other => {
            return Err(Error::Input(format!(
                "unknown study '{other}' (known: {}, all, report, square_cup_rescore)",
                STUDIES.join(", ")
            )))
        }
    };
    check_writable(&opts.out)?;
    let start = Instant::now();
    for n in names {
        opts.note(&format!("study {n}: starting"));
        let t = Instant::now();
        match n {
            "stability" => stability::run(opts)?,
            "square_cup" => square_cup::run(opts)?,
            "square_cup_rescore" => square_cup::rescore(opts)?,
            case => work_precision::run(case, opts)?,
        }
        opts.note(&format!(
            "study {n}: done in {:.1} s",
            t.elapsed().as_secs_f64()
        ));
    }
    report::write(opts)?;
    opts.note(&format!(
        "report {} written; {:.1} s in all",
        opts.out.join("README.md").display(),
        start.elapsed().as_secs_f64()
    ));
    Ok(())
}

/// Fails early, with the folder named, when the output folder cannot be written.
fn check_writable(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let probe = dir.join(".tribo_study_probe");
    std::fs::write(&probe, b"")
        .map_err(|e| Error::io(dir, format!("output folder is not writable: {e}")))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Outcome {
    /// Reached the end; no contact status cycled.
    Converged,
    /// Reached the end (satisfying the free contact law), with the anti-cycling treatment
    /// engaged in some increment.
    ConvergedCycling,
    /// Stopped: Newton failed while some node's contact status cycled.
    Cycled,
    /// Stopped: the residual grew (or became non-finite, or the matrix singular).
    Diverged,
    /// Stopped: the iteration budget ran out without growth or cycling.
    Stalled,
}

impl Outcome {
    pub fn converged(self) -> bool {
        matches!(self, Outcome::Converged | Outcome::ConvergedCycling)
    }

    /// Classifies a failed run by the kind of its last failure ([`Error::failure`]): a
    /// contact status cycled, the iteration budget ran out, or anything else (growth, a
    /// non-finite residual, a singular matrix, a failed local solve).
    pub fn of_failure(err: &Error) -> Outcome {
        match err.failure() {
            (_, true) => Outcome::Cycled,
            (crate::error::Failure::Stalled, false) => Outcome::Stalled,
            _ => Outcome::Diverged,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Outcome::Converged => "converged",
            Outcome::ConvergedCycling => "converged (anti-cycling engaged)",
            Outcome::Cycled => "cycled",
            Outcome::Diverged => "diverged",
            Outcome::Stalled => "stalled",
        }
    }
}

/// Cost of a finished or stopped simulation.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Cost {
    pub wall_s: f64,
    /// Newton iterations of the converged increments.
    pub iterations: usize,
    /// Converged increments.
    pub increments: usize,
    pub cutbacks: usize,
}

impl Cost {
    pub(crate) fn of(sim: &crate::solver::Simulation, wall_s: f64) -> Cost {
        Cost {
            wall_s,
            iterations: sim.history.iter().map(|r| r.iterations).sum(),
            increments: sim.history.len(),
            cutbacks: sim.history.iter().map(|r| r.cutbacks).sum(),
        }
    }
}

/// Seconds since `t`.
pub(crate) fn seconds(t: Instant) -> f64 {
    t.elapsed().as_secs_f64()
}

/// Writes `text` to `path`, naming the path on failure.
pub(crate) fn write_file(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| Error::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Failure;

    /// Studies classify a stop by its typed kind, whatever its message says.
    #[test]
    fn outcomes_follow_the_failure_kind_not_the_text() {
        let stop = |kind, cycling, message: &str| Error::NoConvergence {
            kind,
            cycling,
            message: message.into(),
        };
        let misleading = "status cycling; 25 Newton iterations without convergence";
        assert_eq!(
            Outcome::of_failure(&stop(Failure::Diverged, false, misleading)),
            Outcome::Diverged
        );
        assert_eq!(
            Outcome::of_failure(&stop(Failure::Stalled, false, "")),
            Outcome::Stalled
        );
        assert_eq!(
            Outcome::of_failure(&stop(Failure::ForceGrowth, true, "")),
            Outcome::Cycled
        );
        assert_eq!(
            Outcome::of_failure(&Error::LinearSolver("singular".into())),
            Outcome::Diverged
        );
    }
}
