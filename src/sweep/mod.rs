//! `tribo sweep`: a family of runs of one script over a user's parameter table.
//!
//! A run stays one process described by the script and its `--set`s (`tribo run SCRIPT
//! --out DIR/runs/run_NNN --quiet --set NAME=VALUE ...`), so a sweep goes wherever runs
//! go: here on N processes at a time ([`local`]), or written out for a cluster's own
//! scheduler as a Slurm job array or a GNU parallel command file ([`emit`]); nothing here
//! schedules beyond "start the next when one ends". `tribo sweep collect DIR` gathers the
//! runs' summary.json files into one table and charts ([`collect`]).
//!
//! Folder of a sweep: `sweep.csv` (run id, run folder, the table's columns: what collect
//! reads), `runs/run_NNN/` (each run's output), `logs/run_NNN.log` (its stdout and stderr),
//! and with `--emit` `commands.txt` (one command line per run, row order) and
//! `sweep.slurm`.

pub mod collect;
pub mod emit;
pub mod local;
pub mod table;

use crate::{Error, Result};
use std::path::{Path, PathBuf};
use table::Table;

/// Index of the runs of a sweep, read by `collect`.
pub const INDEX_FILE: &str = "sweep.csv";

/// One script over the rows of a table, into one folder.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The process script (absolute).
    pub script: PathBuf,
    pub table: Table,
    /// The sweep's folder (absolute).
    pub out: PathBuf,
    /// The tribo binary the runs use (absolute).
    pub tribo: PathBuf,
}

impl Sweep {
    /// Reads the table and checks, before any run starts, that the script declares every
    /// column as a top-level `let` (so a typo fails once, not in every run).
    pub fn new(script: &Path, table: &Path, out: &Path, tribo: &Path) -> Result<Sweep> {
        let script = std::fs::canonicalize(script).map_err(|e| Error::io(script, e))?;
        let table = Table::read(table)?;
        let overrides = table
            .columns
            .iter()
            .zip(&table.rows[0])
            .map(|(c, v)| crate::script::parse_override(&format!("{c}={v}")))
            .collect::<Result<Vec<_>>>()?;
        let host = crate::script::HostOptions::default();
        let engine = crate::script::engine(&host, script.parent());
        let ast = crate::script::compile(&engine, &script)?;
        crate::script::apply_overrides(&engine, ast, &overrides, &script)?;
        std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
        let out = std::fs::canonicalize(out).map_err(|e| Error::io(out, e))?;
        Ok(Sweep {
            script,
            table,
            out,
            tribo: tribo.to_path_buf(),
        })
    }

    /// Id of run `i`: `run_000`, `run_001`, ... (wide enough for every row, so that ids
    /// sort in row order).
    pub fn id(&self, i: usize) -> String {
        let width = self
            .table
            .rows
            .len()
            .saturating_sub(1)
            .to_string()
            .len()
            .max(3);
        format!("run_{i:0width$}")
    }

    pub fn run_dir(&self, i: usize) -> PathBuf {
        self.out.join("runs").join(self.id(i))
    }

    pub fn log_file(&self, i: usize) -> PathBuf {
        self.out.join("logs").join(format!("{}.log", self.id(i)))
    }

    /// The command line of run `i`.
    pub fn command(&self, i: usize) -> Vec<String> {
        let mut args = vec![
            self.tribo.display().to_string(),
            "run".into(),
            self.script.display().to_string(),
            "--out".into(),
            self.run_dir(i).display().to_string(),
            "--quiet".into(),
            // The run's folder is the sweep's own: running the sweep again replaces it.
            "--overwrite".into(),
        ];
        for (c, v) in self.table.columns.iter().zip(&self.table.rows[i]) {
            args.push("--set".into());
            args.push(format!("{c}={v}"));
        }
        args
    }

    /// Writes `sweep.csv`: run id, run folder (relative to the sweep's) and the parameters.
    pub fn write_index(&self) -> Result<()> {
        let mut text = format!("id,folder,{}\n", self.table.columns.join(","));
        for (i, row) in self.table.rows.iter().enumerate() {
            let cells: Vec<String> = row.iter().map(|v| csv_cell(v)).collect();
            text.push_str(&format!(
                "{},runs/{},{}\n",
                self.id(i),
                self.id(i),
                cells.join(",")
            ));
        }
        let logs = self.out.join("logs");
        std::fs::create_dir_all(&logs).map_err(|e| Error::io(&logs, e))?;
        crate::output::write_atomic(&self.out.join(INDEX_FILE), text.as_bytes())
    }
}

/// A CSV cell, quoted when it holds a comma or a quote.
pub(crate) fn csv_cell(v: &str) -> String {
    if v.contains([',', '"']) {
        format!("\"{}\"", v.replace('"', "\"\""))
    } else {
        v.to_string()
    }
}
