//! Counts of the solid-shell's local EAS solves (module docs of
//! [`super::solid_shell`], "Local solve"): per element call, how many material updates of
//! all its points (local iterations, `U`) it took and how it got there, so that the cost
//! `Σ U / calls` (material updates per element call) can be read off a run and split by
//! the kind of call. The counts are sums, nothing is estimated.
//!
//! Kinds of call ([`CallKind`]): `predicted` (converged from the linearised prediction of
//! the element's memory), `restarted` (the prediction failed or wandered and full steps
//! from the remembered parameters converged; its `U` includes the prediction's passes),
//! `halved` (full steps failed too and the halved steps converged), `cold` (no memory: the
//! first evaluation of a run, or an element without a memory), `failed` (no solve: the
//! call returned an error). Each split into residual-only calls (line-search trials) and
//! calls with the stiffness.
//!
//! Besides: the distribution of `U` over the predicted calls (1, 2, 3, 4 or more) and of
//! the first local step `δ₁ / scale` of every call from a prediction in decades
//! (`<= 1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 1e-1`, larger or not finite): where a call may stop
//! after one update depends on that step alone.
//!
//! The counters are process-wide relaxed atomics (one add per call and kind, against the
//! call's 20 material updates: nothing measurable), so that they need no path through the
//! solver; a summary reports the difference of two [`snapshot`]s. Runs in parallel threads
//! of one process mix their counts.

use std::sync::atomic::{AtomicU64, Ordering};

/// How an element call's local solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CallKind {
    Predicted,
    Restarted,
    Halved,
    Cold,
    Failed,
}

/// The kinds in [`Counts::calls`]' order, with their names in summaries.
pub const KINDS: [(CallKind, &str); 5] = [
    (CallKind::Predicted, "predicted"),
    (CallKind::Restarted, "restarted"),
    (CallKind::Halved, "halved"),
    (CallKind::Cold, "cold"),
    (CallKind::Failed, "failed"),
];

/// Upper ends of the decades of the first local step's histogram ([`Counts::first_step`]);
/// its last bin holds the larger and non-finite steps.
pub const STEP_DECADES: [f64; 6] = [1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 1e-1];

/// Bins of [`Counts::predicted_updates`]: 1, 2, 3, 4 or more material updates.
pub const UPDATE_BINS: usize = 4;

/// A snapshot of the counts (or the difference of two).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Calls per kind ([`KINDS`]' order), `[residual-only, with stiffness]`.
    pub calls: [[u64; 2]; KINDS.len()],
    /// Material updates of all the call's points (local iterations), the same split.
    pub updates: [[u64; 2]; KINDS.len()],
    /// Predicted calls by their number of updates (1, 2, 3, 4 or more).
    pub predicted_updates: [u64; UPDATE_BINS],
    /// Calls from a prediction by their first local step over the strain scale.
    pub first_step: [u64; STEP_DECADES.len() + 1],
}

impl Counts {
    /// All calls.
    pub fn total_calls(&self) -> u64 {
        self.calls.iter().flatten().sum()
    }

    /// All material updates (of every point of a call: one local iteration).
    pub fn total_updates(&self) -> u64 {
        self.updates.iter().flatten().sum()
    }

    /// `self - earlier`, entry by entry.
    pub fn since(&self, earlier: &Counts) -> Counts {
        let mut out = *self;
        for (o, e) in out
            .calls
            .iter_mut()
            .flatten()
            .zip(earlier.calls.iter().flatten())
        {
            *o -= e;
        }
        for (o, e) in out
            .updates
            .iter_mut()
            .flatten()
            .zip(earlier.updates.iter().flatten())
        {
            *o -= e;
        }
        for (o, e) in out
            .predicted_updates
            .iter_mut()
            .zip(&earlier.predicted_updates)
        {
            *o -= e;
        }
        for (o, e) in out.first_step.iter_mut().zip(&earlier.first_step) {
            *o -= e;
        }
        out
    }
}

const ZERO: AtomicU64 = AtomicU64::new(0);
static CALLS: [AtomicU64; 2 * KINDS.len()] = [ZERO; 2 * KINDS.len()];
static UPDATES: [AtomicU64; 2 * KINDS.len()] = [ZERO; 2 * KINDS.len()];
static PREDICTED_UPDATES: [AtomicU64; UPDATE_BINS] = [ZERO; UPDATE_BINS];
static FIRST_STEP: [AtomicU64; STEP_DECADES.len() + 1] = [ZERO; STEP_DECADES.len() + 1];

/// Records one call: its kind, whether it formed the stiffness, its material updates and,
/// from a prediction, its first local step over the strain scale.
pub(super) fn record(kind: CallKind, stiffness: bool, updates: usize, first_step: Option<f64>) {
    let k = KINDS.iter().position(|(c, _)| *c == kind).unwrap_or(0);
    let slot = 2 * k + usize::from(stiffness);
    CALLS[slot].fetch_add(1, Ordering::Relaxed);
    UPDATES[slot].fetch_add(updates as u64, Ordering::Relaxed);
    if kind == CallKind::Predicted {
        let bin = updates.clamp(1, UPDATE_BINS) - 1;
        PREDICTED_UPDATES[bin].fetch_add(1, Ordering::Relaxed);
    }
    if let Some(step) = first_step {
        let bin = STEP_DECADES
            .iter()
            .position(|&top| step <= top)
            .unwrap_or(STEP_DECADES.len());
        FIRST_STEP[bin].fetch_add(1, Ordering::Relaxed);
    }
}

/// The counts so far in this process.
pub fn snapshot() -> Counts {
    let load = |a: &AtomicU64| a.load(Ordering::Relaxed);
    Counts {
        calls: std::array::from_fn(|k| [load(&CALLS[2 * k]), load(&CALLS[2 * k + 1])]),
        updates: std::array::from_fn(|k| [load(&UPDATES[2 * k]), load(&UPDATES[2 * k + 1])]),
        predicted_updates: std::array::from_fn(|b| load(&PREDICTED_UPDATES[b])),
        first_step: std::array::from_fn(|b| load(&FIRST_STEP[b])),
    }
}
