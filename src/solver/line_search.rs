//! Backtracking line search on the merit function of the Newton iteration.

use super::assembly::{Evaluation, IncrementContext, PhaseTimes};
use super::simulation::Simulation;
use crate::{Error, Result};

/// Halvings of the line search (smallest step 1/16 of the Newton step).
const LINE_SEARCH_CUTS: usize = 4;

impl Simulation {
    /// Backtracking (Armijo) line search on the merit function |R|: the step `alpha dx` with
    /// the first alpha in `alpha0, alpha0/2, ...` (down to `alpha0/16`) that reduces the merit
    /// by the factor `1 - 1e-4 alpha`; failing that, the trial with the smallest merit. A
    /// trial that inverts an element counts as an infinite merit. With the line search off,
    /// the step `alpha0 dx` is taken. Returns the new unknowns, their evaluation and the
    /// number of backtracking steps. A full step (`alpha0 = 1`) that fails the merit test
    /// is still taken if `accept_full` says so (the contraction test).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn line_search(
        &self,
        ctx: &IncrementContext<'_>,
        x: &[f64],
        dx: &[f64],
        merit0: f64,
        alpha0: f64,
        weights: &[f64],
        accept_full: &mut dyn FnMut(&Evaluation) -> Result<bool>,
        times: &mut PhaseTimes,
    ) -> Result<(Vec<f64>, Evaluation, usize)> {
        let trial_x =
            |alpha: f64| -> Vec<f64> { x.iter().zip(dx).map(|(xi, d)| xi + alpha * d).collect() };
        if !self.model.settings.stepping.line_search {
            let xn = trial_x(alpha0);
            let e = ctx.evaluate(&xn, times)?;
            return Ok((xn, e, 0));
        }
        let mut alpha = alpha0;
        let mut best: Option<(f64, Vec<f64>, Evaluation)> = None;
        let mut last_err = None;
        for cut in 0..=LINE_SEARCH_CUTS {
            let xn = trial_x(alpha);
            // The full step, usually accepted, is evaluated whole; a cut only for its
            // residual, and given its Jacobian once accepted (`complete`: the element
            // tangents, no second contact pass).
            let evaluated = if cut == 0 {
                ctx.evaluate(&xn, times)
            } else {
                ctx.evaluate_residual(&xn, times)
            };
            match evaluated {
                Ok(e) => {
                    let m = self.residual_record(&e, weights).1;
                    if m.is_finite() && m <= (1.0 - 1e-4 * alpha) * merit0 {
                        let e = ctx.complete(&xn, e, times)?;
                        return Ok((xn, e, cut));
                    }
                    if cut == 0 && alpha0 == 1.0 && m.is_finite() && accept_full(&e)? {
                        return Ok((xn, e, 0));
                    }
                    if m.is_finite() && best.as_ref().is_none_or(|b| m < b.0) {
                        best = Some((m, xn, e));
                    }
                }
                Err(err) => last_err = Some(err),
            }
            alpha *= 0.5;
        }
        match (best, last_err) {
            (Some((_, xn, e)), _) => {
                let e = ctx.complete(&xn, e, times)?;
                Ok((xn, e, LINE_SEARCH_CUTS))
            }
            (None, Some(err)) => Err(err),
            (None, None) => Err(Error::NoConvergence(
                "non-finite residual at every line-search step".into(),
            )),
        }
    }
}
