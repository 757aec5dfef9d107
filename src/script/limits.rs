//! Resource bounds of a run, each with a default and a command-line override, each stopping
//! with a message that names the limit, the value reached and the option that raises it.
//!
//! * **Memory**: a mesh is refused before it is allocated when its estimated need is over the
//!   limit ([`Limits::check_mesh`]); while the script itself runs, the process's peak
//!   resident memory (`getrusage`) is checked every [`CHECK_EVERY`] operations, and while
//!   the simulation runs, at every Newton iteration (the run's stop request carries the
//!   bound: [`crate::interrupt::Interrupt::memory_over`]).
//! * **Script wall time**: time spent in the script's own code, not in the simulation
//!   (`sim.run()`/`sim.step()` are timed apart and subtracted), checked with the memory.
//! * **Increments** and **output size**: see [`Limits::max_increments`] and
//!   [`crate::paths::set_output_limit`].
//! * **Script arrays and maps**: entries one value may hold ([`Limits::max_array`],
//!   [`Limits::max_map`]). Rhai checks the size of a container after every call that may
//!   change it by counting all its entries (nested ones included), so building an array of
//!   n entries one `push` at a time costs n²/2 visits: about 2.4 ns each on the test
//!   machine, 5 s for 65 536 entries, hours for the 4 194 304 that were allowed before. The
//!   bound is what keeps such a loop short; [`DEFAULT_MAX_ARRAY`] says why it is enough.
//!   Rhai does not check a map that grows by index assignment (`m["k" + i] = i` checks the
//!   new entry, not the map), so the engine also checks a map each time a script variable
//!   holding one is read ([`map_over_bound`]): its own entries at every read (O(1)), its
//!   nested maps counted at every [`CHECK_EVERY`]-th read of a map (O(entries)), so the
//!   counting costs at most 1/64 of an entry visit per entry and read.
//! * **A stop request** (SIGINT/SIGTERM, [`crate::interrupt::Interrupt`]) is polled with the
//!   clock, so that a script busy in its own code (a loop, a script friction law) stops at
//!   the first signal and the run records its stop as interrupted.

use std::cell::Cell;
use std::rc::Rc;
use std::time::{Duration, Instant};

/// The script-progress callback looks at the clock and the memory every this many operations
/// (a `getrusage` call, about 0.3 us, so under 10 ns per operation).
pub const CHECK_EVERY: u64 = 64;

/// Measured peak resident memory per mesh node of a run (assembled tangent, its
/// factorisation, contact data): 63 KB/node for the thin square-cup blank, 80-84 KB/node for
/// the thick cylinder-drag block (scripts/cylinder_drag.rhai with cells = 96 and 128, peak RSS
/// 385 and 712 MB for 4 850 and 8 514 nodes); 100 KB leaves a margin. With status prediction
/// on (the default since session 27; it keeps the element tangents for its re-solves): the
/// cylinder drag 180 and 294 MB (cells = 96, 128), the 25 x 25 x 1 cup 101-121 MiB for
/// 1 352 nodes (plain 80-90), the 50 x 50 x 2 cup 616 MiB (paper) and 721 MiB (benchmark)
/// for 7 803 nodes: 94 KB/node, the nearest to the estimate (not raised: finer meshes were
/// not measured with prediction).
pub const BYTES_PER_NODE: u64 = 100_000;
/// Resident memory of the process before any mesh.
pub const BASE_BYTES: u64 = 20 << 20;

/// Default bound on the entries of one script array (nested arrays and BLOB bytes counted;
/// a record of `sim.history()` counts one). The largest arrays of the shipped scripts are
/// histories of a few thousand increments and node lists of the 7 803-node 50 x 50 x 2 cup;
/// 65 536 holds ten times either, and a script that builds one entry at a time reaches it in
/// about 5 s (see the module docs) rather than running to the script time limit.
pub const DEFAULT_MAX_ARRAY: usize = 1 << 16;
/// Default bound on the entries of the maps in one value (nested maps counted): the same
/// bound as arrays, for the same quadratic cost of Rhai's size check.
pub const DEFAULT_MAX_MAP: usize = 1 << 16;
/// Bound on the length of one script string, in bytes (1 MiB: a script's messages and
/// file names; tables are read from files, not built as strings).
pub const MAX_STRING: usize = 1 << 20;

/// The bounds of one run.
#[derive(Clone, Debug)]
pub struct Limits {
    /// Memory the process may use, in bytes (default: half the machine's memory).
    pub max_memory: u64,
    /// Wall time of the script's own code (the simulation excluded).
    pub max_script_time: Duration,
    /// Increments one simulation may take (settings `increments` above it are refused; an
    /// adaptive run stops there).
    pub max_increments: usize,
    /// Bytes the run may write into its output folder.
    pub max_output: u64,
    /// Entries one script array may hold ([`DEFAULT_MAX_ARRAY`]).
    pub max_array: usize,
    /// Entries the maps of one script value may hold ([`DEFAULT_MAX_MAP`]).
    pub max_map: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_memory: machine_memory().map_or(8 << 30, |m| m / 2),
            max_script_time: Duration::from_secs(600),
            max_increments: 100_000,
            max_output: 20 << 30,
            max_array: DEFAULT_MAX_ARRAY,
            max_map: DEFAULT_MAX_MAP,
        }
    }
}

/// Total memory of the machine (`MemTotal` of /proc/meminfo), in bytes.
pub fn machine_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

use crate::interrupt::mib;
pub use crate::interrupt::peak_memory;

