//! Mutants of the shipped scripts and how a run of one ends. Shared by
//! `examples/mutation_campaign` (the full campaign) and `tests/mutated_scripts.rs` (a seeded
//! sample).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The shipped scripts: scripts/, tests/scripts/, tests/robust/.
pub fn shipped_scripts(root: &Path) -> Vec<PathBuf> {
    let mut all = Vec::new();
    for dir in ["scripts", "tests/scripts", "tests/robust"] {
        let mut v: Vec<PathBuf> = std::fs::read_dir(root.join(dir))
            .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        v.retain(|p| p.extension().is_some_and(|e| e == "rhai"));
        v.sort();
        all.extend(v);
    }
    all
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Number,
    Str,
    Array,
}

/// Replacement texts by kind: numbers to 0, -1, 1e308, NaN, inf, 2.5; strings empty;
/// arrays empty.
fn replacements(kind: Kind) -> &'static [&'static str] {
    match kind {
        Kind::Number => &["0", "-1", "1e308", "(0.0/0.0)", "(1.0/0.0)", "2.5"],
        Kind::Str => &["\"\""],
        Kind::Array => &["[]"],
    }
}

/// Byte ranges of number literals, string literals and non-empty array literals outside
/// comments and template strings.
fn sites(src: &str) -> Vec<(usize, usize, Kind)> {
    let b = src.as_bytes();
    let mut out = Vec::new();
    let mut open: Vec<usize> = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        if c == b'"' || c == b'`' {
            let start = i;
            i += 1;
            while i < b.len() && b[i] != c {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            if c == b'"' && i > start + 1 {
                out.push((start, i + 1, Kind::Str));
            }
            i += 1;
            continue;
        }
        let ident_before = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if c.is_ascii_digit() && !ident_before {
            let start = i;
            while i < b.len()
                && (b[i].is_ascii_digit()
                    || b[i] == b'_'
                    || (b[i] == b'.' && b.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
                    || ((b[i] == b'e' || b[i] == b'E')
                        && b.get(i + 1)
                            .is_some_and(|d| d.is_ascii_digit() || *d == b'-')))
            {
                if (b[i] == b'e' || b[i] == b'E') && b[i + 1] == b'-' {
                    i += 1;
                }
                i += 1;
            }
            out.push((start, i, Kind::Number));
            continue;
        }
        if c == b'[' {
            open.push(i);
        } else if c == b']' {
            if let Some(s) = open.pop() {
                if !src[s + 1..i].trim().is_empty() {
                    out.push((s, i + 1, Kind::Array));
                }
            }
        }
        i += 1;
    }
    out
}

/// Every single-site mutant of `src`: (description, text).
pub fn mutants(src: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (s, e, kind) in sites(src) {
        let line = src[..s].matches('\n').count() + 1;
        for r in replacements(kind) {
            let text = format!("{}{}{}", &src[..s], r, &src[e..]);
            let orig: String = src[s..e].chars().take(30).collect();
            out.push((format!("line {line}: {orig} -> {r}"), text));
        }
    }
    out
}

/// Small sizes for the scripts' size knobs, so a mutant runs in seconds.
pub fn shrink(src: &str) -> Vec<String> {
    let mut sets = Vec::new();
    for (name, value) in [("cells", "4"), ("layers", "1"), ("increments", "3")] {
        let decl = format!("\nlet {name} = ");
        if let Some(at) = src.find(&decl) {
            // Only a literal declaration can be overridden safely.
            let rest = &src[at + decl.len()..];
            let lit = rest.split(';').next().unwrap_or("");
            if lit.trim().parse::<f64>().is_ok() {
                sets.push(format!("{name}={value}"));
            }
        }
    }
    sets
}

#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Ran,
    /// Stopped with an error; `located` when it names file:line:column or a value.
    Refused {
        located: bool,
    },
    Panic,
    Signal(i32),
    Hang,
}

pub struct Outcome {
    pub verdict: Verdict,
    pub stderr: String,
}

