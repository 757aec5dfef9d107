//! When a run writes a frame: by an interval of (pseudo-)time, travel in a forming script,
//! or every n increments; always at the start and at the end.
//!
//! With an interval `h`, a frame is due when the committed time reaches the next multiple of
//! `h` after the last frame's time: frames land near 0, h, 2h, ... whatever the increments,
//! so adaptive stepping with many small increments writes no more frames than fixed
//! stepping. A multiple reached within `1e-9 h` counts as reached (round-off of summed
//! increments). The due test needs only the last frame's time, so a restarted run keeps
//! the cadence.

use crate::{Error, Result};

/// How many frames a run writes when nothing is set: an interval of `end_time / 20`.
pub const DEFAULT_FRAMES: usize = 20;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cadence {
    /// A frame every `n` increments (`n >= 1`), and at the end.
    Increments(usize),
    /// A frame each time the time passes a multiple of this interval (> 0), and at the end.
    Interval(f64),
}

impl Cadence {
    /// The default cadence of a run to `end_time`.
    pub fn default_for(end_time: f64) -> Cadence {
        Cadence::Interval(end_time / DEFAULT_FRAMES as f64)
    }

    /// An interval cadence, checked.
    pub fn interval(h: f64) -> Result<Cadence> {
        if h > 0.0 && h.is_finite() {
            Ok(Cadence::Interval(h))
        } else {
            Err(Error::input("output_interval", h, "must be > 0 and finite"))
        }
    }

    /// Whether increment `index`, converged at `time`, gets a frame, the last frame being at
    /// `last_frame` (`None`: no frame yet). `finished`: the run has reached its end.
    pub fn due(self, index: usize, time: f64, last_frame: Option<f64>, finished: bool) -> bool {
        let Some(last) = last_frame else {
            return true;
        };
        if finished {
            return time > last;
        }
        match self {
            Cadence::Increments(n) => n > 0 && index % n == 0,
            Cadence::Interval(h) => {
                let next = ((last / h) + 1e-9).floor() + 1.0;
                time / h >= next - 1e-9
            }
        }
    }

    /// A short description for summary.json ("every 3 increments", "every 1.5 of time").
    pub fn describe(self) -> String {
        match self {
            Cadence::Increments(n) => format!("every {n} increments"),
            Cadence::Interval(h) => format!("every {} of time", super::fmt_f64(h)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames of a run stepping `times`, with the cadence `c`.
    fn frames(c: Cadence, times: &[f64], end: f64) -> Vec<f64> {
        let mut out = vec![0.0];
        for (i, &t) in times.iter().enumerate() {
            if c.due(i + 1, t, out.last().copied(), t >= end) {
                out.push(t);
            }
        }
        out
    }

    #[test]
    fn interval_frames_follow_time_not_increments() {
        // 30 mm in 300 small increments of 0.1 mm, frames every 1.5 mm: 21 frames.
        let times: Vec<f64> = (1..=300).map(|i| i as f64 * 0.1).collect();
        let f = frames(Cadence::Interval(1.5), &times, 30.0);
        assert_eq!(f.len(), 21);
        for (k, t) in f.iter().enumerate() {
            assert!((t - 1.5 * k as f64).abs() < 1e-9, "frame {k} at {t}");
        }
        // Uneven adaptive steps: one frame per crossed multiple, never two in one interval.
        let times = [0.2, 0.9, 1.4, 1.6, 4.0, 4.2, 4.6, 6.0];
        let f = frames(Cadence::Interval(1.5), &times, 6.0);
        assert_eq!(f, vec![0.0, 1.6, 4.0, 4.6, 6.0]);
        // The end is always a frame, once.
        let f = frames(Cadence::Interval(10.0), &[1.0, 2.0, 3.0], 3.0);
        assert_eq!(f, vec![0.0, 3.0]);
        assert!(!Cadence::Interval(1.0).due(4, 3.0, Some(3.0), true));
        // Round-off: 0.1 summed 15 times is 1.5000000000000002 or 1.4999999999999998.
        let t: f64 = (0..15).map(|_| 0.1).sum();
        assert!(Cadence::Interval(1.5).due(15, t, Some(0.0), false));
        assert!(Cadence::Interval(1.5).due(15, 1.5 - 1e-12, Some(0.0), false));
    }

    #[test]
    fn increment_cadence_and_checks() {
        let times: Vec<f64> = (1..=7).map(|i| i as f64).collect();
        assert_eq!(
            frames(Cadence::Increments(3), &times, 7.0),
            vec![0.0, 3.0, 6.0, 7.0]
        );
        assert_eq!(
            Cadence::default_for(30.0),
            Cadence::Interval(30.0 / DEFAULT_FRAMES as f64)
        );
        assert!(Cadence::interval(0.0).is_err());
        let err = Cadence::interval(f64::NAN).unwrap_err().to_string();
        assert!(err.contains("output_interval"), "{err}");
    }
}
