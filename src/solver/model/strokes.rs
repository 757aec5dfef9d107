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
//!
//! Geometry updated by the wear (optional, `update_geometry_every = k`). After every k
//! strokes the tools' surfaces are replaced by the exact surfaces worn by the wear depth
//! accumulated so far (`tool::worn`: a normal offset by the depth of each field cell):
//! strokes 1..k run on the new tools, strokes k+1..2k on the tools worn by strokes 1..k,
//! and so on; stroke `j` (1-based) runs on the wear of strokes `1..=k floor((j - 1) / k)`.
//! Each stroke then differs from the one before, so extrapolation is refused with it.

use crate::{Error, Result};

/// How many strokes, and how many of them are simulated (the rest extrapolated).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strokes {
    /// Strokes of the production run (N >= 1).
    pub total: usize,
    /// Strokes simulated (1 <= m <= N); `m < N`: the tool-side fields are extrapolated
    /// linearly from them to N.
    pub simulated: usize,
    /// `Some(k)`: the tools' geometry is updated by their wear after every k strokes
    /// (module doc); `None`: the tools keep their exact surfaces.
    pub update_geometry_every: Option<usize>,
}

impl Default for Strokes {
    /// One stroke, simulated: a run as without strokes.
    fn default() -> Self {
        Strokes {
            total: 1,
            simulated: 1,
            update_geometry_every: None,
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
            update_geometry_every: None,
        })
    }

    /// These strokes with the tools' geometry updated by their wear after every `every`
    /// strokes. Errors name the value.
    pub fn updating_geometry_every(self, every: i64) -> Result<Strokes> {
        if every < 1 {
            return Err(Error::input(
                "strokes between geometry updates (update_geometry_every)",
                every,
                "must be >= 1",
            ));
        }
        Ok(Strokes {
            update_geometry_every: Some(every as usize),
            ..self
        })
    }

    /// Whether the tools' geometry is updated by their wear when stroke `stroke` (from 0)
    /// starts: after every `k` strokes, never before the first.
    pub fn updates_geometry_at(&self, stroke: usize) -> bool {
        matches!(self.update_geometry_every, Some(k) if stroke > 0 && stroke % k == 0)
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

    #[test]
    fn the_geometry_is_updated_after_every_k_strokes_only() {
        let s = Strokes::new(7, 7).unwrap();
        assert!((0..7).all(|j| !s.updates_geometry_at(j)));
        let s = s.updating_geometry_every(3).unwrap();
        let at: Vec<usize> = (0..7).filter(|&j| s.updates_geometry_at(j)).collect();
        // Strokes 4 and 7 (1-based) start on the wear of strokes 1-3 and 1-6.
        assert_eq!(at, vec![3, 6]);
        let e = s.updating_geometry_every(0).unwrap_err().to_string();
        assert!(
            e.contains("update_geometry_every") && e.contains('0'),
            "{e}"
        );
    }
}
