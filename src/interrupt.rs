//! A request to stop, raised by SIGINT/SIGTERM (or by a caller) and polled by the stepping
//! loop: between increments by the script layer, between Newton iterations by the solver,
//! which then abandons the increment and keeps the last converged state.
//!
//! The flag is a handle, not a process global, so that runs inside one process (tests, the
//! studies) do not interrupt each other; `tribo run` and `tribo repl` connect the handle of
//! their run to the process's signals with [`Interrupt::install_signal_handlers`]. A second
//! signal while the flag is still raised ends the process at once (exit status 130), for a
//! run that does not reach its next poll soon enough.
//!
//! Polling costs one relaxed atomic load.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// Exit status of a run stopped by a signal (128 + SIGINT, the shell's convention).
pub const EXIT_INTERRUPTED: u8 = 130;

/// Shared stop request; clones see the same flag.
#[derive(Clone, Debug, Default)]
pub struct Interrupt {
    raised: Arc<AtomicBool>,
    /// The signal number that raised the flag (0: raised by a caller).
    signal: Arc<AtomicUsize>,
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
        self.signal.store(signal, Ordering::SeqCst);
        self.raised.store(true, Ordering::SeqCst);
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
    /// raises it, a second one while it is raised exits at once with status 130.
    pub fn install_signal_handlers(&self) -> crate::Result<()> {
        use signal_hook::flag;
        for sig in [SIGINT, SIGTERM] {
            let fail = |e: std::io::Error| {
                crate::Error::Input(format!("cannot install the handler of signal {sig}: {e}"))
            };
            // Registered first, so it sees the flag as it was before this signal.
            flag::register_conditional_shutdown(
                sig,
                i32::from(EXIT_INTERRUPTED),
                self.raised.clone(),
            )
            .map_err(fail)?;
            flag::register_usize(sig, self.signal.clone(), sig as usize).map_err(fail)?;
            flag::register(sig, self.raised.clone()).map_err(fail)?;
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
}
