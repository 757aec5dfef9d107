//! What the element microbenchmarks share: a clock that other processes do not inflate,
//! and reproducible pseudo-random numbers.
use std::time::Instant;

/// Timed rounds per kernel, interleaved so that drift of a shared machine hits all alike.
pub const ROUNDS: usize = 9;

/// Seconds of processor time this thread has used, if the system reports it.
pub fn thread_cpu_seconds() -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9)
}

/// A clock for one round: thread CPU time, else wall time since `wall`.
pub fn clock(wall: &Instant) -> f64 {
    thread_cpu_seconds().unwrap_or_else(|| wall.elapsed().as_secs_f64())
}

/// Uniform numbers in [-1, 1) from a 64-bit linear congruential generator: the same
/// sequence on every machine.
pub struct Uniform(u64);

impl Uniform {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// Evaluations per round: the first command-line argument, else `default`.
pub fn evaluations(default: usize) -> usize {
    std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("EVALUATIONS must be a number"))
        .unwrap_or(default)
}
