//! `tribo bench`: the speed table of a few standard cases, optionally side by side with
//! another tribo binary (`--baseline`), so that every speed claim can be reproduced.
//!
//! Each case is one whole run of a committed script (embedded in the binary, written to a
//! temporary folder) as a child process, `tribo run SCRIPT --set ... --quiet --out DIR`,
//! of this binary and of the baseline in turn (this, baseline, per case, so that drift of a
//! shared machine hits both alike). From the run's `summary.json` it reads the counts and
//! the per-phase seconds (`phase_times_s`, whatever phases the binary records); CPU seconds
//! are the child's user + system time (Linux: the parent's `cutime + cstime` in
//! `/proc/self/stat` before and after waiting for it, 1/100 s resolution), wall seconds the
//! parent's clock around the child. The numbers are reported, never judged.
//!
//! # Comparing builds whose scripts differ
//!
//! A baseline built from an older checkout may not know the current script's settings or
//! functions. So each binary runs its own checkout's script when there is one: for a
//! baseline at `TREE/target/release/tribo` (or with `--baseline-scripts DIR`), the script of
//! the same name in `TREE/scripts/`; otherwise this binary's copy. And each binary gets only
//! the `--set` overrides its script declares (a top-level `let NAME = ...;`); the table
//! lists what was left out.
//!
//! # One thread
//!
//! `--threads N` (default 1; 0 for every core) pins each child to `N` of the processors this
//! process may use (Linux `sched_setaffinity`; elsewhere runs are not pinned), so that the
//! engine's default of one element thread per available core gives `N`: CPU seconds per
//! iteration with one thread are the cost of the iteration itself, free of threading
//! overheads.

pub mod floor;

use crate::{Error, Result};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

const SQUARE_CUP: &str = include_str!("../../scripts/square_cup.rhai");
const CYLINDER_DRAG: &str = include_str!("../../scripts/cylinder_drag.rhai");

/// The cases `--case` accepts.
pub const CASES: [&str; 3] = ["cup", "cup-benchmark", "drag"];

/// What to run.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Case names from [`CASES`] (or "all").
    pub cases: Vec<String>,
    /// Cells per blank edge (cup, default 25) or along the block (drag, default 32).
    pub cells: Option<usize>,
    /// Cells through the sheet (cup only; default 1).
    pub layers: Option<usize>,
    /// Punch travel in mm (cup only; default the variant's own, 30 or 40).
    pub travel: Option<f64>,
    /// Another tribo binary run on the same cases.
    pub baseline: Option<PathBuf>,
    /// Where to write the table as JSON.
    pub json: Option<PathBuf>,
    /// Folder for scripts and run outputs (default: a folder under the system's temp).
    pub work_dir: Option<PathBuf>,
    /// The baseline's scripts folder (default: `TREE/scripts` of a baseline at
    /// `TREE/target/<profile>/tribo`, if it holds the case's script).
    pub baseline_scripts: Option<PathBuf>,
    /// Processors each run may use (0: all this process may use).
    pub threads: usize,
}

/// One case, checked and ready to run.
#[derive(Clone, Debug, Serialize)]
pub struct Case {
    pub name: String,
    /// The `--set` overrides asked for (each binary gets those its script declares).
    pub sets: Vec<String>,
    /// The script's file name (`scripts/NAME` of a checkout).
    pub script_name: &'static str,
    #[serde(skip)]
    script: &'static str,
}

