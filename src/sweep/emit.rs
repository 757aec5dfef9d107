//! A sweep written out for a cluster's own scheduler instead of run here:
//! - `commands.txt`: one shell command line per run, in row order: a GNU parallel command
//!   file (`parallel --jobs N < commands.txt`), and what `bash commands.txt` runs one by one;
//! - `sweep.slurm`: a Slurm job array of one task per run, task `k` running line `k + 1`
//!   of commands.txt (`sbatch sweep.slurm`).

use super::Sweep;
use crate::Result;

pub const COMMANDS_FILE: &str = "commands.txt";
pub const SLURM_FILE: &str = "sweep.slurm";

/// Where a sweep goes when it is not run here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    Slurm,
    Parallel,
}

impl Target {
    pub fn from_name(name: &str) -> Result<Target> {
        match name {
            "slurm" => Ok(Target::Slurm),
            "parallel" => Ok(Target::Parallel),
            other => Err(crate::Error::Input(format!(
                "--emit {other}: must be \"slurm\" or \"parallel\""
            ))),
        }
    }
}

/// Writes the sweep's index, commands.txt and, for Slurm, sweep.slurm; returns what to
/// type to start it.
pub fn write(sweep: &Sweep, target: Target, jobs: usize) -> Result<String> {
    sweep.write_index()?;
    let commands = sweep.out.join(COMMANDS_FILE);
    let mut text = String::new();
    for i in 0..sweep.table.rows.len() {
        let line: Vec<String> = sweep.command(i).iter().map(|a| quote(a)).collect();
        text.push_str(&format!(
            "{} > {} 2>&1\n",
            line.join(" "),
            quote(&sweep.log_file(i).display().to_string())
        ));
    }
    crate::output::write_atomic(&commands, text.as_bytes())?;
    Ok(match target {
        Target::Parallel => format!(
            "parallel --jobs {} < {}    # or, one by one: bash {}",
            jobs.max(1),
            quote(&commands.display().to_string()),
            quote(&commands.display().to_string())
        ),
        Target::Slurm => {
            let script = sweep.out.join(SLURM_FILE);
            crate::output::write_atomic(&script, slurm_script(sweep).as_bytes())?;
            format!("sbatch {}", quote(&script.display().to_string()))
        }
    })
}

/// The job array script: one task per row, each running its line of commands.txt.
pub fn slurm_script(sweep: &Sweep) -> String {
    let n = sweep.table.rows.len();
    let logs = sweep.out.join("logs");
    let commands = sweep.out.join(COMMANDS_FILE);
    format!(
        "#!/bin/bash\n\
         #SBATCH --job-name=tribo-sweep\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --output={logs}/slurm_%A_%a.out\n\
         # {n} runs of {script} over the rows of its table (see sweep.csv); task k runs\n\
         # line k + 1 of commands.txt. Collect with: tribo sweep collect {out}\n\
         set -euo pipefail\n\
         line=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" {commands})\n\
         exec bash -c \"$line\"\n",
        last = n - 1,
        logs = logs.display(),
        script = sweep.script.display(),
        out = quote(&sweep.out.display().to_string()),
        commands = quote(&commands.display().to_string()),
    )
}

/// A word for the shell: as it is when it holds only safe characters, else single-quoted.
pub fn quote(word: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-./=:+,@%".contains(c);
    if !word.is_empty() && word.chars().all(safe) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_quoting() {
        assert_eq!(quote("mu=0.1"), "mu=0.1");
        assert_eq!(quote("/a b/c"), "'/a b/c'");
        assert_eq!(quote("variant=it's"), "'variant=it'\\''s'");
        assert_eq!(quote(""), "''");
    }
}
