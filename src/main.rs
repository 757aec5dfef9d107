//! The `tribo` command line: run a process script, step it in a REPL, or run the studies.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use tribo::script::{self, EarlierOutputs, HostOptions};

#[derive(Parser)]
#[command(
    name = "tribo",
    version,
    about = "Implicit frictional contact of a sheet against rigid curved tools, scripted in Rhai"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a process script to its end.
    Run {
        /// The .rhai process script.
        script: PathBuf,
        /// Output folder (default: out/<script name>, with _NAME-VALUE for each --set:
        /// out/square_cup_variant-benchmark).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a top-level `let NAME = ...;` of the script: --set cells=50 --set variant="benchmark".
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
        /// Continue from a checkpoint (written with settings checkpoint_every, sim.checkpoint,
        /// or at a stop): the script builds the model again, then the state is loaded.
        /// The output folder's files are kept (the run continues there).
        #[arg(long, value_name = "CHECKPOINT")]
        restart: Option<PathBuf>,
        /// Remove an earlier run's results from the output folder before running (only the
        /// files a run writes: history.csv, summary.json, *.pvd, charts with their CSV,
        /// frames/*.vtu, checkpoints/*.json). Without it a folder holding them is refused.
        #[arg(long, conflicts_with = "restart")]
        overwrite: bool,
        #[command(flatten)]
        limits: Limits,
    },
    /// Richardson extrapolation of mesh sequences given as JSON (FILE, or - for standard
    /// input): {"rule": {"min", "max", "assumed"} (optional), "quantities": {NAME: [[h, value]
    /// x 3]}}; prints each quantity's extrapolated value, observed order, asymptotic verdict
    /// and GCI band as JSON (the study's own rules: src/study/richardson.rs).
    Extrapolate {
        /// The input JSON file, or - for standard input.
        file: PathBuf,
    },
    /// Speed against accuracy: work-precision charts and stability maps with a report.
    Study {
        /// hertz, friction_work, cylinder_drag, square_cup, stability, all, report (only
        /// rewrite the report from the results in the folder), or square_cup_rescore (measure
        /// the stored square-cup runs against the stored reference again, without running them).
        name: String,
        /// Output folder (default: out/studies).
        #[arg(long)]
        out: Option<PathBuf>,
        /// No progress lines.
        #[arg(long)]
        quiet: bool,
    },
    /// Speed table of standard cases (whole runs as child processes), optionally side by
    /// side with another tribo binary: tribo bench --case cup --cells 25 --travel 5
    /// --baseline OTHER_TRIBO.
    Bench {
        /// cup (paper variant), cup-benchmark, drag, or all; repeat for several.
        #[arg(long, default_value = "cup")]
        case: Vec<String>,
        /// Cells per blank edge (cup, default 25) or along the block (drag, default 32).
        #[arg(long)]
        cells: Option<usize>,
        /// Cells through the sheet (cup; default 1).
        #[arg(long)]
        layers: Option<usize>,
        /// Punch travel in mm (cup; default the variant's own).
        #[arg(long)]
        travel: Option<f64>,
        /// Another tribo binary to run on the same cases, side by side.
        #[arg(long)]
        baseline: Option<PathBuf>,
        /// Also write the table as JSON to this file.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Folder for the scripts and the runs' outputs (default: under the system temp).
        #[arg(long)]
        work_dir: Option<PathBuf>,
        /// The baseline's own scripts folder (default: TREE/scripts for a baseline at
        /// TREE/target/release/tribo; else this binary's scripts).
        #[arg(long)]
        baseline_scripts: Option<PathBuf>,
        /// Processors each run is pinned to (the engine then uses as many element threads);
        /// 0: all.
        #[arg(long, default_value_t = 1)]
        threads: usize,
    },
    /// A family of runs of SCRIPT, one per row of TABLE.csv (its columns become --set
    /// NAME=VALUE), here on --jobs processes or written out for a cluster (--emit); then
    /// `tribo sweep collect DIR` gathers the summaries into one CSV and charts.
    Sweep(SweepArgs),
    /// Interactive stepping: Rhai lines in one scope, TAB completion, :help NAME. Loads
    /// SCRIPT's scene first if given, with stepping deferred (sim.run() returns at once; a
    /// script that steps itself is loaded up to its first sim.step()).
    Repl {
        /// A process script whose scene to load before the prompt.
        script: Option<PathBuf>,
        /// The REPL writes into OUT/repl (default OUT: out/<script name>, or out), its own
        /// folder, so that it never mixes with a run's results in OUT; each session starts
        /// by removing the previous session's results there.
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        limits: Limits,
    },
}