/// One run of one binary on one case.
#[derive(Clone, Debug, Serialize)]
pub struct Measurement {
    pub binary: String,
    /// The script this binary ran (its own checkout's, or this binary's copy).
    pub script: PathBuf,
    /// The overrides passed, and those left out because the script does not declare them.
    pub sets: Vec<String>,
    pub sets_left_out: Vec<String>,
    /// The run's output folder (its summary.json is where every count comes from).
    pub out_dir: PathBuf,
    pub nodes: usize,
    /// Displacement unknowns, 3 per node.
    pub displacement_unknowns: usize,
    pub increments: usize,
    pub newton_iterations: usize,
    /// Newton iterations of the attempts not kept (cut back, retried, rejected), not in
    /// `newton_iterations` (None for a binary that does not count them).
    pub discarded_iterations: Option<usize>,
    pub line_search_cuts: usize,
    /// Trial states evaluated per Newton iteration, (iterations + cuts) / iterations: the
    /// full step and each cut (predictors and re-evaluations not counted).
    pub trials_per_iteration: f64,
    /// Element evaluations per accepted Newton iteration, full (with tangents) and
    /// residual-only, from the run's own count (`evaluations` in summary.json, failed
    /// attempts included; None for a binary that does not record it).
    pub full_evaluations_per_iteration: Option<f64>,
    pub residual_evaluations_per_iteration: Option<f64>,
    /// Residual-only evaluations later given their Jacobian (an accepted line-search cut:
    /// element tangents and assembly, no second contact pass), per Newton iteration
    /// (`evaluations.jacobian_completions`; None for a binary that does not record it).
    pub completions_per_iteration: Option<f64>,
    /// Seconds per phase as the run recorded them.
    pub phase_times_s: BTreeMap<String, f64>,
    pub cpu_s: Option<f64>,
    pub wall_s: f64,
    /// cpu_s (or wall_s without it) per Newton iteration, in ms.
    pub ms_per_iteration: f64,
    /// wall_s per Newton iteration, in ms.
    pub wall_ms_per_iteration: f64,
    /// Processors the run was pinned to (None: not pinned).
    pub threads: Option<usize>,
}

/// A case with this binary's run and, with `--baseline`, the baseline's.
#[derive(Clone, Debug, Serialize)]
pub struct CaseResult {
    pub case: Case,
    pub this: Measurement,
    pub baseline: Option<Measurement>,
}

/// Checks the options and expands the case list; errors name the offending value.
pub fn cases(opts: &BenchOptions) -> Result<Vec<Case>> {
    if opts.cases.is_empty() {
        return Err(Error::input("--case", "(none)", "give at least one case"));
    }
    if let Some(c) = opts.cells.filter(|&c| c == 0 || c > 400) {
        return Err(Error::input("--cells", c, "must be in 1..=400"));
    }
    if let Some(l) = opts.layers.filter(|&l| l == 0 || l > 16) {
        return Err(Error::input("--layers", l, "must be in 1..=16"));
    }
    if let Some(t) = opts.travel.filter(|t| !(*t > 0.0 && *t <= 60.0)) {
        return Err(Error::input("--travel", t, "must be in (0, 60] mm"));
    }
    if let Some(d) = opts.baseline_scripts.as_ref().filter(|d| !d.is_dir()) {
        return Err(Error::input(
            "--baseline-scripts",
            d.display(),
            "is not a folder (give the baseline checkout's scripts/)",
        ));
    }
    if let Some(b) = &opts.baseline {
        if !b.is_file() {
            return Err(Error::input(
                "--baseline",
                b.display(),
                "is not a file (give the path of another tribo binary)",
            ));
        }
    }
    let mut names = Vec::new();
    for name in &opts.cases {
        match name.as_str() {
            "all" => names.extend(CASES.iter().map(|s| s.to_string())),
            n if CASES.contains(&n) => names.push(n.to_string()),
            other => {
                return Err(Error::input(
                    "--case",
                    format!("\"{other}\""),
                    &format!("must be one of {} or all", CASES.join(", ")),
                ))
            }
        }
    }
    Ok(names
        .into_iter()
        .map(|name| {
            let (script_name, script, sets) = if name == "drag" {
                let cells = opts.cells.unwrap_or(32).max(4);
                (
                    "cylinder_drag.rhai",
                    CYLINDER_DRAG,
                    vec![format!("cells={cells}")],
                )
            } else {
                let variant = if name == "cup" { "paper" } else { "benchmark" };
                let mut sets = vec![
                    format!("variant=\"{variant}\""),
                    format!("cells={}", opts.cells.unwrap_or(25)),
                    format!("layers={}", opts.layers.unwrap_or(1)),
                    "charts=false".to_string(),
                    // The bench's cups are F-bar hexahedra, as BENCHMARKS.md's rows say (the
                    // script's default for one layer became the solid-shell).
                    "element=\"hexahedron\"".to_string(),
                ];
                if let Some(t) = opts.travel {
                    sets.push(format!("travel={t:?}"));
                }
                ("square_cup.rhai", SQUARE_CUP, sets)
            };
            Case {
                name,
                sets,
                script_name,
                script,
            }
        })
        .collect())
}