impl Limits {
    /// Refuses a mesh of `nodes` nodes whose estimated memory is over the limit, before it
    /// is built.
    pub fn check_mesh(&self, nodes: u64) -> Result<(), String> {
        let need = nodes
            .saturating_mul(BYTES_PER_NODE)
            .saturating_add(BASE_BYTES);
        if need > self.max_memory {
            return Err(format!(
                "a mesh of {nodes} nodes needs about {} (estimated at {} KB per node), over the \
                 memory limit of {}{} (raise it with --max-memory-mb)",
                mib(need),
                BYTES_PER_NODE / 1000,
                mib(self.max_memory),
                machine_memory()
                    .map(|m| format!("; this machine has {}", mib(m)))
                    .unwrap_or_default()
            ));
        }
        Ok(())
    }
}

/// Time spent in the script's own code: wall time since the start minus time spent
/// simulating.
#[derive(Debug)]
pub struct ScriptClock {
    start: Instant,
    excluded: Cell<Duration>,
}

impl Default for ScriptClock {
    fn default() -> Self {
        ScriptClock {
            start: Instant::now(),
            excluded: Cell::new(Duration::ZERO),
        }
    }
}

impl ScriptClock {
    /// Runs `f` (a simulation call) without counting its time as script time.
    pub fn exclude<T>(&self, f: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let r = f();
        self.excluded.set(self.excluded.get() + t0.elapsed());
        r
    }

    pub fn script_time(&self) -> Duration {
        self.start.elapsed().saturating_sub(self.excluded.get())
    }
}

/// The progress callback of the engine: `Some(message)` stops the script (Rhai reports it as
/// a termination carrying the message). A raised stop request stops it first ("interrupted:
/// SIGTERM received"): the host then records the stop as interrupted.
pub fn progress_check(
    limits: &Limits,
    clock: &Rc<ScriptClock>,
    interrupt: &crate::interrupt::Interrupt,
    ops: u64,
) -> Option<String> {
    if ops % CHECK_EVERY != 0 {
        return None;
    }
    if interrupt.is_raised() {
        return Some(format!("interrupted: {}", interrupt.reason()));
    }
    let t = clock.script_time();
    if t > limits.max_script_time {
        return Some(format!(
            "the script ran for {:.1} s of its own time (the simulation excluded), over the \
             limit of {} s (raise it with --max-script-seconds)",
            t.as_secs_f64(),
            limits.max_script_time.as_secs()
        ));
    }
    match peak_memory() {
        Some(rss) if rss > limits.max_memory => Some(format!(
            "the run uses {} of memory, over the limit of {} (raise it with --max-memory-mb)",
            mib(rss),
            mib(limits.max_memory)
        )),
        _ => None,
    }
}

/// Whether `value` (a script variable being read) is a map over the bound of
/// [`Limits::max_map`]: its own entries are compared at every read, the entries of its nested
/// maps (inside maps and arrays, as Rhai counts them) at every [`CHECK_EVERY`]-th map read
/// (`reads` counts them). Rhai's own check misses a map grown by index assignment (module
/// docs); this one stops such a loop at its next read of the map.
pub fn map_over_bound(limits: &Limits, value: &rhai::Dynamic, reads: &Cell<u64>) -> bool {
    let Some(map) = value.read_lock::<rhai::Map>() else {
        return false;
    };
    if map.len() > limits.max_map {
        return true;
    }
    let n = reads.get().wrapping_add(1);
    reads.set(n);
    n % CHECK_EVERY == 0 && nested_map_entries(&map) > limits.max_map
}

/// Entries of `map` and of every map inside it (through maps and arrays).
fn nested_map_entries(map: &rhai::Map) -> usize {
    map.len() + map.values().map(inner_map_entries).sum::<usize>()
}

fn inner_map_entries(value: &rhai::Dynamic) -> usize {
    if let Some(map) = value.read_lock::<rhai::Map>() {
        nested_map_entries(&map)
    } else if let Some(array) = value.read_lock::<rhai::Array>() {
        array.iter().map(inner_map_entries).sum()
    } else {
        0
    }
}

/// The message of a Rhai "too large" stop (`what`: Rhai's "Size of array/BLOB", "Size of
/// object map", "Length of string"), naming the bound and how to raise it.
pub fn data_too_large(what: &str, limits: &Limits) -> String {
    let count = |n: usize| {
        let digits = n.to_string();
        let mut out = String::new();
        for (i, c) in digits.chars().enumerate() {
            if i > 0 && (digits.len() - i) % 3 == 0 {
                out.push(' ');
            }
            out.push(c);
        }
        out
    };
    if what.contains("array") {
        format!(
            "a script array would hold more than {} entries (nested arrays counted), the bound \
             on what a script builds (raise it with --max-array-size; each entry added one at \
             a time costs a count of the whole array, so a larger bound is slower to reach)",
            count(limits.max_array)
        )
    } else if what.contains("map") {
        format!(
            "script maps would hold more than {} entries in one value (nested maps counted), \
             the bound on what a script builds (raise it with --max-map-size)",
            count(limits.max_map)
        )
    } else if what.contains("string") {
        format!(
            "a script string would be longer than {} bytes, the bound on what a script builds \
             (a fixed bound: write long text with the output functions, read tables from files)",
            count(MAX_STRING)
        )
    } else {
        format!("{what} too large")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_estimate_refuses_and_names_the_figures() {
        let limits = Limits {
            max_memory: 1 << 30,
            ..Limits::default()
        };
        assert!(limits.check_mesh(1000).is_ok());
        let e = limits.check_mesh(8_000_000).unwrap_err();
        assert!(e.contains("8000000 nodes") && e.contains("1024 MiB"), "{e}");
        assert!(limits.check_mesh(u64::MAX).is_err());
    }

    #[test]
    fn proc_figures_are_read() {
        assert!(machine_memory().unwrap() > 1 << 20);
        let rss = peak_memory().unwrap();
        assert!(rss > 1 << 16 && rss < machine_memory().unwrap());
    }
}