/// `tribo sweep SCRIPT TABLE.csv --out DIR` or `tribo sweep collect DIR`.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
struct SweepArgs {
    #[command(subcommand)]
    collect: Option<SweepCollect>,
    /// The process script.
    #[arg(required = true)]
    script: Option<PathBuf>,
    /// CSV table: a header of script variable names, one run per row (its values become
    /// --set NAME=VALUE).
    #[arg(required = true)]
    table: Option<PathBuf>,
    /// The sweep's folder: sweep.csv, runs/run_NNN/, logs/.
    #[arg(long, required = true)]
    out: Option<PathBuf>,
    /// Runs at a time on this machine (or, with --emit parallel, in the printed command).
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// Do not run: write a Slurm job array (sweep.slurm) or a GNU parallel command file
    /// (commands.txt) into the sweep's folder.
    #[arg(long, value_name = "slurm|parallel")]
    emit: Option<String>,
    /// With --emit slurm: each task's wall-time limit, as Slurm writes it (minutes,
    /// H:M:S or D-H:M:S).
    /// Default: 04:00:00.
    #[arg(long, value_name = "TIME")]
    time: Option<String>,
    /// With --emit slurm: each task's memory (4G, 16000M); each run is also given it as
    /// --max-memory-mb, so a mesh too large for it is refused with a message.
    /// Default: 4G.
    #[arg(long, value_name = "SIZE")]
    mem: Option<String>,
    /// No line per finished run.
    #[arg(long)]
    quiet: bool,
}

#[derive(Subcommand)]
enum SweepCollect {
    /// Gather every run's summary.json into DIR/collected.csv and chart outputs against a
    /// parameter (DIR/chart_Y_vs_X.svg with its CSV).
    Collect {
        /// The sweep's folder.
        dir: PathBuf,
        /// Parameter on the x axis (default: the table's first column).
        #[arg(long)]
        x: Option<String>,
        /// Output to chart (a column of collected.csv, e.g. newton_iterations or
        /// tools.roller.final_force.0); repeat for several charts. Default:
        /// newton_iterations.
        #[arg(long)]
        y: Vec<String>,
        /// Parameter whose values make the chart's lines; repeatable (default: every
        /// parameter but x).
        #[arg(long)]
        series: Vec<String>,
    },
}

/// `--time` and `--mem` of `tribo sweep`: a Slurm job array's only (elsewhere they would
/// be silently ignored).
fn slurm_resources(
    target: Option<tribo::sweep::emit::Target>,
    time: Option<&str>,
    mem: Option<&str>,
) -> tribo::Result<tribo::sweep::emit::SlurmResources> {
    use tribo::sweep::emit::{SlurmResources, Target};
    if target != Some(Target::Slurm) {
        if let Some(flag) = [("--time", time), ("--mem", mem)]
            .iter()
            .find_map(|(flag, v)| v.map(|_| flag))
        {
            return Err(tribo::Error::Input(format!(
                "{flag} is what each task of a Slurm job array asks for: it goes with --emit \
                 slurm only"
            )));
        }
    }
    SlurmResources::parse(
        time.unwrap_or(SlurmResources::DEFAULT_TIME),
        mem.unwrap_or(SlurmResources::DEFAULT_MEM),
    )
}

fn sweep(args: SweepArgs) -> tribo::Result<()> {
    use tribo::sweep;
    if let Some(SweepCollect::Collect { dir, x, y, series }) = args.collect {
        let spec = sweep::collect::ChartSpec { x, y, series };
        for file in sweep::collect::run(&dir, &spec)? {
            println!("{}", file.display());
        }
        return Ok(());
    }
    let (Some(script), Some(table), Some(out)) = (args.script, args.table, args.out) else {
        unreachable!("clap requires SCRIPT, TABLE and --out");
    };
    let this = std::env::current_exe()
        .map_err(|e| tribo::Error::Input(format!("sweep: own binary: {e}")))?;
    let target = args
        .emit
        .as_deref()
        .map(sweep::emit::Target::from_name)
        .transpose()?;
    let slurm = slurm_resources(target, args.time.as_deref(), args.mem.as_deref())?;
    let plan = sweep::Sweep::new(&script, &table, &out, &this)?;
    match target {
        Some(target) => {
            println!("{}", sweep::emit::write(&plan, target, args.jobs, &slurm)?);
            Ok(())
        }
        None => {
            sweep::local::run(&plan, args.jobs, !args.quiet)?;
            eprintln!(
                "{} runs in {}; tribo sweep collect {} gathers their summaries",
                plan.table.rows.len(),
                plan.out.display(),
                plan.out.display()
            );
            Ok(())
        }
    }
}