/// Runs every case with this binary (`this`) and the baseline, prints the table as it
/// goes, writes the JSON if asked, and returns the results.
pub fn run(opts: &BenchOptions, this: &Path) -> Result<Vec<CaseResult>> {
    let cases = cases(opts)?;
    let work = opts.work_dir.clone().unwrap_or_else(|| {
        std::env::temp_dir().join(format!("tribo-bench-{}", std::process::id()))
    });
    std::fs::create_dir_all(&work).map_err(|e| Error::io(&work, e))?;
    let mut results = Vec::new();
    for case in cases {
        let script = work.join(format!("{}.rhai", case.name));
        std::fs::write(&script, case.script).map_err(|e| Error::io(&script, e))?;
        let this_run = measure(
            this,
            &script,
            &case,
            &work.join(format!("{}-this", case.name)),
            opts.threads,
        )?;
        let base_run = match &opts.baseline {
            Some(b) => {
                let own = baseline_script(b, opts.baseline_scripts.as_deref(), case.script_name);
                Some(measure(
                    b,
                    own.as_deref().unwrap_or(&script),
                    &case,
                    &work.join(format!("{}-baseline", case.name)),
                    opts.threads,
                )?)
            }
            None => None,
        };
        let result = CaseResult {
            case,
            this: this_run,
            baseline: base_run,
        };
        print!("{}", table(&result));
        results.push(result);
    }
    if let Some(path) = &opts.json {
        let text = serde_json::to_string_pretty(&results)
            .map_err(|e| Error::Input(format!("bench JSON: {e}")))?;
        std::fs::write(path, text).map_err(|e| Error::io(path, e))?;
    }
    Ok(results)
}

/// The children's CPU seconds so far (user + system of waited-for children), Linux only.
fn children_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start at field 3.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // cutime and cstime are fields 16 and 17 (1-based), i.e. 13 and 14 after ')'.
    let ticks = fields.get(13)?.parse::<f64>().ok()? + fields.get(14)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// The baseline's own script for `name`: in `scripts_dir` if given, else in the checkout
/// the binary was built in (`TREE/target/<profile>/tribo` -> `TREE/scripts/name`); None
/// when there is none (this binary's copy is used).
fn baseline_script(binary: &Path, scripts_dir: Option<&Path>, name: &str) -> Option<PathBuf> {
    let dir = match scripts_dir {
        Some(d) => d.to_path_buf(),
        None => binary.parent()?.parent()?.parent()?.join("scripts"),
    };
    Some(dir.join(name)).filter(|p| p.is_file())
}

/// The names a script declares with a top-level `let NAME = ...;` (what `--set` may
/// override): lines starting with `let` at column 0.
pub fn declared_settings(script: &str) -> Vec<String> {
    script
        .lines()
        .filter_map(|line| line.strip_prefix("let "))
        .filter_map(|rest| {
            let name: String = rest
                .trim_start()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            (!name.is_empty()).then_some(name)
        })
        .collect()
}

/// `sets` split into those `script` declares and those it does not.
fn split_sets(sets: &[String], script: &str) -> (Vec<String>, Vec<String>) {
    let declared = declared_settings(script);
    sets.iter().cloned().partition(|s| {
        let name = s.split('=').next().unwrap_or("").trim();
        declared.iter().any(|d| d == name)
    })
}

