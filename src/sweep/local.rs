//! A sweep on this machine: the runs as child processes, at most `jobs` at a time, each
//! run's stdout and stderr in `logs/run_NNN.log`. A failed run does not stop the others;
//! the sweep reports every failure at the end.

use super::Sweep;
use crate::{Error, Result};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// Runs every row of the sweep, `jobs` processes at a time; `progress` prints a line per
/// finished run to stderr.
pub fn run(sweep: &Sweep, jobs: usize, progress: bool) -> Result<()> {
    sweep.write_index()?;
    let total = sweep.table.rows.len();
    let jobs = jobs.max(1);
    let mut running: Vec<(usize, Child)> = Vec::new();
    let (mut next, mut done) = (0, 0);
    let mut failed: Vec<String> = Vec::new();
    while done < total {
        while running.len() < jobs && next < total {
            running.push((next, start(sweep, next)?));
            next += 1;
        }
        let mut finished = None;
        for (k, (_, child)) in running.iter_mut().enumerate() {
            if let Some(status) = child
                .try_wait()
                .map_err(|e| Error::Input(format!("sweep: {e}")))?
            {
                finished = Some((k, status));
                break;
            }
        }
        let Some((k, status)) = finished else {
            std::thread::sleep(Duration::from_millis(20));
            continue;
        };
        let (i, _) = running.swap_remove(k);
        done += 1;
        if !status.success() {
            failed.push(format!(
                "{} ({status}; see {})",
                sweep.id(i),
                sweep.log_file(i).display()
            ));
        }
        if progress {
            let outcome = if status.success() { "done" } else { "FAILED" };
            eprintln!("{} {outcome} ({done}/{total})", sweep.id(i));
        }
    }
    if failed.is_empty() {
        Ok(())
    } else {
        Err(Error::Input(format!(
            "sweep: {} of {total} runs failed: {}",
            failed.len(),
            failed.join(", ")
        )))
    }
}

fn start(sweep: &Sweep, i: usize) -> Result<Child> {
    let log_path = sweep.log_file(i);
    let log = std::fs::File::create(&log_path).map_err(|e| Error::io(&log_path, e))?;
    let err = log.try_clone().map_err(|e| Error::io(&log_path, e))?;
    let args = sweep.command(i);
    Command::new(&args[0])
        .args(&args[1..])
        .stdin(Stdio::null())
        .stdout(log)
        .stderr(err)
        .spawn()
        .map_err(|e| Error::Input(format!("sweep: cannot start {}: {e}", args[0])))
}