/// What a script may read and how much the run may use (see docs/script-api.md, "Limits").
#[derive(clap::Args)]
struct Limits {
    /// A folder scripts may read besides their own (imports, JSON tables); repeatable.
    #[arg(long = "allow-read", value_name = "DIR")]
    allow_read: Vec<PathBuf>,
    /// Largest file a script may read, in MiB.
    #[arg(long = "max-read-mb", value_name = "MIB", default_value_t = 64)]
    max_read_mb: u64,
    /// Memory the run may use, in MiB (default: half the machine's memory). A mesh whose
    /// estimated need is larger is refused before it is built.
    #[arg(long = "max-memory-mb", value_name = "MIB")]
    max_memory_mb: Option<u64>,
    /// Wall time of the script's own code, in seconds (time in the simulation not counted).
    #[arg(long = "max-script-seconds", value_name = "S", default_value_t = 600)]
    max_script_seconds: u64,
    /// Increments one simulation may take.
    #[arg(long = "max-increments", value_name = "N", default_value_t = 100_000)]
    max_increments: usize,
    /// Bytes the run may write into its output folder, in MiB.
    #[arg(long = "max-output-mb", value_name = "MIB", default_value_t = 20_480)]
    max_output_mb: u64,
    /// Entries one script array may hold (nested arrays counted).
    #[arg(long = "max-array-size", value_name = "N", default_value_t = tribo::script::limits::DEFAULT_MAX_ARRAY)]
    max_array_size: usize,
    /// Entries the maps of one script value may hold (nested maps counted).
    #[arg(long = "max-map-size", value_name = "N", default_value_t = tribo::script::limits::DEFAULT_MAX_MAP)]
    max_map_size: usize,
}

impl Limits {
    fn apply(&self, host: &mut HostOptions) {
        host.allow_read = self.allow_read.clone();
        host.max_read_bytes = self.max_read_mb.saturating_mul(1 << 20);
        let l = &mut host.limits;
        if let Some(mb) = self.max_memory_mb {
            l.max_memory = mb.saturating_mul(1 << 20);
        }
        l.max_script_time = std::time::Duration::from_secs(self.max_script_seconds);
        l.max_increments = self.max_increments;
        l.max_output = self.max_output_mb.saturating_mul(1 << 20);
        l.max_array = self.max_array_size;
        l.max_map = self.max_map_size;
        tribo::paths::set_output_limit(l.max_output);
    }
}

fn default_out(script: Option<&PathBuf>) -> PathBuf {
    let stem = script
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "repl".into());
    PathBuf::from("out").join(stem)
}

/// The default folder of `tribo run`: out/<script name>, and for each `--set` in the order
/// given `_NAME-VALUE` (quotes dropped, characters other than letters, digits, `.`, `+` and
/// `-` as `_`), so that the variants of one script each have their own folder:
/// out/square_cup, out/square_cup_variant-benchmark, out/square_cup_cells-50_layers-2.
fn default_run_out(script: &PathBuf, sets: &[String]) -> PathBuf {
    let mut name = default_out(Some(script)).into_os_string();
    for set in sets {
        let (key, value) = set.split_once('=').unwrap_or((set, ""));
        let value = value.trim().trim_matches(|c| c == '"' || c == '\'');
        let safe = |t: &str| -> String {
            t.chars()
                .map(|c| match c {
                    c if c.is_ascii_alphanumeric() || ".+-".contains(c) => c,
                    _ => '_',
                })
                .collect()
        };
        name.push(format!("_{}-{}", safe(key.trim()), safe(value)));
    }
    PathBuf::from(name)
}

