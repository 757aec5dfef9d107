//! A sweep written out for a cluster's own scheduler instead of run here:
//! - `commands.txt`: one shell command line per run, in row order: a GNU parallel command
//!   file (`parallel --jobs N < commands.txt`), and what `bash commands.txt` runs one by one;
//! - `sweep.slurm`: a Slurm job array of one task per run, task `k` running line `k + 1`
//!   of commands.txt (`sbatch sweep.slurm`), with the wall time and memory each task
//!   asks for (`--time`, `--mem`; [`SlurmResources`]). Each run is then also told its
//!   memory (`--max-memory-mb`), so that a mesh too large for the allocation is refused
//!   with a message before it is built instead of being killed by the scheduler.
//!
//! Every path written is absolute, so `sbatch` and `bash commands.txt` work from any
//! submission folder of a file system the nodes share; a sweep folder moved elsewhere is
//! emitted again.

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

/// What each task of a Slurm job array asks for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SlurmResources {
    /// `--time`, in one of Slurm's forms: `M`, `M:S`, `H:M:S`, `D-H`, `D-H:M`, `D-H:M:S`.
    pub time: String,
    /// `--mem` in MiB.
    pub mem_mib: u64,
}

impl SlurmResources {
    /// Default wall time of a task: the benchmark cup runs in 16 s, a converged 100 x 100
    /// sheet in about an hour (BENCHMARKS.md), so four hours leaves room without holding
    /// a queue's longest slot.
    pub const DEFAULT_TIME: &'static str = "04:00:00";
    /// Default memory of a task: the 100 x 100 x 2 cup peaks near 2 GiB.
    pub const DEFAULT_MEM: &'static str = "4G";

    /// Reads `--time` and `--mem` as Slurm writes them (memory: an integer with an
    /// optional K, M, G or T suffix, MiB when none).
    pub fn parse(time: &str, mem: &str) -> Result<SlurmResources> {
        check_slurm_time(time)?;
        Ok(SlurmResources {
            time: time.to_string(),
            mem_mib: slurm_mem_mib(mem)?,
        })
    }
}

impl Default for SlurmResources {
    fn default() -> Self {
        SlurmResources::parse(Self::DEFAULT_TIME, Self::DEFAULT_MEM).expect("valid defaults")
    }
}

/// Slurm's time forms: `M`, `M:S`, `H:M:S`, `D-H`, `D-H:M`, `D-H:M:S`, all fields
/// unsigned integers.
fn check_slurm_time(time: &str) -> Result<()> {
    let fields = |t: &str| {
        t.split(':')
            .all(|f| !f.is_empty() && f.bytes().all(|b| b.is_ascii_digit()))
    };
    let ok = match time.split_once('-') {
        Some((days, rest)) => {
            !days.is_empty()
                && days.bytes().all(|b| b.is_ascii_digit())
                && rest.split(':').count() <= 3
                && fields(rest)
        }
        None => time.split(':').count() <= 3 && fields(time),
    };
    if ok && time.bytes().any(|b| b != b'0' && b.is_ascii_digit()) {
        Ok(())
    } else {
        Err(crate::Error::Input(format!(
            "--time {time}: not a Slurm time limit\n  write minutes (90), hours:minutes:seconds \
             (04:00:00) or days-hours:minutes:seconds (1-12:00:00), not zero"
        )))
    }
}

/// Slurm's `--mem` in MiB: digits and an optional K, M, G or T suffix (M when none).
fn slurm_mem_mib(mem: &str) -> Result<u64> {
    let bad = || {
        crate::Error::Input(format!(
            "--mem {mem}: not a Slurm memory size\n  write a whole number with an optional \
             unit K, M, G or T (4G, 16000M), at least 1M"
        ))
    };
    let (digits, unit) = match mem.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => (&mem[..i], c.to_ascii_uppercase()),
        _ => (mem, 'M'),
    };
    let n: u64 = digits.parse().map_err(|_| bad())?;
    let mib = match unit {
        'K' => n / 1024,
        'M' => n,
        'G' => n.checked_mul(1024).ok_or_else(bad)?,
        'T' => n.checked_mul(1 << 20).ok_or_else(bad)?,
        _ => return Err(bad()),
    };
    if mib == 0 {
        return Err(bad());
    }
    Ok(mib)
}

/// Writes the sweep's index, commands.txt and, for Slurm, sweep.slurm; returns what to
/// type to start it. `slurm`: the resources each task asks for (Slurm only).
pub fn write(sweep: &Sweep, target: Target, jobs: usize, slurm: &SlurmResources) -> Result<String> {
    sweep.write_index()?;
    let commands = sweep.out.join(COMMANDS_FILE);
    let mut text = String::new();
    for i in 0..sweep.table.rows.len() {
        let mut args = sweep.command(i);
        if target == Target::Slurm {
            args.push("--max-memory-mb".into());
            args.push(slurm.mem_mib.to_string());
        }
        let line: Vec<String> = args.iter().map(|a| quote(a)).collect();
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
            crate::output::write_atomic(&script, slurm_script(sweep, slurm).as_bytes())?;
            format!("sbatch {}", quote(&script.display().to_string()))
        }
    })
}

/// The job array script: one task per row, each running its line of commands.txt.
pub fn slurm_script(sweep: &Sweep, resources: &SlurmResources) -> String {
    let n = sweep.table.rows.len();
    let logs = sweep.out.join("logs");
    let commands = sweep.out.join(COMMANDS_FILE);
    format!(
        "#!/bin/bash\n\
         #SBATCH --job-name=tribo-sweep\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --time={time}\n\
         #SBATCH --mem={mem}M\n\
         #SBATCH --output={logs}/slurm_%A_%a.out\n\
         # {n} runs of {script} over the rows of its table (see sweep.csv); task k runs\n\
         # line k + 1 of commands.txt. Collect with: tribo sweep collect {out}\n\
         set -euo pipefail\n\
         line=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" {commands})\n\
         exec bash -c \"$line\"\n",
        last = n - 1,
        time = resources.time,
        mem = resources.mem_mib,
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

    #[test]
    fn slurm_times_and_memory_sizes() {
        for good in ["90", "30:00", "04:00:00", "1-12", "1-12:30", "2-00:00:00"] {
            assert!(check_slurm_time(good).is_ok(), "{good}");
        }
        for bad in [
            "",
            "0",
            "00:00:00",
            "1:2:3:4",
            "1h",
            "-5",
            "1-",
            "4:00:x",
            "1-2:3:4:5",
        ] {
            let e = check_slurm_time(bad).unwrap_err().to_string();
            assert!(e.contains(&format!("--time {bad}:")), "{bad}: {e}");
        }
        assert_eq!(slurm_mem_mib("4G").unwrap(), 4096);
        assert_eq!(slurm_mem_mib("16000").unwrap(), 16000);
        assert_eq!(slurm_mem_mib("512m").unwrap(), 512);
        assert_eq!(slurm_mem_mib("2T").unwrap(), 2 << 20);
        assert_eq!(slurm_mem_mib("2048K").unwrap(), 2);
        for bad in [
            "",
            "G",
            "4X",
            "-1G",
            "0",
            "1K",
            "4.5G",
            "99999999999999999999T",
        ] {
            let e = slurm_mem_mib(bad).unwrap_err().to_string();
            assert!(e.contains(&format!("--mem {bad}:")), "{bad}: {e}");
        }
    }
}
