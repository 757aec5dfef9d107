//! Issue 18, families of runs: `tribo sweep` over the cylinder drag's mu x r (12 coarse,
//! short runs). The same summaries (but for timings) come from `--jobs 2`, from the runs
//! started one by one with `tribo run`, from the emitted GNU parallel command file run by
//! `bash`, and from the emitted Slurm array script run by `bash` for one task index;
//! `tribo sweep collect` writes the table of every run and the chart.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_tribo");
const MU: [f64; 3] = [0.1, 0.2, 0.3];
/// 0: the engine's default per node.
const R: [f64; 4] = [0.0, 3.0, 300.0, 30000.0];
/// Every run coarse and short: 8 cells, 6 increments (about 0.1 s each).
const FIXED: [(&str, &str); 2] = [("cells", "8"), ("increments", "6")];

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/cylinder_drag.rhai")
}

fn rows() -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for mu in MU {
        for r in R {
            let mut row = vec![mu.to_string(), r.to_string()];
            row.extend(FIXED.iter().map(|(_, v)| v.to_string()));
            rows.push(row);
        }
    }
    rows
}

fn tribo(args: &[&str]) -> String {
    let out = Command::new(BIN).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "tribo {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn bash(script: &Path, task: Option<usize>) {
    let mut cmd = Command::new("bash");
    cmd.arg(script);
    if let Some(k) = task {
        cmd.env("SLURM_ARRAY_TASK_ID", k.to_string());
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "bash {} failed:\n{}",
        script.display(),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A run's summary.json without what depends on the machine's load (times).
fn summary(dir: &Path) -> Value {
    let path = dir.join("summary.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut v: Value = serde_json::from_str(&text).unwrap();
    let m = v.as_object_mut().unwrap();
    m.remove("wall_time_s");
    m.remove("phase_times_s");
    assert_eq!(m["status"], "finished", "{}", path.display());
    v
}

#[test]
fn local_jobs_one_by_one_parallel_file_and_slurm_array_agree_and_collect_charts() {
    let dir = std::env::temp_dir().join(format!("tribo-sweep-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let table = dir.join("mu_r.csv");
    let mut text = String::from("# cylinder drag, mu x r\nmu,r");
    for (name, _) in FIXED {
        text.push_str(&format!(",{name}"));
    }
    text.push('\n');
    for row in rows() {
        text.push_str(&row.join(","));
        text.push('\n');
    }
    std::fs::write(&table, text).unwrap();
    let (script, n) = (script(), rows().len());
    assert!(n >= 12);
    let path = |p: &Path| p.display().to_string();

    // Reference: every run by hand.
    let by_hand: Vec<Value> = rows()
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let out = dir.join(format!("by_hand/{i}"));
            let mut args = vec!["run".to_string(), path(&script), "--quiet".into()];
            args.extend(["--out".to_string(), path(&out)]);
            let names = ["mu", "r"].into_iter().chain(FIXED.iter().map(|(n, _)| *n));
            for (name, value) in names.zip(row) {
                args.extend(["--set".to_string(), format!("{name}={value}")]);
            }
            tribo(&args.iter().map(String::as_str).collect::<Vec<_>>());
            summary(&out)
        })
        .collect();
    // The parameters reached the runs.
    for (row, s) in rows().iter().zip(&by_hand) {
        let friction = s["tools"]["roller"]["friction"].as_str().unwrap();
        assert_eq!(friction, format!("Coulomb mu = {}", row[0]));
    }
    // The solution does not depend on r (to the Newton tolerance, 1e-9 relative on forces
    // here 8 digits), Newton's path does.
    for (k, block) in by_hand.chunks(R.len()).enumerate() {
        let fx = |s: &Value| s["tools"]["roller"]["final_force"][0].as_f64().unwrap();
        for s in block {
            let (a, b) = (fx(s), fx(&block[0]));
            assert!(
                (a - b).abs() <= 1e-8 * b.abs(),
                "mu = {}: {a} against {b}",
                MU[k]
            );
        }
    }
    let iterations: Vec<u64> = by_hand
        .iter()
        .map(|s| s["newton_iterations"].as_u64().unwrap())
        .collect();
    assert!(
        iterations.iter().any(|&k| k != iterations[0]),
        "r changes Newton's path, so not every run takes {} iterations",
        iterations[0]
    );

    let sweep = |out: &Path, extra: &[&str]| {
        let mut args = vec!["sweep", script.to_str().unwrap(), table.to_str().unwrap()];
        let out = path(out);
        args.extend(["--out", &out, "--quiet"]);
        args.extend(extra);
        tribo(&args)
    };
    let run_dir = |out: &Path, i: usize| out.join(format!("runs/run_{i:03}"));

    // Here on two processes.
    let local = dir.join("local");
    sweep(&local, &["--jobs", "2"]);
    for (i, expected) in by_hand.iter().enumerate() {
        assert_eq!(&summary(&run_dir(&local, i)), expected, "run {i}, --jobs 2");
    }

    // The GNU parallel command file, one line per run, run by bash one after the other.
    let parallel = dir.join("parallel");
    let said = sweep(&parallel, &["--emit", "parallel", "--jobs", "4"]);
    assert!(said.starts_with("parallel --jobs 4 < "), "{said}");
    let commands = parallel.join("commands.txt");
    let lines = std::fs::read_to_string(&commands).unwrap();
    assert_eq!(lines.lines().count(), n);
    assert!(!run_dir(&parallel, 0).exists(), "--emit ran something");
    bash(&commands, None);
    for (i, expected) in by_hand.iter().enumerate() {
        assert_eq!(
            &summary(&run_dir(&parallel, i)),
            expected,
            "run {i}, parallel file"
        );
    }

    // The Slurm job array: its form, and one task run by bash with its index set.
    let slurm = dir.join("slurm");
    let said = sweep(&slurm, &["--emit", "slurm"]);
    let job = slurm.join("sweep.slurm");
    assert_eq!(said.trim(), format!("sbatch {}", path(&job)));
    let text = std::fs::read_to_string(&job).unwrap();
    assert!(text.starts_with("#!/bin/bash\n"));
    let directives: Vec<&str> = text.lines().filter(|l| l.starts_with("#SBATCH ")).collect();
    assert!(
        directives.contains(&format!("#SBATCH --array=0-{}", n - 1).as_str()),
        "{text}"
    );
    assert!(directives.contains(&"#SBATCH --ntasks=1"), "{text}");
    // The default wall time and memory, and each run told its memory.
    assert!(directives.contains(&"#SBATCH --time=04:00:00"), "{text}");
    assert!(directives.contains(&"#SBATCH --mem=4096M"), "{text}");
    let commands = std::fs::read_to_string(slurm.join("commands.txt")).unwrap();
    assert!(
        commands
            .lines()
            .all(|l| l.contains(" --max-memory-mb 4096 ")),
        "{commands}"
    );
    assert!(text.contains("SLURM_ARRAY_TASK_ID") && text.contains("commands.txt"));
    let task = 7;
    bash(&job, Some(task));
    assert_eq!(
        summary(&run_dir(&slurm, task)),
        by_hand[task],
        "slurm task {task}"
    );
    for i in (0..n).filter(|&i| i != task) {
        assert!(
            !run_dir(&slurm, i).join("summary.json").exists(),
            "task {task} ran run {i}"
        );
    }

    // Collect: the table of all runs and the chart.
    let listed = tribo(&[
        "sweep",
        "collect",
        local.to_str().unwrap(),
        "--x",
        "mu",
        "--series",
        "r",
        "--y",
        "tools.roller.final_force.0",
    ]);
    let chart = local.join("chart_tools_roller_final_force_0_vs_mu.svg");
    assert!(listed.contains(&path(&chart)), "{listed}");
    let collected = std::fs::read_to_string(local.join("collected.csv")).unwrap();
    let mut lines = collected.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&header[..3], ["id", "mu", "r"]);
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (fx, its) = (
        column("tools.roller.final_force.0"),
        column("newton_iterations"),
    );
    let body: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(body.len(), n);
    for (i, (cells, s)) in body.iter().zip(&by_hand).enumerate() {
        assert_eq!(cells[0], format!("run_{i:03}"));
        let force: f64 = cells[fx].parse().unwrap();
        assert_eq!(
            force,
            s["tools"]["roller"]["final_force"][0].as_f64().unwrap()
        );
        assert_eq!(cells[its], s["newton_iterations"].to_string());
    }
    let svg = std::fs::read_to_string(&chart).unwrap();
    assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"));
    for r in R {
        assert!(svg.contains(&format!("r = {r}")), "no line for r = {r}");
    }
    let points = std::fs::read_to_string(chart.with_extension("csv")).unwrap();
    assert_eq!(points.lines().count(), n + 1, "{points}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--time` and `--mem` reach the job array as Slurm reads them; bad values, or the flags
/// without `--emit slurm`, are refused before anything is written.
#[test]
fn slurm_time_and_memory_are_settable_and_checked() {
    let dir = std::env::temp_dir().join(format!("tribo-sweep-res-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let table = dir.join("mu.csv");
    std::fs::write(&table, "mu,cells,increments\n0.1,8,6\n0.2,8,6\n").unwrap();
    let (script, table) = (script(), table.display().to_string());
    let script = script.display().to_string();
    let out = dir.join("ok");
    let out_s = out.display().to_string();
    let args = ["sweep", &script, &table, "--out", &out_s, "--emit", "slurm"];
    tribo(&[&args[..], &["--time", "1-12:00:00", "--mem", "16G"]].concat());
    let text = std::fs::read_to_string(out.join("sweep.slurm")).unwrap();
    assert!(text.contains("\n#SBATCH --time=1-12:00:00\n"), "{text}");
    assert!(text.contains("\n#SBATCH --mem=16384M\n"), "{text}");
    let commands = std::fs::read_to_string(out.join("commands.txt")).unwrap();
    assert_eq!(
        commands.matches(" --max-memory-mb 16384 ").count(),
        2,
        "{commands}"
    );

    let refused = |extra: &[&str], folder: &str, said: &str| {
        let out = dir.join(folder);
        let out_s = out.display().to_string();
        let mut all = vec!["sweep", &script, &table, "--out", &out_s];
        all.extend_from_slice(extra);
        let run = Command::new(BIN).args(&all).output().unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{all:?}: {err}");
        assert!(err.contains(said), "{all:?}: {err}");
        assert!(!out.exists(), "{all:?} wrote its folder before refusing");
    };
    refused(
        &["--emit", "slurm", "--time", "4h"],
        "t",
        "--time 4h: not a Slurm time limit",
    );
    refused(
        &["--emit", "slurm", "--mem", "4GB"],
        "m",
        "--mem 4GB: not a Slurm memory size",
    );
    refused(
        &["--emit", "parallel", "--mem", "4G"],
        "p",
        "--mem is what each task",
    );
    refused(&["--time", "10"], "l", "--time is what each task");
}
