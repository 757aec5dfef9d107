//! Backtracking line search on the merit function of the Newton iteration.

use super::assembly::{Evaluation, IncrementContext, PhaseTimes};
use super::simulation::Simulation;
use crate::{Error, Result};

/// Halvings of the line search (smallest step 1/16 of the Newton step).
const LINE_SEARCH_CUTS: usize = 4;
/// Further halvings when no trial of the backtracking is admissible (smallest step
/// 2^-16 of the last trial).
const ADMISSIBLE_CUTS: usize = 16;

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
        if best.is_none() {
            // Every trial down to alpha0/16 was inadmissible (an element turned inside out,
            // a material state out of range): the step is far too long, not wrong in
            // direction, so it is shortened until the state is admissible again.
            if let Some((xn, e)) = self.admissible_fraction(ctx, &trial_x, alpha, times) {
                best = Some((0.0, xn, e));
            }
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

    /// The first admissible trial `trial_x(alpha)` for alpha halved from `alpha` down to
    /// 2^-ADMISSIBLE_CUTS of it (residual-only evaluations, then one whole evaluation of
    /// the one kept), or `None`. Runs only where the ordinary backtracking found no
    /// admissible trial at all, so it changes no run that converged before. O(ADMISSIBLE_CUTS)
    /// residual evaluations at most.
    fn admissible_fraction(
        &self,
        ctx: &IncrementContext<'_>,
        trial_x: &dyn Fn(f64) -> Vec<f64>,
        mut alpha: f64,
        times: &mut PhaseTimes,
    ) -> Option<(Vec<f64>, Evaluation)> {
        for _ in 0..ADMISSIBLE_CUTS {
            let xn = trial_x(alpha);
            if ctx.evaluate_residual(&xn, times).is_ok() {
                let e = ctx.evaluate(&xn, times).ok()?;
                return Some((xn, e));
            }
            alpha *= 0.5;
        }
        None
    }
}
