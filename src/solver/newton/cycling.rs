//! Detection of active-set cycling within one increment's Newton iterations.
//!
//! The generalised Newton method on the Alart-Curnier operator is a semismooth Newton
//! method: each iteration picks a status (gap, stick, slip) per node from the augmented
//! multiplier. Near the boundary of the Coulomb cone (|sigma_t| ≈ mu |sigma_n|, large mu) or
//! at the edge of the contact zone, a node can flip back and forth between two statuses
//! from one iterate to the next, and Newton never settles. The monitor counts each node's
//! status changes within the increment; a node that changed `cycle_flips` times cycles.
//!
//! Treatment ([`AntiCycling`]): `Freeze` fixes the cycling node's status for the rest of
//! the increment -- slip if slip took part in the cycle (the force then lies on the cone,
//! so Coulomb's inequality holds), else stick (no penetration) -- so the remaining Newton
//! problem is smooth near the solution and converges quadratically. A state that satisfies
//! only the frozen law is not a solution: Newton then releases every status
//! ([`CyclingMonitor::release`]) and goes on with the free law from there, close to the
//! solution; nodes that cycle again may be frozen again, a bounded number of times, after
//! which the free law alone decides. `Damp` halves the Newton update while a node cycles
//! instead.

use crate::contact::ContactStatus;
use crate::solver::settings::AntiCycling;

/// Per (tool, candidate) status history of the current increment.
#[derive(Clone, Debug)]
pub struct CyclingMonitor {
    last: Vec<Vec<Option<ContactStatus>>>,
    flips: Vec<Vec<usize>>,
    /// Flips counted, and statuses frozen, before the last release (for the report).
    released_flips: Vec<Vec<usize>>,
    released_frozen: Vec<Vec<Option<ContactStatus>>>,
    seen_slip: Vec<Vec<bool>>,
    /// Status imposed on each pair (None: free).
    pub frozen: Vec<Vec<Option<ContactStatus>>>,
    treatment: AntiCycling,
    threshold: usize,
}

/// A node whose status cycled within an increment.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CyclingNode {
    pub tool: usize,
    pub node: usize,
    pub flips: usize,
    /// The status it was frozen to (None when not frozen).
    pub frozen: Option<String>,
}

impl CyclingMonitor {
    /// `sizes`: number of candidates of each tool.
    pub fn new(sizes: &[usize], treatment: AntiCycling, threshold: usize) -> Self {
        CyclingMonitor {
            last: sizes.iter().map(|&n| vec![None; n]).collect(),
            flips: sizes.iter().map(|&n| vec![0; n]).collect(),
            released_flips: sizes.iter().map(|&n| vec![0; n]).collect(),
            released_frozen: sizes.iter().map(|&n| vec![None; n]).collect(),
            seen_slip: sizes.iter().map(|&n| vec![false; n]).collect(),
            frozen: sizes.iter().map(|&n| vec![None; n]).collect(),
            treatment,
            threshold,
        }
    }

    /// Records the statuses of one Newton iterate; returns true when a node starts cycling
    /// and is frozen now (the caller must re-evaluate with the frozen statuses).
    pub fn observe(&mut self, statuses: impl Fn(usize, usize) -> ContactStatus) -> bool {
        let mut newly_frozen = false;
        for c in 0..self.last.len() {
            for k in 0..self.last[c].len() {
                let s = statuses(c, k);
                if s == ContactStatus::Slip {
                    self.seen_slip[c][k] = true;
                }
                if let Some(prev) = self.last[c][k] {
                    if prev != s {
                        self.flips[c][k] += 1;
                    }
                }
                self.last[c][k] = Some(s);
                if self.treatment == AntiCycling::Freeze
                    && self.frozen[c][k].is_none()
                    && self.flips[c][k] >= self.threshold
                {
                    self.frozen[c][k] = Some(if self.seen_slip[c][k] {
                        ContactStatus::Slip
                    } else {
                        ContactStatus::Stick
                    });
                    newly_frozen = true;
                }
            }
        }
        newly_frozen
    }

