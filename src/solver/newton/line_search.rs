//! Backtracking line search on the merit function of the Newton iteration.

use crate::solver::assembly::{Evaluation, IncrementContext, PhaseTimes};
use crate::solver::newton::Newton;
use crate::{Error, Result};

/// Halvings of the line search (smallest step 1/16 of the Newton step).
const LINE_SEARCH_CUTS: usize = 4;
/// Further halvings, residual-only, when every trial down to 1/16 raised the merit at
/// least `KINK_MERIT_RISE` times (smallest step 2^-16 of the Newton step); see
/// [`Newton::line_search`].
const DEEP_CUTS: usize = 12;
/// How many times the merit of the best trial down to 1/16 must exceed the start's for the
/// deeper cuts: along a Newton step the merit's slope at the start is `-|R|`, so a tenfold
/// rise within 1/16 of the step means a status switched close to its start (a kink), not
/// curvature (U-channel: x 60 to x 900 at 1/16). A threshold of 1 or 2 also took the deeper
/// cuts at milder rises and cost the coarse cups iterations; at 10 they keep theirs.
const KINK_MERIT_RISE: f64 = 10.0;

impl Newton<'_> {
    /// Backtracking (Armijo) line search on the merit function |R|: the step `alpha dx` with
    /// the first alpha in `alpha0, alpha0/2, ...` (down to `alpha0/16`) that reduces the merit
    /// by the factor `1 - 1e-4 alpha`; failing that, the trial with the smallest merit. A
    /// trial that inverts an element counts as an infinite merit. With the line search off,
    /// the step `alpha0 dx` is taken. Returns the new unknowns, their evaluation and the
    /// number of backtracking steps. A full step (`alpha0 = 1`) that fails the merit test
    /// is still taken if `accept_full` says so (the contraction test).
    ///
    /// When every trial down to 1/16 raises the merit tenfold or more, the search goes on
    /// halving (to 2^-16, residual-only evaluations) and takes the first step that passes
    /// the same test; only if none does, the least bad of the first five trials. Why: a
    /// Newton step computed
    /// while a node lies a round-off gap off a tool (a flat flange under a flat holder, gaps
    /// of 1e-6 mm) pushes that node into the tool after a tiny fraction of the step, so the
    /// merit rises linearly from that fraction on and every trial down to 1/16 raises it
    /// (by 60 to 900 times on the U-channel's holder, where such a step pushed 18 more
    /// flange nodes into it); the least bad trial then moved the strip into a state the next
    /// iterations had to undo, and increments were cut back. The deeper cuts cost one
    /// residual evaluation each, only in that case. A milder rise (1.2-2 times at 1/16,
    /// from material points switching between loading and unloading along the step) keeps
    /// the least bad trial: there the deeper cuts cost the coarse paper cup 9 iterations.
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
        residual_first: bool,
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
            // With `residual_first`, the full step too is evaluated for its residual only
            // and returned without its Jacobian when accepted: the iterate it leads to is
            // expected to converge, and then none is needed (Newton completes it if not).
            let evaluated = if cut == 0 && !residual_first {
                ctx.evaluate(&xn, times)
            } else {
                ctx.evaluate_residual(&xn, times)
            };
            match evaluated {
                Ok(e) => {
                    let m = self.residual_record(&e, weights).1;
                    if m.is_finite() && m <= (1.0 - 1e-4 * alpha) * merit0 {
                        let e = match cut == 0 && residual_first {
                            true => e,
                            false => ctx.complete(&xn, e, times)?,
                        };
                        return Ok((xn, e, cut));
                    }
                    // The contraction test solves with the trial's Jacobian (`complete`
                    // returns a full evaluation as it is).
                    let contraction = cut == 0 && alpha0 == 1.0 && m.is_finite();
                    let e = match contraction {
                        true => ctx.complete(&xn, e, times)?,
                        false => e,
                    };
                    if contraction && accept_full(&e)? {
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
        let kink_near_start = best.as_ref().is_none_or(|b| b.0 > KINK_MERIT_RISE * merit0);
        let deep = if kink_near_start { DEEP_CUTS } else { 0 };
        for cut in LINE_SEARCH_CUTS + 1..=LINE_SEARCH_CUTS + deep {
            let xn = trial_x(alpha);
            if let Ok(e) = ctx.evaluate_residual(&xn, times) {
                let m = self.residual_record(&e, weights).1;
                if m.is_finite() && m <= (1.0 - 1e-4 * alpha) * merit0 {
                    let e = ctx.complete(&xn, e, times)?;
                    return Ok((xn, e, cut));
                }
            }
            alpha *= 0.5;
        }
        match (best, last_err) {
            (Some((_, xn, e)), _) => {
                let e = ctx.complete(&xn, e, times)?;
                Ok((xn, e, LINE_SEARCH_CUTS))
            }
            (None, Some(err)) => Err(crate::element::prefix(
                err,
                "every line-search trial failed, the last one",
            )),
            (None, None) => Err(Error::no_convergence(
                crate::error::Failure::NonFinite,
                "non-finite residual at every line-search step",
            )),
        }
    }
}
