//! A production run of several strokes of the same process (issue 53): what is asked, not
//! how it runs (that is `solver::simulation::strokes`).
//!
//! Stroke `k` (1-based) is the whole process, from pseudo-time 0 to the end time, on a new
//! blank: the sheet's state (displacements, multipliers, plastic state, contact history,
//! energy) starts as the model's initial state and the tools start at their schedules'
//! t = 0 poses. Only the tools' side carries over: their tool-side fields (work per area,
//! sliding distance, pressures, wear) keep accumulating.
//!
//! Extrapolation. When nothing the process reads depends on the tools' state, every stroke
//! is the same and adds the same increment `dF` to each additive tool-side field (work,
//! sliding distance, time-integrated pressure, wear), so after `simulated` strokes of `total`
//! the fields are scaled by `total / simulated`: `F_N = N dF = (N / m) F_m`. The peak
//! pressure is a maximum over the strokes, the same in every stroke: it is kept.

use crate::{Error, Result};

/// How many strokes, and how many of them are simulated (the rest extrapolated).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strokes {
    /// Strokes of the production run (N >= 1).
    pub total: usize,
    /// Strokes simulated (1 <= m <= N); `m < N`: the tool-side fields are extrapolated
    /// linearly from them to N.
    pub simulated: usize,
}

impl Default for Strokes {
    /// One stroke, simulated: a run as without strokes.
    fn default() -> Self {
        Strokes {
            total: 1,
            simulated: 1,
        }
    }
}

impl Strokes {
    /// `total` strokes of which the first `simulated` are simulated. Errors name the value.
    pub fn new(total: i64, simulated: i64) -> Result<Strokes> {
        if total < 1 {
            return Err(Error::input("number of strokes", total, "must be >= 1"));
        }
        if simulated < 1 || simulated > total {
            return Err(Error::input(
                "strokes simulated (simulate)",
                simulated,
                &format!("must be between 1 and the number of strokes {total}"),
            ));
        }
        Ok(Strokes {
            total: total as usize,
            simulated: simulated as usize,
        })
    }

    /// Whether the fields of the strokes not simulated are extrapolated.
    pub fn extrapolated(&self) -> bool {
        self.simulated < self.total
    }

    /// The factor applied to the additive tool-side fields after the last simulated stroke.
    pub fn extrapolation_factor(&self) -> f64 {
        self.total as f64 / self.simulated as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_checked_and_the_factor_is_n_over_m() {
        assert_eq!(Strokes::default(), Strokes::new(1, 1).unwrap());
        let s = Strokes::new(1000, 2).unwrap();
        assert!(s.extrapolated());
        assert_eq!(s.extrapolation_factor(), 500.0);
        assert!(!Strokes::new(3, 3).unwrap().extrapolated());
        let e = Strokes::new(0, 1).unwrap_err().to_string();
        assert!(e.contains("number of strokes"), "{e}");
        let e = Strokes::new(2, 3).unwrap_err().to_string();
        assert!(e.contains("simulate") && e.contains('3'), "{e}");
        assert!(Strokes::new(2, 0).is_err());
    }
}