/// Pins the child `command` will start to the first `n` processors this process may use
/// (Linux; `n = 0`, or elsewhere: no pinning). Returns how many it was given, None when not
/// pinned.
#[cfg(target_os = "linux")]
fn pin_child(command: &mut std::process::Command, n: usize) -> Option<usize> {
    use std::os::unix::process::CommandExt;
    if n == 0 {
        return None;
    }
    // SAFETY: cpu_set_t is plain data; sched_getaffinity writes at most its size.
    let (set, taken) = unsafe {
        let mut own: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut own) != 0 {
            return None;
        }
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        let mut taken = 0;
        for cpu in 0..libc::CPU_SETSIZE as usize {
            if taken < n && libc::CPU_ISSET(cpu, &own) {
                libc::CPU_SET(cpu, &mut set);
                taken += 1;
            }
        }
        (set, taken)
    };
    if taken == 0 {
        return None;
    }
    // SAFETY: the closure runs in the child between fork and exec and only calls
    // sched_setaffinity (async-signal-safe) on a mask prepared before the fork.
    unsafe {
        command.pre_exec(move || {
            if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    Some(taken)
}

#[cfg(not(target_os = "linux"))]
fn pin_child(_command: &mut std::process::Command, _n: usize) -> Option<usize> {
    None
}

fn measure(
    binary: &Path,
    script: &Path,
    case: &Case,
    out: &Path,
    threads: usize,
) -> Result<Measurement> {
    let text = std::fs::read_to_string(script).map_err(|e| Error::io(script, e))?;
    // The run's folder is the bench's own (a --work-dir used again holds the last
    // measurement); cleared here rather than with --overwrite, which a baseline binary from
    // before that option would refuse.
    crate::output::clear_previous_outputs(out)?;
    let (sets, sets_left_out) = split_sets(&case.sets, &text);
    let mut command = std::process::Command::new(binary);
    command
        .arg("run")
        .arg(script)
        .arg("--quiet")
        .arg("--out")
        .arg(out)
        .args(sets.iter().flat_map(|s| ["--set", s.as_str()]));
    let pinned = pin_child(&mut command, threads);
    let cpu0 = children_cpu_seconds();
    let start = Instant::now();
    let output = command
        .output()
        .map_err(|e| Error::Input(format!("bench: cannot start {}: {e}", binary.display())))?;
    let wall_s = start.elapsed().as_secs_f64();
    let cpu_s = match (cpu0, children_cpu_seconds()) {
        (Some(a), Some(b)) => Some(b - a),
        _ => None,
    };
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
        return Err(Error::no_convergence(
            crate::error::Failure::Unrecoverable,
            format!(
                "bench case {} with {}: the run failed ({}): {}",
                case.name,
                binary.display(),
                output.status,
                tail.into_iter().rev().collect::<Vec<_>>().join(" | ")
            ),
        ));
    }
    let summary_path = out.join("summary.json");
    let text = std::fs::read_to_string(&summary_path).map_err(|e| Error::io(&summary_path, e))?;
    let summary: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::Input(format!("{}: {e}", summary_path.display())))?;
    let count = |key: &str| -> Result<usize> {
        summary[key]
            .as_u64()
            .map(|v| v as usize)
            .ok_or_else(|| Error::Input(format!("{}: no count \"{key}\"", summary_path.display())))
    };
    let nodes = count("nodes")?;
    let newton_iterations = count("newton_iterations")?;
    let line_search_cuts = count("line_search_cuts")?;
    let phase_times_s = summary["phase_times_s"]
        .as_object()
        .map(|m| {
            m.iter()
                .filter_map(|(k, v)| v.as_f64().map(|v| (k.clone(), v)))
                .collect()
        })
        .unwrap_or_default();
    let iterations = newton_iterations.max(1) as f64;
    let per_iteration = |key: &str| summary["evaluations"][key].as_f64().map(|v| v / iterations);
    Ok(Measurement {
        binary: binary.display().to_string(),
        script: script.to_path_buf(),
        sets,
        sets_left_out,
        out_dir: out.to_path_buf(),
        nodes,
        displacement_unknowns: 3 * nodes,
        increments: count("increments")?,
        newton_iterations,
        discarded_iterations: summary["discarded_iterations"].as_u64().map(|v| v as usize),
        line_search_cuts,
        trials_per_iteration: (newton_iterations + line_search_cuts) as f64 / iterations,
        full_evaluations_per_iteration: per_iteration("full"),
        residual_evaluations_per_iteration: per_iteration("residual_only"),
        completions_per_iteration: per_iteration("jacobian_completions"),
        phase_times_s,
        cpu_s,
        wall_s,
        ms_per_iteration: 1e3 * cpu_s.unwrap_or(wall_s) / iterations,
        wall_ms_per_iteration: 1e3 * wall_s / iterations,
        threads: pinned,
    })
}

