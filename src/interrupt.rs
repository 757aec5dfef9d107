//! A request to stop, raised by SIGINT/SIGTERM (or by a caller) and polled by the stepping
//! loop: between increments by the script layer, between Newton iterations by the solver,
//! which then abandons the increment and keeps the last converged state.
//!
//! The flag is a handle, not a process global, so that runs inside one process (tests, the
//! studies) do not interrupt each other; `tribo run` and `tribo repl` connect the handle of
//! their run to the process's signals with [`Interrupt::install_signal_handlers`]. A second
//! signal while the flag is still raised, more than [`REPEAT_WINDOW_NS`] after the first,
//! ends the process at once (exit status 130), for a run that does not reach its next poll
//! soon enough. One sooner is taken as the same request: GNU `timeout` sends its signal to
//! the run and then to its whole process group, so the run receives it twice within
//! microseconds, and exiting on the second lost the summary, the final checkpoint and the
//! folder's lock (issue 52).
//!
//! The handle also carries the run's memory bound (`--max-memory-mb`, [`Interrupt::set_memory_limit`]):
//! [`Interrupt::memory_over`] compares the process's peak resident memory with it, and the
//! solver asks at the same polls, so that a run whose assembly or factorisation passes the
//! bound stops within one Newton iteration, keeping its last converged state, instead of
//! running on (issue 52: a 26^3 cube peaked at 2 290 MiB against 2 000).
//!
//! Polling the flag costs one relaxed atomic load; the memory question one `getrusage`
//! (about 0.3 us), asked once per Newton iteration.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;

/// Exit status of a run stopped by a signal (128 + SIGINT, the shell's convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// A repeated signal this soon after the first (1 s, in nanoseconds) is the same request.
/// A person pressing Ctrl-C twice to force the stop takes longer than that.
pub const REPEAT_WINDOW_NS: u64 = 1_000_000_000;

/// Shared stop request; clones see the same flag.
#[derive(Clone, Debug, Default)]
pub struct Interrupt {
    raised: Arc<AtomicBool>,
    /// The signal number that raised the flag (0: raised by a caller).
    signal: Arc<AtomicUsize>,
    /// When the flag was raised (CLOCK_MONOTONIC, nanoseconds).
    raised_at: Arc<AtomicU64>,
    /// Peak resident memory the run may reach, in bytes (0: no bound).
    memory_limit: Arc<AtomicU64>,
}

/// Peak resident memory of this process so far, in bytes (`getrusage`, `ru_maxrss`): it
/// only grows, so it says whether a bound was ever passed.
pub fn peak_memory() -> Option<u64> {
    // SAFETY: getrusage writes into the zeroed struct it is given and has no other effect.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let rc = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    (rc == 0).then(|| usage.ru_maxrss.max(0) as u64 * 1024)
}

/// `bytes` in MiB, rounded, for messages.
pub fn mib(bytes: u64) -> String {
    format!("{:.0} MiB", bytes as f64 / (1u64 << 20) as f64)
}