/// A long one-line message as a person reads it: its first clause (the reason) on the first
/// line, each further clause after a "; " outside brackets on a line of its own, indented.
/// Messages that already have lines of their own, or are short, are left as they are.
fn readable(message: &str) -> String {
    if message.contains('\n') || message.len() <= 160 {
        return message.to_string();
    }
    let mut out = String::new();
    let mut depth = 0i32;
    let mut rest = message.char_indices().peekable();
    let mut start = 0;
    while let Some((i, c)) = rest.next() {
        depth += match c {
            '(' | '[' | '{' => 1,
            ')' | ']' | '}' => -1,
            _ => 0,
        };
        if c == ';' && depth == 0 && rest.peek().is_some_and(|&(_, n)| n == ' ') {
            out.push_str(&message[start..i]);
            out.push_str("\n  ");
            rest.next();
            start = i + 2;
        }
    }
    out.push_str(&message[start..]);
    out
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run {
            script,
            out,
            set,
            quiet,
            restart,
            overwrite,
            limits,
        } => (|| {
            let overrides = set
                .iter()
                .map(|s| script::parse_override(s))
                .collect::<tribo::Result<Vec<_>>>()?;
            let mut host = HostOptions {
                out_dir: out.unwrap_or_else(|| default_run_out(&script, &set)),
                progress: !quiet,
                earlier_outputs: match (&restart, overwrite) {
                    (Some(_), _) => EarlierOutputs::Keep,
                    (None, true) => EarlierOutputs::Overwrite,
                    (None, false) => EarlierOutputs::Refuse,
                },
                restart,
                ..HostOptions::default()
            };
            host.interrupt.install_signal_handlers()?;
            limits.apply(&mut host);
            script::run_file(&script, &overrides, &host)?;
            eprintln!("results in {}", host.out_dir.display());
            Ok(())
        })(),
        Command::Extrapolate { file } => extrapolate(&file),
        Command::Study { name, out, quiet } => {
            let out = out.unwrap_or_else(|| PathBuf::from("out/studies"));
            let command = format!("tribo study {name} --out {}", out.display());
            let mut opts = tribo::study::StudyOptions::new(out, command);
            opts.progress = !quiet;
            tribo::study::run(&name, &opts)
        }
        Command::Bench {
            case,
            cells,
            layers,
            travel,
            baseline,
            json,
            work_dir,
            baseline_scripts,
            threads,
        } => (|| {
            let opts = tribo::bench::BenchOptions {
                cases: case,
                cells,
                layers,
                travel,
                baseline,
                json,
                work_dir,
                baseline_scripts,
                threads,
            };
            let this = std::env::current_exe()
                .map_err(|e| tribo::Error::Input(format!("bench: own binary: {e}")))?;
            tribo::bench::run(&opts, &this).map(|_| ())
        })(),
        Command::Sweep(args) => sweep(args),
        Command::Repl {
            script,
            out,
            limits,
        } => {
            let out = out.unwrap_or_else(|| match &script {
                Some(_) => default_out(script.as_ref()),
                None => PathBuf::from("out"),
            });
            let mut host = HostOptions {
                out_dir: out.join("repl"),
                progress: true,
                ..HostOptions::default()
            };
            limits.apply(&mut host);
            host.interrupt
                .install_signal_handlers()
                .and_then(|()| tribo::output::FolderLock::acquire(&host.out_dir))
                .and_then(|lock| {
                    script::prepare_output_folder(&host.out_dir, EarlierOutputs::Overwrite)?;
                    script::repl::run(script.as_deref(), &host)?;
                    drop(lock);
                    Ok(())
                })
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e @ tribo::Error::Interrupted(_)) => {
            eprintln!(
                "{e}: summary.json and checkpoints/final.json (the last converged state) are in the output folder of each simulation that had started"
            );
            ExitCode::from(tribo::interrupt::EXIT_INTERRUPTED)
        }
        Err(e) => {
            eprintln!("error: {}", readable(&e.to_string()));
            ExitCode::FAILURE
        }
    }
}

/// `tribo extrapolate FILE`: the input read (a regular file by the command line's read
/// policy, `paths::read_named_text`, or standard input; at most 16 MiB), the extrapolations
/// printed as JSON.
fn extrapolate(file: &std::path::Path) -> tribo::Result<()> {
    use std::io::Read;
    let limit: u64 = 16 << 20;
    let (text, source) = if file == std::path::Path::new("-") {
        let mut text = String::new();
        std::io::stdin()
            .take(limit)
            .read_to_string(&mut text)
            .map_err(|e| tribo::Error::Input(format!("standard input: {e}")))?;
        (text, "standard input".to_string())
    } else {
        let text = tribo::paths::read_named_text(file, limit, "extrapolation input")?;
        (text, file.display().to_string())
    };
    let out = tribo::study::extrapolate::run(&text, &source)?;
    let json = serde_json::to_string_pretty(&out)
        .map_err(|e| tribo::Error::Input(format!("extrapolate: {e}")))?;
    println!("{json}");
    Ok(())
}