/// Evaluations per iteration as `full+residual+completed` from the run's count (`+c`
/// left out for a binary that does not count its completions), else the trials per
/// iteration marked `~` (a binary that does not count its evaluations).
fn evaluations_cell(m: &Measurement) -> String {
    match (
        m.full_evaluations_per_iteration,
        m.residual_evaluations_per_iteration,
        m.completions_per_iteration,
    ) {
        (Some(f), Some(r), Some(c)) => format!("{f:.2}+{r:.2}+{c:.2}"),
        (Some(f), Some(r), None) => format!("{f:.2}+{r:.2}"),
        _ => format!("~{:.2}", m.trials_per_iteration),
    }
}

/// The rows of one case: this binary, the baseline, and baseline / this (a speed-up above 1
/// where this binary is faster); then which script each ran and any override left out.
fn table(result: &CaseResult) -> String {
    let mut phases: Vec<String> = result.this.phase_times_s.keys().cloned().collect();
    if let Some(b) = &result.baseline {
        for k in b.phase_times_s.keys() {
            if !phases.contains(k) {
                phases.push(k.clone());
            }
        }
    }
    let threads = match result.this.threads {
        Some(n) => format!("{n} processor(s) per run"),
        None => "all processors".to_string(),
    };
    let mut s = format!(
        "\ncase {} ({}; {threads})\n{:<9} {:>7} {:>5} {:>6} {:>6} {:>5} {:>16}",
        result.case.name,
        result.case.sets.join(" "),
        "binary",
        "u dofs",
        "incr",
        "iters",
        "disc",
        "cuts",
        "evals/it f+r+c"
    );
    for p in &phases {
        s += &format!(" {:>12}", format!("{p} s"));
    }
    s += &format!(
        " {:>8} {:>8} {:>10} {:>10}\n",
        "cpu s", "wall s", "cpu ms/it", "wall ms/it"
    );
    let row = |label: &str, m: &Measurement| {
        let discarded = m
            .discarded_iterations
            .map_or("-".to_string(), |d| d.to_string());
        let mut r = format!(
            "{label:<9} {:>7} {:>5} {:>6} {discarded:>6} {:>5} {:>16}",
            m.displacement_unknowns,
            m.increments,
            m.newton_iterations,
            m.line_search_cuts,
            evaluations_cell(m)
        );
        for p in &phases {
            match m.phase_times_s.get(p) {
                Some(v) => r += &format!(" {v:>12.3}"),
                None => r += &format!(" {:>12}", "-"),
            }
        }
        let cpu = m.cpu_s.map_or("-".to_string(), |c| format!("{c:.2}"));
        let cpu_ms = m
            .cpu_s
            .map_or("-".to_string(), |_| format!("{:.2}", m.ms_per_iteration));
        r += &format!(
            " {cpu:>8} {:>8.2} {cpu_ms:>10} {:>10.2}\n",
            m.wall_s, m.wall_ms_per_iteration
        );
        r
    };
    s += &row("this", &result.this);
    if let Some(b) = &result.baseline {
        s += &row("baseline", b);
        let ratio = |a: f64, b: f64| {
            if a > 0.0 {
                format!("{:.2}", b / a)
            } else {
                "-".to_string()
            }
        };
        let t = &result.this;
        let mut r = format!(
            "{:<9} {:>7} {:>5} {:>6} {:>6} {:>5} {:>16}",
            "base/this", "", "", "", "", "", ""
        );
        for p in &phases {
            match (t.phase_times_s.get(p), b.phase_times_s.get(p)) {
                (Some(x), Some(y)) => r += &format!(" {:>12}", ratio(*x, *y)),
                _ => r += &format!(" {:>12}", "-"),
            }
        }
        let (cpu, cpu_ms) = match (t.cpu_s, b.cpu_s) {
            (Some(x), Some(y)) => (ratio(x, y), ratio(t.ms_per_iteration, b.ms_per_iteration)),
            _ => ("-".into(), "-".into()),
        };
        r += &format!(
            " {cpu:>8} {:>8} {cpu_ms:>10} {:>10}\n",
            ratio(t.wall_s, b.wall_s),
            ratio(t.wall_ms_per_iteration, b.wall_ms_per_iteration)
        );
        s += &r;
    }
    for (label, m) in std::iter::once(("this", &result.this))
        .chain(result.baseline.as_ref().map(|b| ("baseline", b)))
    {
        s += &format!("{label}: {}", m.script.display());
        if !m.sets_left_out.is_empty() {
            s += &format!(
                " (left out, not declared by that script: {})",
                m.sets_left_out.join(" ")
            );
        }
        s += "\n";
    }
    s += "evals/it f+r+c: element evaluations per accepted Newton iteration, full (with \
          tangents) + residual-only (line-search trials) + completed (residual-only ones given \
          their Jacobian afterwards: an accepted cut); evaluations and phase seconds include \
          the attempts that failed and were cut back; disc: Newton iterations of those attempts \
          (not in iters)\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(cases: &[&str]) -> BenchOptions {
        BenchOptions {
            cases: cases.iter().map(|s| s.to_string()).collect(),
            cells: None,
            layers: None,
            travel: None,
            baseline: None,
            json: None,
            work_dir: None,
            baseline_scripts: None,
            threads: 1,
        }
    }

    /// Case names and sizes are checked before anything runs; "all" expands; the sizes
    /// reach the script's overrides.
    #[test]
    fn options_are_checked_and_expanded() {
        let err = cases(&opts(&["cup", "kettle"])).unwrap_err().to_string();
        assert!(err.contains("--case") && err.contains("kettle"), "{err}");
        assert!(cases(&opts(&[])).is_err());
        let mut o = opts(&["all"]);
        assert_eq!(cases(&o).unwrap().len(), 3);
        o.cells = Some(0);
        assert!(cases(&o).unwrap_err().to_string().contains("--cells"));
        o.cells = Some(10);
        o.travel = Some(-1.0);
        assert!(cases(&o).unwrap_err().to_string().contains("--travel"));
        o.travel = Some(2.5);
        o.layers = Some(2);
        let c = cases(&o).unwrap();
        assert!(c[1].sets.contains(&"variant=\"benchmark\"".to_string()));
        assert!(c[0].sets.contains(&"travel=2.5".to_string()));
        assert!(c[0].sets.contains(&"layers=2".to_string()));
        assert_eq!(c[2].sets, vec!["cells=10".to_string()]);
        o.baseline = Some(PathBuf::from("/no/such/tribo"));
        let err = cases(&o).unwrap_err().to_string();
        assert!(
            err.contains("--baseline") && err.contains("/no/such/tribo"),
            "{err}"
        );
    }

    /// Overrides go only to scripts that declare them; the shipped scripts declare every
    /// override the cases pass.
    #[test]
    fn overrides_follow_the_script_declarations() {
        let script = "// let commented = 1;\nlet cells = 4; // x\nlet  mu=0.2;\n  let inner = 1;\n";
        assert_eq!(declared_settings(script), vec!["cells", "mu"]);
        let sets = vec![
            "cells=8".to_string(),
            "inner=2".to_string(),
            "mu=0.3".to_string(),
        ];
        let (kept, left) = split_sets(&sets, script);
        assert_eq!(kept, vec!["cells=8".to_string(), "mu=0.3".to_string()]);
        assert_eq!(left, vec!["inner=2".to_string()]);
        let mut o = opts(&["all"]);
        o.travel = Some(3.0);
        for case in cases(&o).unwrap() {
            let (_, left) = split_sets(&case.sets, case.script);
            assert!(left.is_empty(), "{}: {left:?}", case.name);
        }
    }
}
