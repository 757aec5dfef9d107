//! First iterates of an increment's Newton solve: the extrapolating predictor (the last
//! increment's motion continued), the linearised Dirichlet predictor (prescribed jumps
//! spread over the body by one tangent solve) and the seating of force-controlled tools
//! that touch nothing at the first iterate.

use crate::solver::assembly::force_control;
use crate::solver::assembly::{Evaluation, IncrementContext, PhaseTimes};
use crate::solver::linear::LinearSolver;
use crate::solver::newton::Newton;
use crate::Result;
use std::time::Instant;

impl Newton<'_> {
    /// The last increment's displacement change, scaled to this step, added to `x`: in
    /// forming the sheet keeps moving the way it moved, so the first iterate starts near the
    /// right contact statuses (from the committed state, Newton has to rediscover the whole
    /// active set, tens of iterations on a drawn sheet). O(dofs).
    pub(super) fn extrapolate(&self, t_new: f64, x: &mut [f64]) {
        if let Some((dt_last, dx)) = &self.last_step {
            let ratio = (t_new - self.time) / dt_last;
            for (xi, d) in x.iter_mut().zip(dx) {
                *xi += ratio * d;
            }
        }
    }

    /// Linearised Dirichlet predictor: when prescribed values change, the first update
    /// solves the tangent system at the committed state with the prescribed increments as
    /// its constraint rows, so the increment's jump spreads over the body instead of
    /// straining only the elements next to the moved nodes (such a first iterate can
    /// carry a plastic body far outside Newton's basin). For a linear problem the
    /// predictor is the solution.
    pub(super) fn dirichlet_predictor(
        &self,
        ctx: &IncrementContext<'_>,
        t_new: f64,
        x: &mut [f64],
        linear: &mut dyn LinearSolver,
        times: &mut PhaseTimes,
    ) -> Result<()> {
        let jumps: Vec<(usize, f64)> = self
            .model
            .dirichlet
            .iter()
            .filter(|bc| bc.value.value(t_new) != bc.value.value(self.time))
            .flat_map(|bc| {
                let v = bc.value.value(t_new);
                bc.nodes.iter().map(move |&n| (3 * n + bc.component, v))
            })
            .collect();
        if jumps.is_empty() {
            return Ok(());
        }
        let mut eval = ctx.evaluate(x, times)?;
        for &(d, v) in &jumps {
            eval.residual[d] = x[d] - v;
        }
        let ts = Instant::now();
        let dx = self.newton_step(&eval, linear)?;
        times.factorization_and_solve += ts.elapsed().as_secs_f64();
        for (xi, d) in x.iter_mut().zip(&dx) {
            *xi += d;
        }
        Ok(())
    }

    /// Seats every force-controlled tool that touches no node at `eval` (the evaluation of
    /// `x`): its offset moves along its axis by the approach travel, into touch with the
    /// nearest node ahead of it (overlapping it by a thousandth of the contact tolerance, so
    /// that a node touching with a zero multiplier counts as touching, not as a round-off
    /// gap). Returns whether an offset moved (then `x` must be evaluated again).
    ///
    /// Why: a tool touching nothing has the approach equation as its row, and the Newton
    /// step that solves it also moves the body under a Jacobian without that tool. Where
    /// the tool is what holds the body (a holder pressing a strip's flange), that Jacobian
    /// is nearly singular: on the U-channel an extrapolated start opened the holder's four
    /// nodes by 1e-4 mm, and the step moved nodes by 20 mm and turned elements inside out.
    /// Moving the offset alone changes only the start of Newton, not the discrete problem
    /// (the offset is an unknown like the others). O(candidates).
    pub(super) fn seat_force_controlled_tools(&self, eval: &Evaluation, x: &mut [f64]) -> bool {
        let overlap = 1e-3 * self.model.settings.contact_tol;
        let mut moved = false;
        for c in 0..self.model.contacts.len() {
            let Some(s) = self.dofs.tool_offset[c] else {
                continue;
            };
            if !force_control::approaching(&self.model, c, eval.time, &eval.nodal) {
                continue;
            }
            if let Some(travel) = force_control::approach_travel(&self.model, c, &eval.nodal) {
                x[s] += travel + overlap;
                moved = true;
            }
        }
        moved
    }
}