    /// Frees every frozen status and forgets the flips counted so far, so that Newton goes on
    /// with the free law from where the frozen problem converged; `freeze_again`: whether
    /// nodes that cycle once more may be frozen again.
    pub fn release(&mut self, freeze_again: bool) {
        for (past, now) in self.released_frozen.iter_mut().zip(&mut self.frozen) {
            for (p, n) in past.iter_mut().zip(now.iter_mut()) {
                *p = n.take().or(*p);
            }
        }
        for (past, now) in self.released_flips.iter_mut().zip(&mut self.flips) {
            for (p, n) in past.iter_mut().zip(now.iter_mut()) {
                *p += *n;
                *n = 0;
            }
        }
        if !freeze_again {
            self.treatment = AntiCycling::Off;
        }
    }

    /// Some node is cycling now (flipped at least `threshold` times).
    pub fn cycling(&self) -> bool {
        self.flips.iter().flatten().any(|&f| f >= self.threshold)
    }

    /// The frozen statuses, or None when nothing is frozen (the free operator).
    pub fn forced(&self) -> Option<Vec<Vec<Option<ContactStatus>>>> {
        self.frozen
            .iter()
            .flatten()
            .any(Option::is_some)
            .then(|| self.frozen.clone())
    }

    /// Damping factor of the Newton update (1 unless `Damp` and a node cycles).
    pub fn damping(&self) -> f64 {
        if self.treatment == AntiCycling::Damp && self.cycling() {
            0.5
        } else {
            1.0
        }
    }

    /// Nodes that cycled, with mesh node numbers from `node_of(tool, candidate)`.
    pub fn report(&self, node_of: impl Fn(usize, usize) -> usize) -> Vec<CyclingNode> {
        let mut out = Vec::new();
        for (c, flips) in self.flips.iter().enumerate() {
            for (k, &f) in flips.iter().enumerate() {
                let f = f + self.released_flips[c][k];
                if f >= self.threshold {
                    out.push(CyclingNode {
                        tool: c,
                        node: node_of(c, k),
                        flips: f,
                        frozen: self.frozen[c][k]
                            .or(self.released_frozen[c][k])
                            .map(|s| format!("{s:?}").to_lowercase()),
                    });
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ContactStatus::*;

    #[test]
    fn a_node_flipping_stick_slip_is_frozen_to_slip_after_threshold_flips() {
        let mut m = CyclingMonitor::new(&[2], AntiCycling::Freeze, 3);
        let seq = [Stick, Slip, Stick, Slip];
        let mut frozen_at = None;
        for (i, s) in seq.iter().enumerate() {
            // Node 1 goes gap -> stick once and stays: not cycling.
            let other = if i == 0 { Gap } else { Stick };
            if m.observe(|_, k| if k == 0 { *s } else { other }) {
                frozen_at = Some(i);
            }
        }
        assert_eq!(frozen_at, Some(3), "third flip at the fourth iterate");
        assert_eq!(m.frozen[0], vec![Some(Slip), None]);
        let r = m.report(|_, k| 10 + k);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].node, 10);
        assert_eq!(r[0].flips, 3);
        assert_eq!(m.damping(), 1.0);

        let mut d = CyclingMonitor::new(&[1], AntiCycling::Damp, 2);
        d.observe(|_, _| Gap);
        d.observe(|_, _| Stick);
        assert_eq!(d.damping(), 1.0);
        assert!(!d.observe(|_, _| Gap), "damping freezes nothing");
        assert_eq!(d.damping(), 0.5);
        assert!(d.forced().is_none());
    }

    #[test]
    fn release_frees_the_statuses_and_keeps_the_report() {
        let mut m = CyclingMonitor::new(&[1], AntiCycling::Freeze, 2);
        for s in [Gap, Stick, Gap] {
            m.observe(|_, _| s);
        }
        assert!(m.forced().is_some(), "frozen after two flips");
        m.release(true);
        assert!(m.forced().is_none(), "released: the free law decides");
        let r = m.report(|_, k| k);
        assert_eq!((r[0].flips, r[0].frozen.as_deref()), (2, Some("stick")));
        // Flips are counted afresh: one more flip does not freeze it again...
        assert!(!m.observe(|_, _| Stick));
        // ...two do, while freezing again is allowed...
        assert!(m.observe(|_, _| Gap));
        // ...and after a final release nothing is frozen any more.
        m.release(false);
        for s in [Stick, Gap, Stick, Gap] {
            assert!(!m.observe(|_, _| s));
        }
        assert!(m.forced().is_none());
        assert_eq!(m.report(|_, k| k)[0].flips, 2 + 2 + 4);
    }
}
