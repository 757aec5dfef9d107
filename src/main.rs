//! The `tribo` command line: run a process script, step it in a REPL, or run the studies.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use tribo::script::{self, HostOptions};

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
        /// Output folder (default: out/<script name>).
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
        #[arg(long, value_name = "CHECKPOINT")]
        restart: Option<PathBuf>,
    },
    /// Speed against accuracy: work-precision charts and stability maps with a report.
    Study {
        /// hertz, friction_work, cylinder_drag, square_cup, stability, all, or report (only
        /// rewrite the report from the results in the folder).
        name: String,
        /// Output folder (default: out/studies).
        #[arg(long)]
        out: Option<PathBuf>,
        /// No progress lines.
        #[arg(long)]
        quiet: bool,
    },
    /// Interactive stepping; loads SCRIPT's scene first if given.
    Repl {
        script: Option<PathBuf>,
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn default_out(script: Option<&PathBuf>) -> PathBuf {
    let stem = script
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "repl".into());
    PathBuf::from("out").join(stem)
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
        } => (|| {
            let overrides = set
                .iter()
                .map(|s| script::parse_override(s))
                .collect::<tribo::Result<Vec<_>>>()?;
            let host = HostOptions {
                out_dir: out.unwrap_or_else(|| default_out(Some(&script))),
                progress: !quiet,
                restart,
                ..HostOptions::default()
            };
            host.interrupt.install_signal_handlers()?;
            script::run_file(&script, &overrides, &host)?;
            eprintln!("results in {}", host.out_dir.display());
            Ok(())
        })(),
        Command::Study { name, out, quiet } => {
            let out = out.unwrap_or_else(|| PathBuf::from("out/studies"));
            let command = format!("tribo study {name} --out {}", out.display());
            let mut opts = tribo::study::StudyOptions::new(out, command);
            opts.progress = !quiet;
            tribo::study::run(&name, &opts)
        }
        Command::Repl { script, out } => {
            let host = HostOptions {
                out_dir: out.unwrap_or_else(|| default_out(script.as_ref())),
                progress: true,
                ..HostOptions::default()
            };
            host.interrupt
                .install_signal_handlers()
                .and_then(|()| script::repl::run(script.as_deref(), &host))
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
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