/// CLOCK_MONOTONIC in nanoseconds (`clock_gettime` is async-signal-safe, so the handler
/// may call it).
fn monotonic_ns() -> u64 {
    // SAFETY: clock_gettime writes into the zeroed struct it is given and has no other effect.
    let mut ts: libc::timespec = unsafe { std::mem::zeroed() };
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    (ts.tv_sec.max(0) as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(ts.tv_nsec.max(0) as u64)
}

impl Interrupt {
    pub fn new() -> Self {
        Self::default()
    }

    /// True once a stop was requested (until [`clear`](Self::clear)).
    pub fn is_raised(&self) -> bool {
        self.raised.load(Ordering::Relaxed)
    }

    /// Requests a stop as if `signal` had arrived (0: no signal, a caller's request).
    pub fn raise(&self, signal: usize) {
        self.raised_at.store(monotonic_ns(), Ordering::SeqCst);
        self.signal.store(signal, Ordering::SeqCst);
        self.raised.store(true, Ordering::SeqCst);
    }

    /// Bounds the peak resident memory of the run (bytes; 0 removes the bound). Clones
    /// share it.
    pub fn set_memory_limit(&self, bytes: u64) {
        self.memory_limit.store(bytes, Ordering::SeqCst);
    }

    /// When the process's peak resident memory is over the bound: the message naming the
    /// memory reached, the limit and the option that raises it.
    pub fn memory_over(&self) -> Option<String> {
        let limit = self.memory_limit.load(Ordering::Relaxed);
        let peak = peak_memory()?;
        (limit > 0 && peak > limit).then(|| {
            format!(
                "the run's memory reached {}, over the limit of {} (raise it with \
                 --max-memory-mb)",
                mib(peak),
                mib(limit)
            )
        })
    }

    /// Withdraws the request (the REPL, back at its prompt).
    pub fn clear(&self) {
        self.raised.store(false, Ordering::SeqCst);
        self.signal.store(0, Ordering::SeqCst);
    }

    /// Why the run stops, for summary.json and messages: "SIGINT received", ...
    pub fn reason(&self) -> String {
        match self.signal.load(Ordering::SeqCst) {
            0 => "stop requested".to_string(),
            s if s == SIGINT as usize => "SIGINT received".to_string(),
            s if s == SIGTERM as usize => "SIGTERM received".to_string(),
            s => format!("signal {s} received"),
        }
    }

    /// Connects SIGINT and SIGTERM to this flag for the rest of the process: the first
    /// raises it; a second one while it is raised exits at once with status 130, unless it
    /// comes within [`REPEAT_WINDOW_NS`] of the first (the same request delivered twice).
    pub fn install_signal_handlers(&self) -> crate::Result<()> {
        for sig in [SIGINT, SIGTERM] {
            let (raised, signal, at) = (
                self.raised.clone(),
                self.signal.clone(),
                self.raised_at.clone(),
            );
            // Only atomics, clock_gettime and _exit: all async-signal-safe.
            let handler = move || {
                let now = monotonic_ns();
                if raised.load(Ordering::SeqCst) {
                    if now.saturating_sub(at.load(Ordering::SeqCst)) > REPEAT_WINDOW_NS {
                        signal_hook::low_level::exit(i32::from(EXIT_INTERRUPTED));
                    }
                    return;
                }
                at.store(now, Ordering::SeqCst);
                signal.store(sig as usize, Ordering::SeqCst);
                raised.store(true, Ordering::SeqCst);
            };
            // SAFETY: the handler does only async-signal-safe work (see above).
            unsafe { signal_hook::low_level::register(sig, handler) }.map_err(|e| {
                crate::Error::Input(format!("cannot install the handler of signal {sig}: {e}"))
            })?;
        }
        Ok(())
    }
}

pub use signal_hook::consts::{SIGINT, SIGTERM};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raise_is_seen_by_clones_and_clear_withdraws_it() {
        let a = Interrupt::new();
        let b = a.clone();
        assert!(!b.is_raised());
        a.raise(SIGTERM as usize);
        assert!(b.is_raised());
        assert_eq!(b.reason(), "SIGTERM received");
        b.clear();
        assert!(!a.is_raised());
        // Another handle is independent.
        let c = Interrupt::new();
        a.raise(SIGINT as usize);
        assert!(!c.is_raised());
        assert_eq!(a.reason(), "SIGINT received");
    }

    #[test]
    fn the_memory_bound_is_shared_and_names_its_figures() {
        let a = Interrupt::new();
        assert!(a.memory_over().is_none(), "no bound by default");
        let peak = peak_memory().unwrap();
        a.clone().set_memory_limit(peak / 2);
        let message = a.memory_over().expect("over half the peak");
        assert!(
            message.contains(&mib(peak / 2)) && message.contains("--max-memory-mb"),
            "{message}"
        );
        // The peak only grows, so a bound above it twice over is not reached here.
        a.set_memory_limit(peak.saturating_mul(2).max(1 << 40));
        assert!(a.memory_over().is_none());
    }
}