/// Runs one mutant as `tribo run` in a folder mirroring the original's (its data files are
/// linked and the original folder is readable), killed once it has used `limit` of CPU
/// time, or [`WALL_FACTOR`] times `limit` of wall time (a process blocked without using
/// the CPU hangs too). CPU time, because a hang is a run that never ends, not one slowed
/// by a loaded machine: on 2 cores shared with compilers, a run of 50 s CPU took 400 s.
pub fn run_mutant(
    bin: &Path,
    original: &Path,
    text: &str,
    work: &Path,
    limit: Duration,
) -> Outcome {
    let _ = std::fs::remove_dir_all(work);
    std::fs::create_dir_all(work).unwrap();
    let dir = original.parent().unwrap();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.extension().is_none_or(|x| x != "rhai") {
            let _ = std::os::unix::fs::symlink(&p, work.join(e.file_name()));
        }
    }
    let script = work.join(original.file_name().unwrap());
    std::fs::write(&script, text).unwrap();
    let err_file = work.join("stderr.txt");
    let mut cmd = Command::new(bin);
    cmd.arg("run")
        .arg(&script)
        .args(["--quiet", "--max-script-seconds", "20", "--allow-read"])
        .arg(dir)
        .arg("--out")
        .arg(work.join("out"));
    for s in shrink(text) {
        cmd.args(["--set", &s]);
    }
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&err_file).unwrap())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        let cpu = cpu_time(child.id()).unwrap_or_default();
        if cpu > limit || start.elapsed() > WALL_FACTOR * limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr = std::fs::read_to_string(&err_file).unwrap_or_default();
    let verdict = match status {
        None => Verdict::Hang,
        Some(_) if stderr.contains("panicked") => Verdict::Panic,
        Some(s) => match s.code() {
            Some(0) => Verdict::Ran,
            Some(_) => Verdict::Refused {
                located: located(&stderr),
            },
            None => Verdict::Signal(std::os::unix::process::ExitStatusExt::signal(&s).unwrap_or(0)),
        },
    };
    let _ = std::fs::remove_dir_all(work);
    Outcome { verdict, stderr }
}

/// Wall time allowed per unit of the CPU limit (see [`run_mutant`]).
pub const WALL_FACTOR: u32 = 8;

/// User plus system CPU time of a running process, from `/proc/<pid>/stat` (fields 14 and
/// 15, in clock ticks of 1/100 s, the kernel's USER_HZ on every Linux platform this runs on).
pub fn cpu_time(pid: u32) -> Option<Duration> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count after it.
    let rest = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<u64>().ok();
    // `rest` starts at field 3, so fields 14 and 15 are at indices 11 and 12.
    Some(Duration::from_millis(10 * (ticks(11)? + ticks(12)?)))
}

/// The error names the place (`file.rhai:line:`) or the value at fault (`name = value`).
fn located(stderr: &str) -> bool {
    let Some(line) = stderr.lines().rev().find(|l| l.starts_with("error:")) else {
        return false;
    };
    let place = line.find(".rhai:").is_some_and(|at| {
        line[at + 6..]
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_digit())
    });
    place || line.contains(" = ") || line.contains("--set ")
}

/// xorshift64: a seeded, dependency-free choice of mutants.
pub struct XorShift(pub u64);

impl XorShift {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Tallies of a campaign.
#[derive(Default, Debug)]
pub struct Tally {
    pub tries: usize,
    pub ran: usize,
    pub refused: usize,
    pub unlocated: Vec<String>,
    pub panics: Vec<String>,
    pub hangs: Vec<String>,
    pub signals: Vec<String>,
}

impl Tally {
    pub fn add(&mut self, what: String, o: &Outcome) {
        self.tries += 1;
        match &o.verdict {
            Verdict::Ran => self.ran += 1,
            Verdict::Refused { located } => {
                self.refused += 1;
                if !located {
                    let last = o.stderr.lines().last().unwrap_or("").to_string();
                    self.unlocated.push(format!("{what}: {last}"));
                }
            }
            Verdict::Panic => self.panics.push(format!("{what}: {}", o.stderr)),
            Verdict::Hang => self.hangs.push(what),
            Verdict::Signal(s) => self.signals.push(format!("{what}: signal {s}")),
        }
    }
}

/// Runs every mutant `(original script, what was mutated, mutated text)` on `jobs` threads,
/// each in its own folder below `work_base` (removed afterwards), killed after `limit`;
/// with `progress_every`, prints a count to stderr that often.
pub fn run_all(
    bin: &Path,
    mutants: Vec<(PathBuf, String, String)>,
    jobs: usize,
    limit: Duration,
    work_base: &Path,
    progress_every: Option<usize>,
) -> Tally {
    use std::sync::{Arc, Mutex};
    let queue = Arc::new(Mutex::new(mutants));
    let tally = Arc::new(Mutex::new(Tally::default()));
    let workers: Vec<_> = (0..jobs)
        .map(|j| {
            let (queue, tally, bin) = (queue.clone(), tally.clone(), bin.to_path_buf());
            let work = work_base.join(format!("w{j}"));
            std::thread::spawn(move || loop {
                let Some((script, what, text)) = queue.lock().unwrap().pop() else {
                    break;
                };
                let o = run_mutant(&bin, &script, &text, &work, limit);
                let mut t = tally.lock().unwrap();
                t.add(format!("{}: {what}", script.display()), &o);
                if progress_every.is_some_and(|k| t.tries % k == 0) {
                    eprintln!("{} tried", t.tries);
                }
            })
        })
        .collect();
    for w in workers {
        w.join().unwrap();
    }
    let _ = std::fs::remove_dir_all(work_base);
    let tally = std::mem::take(&mut *tally.lock().unwrap());
    tally
}
